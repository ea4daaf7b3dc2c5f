//! Where the clamp cutoff switches on and off behind a t that wraps or overflows to zero, found
//! without visiting every code: the candidate boundaries of the rounded product, each crossed
//! by bisection.
//!
//! Under `cutoff = "clamp"` the base is cut when `t * 2^a + K < 0` (`K` the aligned offset,
//! docs/arithmetic.md section 3.2), that is when `t < T*` with `T* = ceil(-K / 2^a)`. And
//! `t = g(w)`, where `w = u * 2^L` is the product `p = d * slope` rounded to t's LSB (`u` the
//! rounded product when t drops bits, `u = p` and `L` the left shift otherwise) and `g` is t's
//! overflow mode. `p` is affine in the input code, rounding is monotone, so `u(c)` is monotone
//! in c (non-decreasing for a positive slope, non-increasing for a negative one). The cut flag
//! is `phi(u(c))` with `phi` constant between consecutive *candidate thresholds* `U`:
//!
//! * `WRAP`: `t = tmin + ((w - tmin) mod 2^W)`, so with `u0 = tmin / 2^L`, `P = 2^(W - L)` and
//!   `E = ceil((T* - tmin) / 2^L)`, the cut inputs are `(u - u0) mod P < E`: thresholds
//!   `u0 + jP` and `u0 + E + jP` for every integer j (none when `L >= W`, where t is always 0,
//!   or when every or no residue is cut);
//! * `SAT_ZERO`, `SAT`, `SAT_SYM`: `g` is piecewise constant or the identity, switching at
//!   `w = tmin`, `tmin + 1` and `tmax + 1`; with the cut test at `w = T*`, the thresholds are
//!   `ceil(b / 2^L)` of these four `b`.
//!
//! Between two consecutive codes whose cut flags differ, `u` crosses a threshold; the code
//! where it does is the first code with `u(c) >= U` (or `< U` for a negative slope): one
//! bisection per threshold, and the model's own cut flag ([`Datapath::is_cut`]) of that code
//! and the one before decides whether it is a switch. So the switches found are exact: every
//! switch is the crossing of some threshold. The thresholds are counted arithmetically;
//! beyond [`MAX_BISECTIONS`] of them per n, a range of at most [`MAX_SCAN_CODES`] codes is
//! scanned instead (also exact), and a wider one gets [`MAX_BISECTIONS`] evenly spaced
//! thresholds and is reported as not complete.

use crate::fixed::{round_shift_i128, Overflow};
use crate::pipeline::datapath::CutStructure;
use crate::pipeline::{first_code_where, Datapath, NConstants, ProbeColumns};
use crate::reference::lobe::Cutoff;

/// The most thresholds bisected per exponent.
pub const MAX_BISECTIONS: u64 = 1024;

/// The most codes scanned per exponent when there are more thresholds than
/// [`MAX_BISECTIONS`].
pub const MAX_SCAN_CODES: u64 = 1 << 22;

/// The codes where the cut flag of one n switches.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Switches {
    /// Each code `c` whose cut flag differs from that of `c - 1`, ascending.
    pub codes: Vec<i64>,
    /// Whether `codes` holds every switch (false only when thresholds were thinned).
    pub complete: bool,
}

