//! Error-budget analysis of a datapath: where the output error comes from, stage by stage.
//!
//! Every input code and every n is evaluated four ways: the fixed-point datapath itself, the
//! f64 model of the same algorithm (no rounding anywhere: the reference of `check`), the same
//! f64 model with exactly one error source quantized as the datapath quantizes it (one
//! evaluation per source), and cos^n itself. From these come the per-source attribution of the
//! output error and its first-order consistency with the measured total, the approximation /
//! quantization split at the output, histograms, error against c and against n. Headroom and
//! overflow counts come from the exhaustive check, whose report is included whole.
//!
//! Work is split by n across threads and merged in n order, so every figure is deterministic.

use serde::Serialize;

use crate::analysis::accumulate::{MaxAt, Moments};
use crate::analysis::budget_expr::{metric_value, Budget, Metric};
use crate::analysis::check::{check, CheckReport, Input};
use crate::engine::{fold_n, Chunk, Codes};
use crate::error::Error;
use crate::fixed::Format;
use crate::pipeline::f64_walk::{mixed_eval, sources, Source};
use crate::pipeline::{Datapath, StageSpec, Variant};

/// Error figures of one source (or of the whole datapath) at the output.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SourceStats {
    /// `constants`, `t`, `b`, `sq1`.., `coef`, `out`, or `all` for the datapath itself.
    pub source: String,
    /// The format it rounds into (empty for `all`).
    pub format: String,
    /// Its rounding mode (empty for `all`).
    pub rounding: String,
    /// max |output error| with this source alone quantized.
    pub max_abs: f64,
    /// The same in output LSBs.
    pub max_ulp: f64,
    /// Mean output error (the bias this source adds).
    pub mean: f64,
    /// Root mean square of the output error.
    pub rms: f64,
    /// Where `max_abs` is reached.
    pub worst: Input,
}

/// Per-source attribution of the output quantization error, and how well the parts add up.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Attribution {
    /// One entry per source, in pipeline order: the output error when that source alone is
    /// quantized and every other is exact.
    pub sources: Vec<SourceStats>,
    /// One entry per source, in pipeline order: what quantizing this source adds to the output
    /// error when every source before it is already quantized. These parts add up to the
    /// total exactly, input by input.
    pub incremental: Vec<SourceStats>,
    /// The datapath itself: every source quantized (the `out` error of `check`).
    pub total: SourceStats,
    /// The sum of the sources' max |error|: the first-order worst case.
    pub sum_of_max_abs: f64,
    /// The root sum of squares of the sources' RMS errors: the first-order RMS if the sources
    /// are uncorrelated.
    pub rss_of_rms: f64,
    /// max over inputs of |total error - sum of the sources' errors at that input|: what the
    /// first-order model misses (products of errors, rounding interactions).
    pub residual_max_abs: f64,
    /// Where the residual is largest.
    pub residual_worst: Input,
}

/// The approximation / quantization split of the output error against `coef * cos^n`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Split {
    /// max |f64 model output - coef * cos^n|: the approximation alone.
    pub approx_max_abs: f64,
    /// Where it is reached.
    pub approx_worst: Input,
    /// max |fixed output - f64 model output|: the quantization alone.
    pub quant_max_abs: f64,
    /// Where it is reached.
    pub quant_worst: Input,
    /// max |fixed output - coef * cos^n|: both.
    pub total_max_abs: f64,
    /// Where it is reached.
    pub total_worst: Input,
}

/// A histogram with bins of equal width.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Histogram {
    /// What is counted, with its unit.
    pub quantity: String,
    /// The left edge of the first bin.
    pub lo: f64,
    /// The width of every bin.
    pub bin_width: f64,
    /// Counts per bin.
    pub counts: Vec<u64>,
    /// Values below the first bin.
    pub below: u64,
    /// Values at or above the end of the last bin.
    pub above: u64,
}

