//! Exhaustive accuracy check of a datapath against f64, on every input code and every n.
//!
//! For each stage the fixed-point value is compared with the f64 value of the same algorithm
//! (same constants before quantization, no rounding anywhere); the lobe before the coefficient
//! is also compared with cos^n itself, which splits its error into quantization and
//! approximation. Work is split by n across threads and merged in n order, so every figure is
//! deterministic.

use serde::Serialize;

mod fold;
mod screen;
use fold::{check_one_n, Acc, PerN, Scratch};

use crate::analysis::accumulate::MaxAt;
use crate::engine::{each_chunk, map_n, map_n_with, Codes, Span};
use crate::error::Error;
use crate::fixed::{Event, Overflow};
use crate::pipeline::datapath::{CutStructure, STAGE_T};
use crate::pipeline::f64_walk::F64Walk;
use crate::pipeline::fast::EventCounts;
use crate::pipeline::{first_code_where, Datapath, NConstants, OutputScratch, MAX_STAGES};
use crate::reference::lobe::Cutoff;
use crate::reference::normalisation::classic_coefficient;

/// An input where a figure is reached.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Input {
    /// The exponent.
    pub n: u32,
    /// The raw input code.
    pub c_raw: i64,
    /// The input value.
    pub c: f64,
}

/// Accuracy figures of one stage.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StageStats {
    /// Stage name (`d`, `t`, `b`, `sq1`.., `coef`, `out`).
    pub stage: String,
    /// The stage's format.
    pub format: String,
    /// max |fixed - f64|.
    pub max_abs_err: f64,
    /// Mean of fixed - f64 (the bias).
    pub mean_err: f64,
    /// Mean of |fixed - f64|.
    pub mean_abs_err: f64,
    /// Root mean square of fixed - f64.
    pub rms_err: f64,
    /// max |fixed - f64| in units of the stage's LSB.
    pub max_ulp: f64,
    /// Share of evaluations within 1/2 LSB of the f64 value (correctly rounded).
    pub correctly_rounded: f64,
    /// Share within 1 LSB (faithfully rounded: one of the two neighbouring codes).
    pub faithfully_rounded: f64,
    /// Where max_abs_err is reached.
    pub worst: Input,
    /// Smallest raw value seen.
    pub raw_min: i64,
    /// Largest raw value seen.
    pub raw_max: i64,
    /// Quantizations that wrapped.
    pub wrapped: u64,
    /// Quantizations that saturated.
    pub saturated: u64,
    /// Quantizations that overflowed to zero (SAT_ZERO).
    pub zeroed: u64,
}

/// One place where the output decreases as c increases.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct MonotonicityViolation {
    /// The exponent.
    pub n: u32,
    /// The input code where the output is lower than at the code before it.
    pub c_raw: i64,
    /// Output raw at the code before.
    pub out_before: i64,
    /// Output raw here.
    pub out_here: i64,
}

/// The result of an exhaustive check.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CheckReport {
    /// The configuration's name.
    pub config: String,
    /// The n set, as written.
    pub n_set: String,
    /// Number of exponents.
    pub n_exponents: usize,
    /// Input codes evaluated per exponent (codes above 1.0 clamp to the code of 1.0 and are
    /// not evaluated again).
    pub n_input_codes: u64,
    /// Input codes above 1.0 per exponent, all equal to 1.0 after the input clamp.
    pub n_codes_above_one: u64,
    /// Evaluations in all.
    pub n_evaluations: u64,
    /// Per stage, in pipeline order.
    pub stages: Vec<StageStats>,
    /// max |fixed lobe - f64 lobe of the same algorithm| (before the coefficient).
    pub shape_quant_max_abs: f64,
    /// Where it is reached.
    pub shape_quant_worst: Input,
    /// max |f64 lobe - cos^n|: the approximation alone.
    pub shape_approx_max_abs: f64,
    /// Where it is reached.
    pub shape_approx_worst: Input,
    /// max |fixed lobe - cos^n|: both together.
    pub shape_total_max_abs: f64,
    /// Where it is reached.
    pub shape_total_worst: Input,
    /// max output error in output LSBs.
    pub out_max_ulp: f64,
    /// max |output - exact normalised cos^n| (the output against classic coef(n) * cos^n of
    /// the configured form: the whole datapath's error, approximation, coefficient and
    /// quantization), in output units.
    pub norm_total_max_abs: f64,
    /// Where it is reached.
    pub norm_total_worst: Input,
    /// max over n of that error divided by the exact normalised peak coef(n) (relative).
    pub norm_total_rel: f64,
    /// The same for the algorithm in f64 (its f64 lobe times its f64 coefficient): the floor
    /// no fixed-point width removes, relative to coef(n).
    pub norm_approx_rel: f64,
    /// Whether the output is non-decreasing in c for every n.
    pub monotonic: bool,
    /// Number of monotonicity violations.
    pub n_monotonicity_violations: u64,
    /// The first violations (at most 100), in n then c order.
    pub monotonicity_violations: Vec<MonotonicityViolation>,
    /// Evaluations where the cutoff forced the base to zero.
    pub n_cut: u64,
    /// Remarks that help read the figures (for example, harmless saturation).
    pub notes: Vec<String>,
}

