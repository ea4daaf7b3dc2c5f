//! The `i64` batch kernels: each stage's quantization with its shifts and bounds worked out in
//! advance, and one loop per stage specialised at compile time for its rounding and overflow
//! modes (8 x 4 variants), so the hot loops carry no branch on the modes.
//!
//! These kernels are an optimisation of [`crate::pipeline::Datapath::eval`], which is the
//! plain transcription of the arithmetic; the tests compare the two on random configurations.
//!
//! A kernel is used only where it is proven exact: [`StageQ::proven`] takes a bound on the
//! stage's exact input and accepts the stage only when every shift is below 63 bits and every
//! intermediate, shifted, stays below 2^62. Any other stage runs [`Kernel::Exact`], the same
//! `i128` quantization as `eval`, one element at a time.

use crate::fixed::{quantize, quantize_i64, Event, Exact, Format, Overflow, Quantized, Rounding};
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

/// The largest number of magnitude bits an `i64` kernel handles: every exact input, and every
/// value shifted left, stays below `2^MAX_KERNEL_BITS`, so no `i64` operation can overflow.
pub const MAX_KERNEL_BITS: u32 = 62;

impl StageQ {
    /// The `i64` kernel of a stage receiving exact values with `frac_in` fraction bits whose
    /// magnitudes are below `2^in_bits`, or `None` when it would not be exact: a right shift of
    /// 63 bits or more, or an input or a left-shifted value that may reach `2^62`.
    ///
    /// # Examples
    /// ```
    /// use specfx::fixed::{Overflow, Rounding};
    /// use specfx::pipeline::fast::StageQ;
    /// use specfx::pipeline::StageSpec;
    /// let spec = |f: &str| StageSpec {
    ///     format: f.parse().unwrap(),
    ///     rounding: Rounding::Rnd,
    ///     overflow: Overflow::Sat,
    /// };
    /// // u1.15 x u8.16 (40 bits, 31 fraction bits) into s1.62: a left shift by 31.
    /// assert!(StageQ::proven(31, 40, &spec("s1.62")).is_none());
    /// assert!(StageQ::proven(31, 40, &spec("u8.16")).is_some());
    /// // 19 fraction bits into s60.-56: a right shift by 75.
    /// assert!(StageQ::proven(19, 27, &spec("s60.-56")).is_none());
    /// ```
    pub fn proven(frac_in: i32, in_bits: u32, spec: &StageSpec) -> Option<StageQ> {
        let shift = i64::from(frac_in) - i64::from(spec.format.frac_bits());
        let right = u32::try_from(shift.max(0)).ok()?;
        let left = u32::try_from((-shift).max(0)).ok()?;
        let exact = right <= MAX_KERNEL_BITS
            && in_bits
                .checked_add(left)
                .is_some_and(|bits| bits <= MAX_KERNEL_BITS);
        exact.then(|| StageQ::new(right, left, spec))
    }