/// Every place in `lo..=last` where the cut flag of this n switches between two consecutive
/// codes (see the module documentation for how), for any cutoff: none without one, the one
/// bisection of [`Datapath::first_live_code`] where the cut codes are a proven prefix, the
/// threshold analysis otherwise.
///
/// # Examples
/// ```
/// use specfx::golden::switches::cut_switches;
/// use specfx::pipeline::{Config, Datapath};
/// // u1.30 input behind a wrapping t: 2^30 + 1 codes up to 1.0, no scan.
/// let toml = "n = \"1024\"\n[c]\nformat = \"u1.30\"\n[d]\nformat = \"s1.30\"\n[t]\noverflow = \"WRAP\"\n";
/// let dp = Datapath::new(Config::from_toml(toml).unwrap()).unwrap();
/// let nc = dp.constants_for(1024).unwrap();
/// let s = cut_switches(&dp, nc, 0, dp.one_code());
/// assert!(s.complete);
/// for &c in &s.codes {
///     assert_ne!(dp.eval(c, nc).cut, dp.eval(c - 1, nc).cut);
/// }
/// ```
pub fn cut_switches(dp: &Datapath, nc: &NConstants, lo: i64, last: i64) -> Switches {
    let mut out = Switches {
        codes: Vec::new(),
        complete: true,
    };
    if last <= lo {
        return out;
    }
    match dp.cut_structure() {
        CutStructure::Never => {}
        CutStructure::Prefix => {
            let live = dp.first_live_code(nc, lo..last + 1);
            if live > lo && live <= last {
                out.codes.push(live);
            }
        }
        CutStructure::Scan => {
            debug_assert_eq!(dp.config().cutoff, Cutoff::Clamp);
            let model = Thresholds::new(dp, nc);
            let (ua, ub) = {
                let (x, y) = (model.u(dp, lo), model.u(dp, last));
                (x.min(y), x.max(y))
            };
            let count = model.count(ua, ub);
            let n_codes = u64::try_from(i128::from(last) - i128::from(lo) + 1).unwrap_or(u64::MAX);
            if count > u128::from(MAX_BISECTIONS) && n_codes <= MAX_SCAN_CODES {
                out.codes = scan(dp, nc, lo, last);
                return out;
            }
            out.complete = count <= u128::from(MAX_BISECTIONS);
            let increasing = nc.slope_raw > 0;
            let mut found = Vec::new();
            for threshold in model.list(ua, ub, MAX_BISECTIONS) {
                let c = if increasing {
                    first_code_where(lo..last + 1, |c| model.u(dp, c) >= threshold)
                } else {
                    first_code_where(lo..last + 1, |c| model.u(dp, c) < threshold)
                };
                if c > lo && c <= last && dp.is_cut(c, nc) != dp.is_cut(c - 1, nc) {
                    found.push(c);
                }
            }
            found.sort_unstable();
            found.dedup();
            out.codes = found;
        }
    }
    out
}

/// Every switch of `lo..=last`, by evaluating every code (the brute force the thresholds
/// replace; used when there are more thresholds than codes to bisect cheaply).
fn scan(dp: &Datapath, nc: &NConstants, lo: i64, last: i64) -> Vec<i64> {
    const CHUNK: i64 = 4096;
    let mut cols = ProbeColumns::default();
    let mut found = Vec::new();
    let mut prev: Option<bool> = None;
    let mut start = lo;
    loop {
        let end = start.saturating_add(CHUNK - 1).min(last);
        let chunk: Vec<i64> = (start..=end).collect();
        dp.eval_batch(nc, &chunk, &mut cols);
        for (&c, &cut) in chunk.iter().zip(&cols.cut) {
            if prev.is_some_and(|p| p != cut) {
                found.push(c);
            }
            prev = Some(cut);
        }
        if end == last {
            return found;
        }
        start = end + 1;
    }
}

/// `ceil(b / 2^l)` for any `l`, `|b| < 2^126`.
fn ceil_shift(b: i128, l: u32) -> i128 {
    if l >= 127 {
        i128::from(b > 0)
    } else {
        -((-b) >> l)
    }
}

/// `floor(a / 2^e)` for a period `2^e`, `e <= 64`.
fn floor_div(a: i128, e: u32) -> i128 {
    a >> e
}

/// The candidate thresholds of one n (module documentation).
#[derive(Debug, Clone)]
struct Thresholds {
    slope: i128,
    /// Bits the product drops into t (0 when it shifts left).
    drop: u32,
    rounding: crate::fixed::Rounding,
    /// Fixed thresholds, in u.
    fixed: Vec<i128>,
    /// Periodic thresholds: `base + j * 2^period_bits` for both bases.
    periodic: Option<([i128; 2], u32)>,
}

