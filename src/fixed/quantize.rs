//! Quantization into a format: rounding to its LSB with a [`Rounding`] mode, then overflow
//! handling with an [`Overflow`] mode, reporting what happened as an [`Event`].
use std::fmt;

use crate::fixed::exact::{shl_exact, Exact};
use crate::fixed::format::Format;
use crate::fixed::mode::{Overflow, Rounding};

/// What overflow handling did to a value, so that a pipeline can count it per stage.
///
/// Rounding alone never produces an event; only a value outside the format's range does
/// (plus `SAT_SYM` meeting the most negative code, see [`Overflow::SatSym`]).
///
/// # Examples
///
/// ```
/// use specfx::fixed::{overflow_i64, Event, Format, Overflow};
///
/// let fmt: Format = "u4.0".parse().unwrap();
/// assert_eq!(overflow_i64(16, fmt, Overflow::Wrap).event, Event::Wrapped);
/// assert_eq!(overflow_i64(16, fmt, Overflow::SatZero).event, Event::Zeroed);
/// assert!(Event::Saturated.is_overflow());
/// assert!(!Event::None.is_overflow());
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub enum Event {
    /// The rounded value was a code of the format and was kept as is.
    #[default]
    None,
    /// `WRAP`: the rounded value was out of range and was wrapped to `W` bits.
    Wrapped,
    /// `SAT` or `SAT_SYM`: the rounded value was clamped (for `SAT_SYM`, this includes the most
    /// negative code, replaced by `-max`).
    Saturated,
    /// `SAT_ZERO`: the rounded value was out of range and was replaced by 0.
    Zeroed,
}

impl Event {
    /// True for every event but [`Event::None`].
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Event;
    ///
    /// assert!(Event::Wrapped.is_overflow());
    /// ```
    #[must_use]
    #[inline]
    pub const fn is_overflow(self) -> bool {
        !matches!(self, Event::None)
    }
}

impl fmt::Display for Event {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Event::None => "none",
            Event::Wrapped => "wrapped",
            Event::Saturated => "saturated",
            Event::Zeroed => "zeroed",
        })
    }
}

/// A value brought into a format: its raw code and what overflow handling did.
///
/// # Examples
///
/// ```
/// use specfx::fixed::{quantize, Event, Exact, Format, Overflow, Quantized, Rounding};
///
/// let fmt: Format = "s4.0".parse().unwrap();
/// let q = quantize(Exact::new(15, 1), fmt, Rounding::Rnd, Overflow::Sat); // 7.5
/// assert_eq!(q, Quantized { raw: 7, event: Event::Saturated });
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Quantized {
    /// The raw code, always in the format's range.
    pub raw: i64,
    /// What overflow handling did.
    pub event: Event,
}

/// Quantizes an exact value into `fmt`: rounds to `fmt`'s LSB with `rounding`, then handles
/// overflow with `overflow`, as `ac_fixed` does on assignment.
///
/// When `fmt` has fewer fraction bits than `x`, the raw is shifted right by the difference with
/// the rounding mode ([`round_shift_i128`]); when it has more, the raw is shifted left, which is
/// exact. The rounded value is then compared with the format's range, even when it no longer
/// fits in `i128` (a large left shift): such a value always overflows, and `WRAP` keeps its low
/// `W` bits. The result's raw is always a code of `fmt`.
///
/// This is the plain reference path; [`quantize_i64`] is the fast path for `i64` raws.
///
/// # Examples
///
/// ```
/// use specfx::fixed::{quantize, Event, Exact, Format, Overflow, Rounding};
///
/// let fmt: Format = "s2.2".parse().unwrap(); // codes -8..=7, LSB 0.25
/// let x = Exact::from_f64(-1.375).unwrap(); // -5.5 LSBs: a tie
/// assert_eq!(quantize(x, fmt, Rounding::Trn, Overflow::Wrap).raw, -6);
/// assert_eq!(quantize(x, fmt, Rounding::RndConv, Overflow::Wrap).raw, -6);
/// assert_eq!(quantize(x, fmt, Rounding::RndZero, Overflow::Wrap).raw, -5);
///
/// let big = Exact::from_f64(2.5).unwrap(); // 10 LSBs: out of range
/// let q = quantize(big, fmt, Rounding::Trn, Overflow::Wrap);
/// assert_eq!((q.raw, q.event), (-6, Event::Wrapped));
/// ```
#[must_use]
pub fn quantize(x: Exact, fmt: Format, rounding: Rounding, overflow: Overflow) -> Quantized {
    let shift = i64::from(x.frac_bits) - i64::from(fmt.frac_bits());
    let rounded = if shift >= 0 {
        let shift = u32::try_from(shift).unwrap_or(u32::MAX);
        Rounded::Fits(round_shift_i128(x.raw, shift, rounding))
    } else {
        let left = -shift;
        match shl_exact(x.raw, left) {
            Some(value) => Rounded::Fits(value),
            None => Rounded::Beyond {
                negative: x.raw < 0,
                low_bits: if left < 128 { x.raw << left } else { 0 },
            },
        }
    };
    handle_overflow(rounded, fmt, overflow)
}

/// A rounded value, which may not fit in `i128` after a left shift.
#[derive(Debug, Clone, Copy)]
enum Rounded {
    Fits(i128),
    /// Magnitude at least 2^127: out of range of every format.
    Beyond {
        negative: bool,
        /// The value modulo 2^128 (enough for wrapping to at most 64 bits).
        low_bits: i128,
    },
}