impl Histogram {
    /// A histogram over `[-h, h)` in [`HIST_BINS`] bins, where `h` is the smallest power of
    /// two (at least 1) above `max_abs`, so that every value falls in a bin.
    fn covering(quantity: &str, max_abs: f64) -> Histogram {
        let mut half_range = 1.0;
        while half_range <= max_abs {
            half_range *= 2.0;
        }
        Histogram {
            quantity: quantity.into(),
            lo: -half_range,
            bin_width: 2.0 * half_range / HIST_BINS as f64,
            counts: vec![0; HIST_BINS],
            below: 0,
            above: 0,
        }
    }

    fn add(&mut self, x: f64) {
        let pos = ((x - self.lo) / self.bin_width).floor();
        if pos < 0.0 {
            self.below += 1;
        } else if pos >= self.counts.len() as f64 {
            self.above += 1;
        } else {
            self.counts[pos as usize] += 1;
        }
    }

    fn merge(&mut self, other: &Histogram) {
        for (a, b) in self.counts.iter_mut().zip(&other.counts) {
            *a += b;
        }
        self.below += other.below;
        self.above += other.above;
    }

    /// The total count.
    pub fn total(&self) -> u64 {
        self.counts.iter().sum::<u64>() + self.below + self.above
    }
}

/// Error figures of one exponent.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerN {
    /// The exponent.
    pub n: u32,
    /// max |fixed output - f64 model output|, in output LSBs.
    pub out_quant_max_ulp: f64,
    /// max |fixed output - f64 model output|.
    pub out_quant_max_abs: f64,
    /// max |fixed lobe - cos^n|.
    pub shape_total_max_abs: f64,
    /// max |fixed lobe - f64 lobe|.
    pub shape_quant_max_abs: f64,
    /// max |f64 lobe - cos^n|.
    pub shape_approx_max_abs: f64,
}

/// Error figures of one interval of c.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PerC {
    /// Left edge of the interval.
    pub c_lo: f64,
    /// Right edge (the last interval includes 1.0).
    pub c_hi: f64,
    /// max |fixed output - f64 model output| over every n, in output LSBs.
    pub out_quant_max_ulp: f64,
    /// max |fixed lobe - cos^n| over every n.
    pub shape_total_max_abs: f64,
}

/// The range a stage's values took against its format's range.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Headroom {
    /// Stage name.
    pub stage: String,
    /// The stage's format.
    pub format: String,
    /// Smallest value seen.
    pub seen_min: f64,
    /// Largest value seen.
    pub seen_max: f64,
    /// Smallest value of the format.
    pub format_min: f64,
    /// Largest value of the format.
    pub format_max: f64,
    /// Integer bits the format has.
    pub int_bits: i32,
    /// Integer bits the values seen need (same signedness and fraction bits).
    pub int_bits_needed: i32,
    /// `int_bits - int_bits_needed`: integer bits that were never used (0 when saturating).
    pub spare_int_bits: i32,
    /// Fraction bits that carry only noise: floor(log2) of the stage's worst error in its own
    /// LSBs (vs the same algorithm in f64), at most its fraction bits; `None` when the stage
    /// overflowed, whose error then says nothing about rounding noise.
    pub wasted_frac_bits: Option<i32>,
    /// Quantizations that wrapped.
    pub wrapped: u64,
    /// Quantizations that saturated.
    pub saturated: u64,
    /// Quantizations that overflowed to zero.
    pub zeroed: u64,
}

/// The integer bits a format of `frac` fraction bits needs to hold every raw in `min..=max`.
///
/// # Examples
/// ```
/// use specfx::analysis::budget::int_bits_needed;
/// assert_eq!(int_bits_needed(0, 65535, false, 16), 0); // u0.16
/// assert_eq!(int_bits_needed(0, 65536, false, 16), 1); // 1.0 needs u1.16
/// assert_eq!(int_bits_needed(-65536, 0, true, 16), 1); // -1.0 fits s1.16
/// assert_eq!(int_bits_needed(-65537, 0, true, 16), 2);
/// ```
pub fn int_bits_needed(min: i64, max: i64, signed: bool, frac: i32) -> i32 {
    let bits = |x: i64| 64 - x.leading_zeros() as i32; // bits of a non-negative value
    let width = if signed {
        // A width w holds -2^(w-1)..=2^(w-1)-1.
        let pos = if max > 0 { bits(max) + 1 } else { 1 };
        let neg = if min < 0 { bits(!min) + 1 } else { 1 };
        pos.max(neg)
    } else {
        bits(max.max(0)).max(1)
    };
    width - frac
}