/// The output-side figures of an exhaustive check: what sweeps and the optimiser compare.
/// [`check_outputs`] computes them without the per-stage statistics, and gives the same values
/// as [`CheckReport::output_figures`] of the full [`check`], bit for bit (tested).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct OutputFigures {
    /// Evaluations in all.
    pub n_evaluations: u64,
    /// max |fixed lobe - f64 lobe of the same algorithm|.
    pub shape_quant_max_abs: f64,
    /// max |f64 lobe - cos^n|.
    pub shape_approx_max_abs: f64,
    /// max |fixed lobe - cos^n|.
    pub shape_total_max_abs: f64,
    /// max output error in output LSBs.
    pub out_max_ulp: f64,
    /// Share of outputs within 1/2 LSB of the f64 output.
    pub out_correctly_rounded: f64,
    /// max |output - exact normalised cos^n| in output units (see [`CheckReport`]).
    pub norm_total_max_abs: f64,
    /// max over n of that error relative to the exact normalised peak coef(n).
    pub norm_total_rel: f64,
    /// The same for the algorithm in f64: the floor of `norm_total_rel`.
    pub norm_approx_rel: f64,
    /// Whether the output never decreases as c increases, for every n.
    pub monotonic: bool,
}

impl OutputFigures {
    /// Effective bits of the normalised output: -log2 of its relative total error.
    pub fn effective_bits(&self) -> f64 {
        effective_bits(self.norm_total_rel)
    }
}

/// Effective bits of a relative error: -log2(rel), 64 for an exact output.
pub fn effective_bits(rel: f64) -> f64 {
    if rel > 0.0 {
        -rel.log2()
    } else {
        64.0
    }
}

impl CheckReport {
    /// The output-side figures of this check.
    pub fn output_figures(&self) -> OutputFigures {
        OutputFigures {
            n_evaluations: self.n_evaluations,
            shape_quant_max_abs: self.shape_quant_max_abs,
            shape_approx_max_abs: self.shape_approx_max_abs,
            shape_total_max_abs: self.shape_total_max_abs,
            out_max_ulp: self.out_max_ulp,
            out_correctly_rounded: self.stages.last().map_or(0.0, |s| s.correctly_rounded),
            norm_total_max_abs: self.norm_total_max_abs,
            norm_total_rel: self.norm_total_rel,
            norm_approx_rel: self.norm_approx_rel,
            monotonic: self.monotonic,
        }
    }
}

/// What one exponent contributes to [`OutputFigures`].
struct OutputsOfN {
    quant: f64,
    approx: f64,
    total: f64,
    out_max_abs: f64,
    norm: f64,
    norm_rel: f64,
    norm_approx: f64,
    n_correct: u64,
    n_violations: u64,
}

