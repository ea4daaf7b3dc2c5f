//! Exhaustive accuracy check of a datapath against f64, on every input code and every n.
//!
//! For each stage the fixed-point value is compared with the f64 value of the same algorithm
//! (same constants before quantization, no rounding anywhere); the lobe before the coefficient
//! is also compared with cos^n itself, which splits its error into quantization and
//! approximation. Work is split by n across threads and merged in n order, so every figure is
//! deterministic.

use serde::Serialize;

use crate::analysis::accumulate::MaxAt;
use crate::analysis::column::{column_figures, Map, Raws, References};
use crate::engine::{each_chunk, each_chunk_in, map_n, map_n_with, Chunk, Codes, Span};
use crate::error::Error;
use crate::fixed::{Event, Overflow};
use crate::pipeline::datapath::{CutStructure, STAGE_B, STAGE_D, STAGE_SQ0, STAGE_T};
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
    let dead_end = dead_prefix_end(dp, nc, codes);
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
    // The f64 lobe of code index i by the same algorithm (see `reference_probes`).
    let f64_lobe = |i: usize| {
        let t = nc.slope * shared.ref_d[i];
        let mut s = reference_base(cfg.cutoff, t, nc.offset, codes[i].min(one) < threshold);
        for _ in 0..nc.depth {
            s *= s;
        }
        s
    };
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
        let approx_over = |range: std::ops::Range<usize>| {
            range.fold((-1.0f64, -1.0f64), |(a, na), i| {
                let (s, cn) = (f64_lobe(i), cos_n(i));
                (
                    a.max((s - cn).abs()),
                    na.max((s * nc.coef - norm_peak * cn).abs()),
                )
            })
        };
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
                c.floor(key, || approx_over(0..codes.len()))
            }
            None => approx_over(n_dead..n_zero),
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
        dp.eval_outputs_untabulated(nc, chunk, o_chunk, &mut scratch);
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
    let per_n = map_n(dp, |nc| outputs_one_n(dp, nc, shared, cache));
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

#[derive(Debug, Clone, Copy)]
struct Acc {
    max_abs: f64,
    worst: (u32, i64),
    sum: f64,
    sum_abs: f64,
    sum_sq: f64,
    n_correct: u64,
    n_faithful: u64,
    raw_min: i64,
    raw_max: i64,
    wrapped: u64,
    saturated: u64,
    zeroed: u64,
}

impl Acc {
    fn new() -> Acc {
        Acc {
            max_abs: -1.0,
            worst: (0, 0),
            sum: 0.0,
            sum_abs: 0.0,
            sum_sq: 0.0,
            n_correct: 0,
            n_faithful: 0,
            raw_min: i64::MAX,
            raw_max: i64::MIN,
            wrapped: 0,
            saturated: 0,
            zeroed: 0,
        }
    }

    /// Adds a column of one stage's raw values against their f64 references `map(refs)` (see
    /// [`column_figures`] for the order of the sums, which is part of the figures' bits).
    fn add_column(
        &mut self,
        raws: Raws<'_>,
        lsb: f64,
        refs: References<'_>,
        map: Map,
        codes: &[i64],
        n: u32,
    ) {
        // A hair of slack for the f64 reference's own rounding.
        let half = 0.5 * lsb * (1.0 + 1e-9);
        let one = lsb * (1.0 - 1e-12);
        let f = column_figures(raws, lsb, refs, map, half, one, self.max_abs);
        if let Some(i) = f.worst {
            self.max_abs = f.max_abs;
            self.worst = (n, codes[i]);
        }
        self.sum += f.sum;
        self.sum_abs += f.sum_abs;
        self.sum_sq += f.sum_sq;
        self.n_correct += f.n_correct;
        self.n_faithful += f.n_faithful;
        self.raw_min = self.raw_min.min(f.raw_range.0);
        self.raw_max = self.raw_max.max(f.raw_range.1);
    }

    /// Adds a column whose every error is exactly +0.0, non-decreasing from `raw_first` to
    /// `raw_last`: the same state as [`Acc::add_column`] would reach on it.
    fn add_exact_column(&mut self, raw_first: i64, raw_last: i64, count: u64, at: (u32, i64)) {
        if 0.0 > self.max_abs {
            self.max_abs = 0.0;
            self.worst = at;
        }
        self.n_correct += count;
        self.n_faithful += count;
        self.raw_min = self.raw_min.min(raw_first);
        self.raw_max = self.raw_max.max(raw_last);
    }