/// One bound of a budget against the measured value.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoundResult {
    /// The metric (`shape_total`, `shape_quant`, `out`, `correct`).
    pub metric: Metric,
    /// The limit in the metric's unit.
    pub limit: f64,
    /// The measured value.
    pub value: f64,
    /// Whether it holds.
    pub pass: bool,
}

/// A bound proved by gappa for one exponent, next to the exhaustive figure.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FormalBound {
    /// The exponent.
    pub n: u32,
    /// Proved max |fixed output - f64 model output| over every input.
    pub bound: f64,
    /// The same in output LSBs.
    pub bound_ulp: f64,
    /// The exhaustive max for this n, in output LSBs.
    pub exhaustive_ulp: f64,
    /// How the bound was obtained (regions, assumptions).
    pub how: String,
}

/// Everything `specfx budget` reports.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BudgetReport {
    /// The configuration's name.
    pub config: String,
    /// The budget, as written, if one was given.
    pub budget: Option<String>,
    /// Every bound against its measured value.
    pub bounds: Vec<BoundResult>,
    /// Whether every bound holds (`None` without a budget).
    pub pass: Option<bool>,
    /// The output LSB.
    pub out_lsb: f64,
    /// Per-source attribution of the output quantization error.
    pub attribution: Attribution,
    /// Approximation / quantization split at the output.
    pub split: Split,
    /// Histogram of the output quantization error, in output LSBs.
    pub histogram_out: Histogram,
    /// Histogram of the lobe error against cos^n, in units of 2^-8.
    pub histogram_shape: Histogram,
    /// Figures per exponent.
    pub per_n: Vec<PerN>,
    /// Figures per interval of c.
    pub per_c: Vec<PerC>,
    /// Range seen against format range, per stage.
    pub headroom: Vec<Headroom>,
    /// Bounds proved by gappa (filled in by the caller that runs it).
    pub formal: Vec<FormalBound>,
    /// Why there are no formal bounds, when there are none.
    pub formal_note: Option<String>,
    /// The exhaustive check (worst inputs, per-stage figures, overflow counts).
    pub check: CheckReport,
}

/// Bins of each histogram.
pub const HIST_BINS: usize = 256;

/// Intervals of c in [`PerC`].
pub const C_BINS: usize = 64;

struct Acc {
    sources: Vec<Moments>,
    incremental: Vec<Moments>,
    total: Moments,
    residual: MaxAt,
    approx: MaxAt,
    total_vs_target: MaxAt,
    hist_out: Histogram,
    hist_shape: Histogram,
    per_c_out: Vec<f64>,
    per_c_shape: Vec<f64>,
    shape_total: f64,
    shape_quant: f64,
    shape_approx: f64,
}

impl Acc {
    fn new(n_sources: usize, out_max_ulp: f64, shape_max: f64) -> Acc {
        Acc {
            sources: vec![Moments::new(); n_sources],
            incremental: vec![Moments::new(); n_sources],
            total: Moments::new(),
            residual: MaxAt::new(),
            approx: MaxAt::new(),
            total_vs_target: MaxAt::new(),
            hist_out: Histogram::covering(
                "output error against the f64 model (output LSBs)",
                out_max_ulp,
            ),
            hist_shape: Histogram::covering(
                "lobe error against cos^n (units of 2^-8)",
                shape_max / crate::analysis::LSB8,
            ),
            per_c_out: vec![0.0; C_BINS],
            per_c_shape: vec![0.0; C_BINS],
            shape_total: 0.0,
            shape_quant: 0.0,
            shape_approx: 0.0,
        }
    }

    fn merge(&mut self, o: &Acc) {
        for (a, b) in self.sources.iter_mut().zip(&o.sources) {
            a.merge(b);
        }
        for (a, b) in self.incremental.iter_mut().zip(&o.incremental) {
            a.merge(b);
        }
        self.total.merge(&o.total);
        self.residual.merge(&o.residual);
        self.approx.merge(&o.approx);
        self.total_vs_target.merge(&o.total_vs_target);
        self.hist_out.merge(&o.hist_out);
        self.hist_shape.merge(&o.hist_shape);
        for (a, b) in self.per_c_out.iter_mut().zip(&o.per_c_out) {
            *a = a.max(*b);
        }
        for (a, b) in self.per_c_shape.iter_mut().zip(&o.per_c_shape) {
            *a = a.max(*b);
        }
    }
}