/// The output figures of one exponent: the dead prefix (cut in both models, see
/// [`dead_prefix_end`]) counts as exact, without evaluation; every later code is evaluated and
/// compared with the f64 walk, exactly as [`check_one_n`] compares them.
fn outputs_one_n(
    dp: &Datapath,
    nc: &NConstants,
    shared: &CodeColumns,
    cache: Option<&CosCache>,
    dead_end: i64,
    tabulate: bool,
) -> OutputsOfN {
    let cfg = dp.config();
    let codes = &shared.codes.codes[..];
    let (lo, last) = (codes[0], codes[codes.len() - 1]);
    let lobe_lsb = dp.stages()[dp.stage_last_square()].format.lsb();
    let out_lsb = cfg.out.format.lsb();
    let half = 0.5 * out_lsb * (1.0 + 1e-9);
    let c_lsb = cfg.c.format.lsb();
    let nf = f64::from(nc.n);
    let threshold = nc.threshold.unwrap_or(i64::MIN);
    let one = dp.one_code();
    let cos_direct = |i: usize| cos_n_of(codes[i], c_lsb, nf, shared.codes.ln_c[i]);
    let n_dead = (dead_end - lo) as usize;
    let row = cache.and_then(|c| {
        c.row(nc.n, n_dead, || {
            (n_dead..codes.len()).map(cos_direct).collect()
        })
    });
    let cos_n = |i: usize| match &row {
        Some(r) if i >= r.start => r.values[i - r.start],
        _ => cos_direct(i),
    };
    let mut r = OutputsOfN {
        quant: -1.0,
        approx: -1.0,
        total: -1.0,
        out_max_abs: -1.0,
        norm: -1.0,
        norm_rel: -1.0,
        norm_approx: -1.0,
        n_correct: n_dead as u64,
        n_violations: 0,
    };
    let norm_peak = classic_coefficient(cfg.coef.form, nf);
    if n_dead > 0 {
        // Every dead output and lobe is 0 in both models; cos^n grows with c, so the largest
        // dead code bounds the others' shape errors.
        let cn = cos_n(n_dead - 1);
        r.quant = 0.0;
        r.approx = cn;
        r.total = cn;
        r.out_max_abs = 0.0;
        r.norm = norm_peak * cn;
        r.norm_approx = norm_peak * cn;
    }
    let f64_lobe = |i: usize| f64_lobe_at(dp, nc, shared, i);
    let n_zero = zero_run_end(dp, nc, codes, n_dead, &f64_lobe);
    if n_zero > n_dead {
        // Every fixed-point lobe and output of the run is 0, and the f64 lobe s, its output
        // s coef and cos^n grow with c: each error against 0 is largest at the run's last
        // code, and the correctly rounded outputs (s coef <= half) are a prefix of the run.
        // Only the f64 lobe's own error against cos^n is looked at code by code.
        let last_zero = n_zero - 1;
        let (s, cn) = (f64_lobe(last_zero), cos_n(last_zero));
        r.quant = r.quant.max(s);
        r.total = r.total.max(cn);
        r.out_max_abs = r.out_max_abs.max((s * nc.coef).abs());
        r.norm = r.norm.max((norm_peak * cn).abs());
        let correct_end = first_code_where(n_dead as i64..n_zero as i64, |i| {
            (-(f64_lobe(i as usize) * nc.coef)).abs() > half
        });
        r.n_correct += (correct_end - n_dead as i64) as u64;
        // The f64 lobe's error over every code (0 in the dead prefix, which the f64 model
        // cuts too) is the datapath's floor: a cache holds it across datapaths.
        let (approx, norm_approx) = match cache {
            Some(c) => {
                let key = (
                    nc.n,
                    nc.depth,
                    nc.slope.to_bits(),
                    nc.offset.to_bits(),
                    nc.coef.to_bits(),
                    threshold,
                    cfg.cutoff as u8,
                    cfg.coef.form as u8,
                );
                c.floor(key, || {
                    f64_floor(dp, nc, codes, norm_peak, &f64_lobe, &cos_n)
                })
            }
            None => floor_over(n_dead..n_zero, nc, norm_peak, &f64_lobe, &cos_n),
        };
        r.approx = r.approx.max(approx);
        r.norm_approx = r.norm_approx.max(norm_approx);
    }
    let mut prev_out = (n_zero > 0).then_some(0);
    // The live codes, a chunk at a time: only the lobe and the output are looked at, so the
    // chunk runs the outputs' path (the squaring chain looked up from b), not every probe.
    let mut scratch = OutputScratch::default();
    let mut outs = vec![0i64; CHUNK.min(codes.len())];
    let mut start = n_zero;
    while start < codes.len() {
        let end = (start + CHUNK).min(codes.len());
        let chunk = &codes[start..end];
        let o_chunk = &mut outs[..chunk.len()];
        if tabulate {
            dp.eval_outputs(nc, chunk, o_chunk, &mut scratch);
        } else {
            dp.eval_outputs_untabulated(nc, chunk, o_chunk, &mut scratch);
        }
        let lobes = scratch.lobes();
        for (j, &k) in chunk.iter().enumerate() {
            let i = start + j;
            let t = nc.slope * shared.ref_d[i];
            let mut s = reference_base(cfg.cutoff, t, nc.offset, k.min(one) < threshold);
            for _ in 0..nc.depth {
                s *= s;
            }
            let fixed_lobe = lobes[j] as f64 * lobe_lsb;
            let o = o_chunk[j];
            let err = o as f64 * out_lsb - s * nc.coef;
            r.out_max_abs = r.out_max_abs.max(err.abs());
            r.n_correct += u64::from(err.abs() <= half);
            let cn = cos_n(i);
            r.quant = r.quant.max((fixed_lobe - s).abs());
            r.approx = r.approx.max((s - cn).abs());
            r.total = r.total.max((fixed_lobe - cn).abs());
            r.norm = r.norm.max((o as f64 * out_lsb - norm_peak * cn).abs());
            r.norm_approx = r.norm_approx.max((s * nc.coef - norm_peak * cn).abs());
            if prev_out.is_some_and(|p| o < p) {
                r.n_violations += 1;
            }
            prev_out = Some(o);
        }
        start = end;
    }
    debug_assert!(last >= lo);
    r.norm_rel = r.norm / norm_peak;
    r.norm_approx /= norm_peak;
    r
}