/// Overflow handling on a rounded value, written plainly (the reference for [`overflow_i64`]).
fn handle_overflow(value: Rounded, fmt: Format, mode: Overflow) -> Quantized {
    let (in_range, negative, low_bits) = match value {
        Rounded::Fits(v) => (fmt.contains_raw(v), v < 0, v),
        Rounded::Beyond { negative, low_bits } => (false, negative, low_bits),
    };
    let min = fmt.min_raw();
    let max = fmt.max_raw();
    if in_range {
        let raw = low_bits as i64;
        if mode == Overflow::SatSym && fmt.is_signed() && raw == min {
            // ac_fixed: the most negative code counts as an overflow under SAT_SYM, and the
            // negative saturation value is built as "most negative code, LSB set".
            return Quantized {
                raw: min | 1,
                event: Event::Saturated,
            };
        }
        return Quantized {
            raw,
            event: Event::None,
        };
    }
    match mode {
        Overflow::Wrap => Quantized {
            raw: wrap_to_width(low_bits, fmt),
            event: Event::Wrapped,
        },
        Overflow::Sat => Quantized {
            raw: if negative { min } else { max },
            event: Event::Saturated,
        },
        Overflow::SatZero => Quantized {
            raw: 0,
            event: Event::Zeroed,
        },
        Overflow::SatSym => Quantized {
            raw: match (negative, fmt.is_signed()) {
                (false, _) => max,
                (true, true) => min | 1,
                (true, false) => min,
            },
            event: Event::Saturated,
        },
    }
}

/// The code of `fmt` congruent to `value` modulo `2^W`.
fn wrap_to_width(value: i128, fmt: Format) -> i64 {
    let modulus = 1i128 << fmt.width();
    let residue = value.rem_euclid(modulus);
    if fmt.is_signed() && residue >= modulus / 2 {
        (residue - modulus) as i64
    } else {
        residue as i64
    }
}

/// Where the bits dropped by a right shift lie relative to half an output LSB.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Remainder {
    Zero,
    BelowHalf,
    Half,
    AboveHalf,
}

/// `floor(raw / 2^shift)` and where the remainder lies, for `shift >= 1`.
fn floor_and_remainder(raw: i128, shift: u32) -> (i128, Remainder) {
    debug_assert!(shift >= 1);
    if shift < 128 {
        let floor = raw >> shift;
        let remainder = (raw as u128) & ((1u128 << shift) - 1);
        let half = 1u128 << (shift - 1);
        let class = if remainder == 0 {
            Remainder::Zero
        } else if remainder < half {
            Remainder::BelowHalf
        } else if remainder == half {
            Remainder::Half
        } else {
            Remainder::AboveHalf
        };
        (floor, class)
    } else {
        // |raw| <= 2^127 <= 2^(shift - 1): the value is in [-1/2, 1/2).
        if raw == 0 {
            (0, Remainder::Zero)
        } else if raw > 0 {
            (0, Remainder::BelowHalf)
        } else if raw == i128::MIN && shift == 128 {
            // Exactly -1/2: floor -1, remainder 2^127 = half.
            (-1, Remainder::Half)
        } else {
            // In (-1/2, 0): floor -1, remainder 2^shift + raw > half.
            (-1, Remainder::AboveHalf)
        }
    }
}

/// Divides `raw` by `2^shift` and rounds with `mode`, exactly, for any `shift`.
///
/// This is the plain `i128` reference path: it classifies the dropped bits against half an
/// LSB and decides in one `match`. `shift = 0` returns `raw`; shifts of 128 and more are
/// handled too (the value is then in `[-1/2, 1/2)`, and `i128::MIN >> 128` is a tie).
///
/// # Examples
///
/// ```
/// use specfx::fixed::{round_shift_i128, Rounding};
///
/// assert_eq!(round_shift_i128(-5, 1, Rounding::RndZero), -2); // -2.5 -> -2
/// assert_eq!(round_shift_i128(-5, 1, Rounding::RndInf), -3); // -2.5 -> -3
/// assert_eq!(round_shift_i128(i128::MIN, 128, Rounding::Rnd), 0); // -0.5 -> 0
/// assert_eq!(round_shift_i128(i128::MIN, 128, Rounding::RndMinInf), -1);
/// ```
#[must_use]
pub fn round_shift_i128(raw: i128, shift: u32, mode: Rounding) -> i128 {
    if shift == 0 {
        return raw;
    }
    let (floor, remainder) = floor_and_remainder(raw, shift);
    let negative = raw < 0;
    let floor_is_odd = floor & 1 == 1;
    let round_up = match (mode, remainder) {
        (_, Remainder::Zero) => false,
        (Rounding::Trn, _) => false,
        (Rounding::TrnZero, _) => negative,
        (_, Remainder::BelowHalf) => false,
        (_, Remainder::AboveHalf) => true,
        (Rounding::Rnd, Remainder::Half) => true,
        (Rounding::RndZero, Remainder::Half) => negative,
        (Rounding::RndInf, Remainder::Half) => !negative,
        (Rounding::RndMinInf, Remainder::Half) => false,
        (Rounding::RndConv, Remainder::Half) => floor_is_odd,
        (Rounding::RndConvOdd, Remainder::Half) => !floor_is_odd,
    };
    // shift >= 1, so floor <= i128::MAX / 2 and floor + 1 cannot overflow.
    floor + i128::from(round_up)
}