    fn new(right: u32, left: u32, spec: &StageSpec) -> StageQ {
        let (mask, half) = if right == 0 {
            (0, 0)
        } else {
            ((1u64 << right) - 1, 1u64 << (right - 1))
        };
        let format: Format = spec.format;
        StageQ {
            right,
            left,
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

/// Quantizes an exact value `raw * 2^-frac` to a stage's spec: the plain transcription that
/// [`Datapath::eval`](crate::pipeline::Datapath::eval) uses, and the kernels' fallback.
#[inline]
pub fn quantize_to(raw: i128, frac: i32, spec: &StageSpec) -> Quantized {
    match i64::try_from(raw) {
        Ok(r) => quantize_i64(r, frac, spec.format, spec.rounding, spec.overflow),
        Err(_) => quantize(
            Exact::new(raw, frac),
            spec.format,
            spec.rounding,
            spec.overflow,
        ),
    }
}

/// Adds one quantization's overflow event to a stage's counts.
#[inline]
pub fn count_event(counts: &mut EventCounts, event: Event) {
    match event {
        Event::None => {}
        Event::Wrapped => counts[0] += 1,
        Event::Saturated => counts[1] += 1,
        Event::Zeroed => counts[2] += 1,
    }
}

/// How a batch computes one stage: the specialised `i64` loop where it is proven exact, the
/// `i128` transcription otherwise.
#[derive(Debug, Clone)]
pub enum Kernel {
    /// The `i64` loop (see [`StageQ::proven`]).
    Fast(StageQ),
    /// Exact `i128` products and [`quantize_to`], one element at a time.
    Exact {
        /// Fraction bits of the exact input.
        frac_in: i32,
        /// The stage's format and modes.
        spec: StageSpec,
    },
}

impl Kernel {
    /// The fastest exact kernel of a stage whose exact input has `frac_in` fraction bits and
    /// magnitudes below `2^in_bits`.
    pub fn for_stage(frac_in: i32, in_bits: u32, spec: &StageSpec) -> Kernel {
        match StageQ::proven(frac_in, in_bits, spec) {
            Some(q) => Kernel::Fast(q),
            None => Kernel::Exact {
                frac_in,
                spec: *spec,
            },
        }
    }

    /// Whether this is the `i64` loop.
    pub fn is_fast(&self) -> bool {
        matches!(self, Kernel::Fast(_))
    }

    /// Applies the stage to a column: `output[i] = quantize(pre(input[i]))`, counting events.
    pub fn run(&self, pre: Pre, input: &[i64], output: &mut [i64], counts: &mut EventCounts) {
        match self {
            Kernel::Fast(q) => run_stage(q, pre, input, output, counts),
            Kernel::Exact { frac_in, spec } => {
                for (x, y) in input.iter().zip(output.iter_mut()) {
                    let x = i128::from(*x);
                    let exact = match pre {
                        Pre::Mul(c) => x * i128::from(c),
                        Pre::Square => x * x,
                        Pre::Identity => x,
                    };
                    let q = quantize_to(exact, *frac_in, spec);
                    *y = q.raw;
                    count_event(counts, q.event);
                }
            }
        }
    }
}

/// Bits needed for the magnitude of a raw value of `format`: every raw `x` has
/// `|x| < 2^bits`.
pub fn magnitude_bits(format: Format) -> u32 {
    let m = format
        .min_raw()
        .unsigned_abs()
        .max(format.max_raw().unsigned_abs());
    64 - m.leading_zeros()
}

/// Bits needed for the magnitude of a constant's raw values.
pub fn constant_bits(raws: impl Iterator<Item = i64>) -> u32 {
    raws.map(|r| 64 - r.unsigned_abs().leading_zeros())
        .max()
        .unwrap_or(0)
}

/// The batch plan of a whole datapath: one kernel per quantizing stage.
#[derive(Debug, Clone)]
pub struct BatchPlan {
    /// The t stage (input: d * slope).
    pub t: Kernel,
    /// Left shift aligning t on the exact sum's fraction bits.
    pub t_align: u32,
    /// Left shift aligning the offset on the exact sum's fraction bits.
    pub offset_align: u32,
    /// The b stage (input: the exact sum after the cutoff); when it is [`Kernel::Fast`] the
    /// sum itself is proven to fit in `i64`.
    pub b: Kernel,
    /// The squaring stages (input: the previous stage squared).
    pub squares: Vec<Kernel>,
    /// The squaring stages bypassed (input: the previous stage as it is).
    pub passes: Vec<Kernel>,
    /// The output stage (input: sq_k * coef).
    pub out: Kernel,
}

impl BatchPlan {
    /// The kernel of squaring stage `i` at an exponent of depth `depth`, and what feeds it:
    /// the square below the depth, the previous stage as it is (bypassed) from it on.
    pub fn square_stage(&self, i: usize, depth: u32) -> (&Kernel, Pre) {
        if i < depth as usize {
            (&self.squares[i], Pre::Square)
        } else {
            (&self.passes[i], Pre::Identity)
        }
    }
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
                        let q = StageQ::proven(frac_in, 10, &spec).expect("small shifts");
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