/// How far above its exact value the base of a one-source model can be: one LSB of t (or t's
/// saturation at its minimum), plus one LSB of each minimax constant.
fn base_margin(dp: &Datapath) -> (f64, f64) {
    let cfg = dp.config();
    let constants = match cfg.variant {
        Variant::Plain => 0.0,
        Variant::Minimax => cfg.minimax.a_format.lsb() + cfg.minimax.offset_format.lsb(),
    };
    (cfg.t.format.lsb() + constants, cfg.t.format.min_value())
}

/// What every chunk of the budget's stream needs besides the chunk: the sources and the
/// cumulative masks of the incremental attribution (sources 0..=i quantized).
struct Sources {
    srcs: Vec<Source>,
    cumulative: Vec<u32>,
}

impl Sources {
    fn new(srcs: Vec<Source>) -> Sources {
        let cumulative = srcs
            .iter()
            .scan(0, |m, s| {
                *m |= s.mask();
                Some(*m)
            })
            .collect();
        Sources { srcs, cumulative }
    }
}

/// Folds one chunk of the engine's stream into the budget's accumulator of its n.
fn add_chunk(dp: &Datapath, sources: &Sources, acc: &mut Acc, chunk: &Chunk<'_>) {
    let cfg = dp.config();
    let nc = chunk.nc;
    let out_lsb = cfg.out.format.lsb();
    let lobe_lsb = dp.stages()[dp.stage_last_square()].format.lsb();
    let c_lsb = cfg.c.format.lsb();
    let one = dp.one_code();
    let (margin, t_min) = base_margin(dp);
    let Sources { srcs, cumulative } = sources;
    let lobes = &chunk.probes.values[dp.stage_last_square()];
    let outs = &chunk.probes.values[dp.stage_out()];
    for (i, &code) in chunk.codes.iter().enumerate() {
        let at = (nc.n, code);
        let c = code.min(one) as f64 * c_lsb;
        let target = chunk.cos_n(i);
        let fixed_lobe = lobes[i] as f64 * lobe_lsb;
        let fixed_out = outs[i] as f64 * out_lsb;
        // Dead inputs: every model cuts the base (the one-source models too, whose base
        // is at most `margin` above the exact one) and the datapath outputs 0, so every
        // quantization error is exactly 0.
        let t_exact = nc.slope * (c - 1.0);
        let dead = fixed_out == 0.0
            && fixed_lobe == 0.0
            && cfg.cutoff.cuts(
                t_exact.max(t_min) + nc.offset + margin < 0.0,
                nc.below_threshold(code.min(one)),
            );
        let (ref_lobe, ref_out) = if dead {
            (0.0, 0.0)
        } else {
            mixed_eval(dp, nc, code, 0)
        };
        if !dead {
            let e_total = fixed_out - ref_out;
            acc.total.add(e_total, at);
            let mut sum = 0.0;
            for (src, m) in srcs.iter().zip(&mut acc.sources) {
                let e = mixed_eval(dp, nc, code, src.mask()).1 - ref_out;
                m.add(e, at);
                sum += e;
            }
            acc.residual.add((e_total - sum).abs(), at);
            let mut before = ref_out;
            for (j, m) in acc.incremental.iter_mut().enumerate() {
                let after = if j + 1 == cumulative.len() {
                    fixed_out
                } else {
                    mixed_eval(dp, nc, code, cumulative[j]).1
                };
                m.add(after - before, at);
                before = after;
            }
            let bin = ((c * C_BINS as f64) as usize).min(C_BINS - 1);
            acc.per_c_out[bin] = acc.per_c_out[bin].max(e_total.abs() / out_lsb);
            acc.hist_out.add(e_total / out_lsb);
            acc.shape_quant = acc.shape_quant.max((fixed_lobe - ref_lobe).abs());
        } else {
            acc.hist_out.add(0.0);
        }
        acc.approx.add((ref_out - nc.coef * target).abs(), at);
        acc.total_vs_target
            .add((fixed_out - nc.coef * target).abs(), at);
        let shape_total = fixed_lobe - target;
        acc.shape_total = acc.shape_total.max(shape_total.abs());
        acc.shape_approx = acc.shape_approx.max((ref_lobe - target).abs());
        acc.hist_shape.add(shape_total / crate::analysis::LSB8);
        let bin = ((c * C_BINS as f64) as usize).min(C_BINS - 1);
        acc.per_c_shape[bin] = acc.per_c_shape[bin].max(shape_total.abs());
    }
}

