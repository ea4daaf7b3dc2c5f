//! The `i64` batch kernels: each stage's quantization with its shifts and bounds worked out in
//! advance, and one loop per stage specialised at compile time for its rounding and overflow
//! modes (8 x 4 variants), so the hot loops carry no branch on the modes.
//!
//! These kernels are an optimisation of [`crate::pipeline::Datapath::eval`], which is the
//! plain transcription of the arithmetic; the tests compare the two on random configurations.

use crate::fixed::{Format, Overflow, Rounding};
use crate::pipeline::config::StageSpec;

/// Event codes counted by the kernels: index 0 wrapped, 1 saturated, 2 zeroed.
pub type EventCounts = [u64; 3];

const TRN: u8 = 0;
const TRN_ZERO: u8 = 1;
const RND: u8 = 2;
const RND_ZERO: u8 = 3;
const RND_INF: u8 = 4;
const RND_MIN_INF: u8 = 5;
const RND_CONV: u8 = 6;
const RND_CONV_ODD: u8 = 7;

const WRAP: u8 = 0;
const SAT: u8 = 1;
const SAT_ZERO: u8 = 2;
const SAT_SYM: u8 = 3;

/// One stage's quantization of exact values with a known number of fraction bits:
/// `overflow((floor(x / 2^right) + carry) << left)`.
#[derive(Debug, Clone, Copy)]
pub struct StageQ {
    right: u32,
    left: u32,
    mask: u64,
    half: u64,
    unused: u32,
    min: i64,
    max: i64,
    rounding: Rounding,
    overflow: Overflow,
}

impl StageQ {
    /// A stage receiving exact values with `frac_in` fraction bits; the caller guarantees the
    /// shift is below 63 and every value fits in `i64`.
    pub fn new(frac_in: i32, spec: &StageSpec) -> StageQ {
        let shift = frac_in - spec.format.frac_bits();
        let right = shift.max(0) as u32;
        let (mask, half) = if right == 0 {
            (0, 0)
        } else {
            ((1u64 << right) - 1, 1u64 << (right - 1))
        };
        let format: Format = spec.format;
        StageQ {
            right,
            left: (-shift).max(0) as u32,
            mask,
            half,
            unused: 64 - format.width(),
            min: format.min_raw(),
            max: format.max_raw(),
            rounding: spec.rounding,
            overflow: spec.overflow,
        }
    }

    /// Quantizes one exact value; the flag says whether the overflow mode acted (the event is
    /// then the mode's own: wrapped, saturated or zeroed).
    #[inline(always)]
    fn apply<const R: u8, const O: u8>(&self, x: i64) -> (i64, bool) {
        let floor = x >> self.right;
        let remainder = (x as u64) & self.mask;
        let negative = (x as u64) >> 63;
        let odd = (floor as u64) & 1;
        let half = self.half;
        // With right = 0 the mask is 0 and the carry must be 0 whatever the mode.
        let some = u64::from(self.right > 0);
        let bias = match R {
            TRN => 0,
            TRN_ZERO => self.mask & negative.wrapping_neg(),
            RND => half,
            RND_ZERO => (half + negative * some).wrapping_sub(some),
            RND_INF => half.wrapping_sub(negative * some),
            RND_MIN_INF => half.wrapping_sub(some),
            RND_CONV => (half + odd * some).wrapping_sub(some),
            _ => half.wrapping_sub(odd * some),
        };
        let v = (floor + (remainder.wrapping_add(bias) >> self.right) as i64) << self.left;
        match O {
            WRAP => {
                let r = if self.min < 0 {
                    (v << self.unused) >> self.unused
                } else {
                    v & self.max
                };
                (r, r != v)
            }
            SAT => {
                let r = v.clamp(self.min, self.max);
                (r, r != v)
            }
            SAT_ZERO => {
                let inside = v >= self.min && v <= self.max;
                (if inside { v } else { 0 }, !inside)
            }
            _ => {
                let signed = i64::from(self.min < 0);
                let lo = self.min + signed;
                let r = v.clamp(lo, self.max);
                // Below `lo` SAT_SYM gives `min | signed`: -max, or -1 for one-bit formats.
                let r = if v < lo { self.min | signed } else { r };
                (r, r != v || v < lo)
            }
        }
    }
}

/// The operation feeding a stage: the exact value its quantization receives.
#[derive(Debug, Clone, Copy)]
pub enum Pre {
    /// `x * constant` (the t product with the slope, the output product with the coefficient).
    Mul(i64),
    /// `x * x` (a squaring).
    Square,
    /// `x` as it is (the base, whose exact sum is formed beforehand).
    Identity,
}

#[inline(always)]
fn run<const R: u8, const O: u8>(
    q: &StageQ,
    pre: Pre,
    input: &[i64],
    output: &mut [i64],
    counts: &mut EventCounts,
) {
    let q = *q;
    let mut n_events = 0u64;
    macro_rules! body {
        ($f:expr) => {
            for (x, y) in input.iter().zip(output.iter_mut()) {
                let (v, e) = q.apply::<R, O>($f(*x));
                *y = v;
                n_events += u64::from(e);
            }
        };
    }
    match pre {
        Pre::Mul(c) => body!(|x: i64| x * c),
        Pre::Square => body!(|x: i64| x * x),
        Pre::Identity => body!(|x: i64| x),
    }
    let kind = match O {
        WRAP => 0,
        SAT_ZERO => 2,
        _ => 1,
    };
    counts[kind] += n_events;
}