impl Thresholds {
    fn new(dp: &Datapath, nc: &NConstants) -> Thresholds {
        let cfg = dp.config();
        let t = cfg.t;
        let shift = i64::from(cfg.d.format.frac_bits()) + i64::from(nc.slope_frac)
            - i64::from(t.format.frac_bits());
        let drop = u32::try_from(shift.max(0)).expect("a shift of at most a few thousand bits");
        let left = u32::try_from((-shift).max(0)).expect("a shift of at most a few thousand bits");
        // T*: the smallest t whose sum t * 2^a + K is not negative.
        let ft = t.format.frac_bits();
        let fs = ft.max(nc.offset_frac);
        let a = (fs - ft) as u32;
        let k = i128::from(nc.offset_raw) << (fs - nc.offset_frac) as u32;
        let t_star = -(k >> a);
        let (tmin, tmax) = (
            i128::from(t.format.min_raw()),
            i128::from(t.format.max_raw()),
        );
        let mut fixed = Vec::new();
        let mut periodic = None;
        match t.overflow {
            Overflow::Wrap => {
                let w = t.format.width();
                let span = t_star - tmin;
                if left < w && span > 0 && span < 1i128 << w {
                    let period_bits = w - left;
                    let u0 = tmin >> left;
                    let e = ceil_shift(span, left);
                    if e < 1i128 << period_bits {
                        periodic = Some(([u0, u0 + e], period_bits));
                    }
                }
            }
            Overflow::Sat | Overflow::SatSym | Overflow::SatZero => {
                for b in [tmin, tmin + 1, tmax + 1, t_star] {
                    fixed.push(ceil_shift(b, left));
                }
            }
        }
        Thresholds {
            slope: i128::from(nc.slope_raw),
            drop,
            rounding: t.rounding,
            fixed,
            periodic,
        }
    }

    /// The product of code `c` rounded to t's LSB (before t's overflow), or the product
    /// itself when t does not drop bits.
    fn u(&self, dp: &Datapath, c: i64) -> i128 {
        let (_, d) = dp.op_sub(c);
        let p = i128::from(d) * self.slope;
        if self.drop > 0 {
            round_shift_i128(p, self.drop, self.rounding)
        } else {
            p
        }
    }

    /// The range `j0..=j1` of a periodic family's thresholds in `(ua, ub]`.
    fn family(base: i128, bits: u32, ua: i128, ub: i128) -> (i128, i128) {
        // j0 = ceil((ua + 1 - base) / P), j1 = floor((ub - base) / P).
        let j0 = -floor_div(-(ua + 1 - base), bits);
        let j1 = floor_div(ub - base, bits);
        (j0, j1)
    }

    /// How many thresholds lie in `(ua, ub]`.
    fn count(&self, ua: i128, ub: i128) -> u128 {
        let mut n = self.fixed.iter().filter(|&&x| ua < x && x <= ub).count() as u128;
        if let Some((bases, bits)) = self.periodic {
            for base in bases {
                let (j0, j1) = Self::family(base, bits, ua, ub);
                if j1 >= j0 {
                    n = n.saturating_add((j1 - j0) as u128 + 1);
                }
            }
        }
        n
    }