/// Divides `raw` by `2^shift` and rounds with `mode`: the fast path for hot loops.
///
/// Agrees with [`round_shift_i128`] for every `raw` and `shift` (tested). For `1 <= shift <= 63`
/// it is branch-free on the data: `floor(raw / 2^shift)` plus the carry out of
/// `remainder + bias`, where the bias (at most `2^shift - 1`) encodes the mode, e.g. `half`
/// for `RND`, `half - 1 + (floor & 1)` for `RND_CONV`. Shifts of 64 and more, where the value
/// is in `[-1/2, 1/2)`, go to the `i128` path.
///
/// # Examples
///
/// ```
/// use specfx::fixed::{round_shift_i64, Rounding};
///
/// assert_eq!(round_shift_i64(7, 1, Rounding::RndConv), 4); // 3.5 -> 4
/// assert_eq!(round_shift_i64(5, 1, Rounding::RndConv), 2); // 2.5 -> 2
/// assert_eq!(round_shift_i64(-7, 2, Rounding::TrnZero), -1); // -1.75 -> -1
/// assert_eq!(round_shift_i64(-7, 2, Rounding::Trn), -2);
/// assert_eq!(round_shift_i64(i64::MIN, 64, Rounding::RndInf), -1); // -0.5 -> -1
/// ```
#[must_use]
#[inline]
pub fn round_shift_i64(raw: i64, shift: u32, mode: Rounding) -> i64 {
    if shift == 0 {
        return raw;
    }
    if shift >= 64 {
        return round_shift_i64_wide(raw, shift, mode);
    }
    let floor = raw >> shift;
    let mask = (1u64 << shift) - 1;
    let remainder = (raw as u64) & mask;
    let half = 1u64 << (shift - 1);
    let negative = (raw as u64) >> 63; // 1 when raw < 0
    let floor_is_odd = (floor as u64) & 1;
    // remainder + bias < 2^(shift + 1) <= 2^64: the carry out of bit `shift` is 0 or 1.
    let bias = match mode {
        Rounding::Trn => 0,
        Rounding::TrnZero => mask & negative.wrapping_neg(),
        Rounding::Rnd => half,
        Rounding::RndZero => half - 1 + negative,
        Rounding::RndInf => half - negative,
        Rounding::RndMinInf => half - 1,
        Rounding::RndConv => half - 1 + floor_is_odd,
        Rounding::RndConvOdd => half - floor_is_odd,
    };
    floor + ((remainder + bias) >> shift) as i64
}

#[cold]
#[inline(never)]
fn round_shift_i64_wide(raw: i64, shift: u32, mode: Rounding) -> i64 {
    // The result is -1, 0 or 1.
    round_shift_i128(i128::from(raw), shift, mode) as i64
}

/// Overflow handling for a rounded value that fits in `i64`: the fast path for hot loops.
///
/// Agrees with the overflow step of [`quantize`] (tested): `WRAP` keeps the low `W` bits,
/// `SAT` clamps, `SAT_ZERO` gives 0, `SAT_SYM` clamps signed values to `[-max, max]` with
/// `ac_fixed`'s treatment of the most negative code (see [`Overflow::SatSym`]).
///
/// # Examples
///
/// ```
/// use specfx::fixed::{overflow_i64, Event, Format, Overflow, Quantized};
///
/// let fmt: Format = "s4.0".parse().unwrap(); // codes -8..=7
/// assert_eq!(overflow_i64(8, fmt, Overflow::Wrap), Quantized { raw: -8, event: Event::Wrapped });
/// assert_eq!(overflow_i64(-9, fmt, Overflow::Sat), Quantized { raw: -8, event: Event::Saturated });
/// assert_eq!(overflow_i64(-9, fmt, Overflow::SatZero), Quantized { raw: 0, event: Event::Zeroed });
/// assert_eq!(overflow_i64(-8, fmt, Overflow::SatSym), Quantized { raw: -7, event: Event::Saturated });
/// assert_eq!(overflow_i64(5, fmt, Overflow::SatSym), Quantized { raw: 5, event: Event::None });
/// ```
#[must_use]
#[inline]
pub fn overflow_i64(value: i64, fmt: Format, mode: Overflow) -> Quantized {
    let min = fmt.min_raw();
    let max = fmt.max_raw();
    let (raw, event) = match mode {
        Overflow::Wrap => {
            let raw = if fmt.is_signed() {
                let unused = 64 - fmt.width();
                (value << unused) >> unused
            } else {
                value & max
            };
            (
                raw,
                if raw == value {
                    Event::None
                } else {
                    Event::Wrapped
                },
            )
        }
        Overflow::Sat => {
            let raw = value.clamp(min, max);
            (
                raw,
                if raw == value {
                    Event::None
                } else {
                    Event::Saturated
                },
            )
        }
        Overflow::SatZero => {
            if min <= value && value <= max {
                (value, Event::None)
            } else {
                (0, Event::Zeroed)
            }
        }
        Overflow::SatSym => {
            // Signed: every value <= min saturates, to `min | 1` (= -max, or -1 when W = 1).
            let signed = i64::from(fmt.is_signed());
            let lowest_kept = min + signed;
            if value < lowest_kept {
                (min | signed, Event::Saturated)
            } else if value > max {
                (max, Event::Saturated)
            } else {
                (value, Event::None)
            }
        }
    };
    Quantized { raw, event }
}