    /// Adds `count` evaluations of a constant (the coefficient) against its f64 value.
    fn add_constant(&mut self, raw: i64, lsb: f64, reference: f64, count: u64, at: (u32, i64)) {
        let err = raw as f64 * lsb - reference;
        let abs = err.abs();
        if abs > self.max_abs {
            self.max_abs = abs;
            self.worst = at;
        }
        let w = count as f64;
        self.sum += w * err;
        self.sum_abs += w * abs;
        self.sum_sq += w * err * err;
        self.n_correct += count * u64::from(abs <= 0.5 * lsb * (1.0 + 1e-9));
        self.n_faithful += count * u64::from(abs < lsb * (1.0 - 1e-12));
        self.raw_min = self.raw_min.min(raw);
        self.raw_max = self.raw_max.max(raw);
    }

    /// Adds `count` evaluations whose value and reference are both exactly 0.
    fn add_exact_zeros(&mut self, count: u64) {
        if count > 0 {
            if self.max_abs < 0.0 {
                self.max_abs = 0.0;
            }
            self.n_correct += count;
            self.n_faithful += count;
            self.raw_min = self.raw_min.min(0);
            self.raw_max = self.raw_max.max(0);
        }
    }

    fn add_events(&mut self, counts: &EventCounts) {
        self.wrapped += counts[0];
        self.saturated += counts[1];
        self.zeroed += counts[2];
    }

    fn merge(&mut self, o: &Acc) {
        if o.max_abs > self.max_abs {
            self.max_abs = o.max_abs;
            self.worst = o.worst;
        }
        self.sum += o.sum;
        self.sum_abs += o.sum_abs;
        self.sum_sq += o.sum_sq;
        self.n_correct += o.n_correct;
        self.n_faithful += o.n_faithful;
        self.raw_min = self.raw_min.min(o.raw_min);
        self.raw_max = self.raw_max.max(o.raw_max);
        self.wrapped += o.wrapped;
        self.saturated += o.saturated;
        self.zeroed += o.zeroed;
    }
}

/// Everything gathered for one n.
struct PerN {
    stages: Vec<Acc>,
    quant: MaxAt,
    approx: MaxAt,
    total: MaxAt,
    norm: MaxAt,
    norm_rel: f64,
    norm_approx_rel: f64,
    n_violations: u64,
    violations: Vec<MonotonicityViolation>,
    n_cut: u64,
}

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

/// One exponent's exhaustive check as a fold over the stream's chunks: the phases of a chunk
/// are methods, in the order [`check_one_n`] calls them.
struct NFold<'a> {
    dp: &'a Datapath,
    nc: &'a NConstants,
    lsb: Vec<f64>,
    /// Each stage's format width in bits.
    width: Vec<u32>,
    c_lsb: f64,
    one: i64,
    last_sq: usize,
    coef_idx: usize,
    out: usize,
    nf: f64,
    threshold: i64,
    norm_peak: f64,
    /// d = c - 1 is exact in its format; when c has at most 52 bits and d at most 53, its f64
    /// reference and its fixed-point value are the same f64 for every code, so every error is
    /// +0.0 and d's figures follow without computing them (the same bits as computing them).
    d_is_exact: bool,
    acc: Vec<Acc>,
    quant: MaxAt,
    approx: MaxAt,
    total: MaxAt,
    norm: MaxAt,
    norm_approx: f64,
    violations: Vec<MonotonicityViolation>,
    n_violations: u64,
    n_cut: u64,
    prev_out: Option<i64>,
    /// The largest code whose fixed and f64 lobes are both 0: cos^n is increasing in c, so
    /// its error there is the largest of all such codes and needs one evaluation at the end.
    zero_lobe_code: Option<(i64, f64)>,
    /// b's f64 reference over the chunk (t's is `slope * d`, d's is shared by every n).
    ref_b: Vec<f64>,
    /// Compacted columns of the inputs whose base is not 0 in both models ("live").
    live: Vec<usize>,
    live_codes: Vec<i64>,
    live_raws: Vec<i64>,
    live_refs: Vec<f64>,
    /// cos^n of the live inputs.
    live_cos: Vec<f64>,
}

