//! The code-space helpers of the check: every input code up to 1.0 with its `ln c` and d's
//! reference ([`CodeColumns`]), `cos^n`, the f64 base, and the prefixes proven dead or zero
//! (by bisection where the configuration proves them monotone) that need no evaluation.

use crate::engine::Codes;
use crate::error::Error;
use crate::fixed::{Event, Overflow};
use crate::pipeline::datapath::CutStructure;
use crate::pipeline::{first_code_where, Datapath, NConstants};
use crate::reference::lobe::Cutoff;

/// Codes evaluated per batch: small enough for the columns to stay in cache.
pub(super) const CHUNK: usize = 2048;

/// The f64 base of the same algorithm: `t + offset` after the cutoff (`cut_by_threshold`: the
/// clamped input is below the paper cutoff's threshold code).
#[inline]
pub(super) fn reference_base(cutoff: Cutoff, t: f64, offset: f64, cut_by_threshold: bool) -> f64 {
    let sum = t + offset;
    if cutoff.cuts(sum < 0.0, cut_by_threshold) {
        0.0
    } else {
        sum
    }
}

/// The end of the dead prefix of one n: every code below it is cut in the fixed-point model
/// and has a base of 0 in the f64 model, so its b..out stages need no evaluation. Both
/// boundaries are found by bisection where they are proven monotone: the fixed-point cut by
/// [`Datapath::first_live_code`], the f64 base because `c - 1`, the product with a positive
/// slope, the sum and the clamp are each monotone in f64. `codes[0]` where nothing is proven.
pub(super) fn dead_prefix_end(dp: &Datapath, nc: &NConstants, codes: &[i64]) -> i64 {
    let (lo, end) = (codes[0], codes[codes.len() - 1] + 1);
    if dp.cut_structure() != CutStructure::Prefix {
        return lo;
    }
    let fixed = dp.first_live_code(nc, lo..end);
    let cfg = dp.config();
    if cfg.cutoff == Cutoff::Paper {
        // The f64 base is 0 exactly where the clamped code is below the threshold, which is
        // also where the fixed-point base is cut.
        return fixed;
    }
    if nc.slope.is_nan() || nc.slope <= 0.0 {
        return lo;
    }
    let one = dp.one_code();
    let c_lsb = cfg.c.format.lsb();
    let positive = |k: i64| {
        let d = (k.min(one) as f64 * c_lsb) - 1.0;
        reference_base(cfg.cutoff, nc.slope * d, nc.offset, false) != 0.0
    };
    first_code_where(lo..fixed, positive)
}

/// The f64 lobe of code index `i` by the same algorithm (see `reference_probes`).
#[inline]
pub(super) fn f64_lobe_at(dp: &Datapath, nc: &NConstants, shared: &CodeColumns, i: usize) -> f64 {
    let cfg = dp.config();
    let threshold = nc.threshold.unwrap_or(i64::MIN);
    let t = nc.slope * shared.ref_d[i];
    let below = shared.codes.codes[i].min(dp.one_code()) < threshold;
    let mut s = reference_base(cfg.cutoff, t, nc.offset, below);
    for _ in 0..nc.depth {
        s *= s;
    }
    s
}

/// The f64 lobe `s`'s errors over the code indices `range`: `(max |s - cos^n|, max |s coef -
/// peak cos^n|)`, -1 for an empty range.
pub(super) fn floor_over(
    range: std::ops::Range<usize>,
    nc: &NConstants,
    norm_peak: f64,
    s: &dyn Fn(usize) -> f64,
    cos_n: &dyn Fn(usize) -> f64,
) -> (f64, f64) {
    range.fold((-1.0f64, -1.0f64), |(a, na), i| {
        let (s, cn) = (s(i), cos_n(i));
        (
            a.max((s - cn).abs()),
            na.max((s * nc.coef - norm_peak * cn).abs()),
        )
    })
}

/// [`floor_over`] every code: the datapath's floor, the same for every datapath with the
/// same f64 lobe. Below the f64 model's own cut prefix ([`f64_zero_end`]) the f64 lobe is 0
/// and each error is cos^n (times the peak), which grows with c: the prefix's last code
/// stands for it.
pub(super) fn f64_floor(
    dp: &Datapath,
    nc: &NConstants,
    codes: &[i64],
    norm_peak: f64,
    s: &dyn Fn(usize) -> f64,
    cos_n: &dyn Fn(usize) -> f64,
) -> (f64, f64) {
    let z = f64_zero_end(dp, nc, codes);
    let (a, na) = floor_over(z..codes.len(), nc, norm_peak, s, cos_n);
    match z.checked_sub(1).map(cos_n) {
        Some(cn) => (a.max(cn), na.max(norm_peak * cn)),
        None => (a, na),
    }
}