fn stats(
    name: String,
    format: String,
    rounding: String,
    m: &Moments,
    count: f64,
    lsb: f64,
    c_lsb: f64,
) -> SourceStats {
    SourceStats {
        source: name,
        format,
        rounding,
        max_abs: m.max.value.max(0.0),
        max_ulp: m.max.value.max(0.0) / lsb,
        mean: m.sum / count,
        rms: (m.sum_sq / count).sqrt(),
        worst: input(m.max.at, c_lsb),
    }
}

fn input(at: (u32, i64), c_lsb: f64) -> Input {
    Input {
        n: at.0,
        c_raw: at.1,
        c: at.1 as f64 * c_lsb,
    }
}

/// The spec of a source's quantization, for its format and rounding columns.
fn source_spec(dp: &Datapath, src: Source) -> (Format, String) {
    let cfg = dp.config();
    let spec = |s: &StageSpec| (s.format, s.rounding.to_string());
    match src {
        Source::Constants => (cfg.minimax.a_format, cfg.minimax.rounding.to_string()),
        Source::T => spec(&cfg.t),
        Source::B => spec(&cfg.b),
        Source::Square(i) => spec(&cfg.square[i]),
        Source::Coef => (cfg.coef.format, cfg.coef.rounding.to_string()),
        Source::Out => spec(&cfg.out),
    }
}