/// `cos^n` of the input code `code` (`lsb` its weight, `ln_c` the `ln` of its value clamped to
/// 1.0): 0 at and below 0.
fn cos_n_of(code: i64, lsb: f64, n: f64, ln_c: f64) -> f64 {
    if code as f64 * lsb <= 0.0 {
        0.0
    } else {
        (n * ln_c).exp()
    }
}

/// `cos^n` of one exponent's codes from `start` (an index into the input codes) to the last.
#[derive(Debug)]
struct CosRow {
    start: usize,
    values: Vec<f64>,
}

/// The `cos^n` of the live codes of each exponent, kept across the exhaustive checks of
/// datapaths with the same input format (the optimiser's candidates differ in their stages,
/// not in `c` or its codes): each row is computed once, by the first check that needs it,
/// from that check's first live code on (a later check with more live codes computes the
/// extra ones itself). At most `capacity` values are kept (8 bytes each); past that, rows are
/// computed and not kept. The figures of every configuration checked through the cache are
/// kept too (a few hundred bytes each, keyed by the whole configuration), so that a search
/// that meets a candidate again (the optimiser's frontier, one search per budget) does not
/// check it twice. Shared by threads.
#[derive(Debug)]
pub struct CosCache {
    format: std::sync::OnceLock<crate::fixed::Format>,
    rows: std::sync::Mutex<std::collections::BTreeMap<u32, std::sync::Arc<CosRow>>>,
    floors: std::sync::Mutex<std::collections::BTreeMap<FloorKey, (f64, f64)>>,
    figures: std::sync::Mutex<std::collections::HashMap<String, OutputFigures>>,
    capacity: usize,
    kept: std::sync::atomic::AtomicUsize,
}

impl CosCache {
    /// An empty cache keeping at most `capacity` values.
    pub fn new(capacity: usize) -> CosCache {
        CosCache {
            format: std::sync::OnceLock::new(),
            rows: std::sync::Mutex::new(std::collections::BTreeMap::new()),
            floors: std::sync::Mutex::new(std::collections::BTreeMap::new()),
            figures: std::sync::Mutex::new(std::collections::HashMap::new()),
            capacity,
            kept: std::sync::atomic::AtomicUsize::new(0),
        }
    }

