//! Exhaustive accuracy check of a datapath against f64, on every input code and every n.
//!
//! For each stage the fixed-point value is compared with the f64 value of the same algorithm
//! (same constants before quantization, no rounding anywhere); the lobe before the coefficient
//! is also compared with cos^n itself, which splits its error into quantization and
//! approximation. Work is split by n across threads and merged in n order, so every figure is
//! deterministic.

mod codes;
mod fold;
mod outputs;
mod report;
mod screen;
pub use codes::MAX_CHECK_CODES;
use codes::{code_columns, dead_prefix_end, overflowed_chunks, CHUNK};
use fold::{check_one_n, Acc, PerN, Scratch};
pub use outputs::{check_outputs, check_outputs_cached, CosCache};
use report::MAX_LISTED_VIOLATIONS;
pub use report::{
    effective_bits, CheckReport, Input, MonotonicityViolation, OutputFigures, StageStats,
};

use crate::analysis::accumulate::MaxAt;
use crate::engine::{each_chunk, map_n, map_n_with, Span};
use crate::error::Error;
use crate::pipeline::datapath::STAGE_T;
use crate::pipeline::f64_walk::F64Walk;
use crate::pipeline::fast::EventCounts;
use crate::pipeline::{Datapath, NConstants, MAX_STAGES};
use crate::reference::lobe::Cutoff;

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