    /// The thresholds in `(ua, ub]`, ascending; at most `cap` of them (evenly spaced over each
    /// periodic family, ends included) when there are more.
    fn list(&self, ua: i128, ub: i128, cap: u64) -> Vec<i128> {
        let mut v: Vec<i128> = self
            .fixed
            .iter()
            .copied()
            .filter(|&x| ua < x && x <= ub)
            .collect();
        if let Some((bases, bits)) = self.periodic {
            let per_family = i128::from((cap / 2).max(2));
            for base in bases {
                let (j0, j1) = Self::family(base, bits, ua, ub);
                if j1 < j0 {
                    continue;
                }
                let span = j1 - j0;
                if span < per_family {
                    v.extend((j0..=j1).map(|j| base + (j << bits)));
                } else {
                    // per_family evenly spaced j, both ends included; span / (k - 1) first so
                    // that nothing overflows.
                    let steps = per_family - 1;
                    let (q, r) = (span / steps, span % steps);
                    v.extend((0..per_family).map(|i| {
                        let j = j0 + q * i + r * i / steps;
                        base + (j << bits)
                    }));
                }
            }
        }
        v.sort_unstable();
        v.dedup();
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::Config;

    fn datapath(toml: &str) -> Datapath {
        Datapath::new(Config::from_toml(toml).unwrap()).unwrap()
    }

    /// Every code whose cut flag differs from the code before, from the scalar model.
    fn brute_force(dp: &Datapath, nc: &NConstants, lo: i64, last: i64) -> Vec<i64> {
        (lo + 1..=last)
            .filter(|&c| dp.eval(c, nc).cut != dp.eval(c - 1, nc).cut)
            .collect()
    }

    #[test]
    fn ceil_shift_is_the_ceiling() {
        for b in -40i128..40 {
            for l in 0..6u32 {
                let want = (b as f64 / f64::from(1u32 << l)).ceil() as i128;
                assert_eq!(ceil_shift(b, l), want, "{b} / 2^{l}");
            }
        }
        assert_eq!(ceil_shift(5, 200), 1);
        assert_eq!(ceil_shift(0, 200), 0);
        assert_eq!(ceil_shift(-5, 200), 0);
    }

    #[test]
    fn switches_equal_a_brute_force_scan_on_small_formats() {
        // Wrapping and zeroing t, dropping bits and shifting left, narrow t (many periods),
        // every rounding, a signed input, a minimax slope, the paper cutoff and a saturating
        // t for the other paths.
        let configs = [
            "n = \"1..=40,500,1000,4095\"\n[c]\nformat = \"u1.9\"\n[d]\nformat = \"s1.9\"\n[t]\nformat = \"s2.8\"\noverflow = \"WRAP\"\n[coef]\nformat = \"u12.8\"\n[out]\nformat = \"u12.8\"\n",
            "n = \"1..=20,500,3001\"\n[c]\nformat = \"u1.9\"\n[d]\nformat = \"s1.9\"\n[t]\nformat = \"s2.3\"\noverflow = \"WRAP\"\nrounding = \"TRN\"\n[coef]\nformat = \"u12.8\"\n[out]\nformat = \"u12.8\"\n",
            "n = \"3,17,99,640,2047\"\n[c]\nformat = \"s2.8\"\n[d]\nformat = \"s3.8\"\n[t]\nformat = \"s2.12\"\noverflow = \"WRAP\"\nrounding = \"RND_CONV\"\n[coef]\nformat = \"u12.8\"\n[out]\nformat = \"u12.8\"\n",
            "n = \"1..=20,77,1000\"\n[c]\nformat = \"u1.9\"\n[d]\nformat = \"s1.9\"\n[t]\nformat = \"s2.6\"\noverflow = \"SAT_ZERO\"\nrounding = \"RND_ZERO\"\n",
            "n = \"300,4000\"\n[c]\nformat = \"u1.8\"\n[d]\nformat = \"s1.8\"\n[t]\nformat = \"s4.-1\"\noverflow = \"WRAP\"\n[coef]\nformat = \"u12.8\"\n[out]\nformat = \"u12.8\"\n",
            "n = \"5,60,4000\"\n[c]\nformat = \"u1.8\"\n[d]\nformat = \"s1.8\"\n[t]\nformat = \"s3.0\"\noverflow = \"WRAP\"\nrounding = \"TRN_ZERO\"\n[coef]\nformat = \"u12.8\"\n[out]\nformat = \"u12.8\"\n",
            "n = \"5,60,333\"\n[c]\nformat = \"u1.8\"\n[d]\nformat = \"s1.8\"\n[t]\nformat = \"s2.1\"\noverflow = \"SAT_ZERO\"\nrounding = \"TRN_ZERO\"\n",
            "variant = \"minimax\"\nn = \"16..=24,300,4000\"\n[c]\nformat = \"u1.10\"\n[d]\nformat = \"s1.10\"\n[t]\nformat = \"s2.12\"\noverflow = \"WRAP\"\n[coef]\nformat = \"u12.8\"\n[out]\nformat = \"u12.8\"\n",
            "variant = \"minimax\"\nn = \"16,300\"\n[c]\nformat = \"u1.10\"\n[d]\nformat = \"s1.10\"\n[t]\nformat = \"s2.20\"\noverflow = \"SAT_ZERO\"\n",
            "n = \"16,40,1000\"\n[c]\nformat = \"u1.10\"\n[d]\nformat = \"s1.10\"\n[t]\nformat = \"s3.20\"\noverflow = \"WRAP\"\n",
            "n = \"20000,65535\"\n[c]\nformat = \"u1.12\"\n[d]\nformat = \"s1.12\"\n[t]\nformat = \"s2.0\"\noverflow = \"WRAP\"\n[coef]\nformat = \"u16.8\"\n[out]\nformat = \"u16.8\"\n",
            "cutoff = \"paper\"\nn = \"2,40,1000\"\n[c]\nformat = \"u1.10\"\n[d]\nformat = \"s1.10\"\n",
            "n = \"2,40,1000\"\n[c]\nformat = \"u1.10\"\n[d]\nformat = \"s1.10\"\n",
        ];
        let mut total = 0;
        let (mut bisected, mut scanned) = (false, false);
        for toml in configs {
            let dp = datapath(toml);
            let (lo, hi) = (*dp.input_codes().start(), *dp.input_codes().end());
            let last = hi.min(dp.one_code());
            for nc in dp.constants() {
                let got = cut_switches(&dp, nc, lo, last);
                assert!(got.complete, "{toml} n = {}", nc.n);
                assert_eq!(
                    got.codes,
                    brute_force(&dp, nc, lo, last),
                    "{toml} n = {}",
                    nc.n
                );
                total += got.codes.len();
                if dp.cut_structure() == CutStructure::Scan {
                    let m = Thresholds::new(&dp, nc);
                    let (x, y) = (m.u(&dp, lo), m.u(&dp, last));
                    let few = m.count(x.min(y), x.max(y)) <= u128::from(MAX_BISECTIONS);
                    bisected |= few && !got.codes.is_empty();
                    scanned |= !few;
                }
            }
        }
        assert!(total > 3000, "the configurations switch often: {total}");
        assert!(bisected && scanned);
    }

    #[test]
    fn a_wide_wrapping_input_is_bisected_not_scanned() {
        // u1.30: 2^30 + 1 codes up to 1.0. t = s2.16 wraps every 2^18 of its codes, and the
        // product reaches -64 * 2^16 at n = 1024: 16 periods, two thresholds each.
        let dp = datapath(
            "n = \"17,1024\"\n[c]\nformat = \"u1.30\"\n[d]\nformat = \"s1.30\"\n[t]\noverflow = \"WRAP\"\n",
        );
        let nc = dp.constants_for(1024).unwrap();
        let s = cut_switches(&dp, nc, 0, dp.one_code());
        assert!(s.complete);
        // Hand count: before wrapping, t = 64 (c - 1) runs over [-64, 0]; s2.16 keeps it
        // modulo 4 in [-2, 2), and the base t + 1 is cut when the kept t is below -1, i.e. when
        // the unwrapped t lies in [-2 + 4j, -1 + 4j). For j = -15..=0 these 16 intervals lie
        // inside (-64, 0] (c = 0, t = -64, keeps 0: not cut), each entered and left once.
        for &c in &s.codes {
            assert_ne!(dp.eval(c, nc).cut, dp.eval(c - 1, nc).cut, "{c}");
        }
        assert_eq!(s.codes.len(), 32);
        // Between switches the flag is constant: sample a few codes between each pair.
        let mut edges = vec![0];
        edges.extend(&s.codes);
        edges.push(dp.one_code() + 1);
        for w in edges.windows(2) {
            let flag = dp.eval(w[0], nc).cut;
            for i in 1..8 {
                let c = w[0] + (w[1] - 1 - w[0]) * i / 8;
                assert_eq!(dp.eval(c, nc).cut, flag, "{c}");
            }
        }
    }
}