/// The end (a code index) of the prefix of `codes` whose f64 base is proven 0 (cut) for this
/// n, whatever the fixed-point stages: below the threshold with the paper cutoff (the codes
/// are increasing), where the f64 base is 0 with the clamp and a positive slope (found by
/// bisection, as in [`dead_prefix_end`]); 0 otherwise.
pub(super) fn f64_zero_end(dp: &Datapath, nc: &NConstants, codes: &[i64]) -> usize {
    let cfg = dp.config();
    let (lo, end) = (codes[0], codes[codes.len() - 1] + 1);
    let one = dp.one_code();
    let first = match cfg.cutoff {
        Cutoff::Paper => match nc.threshold {
            Some(thr) => first_code_where(lo..end, |k| k.min(one) >= thr),
            None => lo,
        },
        Cutoff::Clamp if nc.slope > 0.0 => {
            let c_lsb = cfg.c.format.lsb();
            first_code_where(lo..end, |k| {
                let d = (k.min(one) as f64 * c_lsb) - 1.0;
                reference_base(cfg.cutoff, nc.slope * d, nc.offset, false) != 0.0
            })
        }
        _ => lo,
    };
    (first - lo) as usize
}

/// The end (a code index) of the zero run of one n: from `n_dead` on, the codes whose
/// fixed-point lobe is 0 (a prefix, [`Datapath::first_nonzero_lobe`]) and whose f64 lobe
/// `f64_lobe` is proven non-decreasing: a positive slope and a base that the cutoff cannot
/// leave negative there (the clamp, or a non-negative base at the run's first code), since
/// `c - 1`, the product, the sum and the squares of non-negative values are each monotone in
/// f64. `n_dead` where nothing is proven.
pub(super) fn zero_run_end(
    dp: &Datapath,
    nc: &NConstants,
    codes: &[i64],
    n_dead: usize,
    f64_lobe: &dyn Fn(usize) -> f64,
) -> usize {
    if n_dead >= codes.len() || nc.slope.is_nan() || nc.slope <= 0.0 {
        return n_dead;
    }
    let cfg = dp.config();
    if cfg.cutoff != Cutoff::Clamp {
        // The base at the run's first code, uncut (s is its square or more, so its sign is
        // not in s): non-negative there, it stays so above.
        let c = codes[n_dead].min(dp.one_code()) as f64 * cfg.c.format.lsb();
        if nc.slope * (c - 1.0) + nc.offset < 0.0 || f64_lobe(n_dead).is_nan() {
            return n_dead;
        }
    }
    let start = codes[n_dead];
    let end = dp.first_nonzero_lobe(nc, start..codes[codes.len() - 1] + 1);
    n_dead + (end - start) as usize
}

/// Per-code inputs shared by every n: the codes with ln c, and d's f64 reference.
pub(super) struct CodeColumns {
    pub(super) codes: Codes,
    pub(super) ref_d: Vec<f64>,
}

/// The whole chunks of `codes` (consecutive codes up to 1.0, [`CHUNK`] each), from the first,
/// that are dead (below `dead_end`) and whose t overflows below its range at every code:
/// `(start, end, t, event index)` of each, with the one value and event t has there (the
/// event index of [`EventCounts`]).
///
/// The proof that t is one value: d = c - 1 is non-decreasing in the code and at most 0, so
/// with a slope of at least 0 the exact product d * slope is non-decreasing and at most 0, and
/// so is its rounding (every rounding mode is monotone); an overflow at the chunk's last code
/// can then only be below the range, and every earlier code's rounded product is lower still,
/// so it overflows too and, unless t wraps, is given the same value with the same event.
pub(super) fn overflowed_chunks<'a>(
    dp: &'a Datapath,
    nc: &'a NConstants,
    codes: &'a [i64],
    dead_end: i64,
) -> impl Iterator<Item = (usize, usize, crate::fixed::Quantized, usize)> + 'a {
    let proven = nc.slope_raw >= 0 && dp.config().t.overflow != Overflow::Wrap;
    let mut start = 0;
    std::iter::from_fn(move || {
        if !proven || start >= codes.len() {
            return None;
        }
        let end = (start + CHUNK).min(codes.len());
        let last = codes[end - 1];
        if last >= dead_end {
            return None;
        }
        let t = dp.op_mul_t(dp.op_sub(last).1, nc);
        let kind = match t.event {
            Event::None => return None,
            Event::Wrapped => 0,
            Event::Saturated => 1,
            Event::Zeroed => 2,
        };
        let chunk = (start, end, t, kind);
        start = end;
        Some(chunk)
    })
}