/// Quantizes the value `raw * 2^-frac_bits` into `fmt`: the fast path of [`quantize`] for a raw
/// that fits in `i64`, e.g. a product of two 32-bit raws.
///
/// Uses [`round_shift_i64`] and [`overflow_i64`]; a left shift that leaves `i64` (so always an
/// overflow) goes to [`quantize`]. Agrees with
/// `quantize(Exact::new(raw.into(), frac_bits), ..)` for every input (tested).
///
/// # Examples
///
/// ```
/// use specfx::fixed::{quantize_i64, Event, Format, Overflow, Rounding};
///
/// let fmt: Format = "u1.15".parse().unwrap();
/// // 0.75 * 0.75 = 0.5625 with 30 fraction bits, back to u1.15.
/// let product = (3i64 << 13) * (3i64 << 13);
/// let q = quantize_i64(product, 30, fmt, Rounding::RndConv, Overflow::Sat);
/// assert_eq!((q.raw, q.event), (0x4800, Event::None));
/// ```
#[must_use]
#[inline]
pub fn quantize_i64(
    raw: i64,
    frac_bits: i32,
    fmt: Format,
    rounding: Rounding,
    overflow: Overflow,
) -> Quantized {
    let shift = i64::from(frac_bits) - i64::from(fmt.frac_bits());
    if shift >= 0 {
        let shift = u32::try_from(shift).unwrap_or(u32::MAX);
        return overflow_i64(round_shift_i64(raw, shift, rounding), fmt, overflow);
    }
    let left = -shift;
    if left < 64 {
        let shifted = raw << left;
        if shifted >> left == raw {
            return overflow_i64(shifted, fmt, overflow);
        }
    }
    quantize_beyond_i64(raw, frac_bits, fmt, rounding, overflow)
}

#[cold]
#[inline(never)]
fn quantize_beyond_i64(
    raw: i64,
    frac_bits: i32,
    fmt: Format,
    rounding: Rounding,
    overflow: Overflow,
) -> Quantized {
    quantize(
        Exact::new(i128::from(raw), frac_bits),
        fmt,
        rounding,
        overflow,
    )
}