impl<'a> NFold<'a> {
    /// A fold whose columns come from `scratch` ([`NFold::finish`] gives them back).
    fn new(dp: &'a Datapath, nc: &'a NConstants, scratch: &mut Scratch) -> NFold<'a> {
        let cfg = dp.config();
        let n_stages = dp.stages().len();
        NFold {
            dp,
            nc,
            lsb: dp.stages().iter().map(|s| s.format.lsb()).collect(),
            width: dp.stages().iter().map(|s| s.format.width()).collect(),
            c_lsb: cfg.c.format.lsb(),
            one: dp.one_code(),
            last_sq: dp.stage_last_square(),
            coef_idx: dp.stage_coef(),
            out: dp.stage_out(),
            nf: f64::from(nc.n),
            threshold: nc.threshold.unwrap_or(i64::MIN),
            norm_peak: classic_coefficient(cfg.coef.form, f64::from(nc.n)),
            d_is_exact: cfg.c.format.width() <= 52 && cfg.d.format.width() <= 53,
            acc: vec![Acc::new(); n_stages],
            quant: MaxAt::new(),
            approx: MaxAt::new(),
            total: MaxAt::new(),
            norm: MaxAt::new(),
            norm_approx: -1.0,
            violations: Vec::new(),
            n_violations: 0,
            n_cut: 0,
            prev_out: None,
            zero_lobe_code: None,
            ref_b: std::mem::take(&mut scratch.ref_b),
            live: std::mem::take(&mut scratch.live),
            live_codes: std::mem::take(&mut scratch.live_codes),
            live_raws: std::mem::take(&mut scratch.live_raws),
            live_refs: std::mem::take(&mut scratch.live_refs),
            live_cos: std::mem::take(&mut scratch.live_cos),
        }
    }

    /// Folds one chunk of the stream.
    #[inline]
    fn chunk(&mut self, c: &Chunk<'_>, ref_d: &[f64]) {
        for (a, counts) in self.acc.iter_mut().zip(&c.probes.event_counts) {
            a.add_events(counts);
        }
        self.reference_b(c, ref_d);
        self.fold_d_t_coef(c, ref_d);
        self.find_live(c);
        self.fold_live_stages(c);
        self.fold_cuts_and_monotonicity(c);
    }

    /// The f64 value of b by the same algorithm (see `reference_probes`), only above the dead
    /// prefix (below it every base is cut, and 0 in the f64 model too); d's is shared by every
    /// n and t's is `slope * d`, computed where it is used.
    fn reference_b(&mut self, c: &Chunk<'_>, ref_d: &[f64]) {
        let (nc, cutoff, one, threshold) =
            (self.nc, self.dp.config().cutoff, self.one, self.threshold);
        self.ref_b.clear();
        if c.dead {
            return;
        }
        // `reference_base` with the cutoff decided once for the chunk (the same values).
        let (slope, offset) = (nc.slope, nc.offset);
        match cutoff {
            Cutoff::Clamp => self.ref_b.extend(ref_d.iter().map(|&d| {
                let sum = slope * d + offset;
                if sum < 0.0 {
                    0.0
                } else {
                    sum
                }
            })),
            Cutoff::None => self.ref_b.extend(ref_d.iter().map(|&d| slope * d + offset)),
            Cutoff::Paper => {
                self.ref_b.extend(ref_d.iter().zip(c.codes).map(|(&d, &k)| {
                    reference_base(cutoff, slope * d, offset, k.min(one) < threshold)
                }))
            }
        }
    }

    /// d's, t's and the coefficient's figures, over every input of the chunk.
    fn fold_d_t_coef(&mut self, c: &Chunk<'_>, ref_d: &[f64]) {
        let (chunk, cols, n) = (c.codes, c.probes, self.nc.n);
        if self.d_is_exact {
            let d = &cols.values[STAGE_D];
            self.acc[STAGE_D].add_exact_column(
                d[0],
                d[d.len() - 1],
                chunk.len() as u64,
                (n, chunk[0]),
            );
        } else {
            self.acc[STAGE_D].add_column(
                Raws::of(&cols.values[STAGE_D], self.width[STAGE_D]),
                self.lsb[STAGE_D],
                References::Column(ref_d),
                Map::Identity,
                chunk,
                n,
            );
        }
        let slope = self.nc.slope;
        self.acc[STAGE_T].add_column(
            Raws::of(&cols.values[STAGE_T], self.width[STAGE_T]),
            self.lsb[STAGE_T],
            References::Column(ref_d),
            Map::Scale(slope),
            chunk,
            n,
        );
        self.acc[self.coef_idx].add_constant(
            self.nc.coef_raw,
            self.lsb[self.coef_idx],
            self.nc.coef,
            chunk.len() as u64,
            (n, chunk[0]),
        );
    }

    /// From b on, an input whose base is 0 in both models stays exactly 0 in both: such
    /// inputs count as exact without being looked at again. Compacts the others ("live")
    /// and remembers the largest dead code.
    fn find_live(&mut self, c: &Chunk<'_>) {
        let (chunk, b) = (c.codes, &c.probes.values[STAGE_B]);
        let ref_b = &self.ref_b;
        let is_live = |i: usize| b[i] != 0 || ref_b[i] != 0.0;
        self.live.clear();
        // The usual live chunk: a run of dead inputs, then only live ones.
        let first_live = if c.dead {
            chunk.len()
        } else {
            (0..chunk.len())
                .find(|&i| is_live(i))
                .unwrap_or(chunk.len())
        };
        let suffix = !c.dead && (first_live..chunk.len()).all(is_live);
        if suffix {
            self.live.extend(first_live..chunk.len());
        } else if !c.dead {
            self.live.extend((0..chunk.len()).filter(|&i| is_live(i)));
        }
        if self.live.len() < chunk.len() {
            let largest_dead = if c.dead {
                chunk.len() - 1
            } else if suffix {
                first_live - 1
            } else {
                (0..chunk.len())
                    .rev()
                    .find(|&i| b[i] == 0 && ref_b[i] == 0.0)
                    .expect("a dead input exists")
            };
            if self
                .zero_lobe_code
                .is_none_or(|(k, _)| chunk[largest_dead] > k)
            {
                self.zero_lobe_code = Some((chunk[largest_dead], c.ln_c[largest_dead]));
            }
        }
        self.live_codes.clear();
        self.live_refs.clear();
        if suffix {
            self.live_codes.extend_from_slice(&chunk[first_live..]);
            self.live_refs.extend_from_slice(&ref_b[first_live..]);
        } else {
            self.live_codes.extend(self.live.iter().map(|&i| chunk[i]));
            self.live_refs.extend(self.live.iter().map(|&i| ref_b[i]));
        }
    }

    /// b, the squarings and the output on the live inputs (the dead ones are exact zeros);
    /// the lobe against cos^n after the last squaring, the normalised output against the
    /// exact normalised cos^n at the output. Where the live inputs are one run of the chunk
    /// (above a cut prefix), the stages' columns are read in place instead of gathered.
    fn fold_live_stages(&mut self, c: &Chunk<'_>) {
        let (chunk, cols, n) = (c.codes, c.probes, self.nc.n);
        let n_dead = (chunk.len() - self.live.len()) as u64;
        let run = match (self.live.first(), self.live.last()) {
            (Some(&a), Some(&b)) if b - a + 1 == self.live.len() => Some(a..b + 1),
            _ => None,
        };
        let mut gathered = std::mem::take(&mut self.live_raws);
        for stage_idx in (STAGE_B..=self.last_sq).chain([self.out]) {
            if stage_idx == self.out {
                // live_refs holds the last squaring's references here.
                for r in &mut self.live_refs {
                    *r *= self.nc.coef;
                }
            } else if stage_idx > STAGE_B && stage_idx - STAGE_SQ0 < self.nc.depth as usize {
                // A squaring stage (a bypassed one passes its reference on as it is).
                for r in &mut self.live_refs {
                    *r *= *r;
                }
            }
            let raws: &[i64] = match &run {
                Some(r) => &cols.values[stage_idx][r.clone()],
                None => {
                    gathered.clear();
                    gathered.extend(self.live.iter().map(|&i| cols.values[stage_idx][i]));
                    &gathered
                }
            };
            self.acc[stage_idx].add_column(
                Raws::of(raws, self.width[stage_idx]),
                self.lsb[stage_idx],
                References::Column(&self.live_refs),
                Map::Identity,
                &self.live_codes,
                n,
            );
            self.acc[stage_idx].add_exact_zeros(n_dead);
            if stage_idx == self.last_sq {
                self.fold_lobe(c, raws);
            }
            if stage_idx == self.out {
                self.fold_normalised(c, raws);
            }
        }
        self.live_raws = gathered;
    }

    /// The normalised output against the exact normalised cos^n, on the live inputs (`raws`
    /// the output's values, `live_refs` the f64 lobe times the f64 coefficient, `live_cos`
    /// their cos^n).
    fn fold_normalised(&mut self, c: &Chunk<'_>, raws: &[i64]) {
        let lsb_out = self.lsb[self.out];
        for (j, &i) in self.live.iter().enumerate() {
            let cos_n = self.live_cos[j];
            let o = raws[j] as f64 * lsb_out;
            self.norm
                .add((o - self.norm_peak * cos_n).abs(), (self.nc.n, c.codes[i]));
            self.norm_approx = self
                .norm_approx
                .max((self.live_refs[j] - self.norm_peak * cos_n).abs());
        }
    }

    /// The lobe against cos^n on the live inputs (`raws` the last squaring's values,
    /// `live_refs` their f64 references): its quantization, approximation and total error.
    /// Leaves the live inputs' cos^n (0 at and below c = 0) in `live_cos`.
    fn fold_lobe(&mut self, c: &Chunk<'_>, raws: &[i64]) {
        let lsb_sq = self.lsb[self.last_sq];
        self.live_cos.clear();
        self.live_cos.extend(self.live.iter().map(|&i| {
            if c.codes[i] as f64 * self.c_lsb <= 0.0 {
                0.0
            } else {
                (self.nf * c.ln_c[i]).exp()
            }
        }));
        for (j, &i) in self.live.iter().enumerate() {
            let at = (self.nc.n, c.codes[i]);
            let s_fixed = raws[j] as f64 * lsb_sq;
            let s_ref = self.live_refs[j];
            let cos_n = self.live_cos[j];
            self.quant.add((s_fixed - s_ref).abs(), at);
            self.approx.add((s_ref - cos_n).abs(), at);
            self.total.add((s_fixed - cos_n).abs(), at);
        }
    }

    /// Counts the cut inputs and the outputs below the one before them. A dead chunk is all
    /// cut with all outputs 0: only its first output can fall below the one before it.
    fn fold_cuts_and_monotonicity(&mut self, c: &Chunk<'_>) {
        let (n_chunk_cut, checked) = if c.dead {
            (c.codes.len() as u64, 1)
        } else {
            (
                c.probes.cut.iter().filter(|&&cut| cut).count() as u64,
                c.codes.len(),
            )
        };
        self.n_cut += n_chunk_cut;
        let outs = &c.probes.values[self.out][..checked];
        // Most chunks have no violation: one pass that counts them, in the chunk and against
        // the output before it, and the per-output walk only where there is one.
        let inside = outs.windows(2).filter(|w| w[1] < w[0]).count();
        let at_start = self.prev_out.is_some_and(|p| outs[0] < p);
        if inside == 0 && !at_start {
            self.prev_out = Some(outs[checked - 1]);
            return;
        }
        for (&o, &code) in outs.iter().zip(c.codes) {
            if let Some(prev) = self.prev_out {
                if o < prev {
                    self.n_violations += 1;
                    if self.violations.len() < MAX_LISTED_VIOLATIONS {
                        self.violations.push(MonotonicityViolation {
                            n: self.nc.n,
                            c_raw: code,
                            out_before: prev,
                            out_here: o,
                        });
                    }
                }
            }
            self.prev_out = Some(o);
        }
    }

    /// Folds the whole chunks, from the first, that are dead (below `dead_end`) and whose t
    /// overflows below its range at every code ([`overflowed_chunks`]), without evaluating
    /// them; returns the index of the first code left to the stream.
    ///
    /// Such a chunk's figures follow from its codes: d is exact (`d_is_exact`), t is one raw
    /// value with one event at every code, the coefficient is a constant, and from b on every
    /// value is 0 in both models.
    fn overflowed_prefix(&mut self, shared: &CodeColumns, dead_end: i64) -> usize {
        let (dp, nc) = (self.dp, self.nc);
        if !self.d_is_exact {
            return 0;
        }
        let codes = &shared.codes.codes;
        let mut next = 0;
        for (start, end, t, kind) in overflowed_chunks(dp, nc, codes, dead_end) {
            next = end;
            let last = codes[end - 1];
            let chunk = &codes[start..end];
            let (n, len) = (nc.n, chunk.len() as u64);
            let mut counts = [0u64; 3];
            counts[kind] = len;
            self.acc[STAGE_T].add_events(&counts);
            self.acc[STAGE_D].add_exact_column(
                dp.op_sub(chunk[0]).1,
                dp.op_sub(last).1,
                len,
                (n, chunk[0]),
            );
            self.acc[STAGE_T].add_column(
                Raws::Constant(t.raw),
                self.lsb[STAGE_T],
                References::D {
                    first: chunk[0],
                    len: chunk.len(),
                    c_lsb: self.c_lsb,
                },
                Map::Scale(nc.slope),
                chunk,
                n,
            );
            self.acc[self.coef_idx].add_constant(
                nc.coef_raw,
                self.lsb[self.coef_idx],
                nc.coef,
                len,
                (n, chunk[0]),
            );
            // From b on every value is 0 in both models; the largest such code is the
            // chunk's last.
            for stage_idx in (STAGE_B..=self.last_sq).chain([self.out]) {
                self.acc[stage_idx].add_exact_zeros(len);
            }
            if self.zero_lobe_code.is_none_or(|(k, _)| last > k) {
                self.zero_lobe_code = Some((last, shared.codes.ln_c[end - 1]));
            }
            // Every base is cut and every output is 0: none below the one before it.
            self.n_cut += len;
            debug_assert!(
                self.prev_out.is_none_or(|p| p == 0),
                "a prefix of the codes"
            );
            self.prev_out = Some(0);
        }
        next
    }

    /// The exponent's figures, with the largest code of zero lobes counted once.
    fn finish(mut self, scratch: &mut Scratch) -> PerN {
        scratch.ref_b = std::mem::take(&mut self.ref_b);
        scratch.live = std::mem::take(&mut self.live);
        scratch.live_codes = std::mem::take(&mut self.live_codes);
        scratch.live_raws = std::mem::take(&mut self.live_raws);
        scratch.live_refs = std::mem::take(&mut self.live_refs);
        scratch.live_cos = std::mem::take(&mut self.live_cos);
        if let Some((code, lnc)) = self.zero_lobe_code {
            let at = (self.nc.n, code);
            let cos_n = if code <= 0 {
                0.0
            } else {
                (self.nf * lnc).exp()
            };
            self.quant.add(0.0, at);
            self.approx.add(cos_n, at);
            self.total.add(cos_n, at);
            self.norm.add(self.norm_peak * cos_n, at);
            self.norm_approx = self.norm_approx.max(self.norm_peak * cos_n);
        }
        PerN {
            stages: self.acc,
            quant: self.quant,
            approx: self.approx,
            total: self.total,
            norm_rel: self.norm.value / self.norm_peak,
            norm_approx_rel: self.norm_approx / self.norm_peak,
            norm: self.norm,
            n_violations: self.n_violations,
            violations: self.violations,
            n_cut: self.n_cut,
        }
    }
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

/// One exponent's exhaustive check: every chunk of the stream above the dead prefix's start,
/// folded by [`NFold`].
/// A worker's columns, reused from one exponent to the next.
#[derive(Default)]
struct Scratch {
    probes: crate::pipeline::ProbeColumns,
    ref_b: Vec<f64>,
    live: Vec<usize>,
    live_codes: Vec<i64>,
    live_raws: Vec<i64>,
    live_refs: Vec<f64>,
    live_cos: Vec<f64>,
}

fn check_one_n(
    dp: &Datapath,
    nc: &NConstants,
    shared: &CodeColumns,
    scratch: &mut Scratch,
) -> PerN {
    let dead_end = dead_prefix_end(dp, nc, &shared.codes.codes);
    let mut fold = NFold::new(dp, nc, scratch);
    let mut probes = std::mem::take(&mut scratch.probes);
    let span = Span {
        from: fold.overflowed_prefix(shared, dead_end),
        dead_end,
        chunk_codes: CHUNK,
    };
    each_chunk_in(dp, nc, &shared.codes, span, &mut probes, |c| {
        fold.chunk(c, &shared.ref_d[c.start..c.start + c.codes.len()]);
    });
    let per_n = fold.finish(scratch);
    scratch.probes = probes;
    per_n
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