/// `cos^n` of the input code `code` (`lsb` its weight, `ln_c` the `ln` of its value clamped to
/// 1.0): 0 at and below 0.
pub(super) fn cos_n_of(code: i64, lsb: f64, n: f64, ln_c: f64) -> f64 {
    if code as f64 * lsb <= 0.0 {
        0.0
    } else {
        (n * ln_c).exp()
    }
}

/// The largest number of input codes an exhaustive check evaluates per exponent: every code of
/// a 24-bit fraction up to 1.0 (`u1.24`, 0..=2^24). Its columns (the codes, their `ln c` and
/// d's reference, 24 bytes a code) then take 384 MiB, whatever the number of exponents.
pub const MAX_CHECK_CODES: u64 = (1 << 24) + 1;

/// Every input code up to 1.0 with its ln c and d's f64 reference, or [`Error::TooManyCodes`].
pub(super) fn code_columns(dp: &Datapath) -> Result<CodeColumns, Error> {
    let codes_all = dp.input_codes();
    let last = (*codes_all.end()).min(dp.one_code());
    let n_codes = (last - codes_all.start() + 1) as u64;
    if n_codes > MAX_CHECK_CODES {
        return Err(Error::TooManyCodes {
            format: dp.config().c.format.to_string(),
            n_codes,
            limit: MAX_CHECK_CODES,
        });
    }
    let codes: Vec<i64> = (*codes_all.start()..=last).collect();
    let c_lsb = dp.config().c.format.lsb();
    let one = dp.one_code();
    Ok(CodeColumns {
        ref_d: codes
            .iter()
            .map(|&k| (k.min(one) as f64 * c_lsb) - 1.0)
            .collect(),
        codes: Codes::new(dp, codes),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::Config;
    use crate::reference::normalisation::classic_coefficient;

    /// The floor a cache keeps ([`f64_floor`]: from the f64 model's cut prefix on, the
    /// prefix's last code standing for the rest) is the floor over every code, bit for bit:
    /// on real datapaths (clamp, paper, none, minimax, a signed input), and with a `cos^n`
    /// made up so that the prefix's last code is the maximum.
    #[test]
    fn the_floor_above_the_f64_cut_prefix_is_the_floor_over_every_code() {
        let mut prefixes = 0;
        for toml in [
            "",
            "cutoff = \"paper\"\nk = 5\n",
            "cutoff = \"none\"\nk = 3\n",
            "variant = \"minimax\"\n",
            "[c]\nformat = \"s2.10\"\n[d]\nformat = \"s3.11\"\n",
        ] {
            let mut cfg = Config::from_toml(toml).unwrap();
            cfg.n = "16,17,40,100,333,1000,1024".parse().unwrap();
            let dp = Datapath::new(cfg).unwrap();
            let shared = code_columns(&dp).unwrap();
            let codes = &shared.codes.codes[..];
            let c_lsb = dp.config().c.format.lsb();
            for nc in dp.constants() {
                let nf = f64::from(nc.n);
                let peak = classic_coefficient(dp.config().coef.form, nf);
                let s = |i: usize| f64_lobe_at(&dp, nc, &shared, i);
                let cos_n = |i: usize| cos_n_of(codes[i], c_lsb, nf, shared.codes.ln_c[i]);
                let z = f64_zero_end(&dp, nc, codes);
                assert!((0..z).all(|i| s(i) == 0.0), "{toml} n={}", nc.n);
                prefixes += usize::from(z > 0);
                let want = floor_over(0..codes.len(), nc, peak, &s, &cos_n);
                let got = f64_floor(&dp, nc, codes, peak, &s, &cos_n);
                assert_eq!(got.0.to_bits(), want.0.to_bits(), "{toml} n={}", nc.n);
                assert_eq!(got.1.to_bits(), want.1.to_bits(), "{toml} n={}", nc.n);
                if z > 1 {
                    let made_up = |i: usize| if i < z { 10.0 + i as f64 } else { 0.5 };
                    let want = floor_over(0..codes.len(), nc, peak, &s, &made_up);
                    let got = f64_floor(&dp, nc, codes, peak, &s, &made_up);
                    assert_eq!(got, want, "{toml} n={}", nc.n);
                    assert_eq!(got.0, 10.0 + (z - 1) as f64);
                }
            }
        }
        assert!(prefixes > 20, "the clamp and the paper cutoff cut a prefix");
    }
}