#[inline(always)]
fn run_r<const R: u8>(
    q: &StageQ,
    pre: Pre,
    input: &[i64],
    output: &mut [i64],
    counts: &mut EventCounts,
) {
    match q.overflow {
        Overflow::Wrap => run::<R, WRAP>(q, pre, input, output, counts),
        Overflow::Sat => run::<R, SAT>(q, pre, input, output, counts),
        Overflow::SatZero => run::<R, SAT_ZERO>(q, pre, input, output, counts),
        Overflow::SatSym => run::<R, SAT_SYM>(q, pre, input, output, counts),
    }
}

/// Applies one stage to a column: `output[i] = quantize(pre(input[i]))`, counting events.
///
/// On x86-64 CPUs with AVX2 and BMI2 the same code runs compiled for them (chosen at run time;
/// the results are identical, integer arithmetic does not depend on the instruction set).
pub fn run_stage(
    q: &StageQ,
    pre: Pre,
    input: &[i64],
    output: &mut [i64],
    counts: &mut EventCounts,
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("bmi2") {
        // SAFETY: the CPU supports AVX2 and BMI2, checked just above.
        return unsafe { run_stage_avx2(q, pre, input, output, counts) };
    }
    run_stage_any(q, pre, input, output, counts)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi2")]
unsafe fn run_stage_avx2(
    q: &StageQ,
    pre: Pre,
    input: &[i64],
    output: &mut [i64],
    counts: &mut EventCounts,
) {
    run_stage_any(q, pre, input, output, counts)
}

#[inline(always)]
fn run_stage_any(
    q: &StageQ,
    pre: Pre,
    input: &[i64],
    output: &mut [i64],
    counts: &mut EventCounts,
) {
    match q.rounding {
        Rounding::Trn => run_r::<TRN>(q, pre, input, output, counts),
        Rounding::TrnZero => run_r::<TRN_ZERO>(q, pre, input, output, counts),
        Rounding::Rnd => run_r::<RND>(q, pre, input, output, counts),
        Rounding::RndZero => run_r::<RND_ZERO>(q, pre, input, output, counts),
        Rounding::RndInf => run_r::<RND_INF>(q, pre, input, output, counts),
        Rounding::RndMinInf => run_r::<RND_MIN_INF>(q, pre, input, output, counts),
        Rounding::RndConv => run_r::<RND_CONV>(q, pre, input, output, counts),
        Rounding::RndConvOdd => run_r::<RND_CONV_ODD>(q, pre, input, output, counts),
    }
}

/// The `i64` plan of a whole datapath.
#[derive(Debug, Clone)]
pub struct FastPlan {
    /// The t stage (input: d * slope).
    pub t: StageQ,
    /// Left shift aligning t on the exact sum's fraction bits.
    pub t_align: u32,
    /// Left shift aligning the offset on the exact sum's fraction bits.
    pub offset_align: u32,
    /// The b stage (input: the exact sum after the cutoff).
    pub b: StageQ,
    /// The squaring stages.
    pub squares: Vec<StageQ>,
    /// The output stage (input: sq_k * coef).
    pub out: StageQ,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fixed::{quantize, Event, Exact};

    /// Every mode pair against the library's `quantize` on values around ties and bounds.
    #[test]
    fn kernels_agree_with_quantize_for_every_mode() {
        let formats = ["s2.4", "u2.4", "s1.0", "u1.3", "s3.-1", "u4.6"];
        for fmt in formats {
            let format: Format = fmt.parse().unwrap();
            for frac_in in [
                format.frac_bits(),
                format.frac_bits() + 1,
                format.frac_bits() + 3,
                format.frac_bits() - 2,
            ] {
                for rounding in Rounding::ALL {
                    for overflow in Overflow::ALL {
                        let spec = StageSpec {
                            format,
                            rounding,
                            overflow,
                        };
                        let q = StageQ::new(frac_in, &spec);
                        let input: Vec<i64> = (-300..=300).collect();
                        let mut out = vec![0; input.len()];
                        let mut counts = [0; 3];
                        run_stage(&q, Pre::Identity, &input, &mut out, &mut counts);
                        let mut want_counts = [0; 3];
                        for (x, got) in input.iter().zip(&out) {
                            let w = quantize(
                                Exact::new(i128::from(*x), frac_in),
                                format,
                                rounding,
                                overflow,
                            );
                            assert_eq!(
                                *got, w.raw,
                                "{fmt} frac_in={frac_in} {rounding} {overflow} x={x}"
                            );
                            match w.event {
                                Event::None => {}
                                Event::Wrapped => want_counts[0] += 1,
                                Event::Saturated => want_counts[1] += 1,
                                Event::Zeroed => want_counts[2] += 1,
                            }
                        }
                        assert_eq!(counts, want_counts, "{fmt} {rounding} {overflow}");
                    }
                }
            }
        }
    }
}