/// Quantizes a finite `f64` into `fmt`, exactly as [`quantize`] would its exact value (every
/// finite `f64` is a dyadic rational); `None` for NaN and infinities.
///
/// This is how a model that keeps some stages in `f64` quantizes one of them.
///
/// # Examples
///
/// ```
/// use specfx::fixed::{quantize_f64, Event, Format, Overflow, Rounding};
///
/// let fmt: Format = "s2.2".parse().unwrap();
/// let q = quantize_f64(-1.375, fmt, Rounding::RndConv, Overflow::Wrap).unwrap();
/// assert_eq!((q.raw, q.event), (-6, Event::None));
/// assert_eq!(quantize_f64(f64::NAN, fmt, Rounding::Trn, Overflow::Sat), None);
/// ```
#[must_use]
#[inline]
pub fn quantize_f64(
    x: f64,
    fmt: Format,
    rounding: Rounding,
    overflow: Overflow,
) -> Option<Quantized> {
    let e = Exact::from_f64(x)?;
    // A finite f64's raw has at most 53 significant bits, so it always fits in i64.
    Some(quantize_i64(
        e.raw as i64,
        e.frac_bits,
        fmt,
        rounding,
        overflow,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Column order of the tables below.
    const MODES: [Rounding; 8] = [
        Rounding::Trn,
        Rounding::TrnZero,
        Rounding::Rnd,
        Rounding::RndZero,
        Rounding::RndInf,
        Rounding::RndMinInf,
        Rounding::RndConv,
        Rounding::RndConvOdd,
    ];

    /// Runs one expected rounding through every path that can express it.
    fn check_rounding(raw: i128, shift: u32, mode: Rounding, expected: i128) {
        let what = format!("raw {raw} >> {shift} with {mode}");
        assert_eq!(round_shift_i128(raw, shift, mode), expected, "i128: {what}");
        // Through quantize into a 64-bit integer format, which never overflows here.
        let s64: Format = "s64.0".parse().unwrap();
        if let Ok(frac_bits) = i32::try_from(shift) {
            for overflow in Overflow::ALL {
                let q = quantize(Exact::new(raw, frac_bits), s64, mode, overflow);
                let expected_q = if overflow == Overflow::SatSym && expected == i128::from(i64::MIN)
                {
                    Quantized {
                        raw: i64::MIN + 1,
                        event: Event::Saturated,
                    }
                } else {
                    Quantized {
                        raw: expected as i64,
                        event: Event::None,
                    }
                };
                assert_eq!(q, expected_q, "quantize {overflow}: {what}");
            }
        }
        if let Ok(raw64) = i64::try_from(raw) {
            assert_eq!(
                i128::from(round_shift_i64(raw64, shift, mode)),
                expected,
                "i64: {what}"
            );
            if let Ok(frac_bits) = i32::try_from(shift) {
                let q = quantize_i64(raw64, frac_bits, s64, mode, Overflow::Wrap);
                assert_eq!(i128::from(q.raw), expected, "quantize_i64: {what}");
                assert_eq!(q.event, Event::None, "quantize_i64: {what}");
            }
        }
    }

    fn check_table(shift: u32, rows: &[(i128, [i128; 8])]) {
        for &(raw, expected) in rows {
            for (mode, want) in MODES.into_iter().zip(expected) {
                check_rounding(raw, shift, mode, want);
            }
        }
    }

    #[test]
    fn rounding_truth_table_dropping_one_bit() {
        #[rustfmt::skip]
        let rows = [
            //      TRN TRN_Z RND RND_Z INF MIN_INF CONV ODD      value
            (-7, [-4, -3, -3, -3, -4, -4, -4, -3]), // -3.5
            (-6, [-3, -3, -3, -3, -3, -3, -3, -3]), // -3
            (-5, [-3, -2, -2, -2, -3, -3, -2, -3]), // -2.5
            (-4, [-2, -2, -2, -2, -2, -2, -2, -2]), // -2
            (-3, [-2, -1, -1, -1, -2, -2, -2, -1]), // -1.5
            (-2, [-1, -1, -1, -1, -1, -1, -1, -1]), // -1
            (-1, [-1,  0,  0,  0, -1, -1,  0, -1]), // -0.5
            ( 0, [ 0,  0,  0,  0,  0,  0,  0,  0]), // 0
            ( 1, [ 0,  0,  1,  0,  1,  0,  0,  1]), // 0.5
            ( 2, [ 1,  1,  1,  1,  1,  1,  1,  1]), // 1
            ( 3, [ 1,  1,  2,  1,  2,  1,  2,  1]), // 1.5
            ( 4, [ 2,  2,  2,  2,  2,  2,  2,  2]), // 2
            ( 5, [ 2,  2,  3,  2,  3,  2,  2,  3]), // 2.5
            ( 6, [ 3,  3,  3,  3,  3,  3,  3,  3]), // 3
            ( 7, [ 3,  3,  4,  3,  4,  3,  4,  3]), // 3.5
        ];
        check_table(1, &rows);
    }

    #[test]
    fn rounding_truth_table_dropping_two_bits() {
        #[rustfmt::skip]
        let rows = [
            //      TRN TRN_Z RND RND_Z INF MIN_INF CONV ODD      value
            (-7, [-2, -1, -2, -2, -2, -2, -2, -2]), // -1.75
            (-6, [-2, -1, -1, -1, -2, -2, -2, -1]), // -1.5
            (-5, [-2, -1, -1, -1, -1, -1, -1, -1]), // -1.25
            (-4, [-1, -1, -1, -1, -1, -1, -1, -1]), // -1
            (-3, [-1,  0, -1, -1, -1, -1, -1, -1]), // -0.75
            (-2, [-1,  0,  0,  0, -1, -1,  0, -1]), // -0.5
            (-1, [-1,  0,  0,  0,  0,  0,  0,  0]), // -0.25
            ( 0, [ 0,  0,  0,  0,  0,  0,  0,  0]), // 0
            ( 1, [ 0,  0,  0,  0,  0,  0,  0,  0]), // 0.25
            ( 2, [ 0,  0,  1,  0,  1,  0,  0,  1]), // 0.5
            ( 3, [ 0,  0,  1,  1,  1,  1,  1,  1]), // 0.75
            ( 4, [ 1,  1,  1,  1,  1,  1,  1,  1]), // 1
            ( 5, [ 1,  1,  1,  1,  1,  1,  1,  1]), // 1.25
            ( 6, [ 1,  1,  2,  1,  2,  1,  2,  1]), // 1.5
            ( 7, [ 1,  1,  2,  2,  2,  2,  2,  2]), // 1.75
        ];
        check_table(2, &rows);
    }

    #[test]
    fn rounding_at_both_ends_of_i64() {
        const H: i128 = 1 << 62;
        const MAX: i128 = i64::MAX as i128;
        const MIN: i128 = i64::MIN as i128;
        #[rustfmt::skip]
        let cases: [(i128, u32, [i128; 8]); 18] = [
            //                   TRN TRN_Z RND RND_Z INF MIN_INF CONV ODD
            (MAX, 0,     [MAX; 8]),
            (MIN, 0,     [MIN; 8]),
            // 2^62 - 1/2: a tie between 2^62 - 1 (odd) and 2^62 (even).
            (MAX, 1,     [H - 1, H - 1, H, H - 1, H, H - 1, H, H - 1]),
            (MAX - 1, 1, [H - 1; 8]),
            (MIN, 1,     [-H; 8]),
            // -2^62 + 1/2: a tie between -2^62 (even) and -2^62 + 1 (odd).
            (MIN + 1, 1, [-H, -H + 1, -H + 1, -H + 1, -H, -H, -H, -H + 1]),
            // 1 - 2^-63 and -1 + 2^-63.
            (MAX, 63,     [0, 0, 1, 1, 1, 1, 1, 1]),
            (MIN, 63,     [-1; 8]),
            (MIN + 1, 63, [-1, 0, -1, -1, -1, -1, -1, -1]),
            // +-2^-63: one LSB of the input either side of zero.
            (1, 63,  [0; 8]),
            (-1, 63, [-1, 0, 0, 0, 0, 0, 0, 0]),
            // +-1/2 and 3/2 with many dropped bits.
            (H, 63,     [0, 0, 1, 0, 1, 0, 0, 1]),
            (-H, 63,    [-1, 0, 0, 0, -1, -1, 0, -1]),
            (3 * (H / 2), 62, [1, 1, 2, 1, 2, 1, 2, 1]),
            // -1/2 exactly with a shift of 64, and just under +1/2.
            (MIN, 64, [-1, 0, 0, 0, -1, -1, 0, -1]),
            (MAX, 64, [0; 8]),
            // Tiny negative values far below the LSB.
            (-1, 200,                [-1, 0, 0, 0, 0, 0, 0, 0]),
            (MIN, u32::MAX,          [-1, 0, 0, 0, 0, 0, 0, 0]),
        ];
        for (raw, shift, expected) in cases {
            for (mode, want) in MODES.into_iter().zip(expected) {
                check_rounding(raw, shift, mode, want);
            }
        }
    }

    #[test]
    fn rounding_at_both_ends_of_i128() {
        #[rustfmt::skip]
        let cases: [(i128, u32, [i128; 8]); 9] = [
            //                         TRN TRN_Z RND RND_Z INF MIN_INF CONV ODD
            // 1 - 2^-127 and -1 + 2^-127.
            (i128::MAX, 127,     [0, 0, 1, 1, 1, 1, 1, 1]),
            (i128::MIN, 127,     [-1; 8]),
            (i128::MIN + 1, 127, [-1, 0, -1, -1, -1, -1, -1, -1]),
            // -1/2 exactly, the only tie beyond a shift of 127.
            (i128::MIN, 128,     [-1, 0, 0, 0, -1, -1, 0, -1]),
            (i128::MIN + 1, 128, [-1, 0, 0, 0, 0, 0, 0, 0]),
            (i128::MAX, 128,     [0; 8]),
            (i128::MIN, 129,     [-1, 0, 0, 0, 0, 0, 0, 0]),
            // +1/2 and -1/2 with 127 dropped bits.
            (1 << 126, 127,      [0, 0, 1, 0, 1, 0, 0, 1]),
            (-(1 << 126), 127,   [-1, 0, 0, 0, -1, -1, 0, -1]),
        ];
        for (raw, shift, expected) in cases {
            for (mode, want) in MODES.into_iter().zip(expected) {
                check_rounding(raw, shift, mode, want);
            }
        }
    }

    /// Expected (raw, event) per overflow mode, in the order WRAP, SAT, SAT_ZERO, SAT_SYM.
    type OverflowRow = (i128, [(i64, Event); 4]);

    fn check_overflow_table(formats: &[&str], rows: &[OverflowRow]) {
        for text in formats {
            let fmt: Format = text.parse().unwrap();
            for &(value, expected) in rows {
                for (mode, (raw, event)) in Overflow::ALL.into_iter().zip(expected) {
                    let want = Quantized { raw, event };
                    let what = format!("{value} into {fmt} with {mode}");
                    let exact = Exact::new(value, fmt.frac_bits());
                    assert_eq!(
                        quantize(exact, fmt, Rounding::Trn, mode),
                        want,
                        "quantize: {what}"
                    );
                    // Also with one extra fraction bit to drop (exact, so any mode).
                    if let Some(twice) = value.checked_mul(2) {
                        let doubled = Exact::new(twice, fmt.frac_bits() + 1);
                        assert_eq!(
                            quantize(doubled, fmt, Rounding::RndConv, mode),
                            want,
                            "quantize with a shift: {what}"
                        );
                    }
                    if let Ok(value64) = i64::try_from(value) {
                        assert_eq!(
                            overflow_i64(value64, fmt, mode),
                            want,
                            "overflow_i64: {what}"
                        );
                        assert_eq!(
                            quantize_i64(value64, fmt.frac_bits(), fmt, Rounding::Rnd, mode),
                            want,
                            "quantize_i64: {what}"
                        );
                    }
                }
            }
        }
    }

    use Event::{None as Kept, Saturated as Sat, Wrapped as Wrap, Zeroed as Zero};

    #[test]
    fn overflow_truth_table_signed_4_bits() {
        #[rustfmt::skip]
        let rows: [OverflowRow; 11] = [
            //          WRAP          SAT          SAT_ZERO     SAT_SYM
            (7,    [(7, Kept),    (7, Kept),    (7, Kept),    (7, Kept)]),   // max
            (8,    [(-8, Wrap),  (7, Sat),    (0, Zero),   (7, Sat)]),   // max + 1
            (6,    [(6, Kept),    (6, Kept),    (6, Kept),    (6, Kept)]),   // max - 1
            (-8,   [(-8, Kept),   (-8, Kept),   (-8, Kept),   (-7, Sat)]),  // min
            (-7,   [(-7, Kept),   (-7, Kept),   (-7, Kept),   (-7, Kept)]),  // min + 1
            (-9,   [(7, Wrap),   (-8, Sat),   (0, Zero),   (-7, Sat)]),  // min - 1
            (0,    [(0, Kept),    (0, Kept),    (0, Kept),    (0, Kept)]),
            (100,  [(4, Wrap),   (7, Sat),    (0, Zero),   (7, Sat)]),   // 100 = 6*16 + 4
            (-100, [(-4, Wrap),  (-8, Sat),   (0, Zero),   (-7, Sat)]),  // -100 = -7*16 + 12
            (23,   [(7, Wrap),   (7, Sat),    (0, Zero),   (7, Sat)]),   // wraps onto max
            (-24,  [(-8, Wrap),  (-8, Sat),   (0, Zero),   (-7, Sat)]),  // wraps onto min
        ];
        check_overflow_table(&["s4.0", "s-1.5", "s6.-2"], &rows);
    }

    #[test]
    fn overflow_truth_table_unsigned_4_bits() {
        #[rustfmt::skip]
        let rows: [OverflowRow; 9] = [
            //          WRAP          SAT          SAT_ZERO     SAT_SYM
            (15,   [(15, Kept),   (15, Kept),   (15, Kept),   (15, Kept)]),  // max
            (16,   [(0, Wrap),   (15, Sat),   (0, Zero),   (15, Sat)]),  // max + 1
            (14,   [(14, Kept),   (14, Kept),   (14, Kept),   (14, Kept)]),  // max - 1
            (0,    [(0, Kept),    (0, Kept),    (0, Kept),    (0, Kept)]),   // min
            (1,    [(1, Kept),    (1, Kept),    (1, Kept),    (1, Kept)]),   // min + 1
            (-1,   [(15, Wrap),  (0, Sat),    (0, Zero),   (0, Sat)]),   // min - 1
            (100,  [(4, Wrap),   (15, Sat),   (0, Zero),   (15, Sat)]),
            (-100, [(12, Wrap),  (0, Sat),    (0, Zero),   (0, Sat)]),
            (-16,  [(0, Wrap),   (0, Sat),    (0, Zero),   (0, Sat)]),
        ];
        check_overflow_table(&["u4.0", "u0.4", "u14.-10"], &rows);
    }

    #[test]
    fn overflow_truth_table_64_bits() {
        const MAX: i64 = i64::MAX;
        const MIN: i64 = i64::MIN;
        const MAX_: i128 = MAX as i128;
        const MIN_: i128 = MIN as i128;
        #[rustfmt::skip]
        let rows: [OverflowRow; 7] = [
            //              WRAP            SAT           SAT_ZERO     SAT_SYM
            (MAX_,      [(MAX, Kept),     (MAX, Kept),   (MAX, Kept),  (MAX, Kept)]),
            (MAX_ + 1,  [(MIN, Wrap),    (MAX, Sat),   (0, Zero),   (MAX, Sat)]),
            (MIN_,      [(MIN, Kept),     (MIN, Kept),   (MIN, Kept),  (-MAX, Sat)]),
            (MIN_ + 1,  [(-MAX, Kept),    (-MAX, Kept),  (-MAX, Kept), (-MAX, Kept)]),
            (MIN_ - 1,  [(MAX, Wrap),    (MIN, Sat),   (0, Zero),   (-MAX, Sat)]),
            (i128::MAX, [(-1, Wrap),     (MAX, Sat),   (0, Zero),   (MAX, Sat)]),
            (i128::MIN, [(0, Wrap),      (MIN, Sat),   (0, Zero),   (-MAX, Sat)]),
        ];
        check_overflow_table(&["s64.0", "s0.64", "s70.-6"], &rows);

        #[rustfmt::skip]
        let rows: [OverflowRow; 5] = [
            //              WRAP            SAT           SAT_ZERO     SAT_SYM
            (MAX_,      [(MAX, Kept),     (MAX, Kept),   (MAX, Kept),  (MAX, Kept)]),
            (MAX_ + 1,  [(0, Wrap),      (MAX, Sat),   (0, Zero),   (MAX, Sat)]),
            (-1,        [(MAX, Wrap),    (0, Sat),     (0, Zero),   (0, Sat)]),
            (MIN_,      [(0, Wrap),      (0, Sat),     (0, Zero),   (0, Sat)]),
            (i128::MAX, [(MAX, Wrap),    (MAX, Sat),   (0, Zero),   (MAX, Sat)]),
        ];
        check_overflow_table(&["u63.0", "u1.62"], &rows);
    }

    #[test]
    fn overflow_truth_table_1_bit() {
        // s1: codes -1 and 0. ac_fixed's SAT_SYM sets the sign bit then the LSB (the same bit),
        // so a negative value gives -1 and counts as saturated.
        #[rustfmt::skip]
        let signed: [OverflowRow; 5] = [
            //        WRAP         SAT          SAT_ZERO     SAT_SYM
            (0,   [(0, Kept),   (0, Kept),    (0, Kept),    (0, Kept)]),
            (-1,  [(-1, Kept),  (-1, Kept),   (-1, Kept),   (-1, Sat)]),
            (1,   [(-1, Wrap), (0, Sat),    (0, Zero),   (0, Sat)]),
            (-2,  [(0, Wrap),  (-1, Sat),   (0, Zero),   (-1, Sat)]),
            (3,   [(-1, Wrap), (0, Sat),    (0, Zero),   (0, Sat)]),
        ];
        check_overflow_table(&["s1.0", "s0.1", "s-7.8"], &signed);
        #[rustfmt::skip]
        let unsigned: [OverflowRow; 4] = [
            //        WRAP         SAT          SAT_ZERO     SAT_SYM
            (1,   [(1, Kept),   (1, Kept),    (1, Kept),    (1, Kept)]),
            (2,   [(0, Wrap),  (1, Sat),    (0, Zero),   (1, Sat)]),
            (-1,  [(1, Wrap),  (0, Sat),    (0, Zero),   (0, Sat)]),
            (3,   [(1, Wrap),  (1, Sat),    (0, Zero),   (1, Sat)]),
        ];
        check_overflow_table(&["u1.0", "u0.1"], &unsigned);
    }

    #[test]
    fn rounding_up_can_overflow() {
        let s4: Format = "s4.0".parse().unwrap();
        let u4: Format = "u4.0".parse().unwrap();
        // 7.5 rounds to 8 with RND: out of s4.0.
        let x = Exact::new(15, 1);
        assert_eq!(
            quantize(x, s4, Rounding::Rnd, Overflow::Sat),
            Quantized {
                raw: 7,
                event: Event::Saturated
            }
        );
        assert_eq!(
            quantize(x, s4, Rounding::Rnd, Overflow::Wrap),
            Quantized {
                raw: -8,
                event: Event::Wrapped
            }
        );
        assert_eq!(
            quantize(x, s4, Rounding::Trn, Overflow::Sat),
            Quantized {
                raw: 7,
                event: Event::None
            }
        );
        // -8.5 rounds to -8 with RND (in range) and to -9 with RND_INF (out of range).
        let y = Exact::new(-17, 1);
        assert_eq!(
            quantize(y, s4, Rounding::Rnd, Overflow::Sat),
            Quantized {
                raw: -8,
                event: Event::None
            }
        );
        assert_eq!(
            quantize(y, s4, Rounding::RndInf, Overflow::SatZero),
            Quantized {
                raw: 0,
                event: Event::Zeroed
            }
        );
        // -0.25 rounds to 0 in u4.0 with RND (no overflow) but to -1 with TRN (overflow).
        let z = Exact::new(-1, 2);
        assert_eq!(
            quantize(z, u4, Rounding::Rnd, Overflow::Sat),
            Quantized {
                raw: 0,
                event: Event::None
            }
        );
        assert_eq!(
            quantize(z, u4, Rounding::Trn, Overflow::Wrap),
            Quantized {
                raw: 15,
                event: Event::Wrapped
            }
        );
        assert_eq!(
            quantize_i64(-1, 2, u4, Rounding::Trn, Overflow::Sat),
            Quantized {
                raw: 0,
                event: Event::Saturated
            }
        );
    }

    #[test]
    fn left_shifts_beyond_i64_and_i128_overflow() {
        let s8: Format = "s8.0".parse().unwrap();
        let s64: Format = "s64.0".parse().unwrap();
        // 2^100: low 8 bits are zero.
        let x = Exact::new(1, -100);
        let expect = |raw, event| Quantized { raw, event };
        assert_eq!(
            quantize(x, s8, Rounding::Trn, Overflow::Wrap),
            expect(0, Event::Wrapped)
        );
        assert_eq!(
            quantize(x, s8, Rounding::Trn, Overflow::Sat),
            expect(127, Event::Saturated)
        );
        assert_eq!(
            quantize_i64(1, -100, s8, Rounding::Trn, Overflow::Sat),
            expect(127, Event::Saturated)
        );
        // -3 * 2^200.
        let y = Exact::new(-3, -200);
        assert_eq!(
            quantize(y, s8, Rounding::Trn, Overflow::Wrap),
            expect(0, Event::Wrapped)
        );
        assert_eq!(
            quantize(y, s8, Rounding::Trn, Overflow::Sat),
            expect(-128, Event::Saturated)
        );
        assert_eq!(
            quantize(y, s8, Rounding::Trn, Overflow::SatSym),
            expect(-127, Event::Saturated)
        );
        assert_eq!(
            quantize(y, s8, Rounding::Trn, Overflow::SatZero),
            expect(0, Event::Zeroed)
        );
        // 3 * 2^62 = 2^63 + 2^62 wraps to -2^62 in 64 bits.
        assert_eq!(
            quantize(Exact::new(3, -62), s64, Rounding::Trn, Overflow::Wrap),
            expect(-(1 << 62), Event::Wrapped)
        );
        assert_eq!(
            quantize_i64(3, -62, s64, Rounding::Trn, Overflow::Wrap),
            expect(-(1 << 62), Event::Wrapped)
        );
        // 0x1234 * 2^120 does not fit in i128; its low 8 bits are 0, low 64 bits are 0.
        assert_eq!(
            quantize(Exact::new(0x1234, -120), s8, Rounding::Trn, Overflow::Wrap),
            expect(0, Event::Wrapped)
        );
        // 0x1234 * 2^-4 * 2^8 = 0x1234 << 4 = 0x12340: low 8 bits 0x40.
        assert_eq!(
            quantize(Exact::new(0x1234, -4), s8, Rounding::Trn, Overflow::Wrap),
            expect(0x40, Event::Wrapped)
        );
        // Zero shifted any amount is zero.
        assert_eq!(
            quantize(Exact::new(0, i32::MIN), s8, Rounding::Trn, Overflow::Sat),
            expect(0, Event::None)
        );
        assert_eq!(
            quantize_i64(0, i32::MIN, s8, Rounding::Trn, Overflow::Sat),
            expect(0, Event::None)
        );
    }

    #[test]
    fn event_names() {
        let names: Vec<String> = [Event::None, Event::Wrapped, Event::Saturated, Event::Zeroed]
            .iter()
            .map(Event::to_string)
            .collect();
        assert_eq!(names, ["none", "wrapped", "saturated", "zeroed"]);
        assert_eq!(Event::default(), Event::None);
    }
}