/// Analyses a datapath exhaustively (every input code up to 1.0, every n) against an optional
/// budget.
///
/// Returns an error message when the input format has too many codes for an exhaustive check.
///
/// # Examples
/// ```
/// use specfx::analysis::budget::analyse;
/// use specfx::pipeline::{Config, Datapath};
/// let mut cfg = Config::baseline();
/// cfg.n = "64".parse().unwrap();
/// let budget = "shape_quant <= 0.5 lsb8".parse().unwrap();
/// let r = analyse(&Datapath::new(cfg).unwrap(), Some(&budget)).unwrap();
/// assert_eq!(r.pass, Some(true));
/// assert_eq!(r.attribution.sources.len(), 8);
/// assert!(r.attribution.total.max_abs <= r.attribution.sum_of_max_abs + r.attribution.residual_max_abs);
/// ```
pub fn analyse(dp: &Datapath, budget: Option<&Budget>) -> Result<BudgetReport, Error> {
    let report = check(dp)?;
    let cfg = dp.config();
    let c_lsb = cfg.c.format.lsb();
    let out_lsb = cfg.out.format.lsb();
    let codes = Codes::up_to_one(dp);
    // The check's maxima size the histograms (with a hair of slack for the f64 reference).
    let ranges = (
        report.out_max_ulp * (1.0 + 1e-9),
        report.shape_total_max_abs * (1.0 + 1e-9),
    );
    let sources = Sources::new(sources(dp));
    let srcs = &sources.srcs;
    let per_n_acc: Vec<Acc> = fold_n(
        dp,
        &codes,
        |_| Acc::new(srcs.len(), ranges.0, ranges.1),
        |acc, chunk| add_chunk(dp, &sources, acc, chunk),
        &|| {},
    );
    let mut acc = Acc::new(srcs.len(), ranges.0, ranges.1);
    let mut per_n = Vec::with_capacity(per_n_acc.len());
    for (nc, a) in dp.constants().iter().zip(&per_n_acc) {
        acc.merge(a);
        per_n.push(PerN {
            n: nc.n,
            out_quant_max_ulp: a.total.max.value / out_lsb,
            out_quant_max_abs: a.total.max.value,
            shape_total_max_abs: a.shape_total,
            shape_quant_max_abs: a.shape_quant,
            shape_approx_max_abs: a.shape_approx,
        });
    }
    let count = (codes.codes.len() * per_n.len()).max(1) as f64;
    // Each source's statistics, from one of the accumulators' columns of moments.
    let per_source = |moments: &[Moments]| -> Vec<SourceStats> {
        srcs.iter()
            .zip(moments)
            .map(|(&src, m)| {
                let (format, rounding) = source_spec(dp, src);
                stats(
                    src.name(),
                    format.to_string(),
                    rounding,
                    m,
                    count,
                    out_lsb,
                    c_lsb,
                )
            })
            .collect()
    };
    let sources_stats = per_source(&acc.sources);
    let incremental = per_source(&acc.incremental);
    let total = stats(
        "all".into(),
        String::new(),
        String::new(),
        &acc.total,
        count,
        out_lsb,
        c_lsb,
    );
    let attribution = Attribution {
        sum_of_max_abs: sources_stats.iter().map(|s| s.max_abs).sum(),
        rss_of_rms: sources_stats
            .iter()
            .map(|s| s.rms * s.rms)
            .sum::<f64>()
            .sqrt(),
        residual_max_abs: acc.residual.value.max(0.0),
        residual_worst: input(acc.residual.at, c_lsb),
        sources: sources_stats,
        incremental,
        total,
    };
    let split = Split {
        approx_max_abs: acc.approx.value,
        approx_worst: input(acc.approx.at, c_lsb),
        quant_max_abs: acc.total.max.value,
        quant_worst: input(acc.total.max.at, c_lsb),
        total_max_abs: acc.total_vs_target.value,
        total_worst: input(acc.total_vs_target.at, c_lsb),
    };
    let per_c = (0..C_BINS)
        .map(|i| PerC {
            c_lo: i as f64 / C_BINS as f64,
            c_hi: (i + 1) as f64 / C_BINS as f64,
            out_quant_max_ulp: acc.per_c_out[i],
            shape_total_max_abs: acc.per_c_shape[i],
        })
        .collect();
    let headroom = dp
        .stages()
        .iter()
        .zip(&report.stages)
        .map(|(info, s)| {
            let f = info.format;
            let needed = int_bits_needed(s.raw_min, s.raw_max, f.is_signed(), f.frac_bits());
            Headroom {
                stage: info.name.clone(),
                format: f.to_string(),
                seen_min: f.to_f64(s.raw_min),
                seen_max: f.to_f64(s.raw_max),
                format_min: f.min_value(),
                format_max: f.max_value(),
                int_bits: f.int_bits(),
                int_bits_needed: needed,
                spare_int_bits: f.int_bits() - needed,
                wasted_frac_bits: (s.wrapped + s.saturated + s.zeroed == 0).then(|| {
                    if s.max_ulp >= 2.0 {
                        (s.max_ulp.log2().floor() as i32).min(f.frac_bits().max(0))
                    } else {
                        0
                    }
                }),
                wrapped: s.wrapped,
                saturated: s.saturated,
                zeroed: s.zeroed,
            }
        })
        .collect();
    let bounds: Vec<BoundResult> = budget.map_or_else(Vec::new, |b| {
        b.bounds
            .iter()
            .map(|bound| {
                let value = metric_value(&report.output_figures(), dp, b.arch, bound.metric);
                let pass = if bound.metric.is_floor() {
                    value >= bound.limit
                } else {
                    value <= bound.limit
                };
                BoundResult {
                    metric: bound.metric,
                    limit: bound.limit,
                    value,
                    pass,
                }
            })
            .collect()
    });
    Ok(BudgetReport {
        config: cfg.name.clone(),
        budget: budget.map(|b| b.text.clone()),
        pass: budget.map(|_| bounds.iter().all(|b| b.pass)),
        bounds,
        out_lsb,
        attribution,
        split,
        histogram_out: acc.hist_out,
        histogram_shape: acc.hist_shape,
        per_n,
        per_c,
        headroom,
        formal: Vec::new(),
        formal_note: None,
        check: report,
    })
}