    /// The values kept.
    pub fn entries(&self) -> usize {
        self.kept.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Whether the cache holds this datapath's codes: the input format of the first datapath
    /// it served.
    fn serves(&self, dp: &Datapath) -> bool {
        *self.format.get_or_init(|| dp.config().c.format) == dp.config().c.format
    }

    /// The row of exponent `n`, made by `make` (the values from index `start` on) when absent;
    /// None when it is absent and does not fit.
    fn row(
        &self,
        n: u32,
        start: usize,
        make: impl FnOnce() -> Vec<f64>,
    ) -> Option<std::sync::Arc<CosRow>> {
        use std::sync::atomic::Ordering;
        if let Some(r) = self.rows.lock().expect("not poisoned").get(&n) {
            return Some(r.clone());
        }
        let values = make();
        if self.kept.load(Ordering::Relaxed) + values.len() > self.capacity {
            return Some(std::sync::Arc::new(CosRow { start, values }));
        }
        let mut rows = self.rows.lock().expect("not poisoned");
        let r = rows.entry(n).or_insert_with(|| {
            self.kept.fetch_add(values.len(), Ordering::Relaxed);
            std::sync::Arc::new(CosRow { start, values })
        });
        Some(r.clone())
    }
}

/// What the f64 lobe of one exponent depends on besides the input codes: n, its depth, the
/// f64 slope, offset and coefficient (as bits), the threshold, the cutoff and the form.
type FloorKey = (u32, u32, u64, u64, u64, i64, u8, u8);

impl CosCache {
    /// The f64 floor of one exponent, `(max |s - cos^n|, max |s coef - peak cos^n|)` over
    /// every code, made by `make` when absent: the same for every datapath whose f64 lobe is
    /// the same (the optimiser's candidates of one algorithm differ only in their stages).
    fn floor(&self, key: FloorKey, make: impl FnOnce() -> (f64, f64)) -> (f64, f64) {
        if let Some(&f) = self.floors.lock().expect("not poisoned").get(&key) {
            return f;
        }
        let f = make();
        self.floors.lock().expect("not poisoned").insert(key, f);
        f
    }
}

/// The output figures of an exhaustive check ([`OutputFigures`]) without the per-stage
/// statistics: the dead prefix of each n is not evaluated at all.
///
/// # Errors
/// As [`check`]: [`Error::TooManyCodes`].
///
/// # Examples
/// ```
/// use specfx::analysis::check::{check, check_outputs};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// assert_eq!(check_outputs(&dp).unwrap(), check(&dp).unwrap().output_figures());
/// ```
pub fn check_outputs(dp: &Datapath) -> Result<OutputFigures, Error> {
    check_outputs_cached(dp, None)
}

/// [`check_outputs`] with the `cos^n` of the live codes taken from `cache` where it holds
/// them (the same values, computed once for every datapath with the same input format: the
/// optimiser's candidates). The figures are those of [`check_outputs`], bit for bit.
///
/// # Errors
/// As [`check`]: [`Error::TooManyCodes`].
///
/// # Examples
/// ```
/// use specfx::analysis::check::{check_outputs, check_outputs_cached, CosCache};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let cache = CosCache::new(1 << 24);
/// let first = check_outputs_cached(&dp, Some(&cache)).unwrap();
/// assert!(cache.entries() > 0);
/// assert_eq!(check_outputs_cached(&dp, Some(&cache)).unwrap(), first);
/// assert_eq!(check_outputs(&dp).unwrap(), first);
/// ```
pub fn check_outputs_cached(
    dp: &Datapath,
    cache: Option<&CosCache>,
) -> Result<OutputFigures, Error> {
    let Some(cache) = cache.filter(|c| c.serves(dp)) else {
        return outputs_of(dp, &code_columns(dp)?, None);
    };
    let key = dp.config().to_toml();
    if let Some(&f) = cache.figures.lock().expect("not poisoned").get(&key) {
        return Ok(f);
    }
    let f = outputs_of(dp, &code_columns(dp)?, Some(cache))?;
    cache.figures.lock().expect("not poisoned").insert(key, f);
    Ok(f)
}

/// The output figures of [`check_outputs_cached`], computed.
fn outputs_of(
    dp: &Datapath,
    shared: &CodeColumns,
    cache: Option<&CosCache>,
) -> Result<OutputFigures, Error> {
    let codes = &shared.codes.codes;
    let dead = map_n(dp, |nc| dead_prefix_end(dp, nc, codes));
    // The squaring chain is looked up from b where its tables (one pass of its kernels over
    // every b code, for each depth) cost fewer evaluations than running it on the codes above
    // the dead prefixes (a bound on the live codes).
    let end = codes[codes.len() - 1] + 1;
    let above_dead: u128 = dead.iter().map(|&d| (end - d) as u128).sum();
    let b = dp.config().b.format;
    let b_codes = (i128::from(b.max_raw()) - i128::from(b.min_raw()) + 1) as u128;
    let depths = dp
        .constants()
        .iter()
        .map(|nc| nc.depth)
        .collect::<std::collections::BTreeSet<_>>()
        .len() as u128;
    let tabulate = b_codes * depths <= above_dead;
    let per_n = map_n(dp, |nc| {
        let i = dp
            .config()
            .n
            .values()
            .binary_search(&nc.n)
            .expect("an exponent of the set");
        outputs_one_n(dp, nc, shared, cache, dead[i], tabulate)
    });
    let mut f = OutputsOfN {
        quant: -1.0,
        approx: -1.0,
        total: -1.0,
        out_max_abs: -1.0,
        norm: -1.0,
        norm_rel: -1.0,
        norm_approx: -1.0,
        n_correct: 0,
        n_violations: 0,
    };
    for p in &per_n {
        f.norm = f.norm.max(p.norm);
        f.norm_rel = f.norm_rel.max(p.norm_rel);
        f.norm_approx = f.norm_approx.max(p.norm_approx);
        f.quant = f.quant.max(p.quant);
        f.approx = f.approx.max(p.approx);
        f.total = f.total.max(p.total);
        f.out_max_abs = f.out_max_abs.max(p.out_max_abs);
        f.n_correct += p.n_correct;
        f.n_violations += p.n_violations;
    }
    let n_eval = shared.codes.codes.len() as u64 * per_n.len() as u64;
    Ok(OutputFigures {
        n_evaluations: n_eval,
        shape_quant_max_abs: f.quant,
        shape_approx_max_abs: f.approx,
        shape_total_max_abs: f.total,
        out_max_ulp: f.out_max_abs / dp.config().out.format.lsb(),
        out_correctly_rounded: f.n_correct as f64 / n_eval as f64,
        norm_total_max_abs: f.norm,
        norm_total_rel: f.norm_rel,
        norm_approx_rel: f.norm_approx,
        monotonic: f.n_violations == 0,
    })
}

/// How many violations are listed in full.
const MAX_LISTED_VIOLATIONS: usize = 100;

/// The f64 value of every stage for one input, by the same algorithm without rounding.
///
/// # Examples
/// ```
/// use specfx::analysis::check::reference_probes;
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let nc = dp.constants_for(16).unwrap();
/// let r = reference_probes(&dp, nc, 0.5);
/// assert_eq!(r[0], -0.5); // d = c - 1
/// assert_eq!(r[1], -0.5); // t = (16/16) d
/// assert_eq!(r[2], 0.5); // b = t + 1
/// assert_eq!(r[6], 0.5f64.powi(16)); // sq4 = b^16
/// ```
pub fn reference_probes(dp: &Datapath, nc: &NConstants, c: f64) -> [f64; MAX_STAGES] {
    let code = c.min(1.0) * dp.one_code() as f64;
    let below = nc.threshold.is_some_and(|thr| code < thr as f64);
    let mut model = F64Walk::new(dp, nc, c, below, 0);
    model.run();
    model.values
}

/// Codes evaluated per batch: small enough for the columns to stay in cache.
const CHUNK: usize = 2048;

/// The f64 base of the same algorithm: `t + offset` after the cutoff (`cut_by_threshold`: the
/// clamped input is below the paper cutoff's threshold code).
#[inline]
fn reference_base(cutoff: Cutoff, t: f64, offset: f64, cut_by_threshold: bool) -> f64 {
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
fn dead_prefix_end(dp: &Datapath, nc: &NConstants, codes: &[i64]) -> i64 {
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
fn f64_lobe_at(dp: &Datapath, nc: &NConstants, shared: &CodeColumns, i: usize) -> f64 {
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
fn floor_over(
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
fn f64_floor(
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
fn f64_zero_end(dp: &Datapath, nc: &NConstants, codes: &[i64]) -> usize {
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
fn zero_run_end(
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
struct CodeColumns {
    codes: Codes,
    ref_d: Vec<f64>,
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
fn overflowed_chunks<'a>(
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

/// The overflow events of every stage (wrapped, saturated, zeroed; indexed like
/// [`Datapath::stages`]) over every input code up to 1.0 and every n: the counts the full
/// [`check`] reports, without its statistics (codes above 1.0 repeat the code of 1.0).
///
/// # Errors
/// As [`check`]: [`Error::TooManyCodes`].
///
/// # Examples
/// ```
/// use specfx::analysis::check::{check, stage_events};
/// use specfx::pipeline::{Config, Datapath};
/// let dp = Datapath::new(Config::baseline()).unwrap();
/// let events = stage_events(&dp).unwrap();
/// let report = check(&dp).unwrap();
/// for (e, s) in events.iter().zip(&report.stages) {
///     assert_eq!(*e, [s.wrapped, s.saturated, s.zeroed]);
/// }
/// ```
pub fn stage_events(dp: &Datapath) -> Result<Vec<EventCounts>, Error> {
    let shared = code_columns(dp)?;
    let n_stages = dp.stages().len();
    let per_n = map_n(dp, |nc| {
        let codes = &shared.codes.codes;
        let dead_end = dead_prefix_end(dp, nc, codes);
        let mut counts = vec![[0u64; 3]; n_stages];
        // The overflowed chunks: t's one event at every code, none elsewhere.
        let mut from = 0;
        for (start, end, _, kind) in overflowed_chunks(dp, nc, codes, dead_end) {
            counts[STAGE_T][kind] += (end - start) as u64;
            from = end;
        }
        let span = Span {
            from,
            dead_end,
            chunk_codes: CHUNK,
        };
        each_chunk(dp, nc, &shared.codes, span, |c| {
            for (sum, e) in counts.iter_mut().zip(&c.probes.event_counts) {
                for (a, b) in sum.iter_mut().zip(e) {
                    *a += b;
                }
            }
        });
        counts
    });
    let mut total = vec![[0u64; 3]; n_stages];
    for counts in per_n {
        for (sum, e) in total.iter_mut().zip(&counts) {
            for (a, b) in sum.iter_mut().zip(e) {
                *a += b;
            }
        }
    }
    Ok(total)
}

/// The largest number of input codes an exhaustive check evaluates per exponent: every code of
/// a 24-bit fraction up to 1.0 (`u1.24`, 0..=2^24). Its columns (the codes, their `ln c` and
/// d's reference, 24 bytes a code) then take 384 MiB, whatever the number of exponents.
pub const MAX_CHECK_CODES: u64 = (1 << 24) + 1;

/// Every input code up to 1.0 with its ln c and d's f64 reference, or [`Error::TooManyCodes`].
fn code_columns(dp: &Datapath) -> Result<CodeColumns, Error> {
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

/// Checks a datapath exhaustively: every input code up to 1.0, every n of its set.
///
/// Returns [`Error::TooManyCodes`] when the input format has more than [`MAX_CHECK_CODES`]
/// codes up to 1.0.
///
/// # Examples
/// ```
/// use specfx::analysis::check::check;
/// use specfx::pipeline::{Config, Datapath};
/// let mut cfg = Config::baseline();
/// cfg.n = "64".parse().unwrap();
/// let r = check(&Datapath::new(cfg).unwrap()).unwrap();
/// assert_eq!(r.n_evaluations, 32769);
/// assert!(r.monotonic);
/// ```
pub fn check(dp: &Datapath) -> Result<CheckReport, Error> {
    check_with_progress(dp, &|_, _| {})
}

/// [`check`], calling `progress(done, total)` as each of the `total` exponents finishes (from
/// the worker threads, in any order; the report is the same).
///
/// # Errors
/// As [`check`].
///
/// # Examples
/// ```
/// use specfx::analysis::check::{check, check_with_progress};
/// use specfx::pipeline::{Config, Datapath};
/// use std::sync::atomic::{AtomicUsize, Ordering};
/// let mut cfg = Config::baseline();
/// cfg.n = "16..=19".parse().unwrap();
/// let dp = Datapath::new(cfg).unwrap();
/// let calls = AtomicUsize::new(0);
/// let r = check_with_progress(&dp, &|done, total| {
///     assert!(done <= total && total == 4);
///     calls.fetch_add(1, Ordering::Relaxed);
/// })
/// .unwrap();
/// assert_eq!(calls.into_inner(), 4);
/// assert_eq!(r, check(&dp).unwrap());
/// ```
pub fn check_with_progress(
    dp: &Datapath,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<CheckReport, Error> {
    let shared = code_columns(dp)?;
    let codes_all = dp.input_codes();
    let last = (*codes_all.end()).min(dp.one_code());
    let n_codes = shared.codes.codes.len() as u64;
    let c_lsb = dp.config().c.format.lsb();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let total = dp.constants().len();
    let per_n: Vec<PerN> = map_n_with(dp, Scratch::default, |scratch, nc| {
        let p = check_one_n(dp, nc, &shared, scratch);
        progress(
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1,
            total,
        );
        p
    });

    let stages = dp.stages();
    let mut acc = vec![Acc::new(); stages.len()];
    let mut quant = MaxAt::new();
    let mut approx = MaxAt::new();
    let mut total = MaxAt::new();
    let mut norm = MaxAt::new();
    let mut norm_rel: f64 = -1.0;
    let mut norm_approx_rel: f64 = -1.0;
    let mut violations = Vec::new();
    let mut n_violations = 0;
    let mut n_cut = 0;
    for p in &per_n {
        norm.merge(&p.norm);
        norm_rel = norm_rel.max(p.norm_rel);
        norm_approx_rel = norm_approx_rel.max(p.norm_approx_rel);
        for (a, b) in acc.iter_mut().zip(&p.stages) {
            a.merge(b);
        }
        quant.merge(&p.quant);
        approx.merge(&p.approx);
        total.merge(&p.total);
        n_violations += p.n_violations;
        for v in &p.violations {
            if violations.len() < MAX_LISTED_VIOLATIONS {
                violations.push(*v);
            }
        }
        n_cut += p.n_cut;
    }
    let n_eval = n_codes * per_n.len() as u64;
    let count = n_eval as f64;
    let input = |at: (u32, i64)| Input {
        n: at.0,
        c_raw: at.1,
        c: at.1 as f64 * c_lsb,
    };
    let stage_stats: Vec<StageStats> = stages
        .iter()
        .zip(&acc)
        .map(|(s, a)| {
            let lsb = s.format.lsb();
            StageStats {
                stage: s.name.clone(),
                format: s.format.to_string(),
                max_abs_err: a.max_abs,
                mean_err: a.sum / count,
                mean_abs_err: a.sum_abs / count,
                rms_err: (a.sum_sq / count).sqrt(),
                max_ulp: a.max_abs / lsb,
                correctly_rounded: a.n_correct as f64 / count,
                faithfully_rounded: a.n_faithful as f64 / count,
                worst: input(a.worst),
                raw_min: a.raw_min,
                raw_max: a.raw_max,
                wrapped: a.wrapped,
                saturated: a.saturated,
                zeroed: a.zeroed,
            }
        })
        .collect();
    let out_max_ulp = stage_stats[dp.stage_out()].max_ulp;
    let mut notes = Vec::new();
    let t = &stage_stats[STAGE_T];
    let t_format = dp.config().t.format;
    let offset_max = dp
        .constants()
        .iter()
        .map(|nc| nc.offset)
        .fold(f64::NEG_INFINITY, f64::max);
    if dp.config().cutoff == Cutoff::Clamp
        && t.saturated > 0
        && t.raw_max < t_format.max_raw()
        && t_format.min_value() + offset_max <= 0.0
    {
        notes.push(format!(
            "t saturated {} times, always at its minimum {}: harmless, since t_min + offset <= 0 gives a base <= 0 that the clamp cuts to 0 anyway; its error figures count those inputs",
            t.saturated,
            t_format.min_value()
        ));
    }
    let above = (*codes_all.end() - last).max(0) as u64;
    Ok(CheckReport {
        config: dp.config().name.clone(),
        n_set: dp.config().n.to_string(),
        n_exponents: per_n.len(),
        n_input_codes: n_codes,
        n_codes_above_one: above,
        n_evaluations: n_eval,
        stages: stage_stats,
        shape_quant_max_abs: quant.value,
        shape_quant_worst: input(quant.at),
        shape_approx_max_abs: approx.value,
        shape_approx_worst: input(approx.at),
        shape_total_max_abs: total.value,
        shape_total_worst: input(total.at),
        out_max_ulp,
        norm_total_max_abs: norm.value,
        norm_total_worst: input(norm.at),
        norm_total_rel: norm_rel,
        norm_approx_rel,
        monotonic: n_violations == 0,
        n_monotonicity_violations: n_violations,
        monotonicity_violations: violations,
        n_cut,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::Config;

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
