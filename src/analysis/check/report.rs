//! What an exhaustive check reports: each stage's figures, the output-side figures sweeps
//! and the optimiser compare ([`OutputFigures`]), and the places where the output decreases.

use serde::Serialize;

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

/// How many violations are listed in full.
pub(super) const MAX_LISTED_VIOLATIONS: usize = 100;
