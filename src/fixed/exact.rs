//! Exact intermediate values (`i128` raw with its own fraction bits) and their exact arithmetic.
use std::cmp::Ordering;
use std::hash::{Hash, Hasher};
use std::ops::{Add, Mul, Neg, Sub};

use crate::fixed::format::Format;
use crate::fixed::mode::Rounding;
use crate::fixed::quantize::round_shift_i128;

/// An exact binary fixed-point value `raw * 2^-frac_bits`, used between datapath stages.
///
/// Arithmetic on `Exact` never rounds: the sum, difference and product are the exact results,
/// and only [`quantize`](crate::fixed::quantize) brings a value back into a [`Format`].
///
/// Fraction bits follow the hardware's bit growth:
/// * `a + b` and `a - b` have `max(a.frac_bits, b.frac_bits)` fraction bits (the operand with
///   fewer is shifted left to align);
/// * `a * b` has `a.frac_bits + b.frac_bits` fraction bits: `u1.16 x u1.16 -> u2.32`.
///
/// Limits: the raw is an `i128`. A product of two raws of any [`Format`] (each fitting `i64`)
/// always fits, since `|i64::MIN|^2 = 2^126`; a sum or difference of two values from formats
/// whose fraction bits differ by at most 63 always fits. Beyond that, the `checked_*` methods
/// return `None` when the aligned operands or the result do not fit in `i128` (or the fraction
/// bits do not fit in `i32`), and the operators `+`, `-`, `*` and unary `-` panic with a message
/// saying so. Nothing ever wraps silently.
///
/// Equality, ordering and hashing compare *values*: `Exact::new(2, 1) == Exact::new(1, 0)`.
/// The fields are public and not normalised; [`normalized`](Exact::normalized) strips trailing
/// zero bits.
///
/// # Examples
///
/// ```
/// use specfx::fixed::{Exact, Format};
///
/// let fmt: Format = "u1.16".parse().unwrap();
/// let a = Exact::from_raw(3 << 15, fmt); // 1.5
/// let p = a * a;
/// assert_eq!((p.raw, p.frac_bits), (9 << 30, 32)); // 2.25 in u2.32
/// assert_eq!(p.to_f64(), 2.25);
/// assert_eq!(a + Exact::new(1, 1), Exact::new(2, 0)); // 1.5 + 0.5 == 2
/// ```
#[derive(Debug, Clone, Copy, Default)]
pub struct Exact {
    /// The raw integer.
    pub raw: i128,
    /// The number of fraction bits: the value is `raw * 2^-frac_bits`. May be negative.
    pub frac_bits: i32,
}

impl Exact {
    /// Zero (with 0 fraction bits).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// assert_eq!(Exact::ZERO, Exact::new(0, 37));
    /// ```
    pub const ZERO: Exact = Exact {
        raw: 0,
        frac_bits: 0,
    };

    /// The value `raw * 2^-frac_bits`.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// assert_eq!(Exact::new(-3, 2).to_f64(), -0.75);
    /// assert_eq!(Exact::new(3, -2).to_f64(), 12.0);
    /// ```
    #[must_use]
    #[inline]
    pub const fn new(raw: i128, frac_bits: i32) -> Exact {
        Exact { raw, frac_bits }
    }

    /// The value of the raw code `raw` read in `fmt`: `raw * 2^-fmt.frac_bits()`.
    ///
    /// `raw` is taken as given; it is not checked against `fmt`'s range.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::{Exact, Format};
    ///
    /// let fmt: Format = "s2.16".parse().unwrap();
    /// let x = Exact::from_raw(-(1 << 16), fmt);
    /// assert_eq!((x.raw, x.frac_bits), (-(1 << 16), 16));
    /// assert_eq!(x.to_f64(), -1.0);
    /// ```
    #[must_use]
    #[inline]
    pub const fn from_raw(raw: i64, fmt: Format) -> Exact {
        Exact {
            raw: raw as i128,
            frac_bits: fmt.frac_bits(),
        }
    }

    /// The exact value of a finite `f64`, or `None` for NaN and infinities.
    ///
    /// Every finite `f64` is `m * 2^e` with `|m| < 2^53` and `-1074 <= e <= 971`, so it always
    /// fits: the result is normalised (odd raw, or zero with 0 fraction bits) and its fraction
    /// bits are in `-971..=1074`. `-0.0` gives zero.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// let x = Exact::from_f64(-0.375).unwrap();
    /// assert_eq!((x.raw, x.frac_bits), (-3, 3));
    /// assert_eq!(Exact::from_f64(1024.0).unwrap(), Exact::new(1, -10));
    /// assert_eq!(Exact::from_f64(f64::NAN), None);
    /// assert_eq!(Exact::from_f64(f64::INFINITY), None);
    /// ```
    #[must_use]
    pub fn from_f64(x: f64) -> Option<Exact> {
        if !x.is_finite() {
            return None;
        }
        if x == 0.0 {
            return Some(Exact::ZERO);
        }
        let bits = x.to_bits();
        let biased_exponent = ((bits >> 52) & 0x7ff) as i32;
        let fraction = bits & ((1u64 << 52) - 1);
        // x = mantissa * 2^exponent
        let (mantissa, exponent) = if biased_exponent == 0 {
            (fraction, -1074)
        } else {
            (fraction | (1u64 << 52), biased_exponent - 1075)
        };
        let zeros = mantissa.trailing_zeros();
        let magnitude = i128::from(mantissa >> zeros);
        let raw = if bits >> 63 == 1 {
            -magnitude
        } else {
            magnitude
        };
        Some(Exact {
            raw,
            frac_bits: -(exponent + zeros as i32),
        })
    }

    /// The value rounded to the nearest `f64`, ties to even, for every `Exact`.
    ///
    /// Rounding happens once, at the result's own LSB (subnormals included), so there is no
    /// double rounding. Values beyond `f64::MAX` after rounding give an infinity; a value that
    /// rounds to zero gives `0.0` (positive, whatever its sign).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// assert_eq!(Exact::new(5, 1).to_f64(), 2.5);
    /// // 2^53 + 1 is a tie between 2^53 and 2^53 + 2: ties to even.
    /// assert_eq!(Exact::new((1 << 53) + 1, 0).to_f64(), 2f64.powi(53));
    /// assert_eq!(Exact::new(1, 1074).to_f64(), f64::from_bits(1));
    /// ```
    #[must_use]
    pub fn to_f64(self) -> f64 {
        if self.raw == 0 {
            return 0.0;
        }
        // Keep at most 53 significant bits, and none below 2^-1074 (the subnormal LSB), by
        // dropping `drop` low bits with ties to even: one rounding, at the f64's own LSB.
        let msb = 127 - i64::from(self.raw.unsigned_abs().leading_zeros());
        let frac_bits = i64::from(self.frac_bits);
        let drop = (msb - 52).max(frac_bits - 1074);
        let (rounded, exponent) = if drop > 0 {
            let shift = u32::try_from(drop).unwrap_or(u32::MAX);
            (
                round_shift_i128(self.raw, shift, Rounding::RndConv),
                drop - frac_bits,
            )
        } else {
            (self.raw, -frac_bits)
        };
        // |rounded| <= 2^53, so the conversion is exact, and so is the scaling unless it
        // overflows (to an infinity, which is then the correctly rounded result).
        scale_by_pow2(rounded as f64, exponent)
    }

    /// True when the value is zero.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// assert!(Exact::new(0, 12).is_zero());
    /// assert!(!Exact::new(1, 1000).is_zero());
    /// ```
    #[must_use]
    #[inline]
    pub const fn is_zero(self) -> bool {
        self.raw == 0
    }

    /// The same value with trailing zero bits of the raw removed (zero becomes [`Exact::ZERO`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// let x = Exact::new(12, 4).normalized();
    /// assert_eq!((x.raw, x.frac_bits), (3, 2));
    /// ```
    #[must_use]
    pub fn normalized(self) -> Exact {
        if self.raw == 0 {
            return Exact::ZERO;
        }
        let zeros = self.raw.trailing_zeros();
        match self.frac_bits.checked_sub(zeros as i32) {
            Some(frac_bits) => Exact {
                raw: self.raw >> zeros,
                frac_bits,
            },
            // The fraction bits would leave i32: strip only as many zeros as they allow.
            None => {
                let strip = (i64::from(self.frac_bits) - i64::from(i32::MIN)) as u32;
                Exact {
                    raw: self.raw >> strip,
                    frac_bits: i32::MIN,
                }
            }
        }
    }

    /// The exact sum, or `None` when the aligned operands or the sum do not fit in `i128`.
    ///
    /// The sum has `max(self.frac_bits, rhs.frac_bits)` fraction bits.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// let s = Exact::new(3, 2).checked_add(Exact::new(1, 0)).unwrap(); // 0.75 + 1
    /// assert_eq!((s.raw, s.frac_bits), (7, 2));
    /// assert_eq!(Exact::new(i128::MAX, 0).checked_add(Exact::new(1, 0)), None);
    /// assert_eq!(Exact::new(1, 0).checked_add(Exact::new(1, 200)), None);
    /// ```
    #[must_use]
    pub fn checked_add(self, rhs: Exact) -> Option<Exact> {
        let (a, b, frac_bits) = align(self, rhs)?;
        Some(Exact {
            raw: a.checked_add(b)?,
            frac_bits,
        })
    }

    /// The exact difference `self - rhs`, or `None` when it does not fit (see
    /// [`checked_add`](Exact::checked_add)).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// let d = Exact::new(1, 0).checked_sub(Exact::new(3, 2)).unwrap(); // 1 - 0.75
    /// assert_eq!((d.raw, d.frac_bits), (1, 2));
    /// assert_eq!(Exact::new(i128::MIN, 0).checked_sub(Exact::new(1, 0)), None);
    /// ```
    #[must_use]
    pub fn checked_sub(self, rhs: Exact) -> Option<Exact> {
        let (a, b, frac_bits) = align(self, rhs)?;
        Some(Exact {
            raw: a.checked_sub(b)?,
            frac_bits,
        })
    }

    /// The exact product, with `self.frac_bits + rhs.frac_bits` fraction bits, or `None` when
    /// the raw product does not fit in `i128` or the fraction bits do not fit in `i32`.
    ///
    /// The product of two raws that fit in `i64` always fits.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// let p = Exact::new(i64::MIN.into(), 63).checked_mul(Exact::new(i64::MIN.into(), 63)).unwrap();
    /// assert_eq!((p.raw, p.frac_bits), (1 << 126, 126)); // (-1) * (-1)
    /// assert_eq!(p.checked_mul(Exact::new(4, 0)), None);
    /// ```
    #[must_use]
    pub fn checked_mul(self, rhs: Exact) -> Option<Exact> {
        Some(Exact {
            raw: self.raw.checked_mul(rhs.raw)?,
            frac_bits: self.frac_bits.checked_add(rhs.frac_bits)?,
        })
    }

    /// The exact negation, or `None` for a raw of `i128::MIN`.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Exact;
    ///
    /// assert_eq!(Exact::new(5, 3).checked_neg(), Some(Exact::new(-5, 3)));
    /// assert_eq!(Exact::new(i128::MIN, 3).checked_neg(), None);
    /// ```
    #[must_use]
    pub fn checked_neg(self) -> Option<Exact> {
        Some(Exact {
            raw: self.raw.checked_neg()?,
            frac_bits: self.frac_bits,
        })
    }
}

/// Both raws shifted to the larger number of fraction bits, or `None` if one does not fit.
fn align(a: Exact, b: Exact) -> Option<(i128, i128, i32)> {
    let frac_bits = a.frac_bits.max(b.frac_bits);
    let a_raw = shl_exact(a.raw, i64::from(frac_bits) - i64::from(a.frac_bits))?;
    let b_raw = shl_exact(b.raw, i64::from(frac_bits) - i64::from(b.frac_bits))?;
    Some((a_raw, b_raw, frac_bits))
}

/// `raw * 2^shift` for `shift >= 0`, or `None` if it does not fit in `i128`.
pub(crate) fn shl_exact(raw: i128, shift: i64) -> Option<i128> {
    debug_assert!(shift >= 0);
    if raw == 0 {
        return Some(0);
    }
    if shift >= 128 {
        return None;
    }
    let shifted = raw << shift;
    (shifted >> shift == raw).then_some(shifted)
}

/// `2^exponent` for `exponent` in `-1022..=1023` (normal range), exactly.
pub(crate) fn pow2(exponent: i32) -> f64 {
    debug_assert!((-1022..=1023).contains(&exponent));
    f64::from_bits(((exponent + 1023) as u64) << 52)
}

/// `x * 2^exponent`, exact whenever the result is representable (x has at most 54
/// significant bits here); steps through the normal range so intermediates stay exact.
fn scale_by_pow2(mut x: f64, mut exponent: i64) -> f64 {
    while exponent > 1023 && x.is_finite() {
        x *= pow2(1023);
        exponent -= 1023;
    }
    while exponent < -1022 && x != 0.0 {
        x *= pow2(-1022);
        exponent += 1022;
    }
    if !(-1022..=1023).contains(&exponent) {
        // x is already infinite or zero.
        return x;
    }
    x * pow2(exponent as i32)
}

impl PartialEq for Exact {
    fn eq(&self, other: &Exact) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Exact {}

impl PartialOrd for Exact {
    fn partial_cmp(&self, other: &Exact) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Exact {
    /// Compares values, whatever the fraction bits, without overflow.
    fn cmp(&self, other: &Exact) -> Ordering {
        // Shift the operand with fewer fraction bits left; if it no longer fits in i128 its
        // magnitude is at least 2^127 > |the other raw|, so its sign decides.
        let (a, b, flipped) = if self.frac_bits >= other.frac_bits {
            (self, other, false)
        } else {
            (other, self, true)
        };
        let shift = i64::from(a.frac_bits) - i64::from(b.frac_bits);
        let ordering = match shl_exact(b.raw, shift) {
            Some(b_raw) => a.raw.cmp(&b_raw),
            None if b.raw > 0 => Ordering::Less,
            None => Ordering::Greater,
        };
        if flipped {
            ordering.reverse()
        } else {
            ordering
        }
    }
}

impl Hash for Exact {
    fn hash<H: Hasher>(&self, state: &mut H) {
        let n = self.normalized();
        n.raw.hash(state);
        n.frac_bits.hash(state);
    }
}

impl Add for Exact {
    type Output = Exact;

    /// The exact sum; see [`Exact::checked_add`].
    ///
    /// # Panics
    ///
    /// When the aligned operands or the sum do not fit in `i128`.
    fn add(self, rhs: Exact) -> Exact {
        self.checked_add(rhs)
            .unwrap_or_else(|| panic!("exact sum of {self:?} and {rhs:?} does not fit in i128"))
    }
}

impl Sub for Exact {
    type Output = Exact;

    /// The exact difference; see [`Exact::checked_sub`].
    ///
    /// # Panics
    ///
    /// When the aligned operands or the difference do not fit in `i128`.
    fn sub(self, rhs: Exact) -> Exact {
        self.checked_sub(rhs).unwrap_or_else(|| {
            panic!("exact difference of {self:?} and {rhs:?} does not fit in i128")
        })
    }
}

impl Mul for Exact {
    type Output = Exact;

    /// The exact product; see [`Exact::checked_mul`].
    ///
    /// # Panics
    ///
    /// When the raw product does not fit in `i128` or the fraction bits do not fit in `i32`.
    fn mul(self, rhs: Exact) -> Exact {
        self.checked_mul(rhs)
            .unwrap_or_else(|| panic!("exact product of {self:?} and {rhs:?} does not fit in i128"))
    }
}

impl Neg for Exact {
    type Output = Exact;

    /// The exact negation; see [`Exact::checked_neg`].
    ///
    /// # Panics
    ///
    /// For a raw of `i128::MIN`.
    fn neg(self) -> Exact {
        self.checked_neg()
            .unwrap_or_else(|| panic!("exact negation of {self:?} does not fit in i128"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn bit_growth_of_the_operations() {
        let u116: Format = "u1.16".parse().unwrap();
        let max = Exact::from_raw(u116.max_raw(), u116); // 2 - 2^-16
        let p = max * max;
        assert_eq!(p.frac_bits, 32);
        assert_eq!(p.raw, ((1i128 << 17) - 1) * ((1i128 << 17) - 1));
        // The product fits in u2.32: below 4.
        let u232: Format = "u2.32".parse().unwrap();
        assert!(u232.contains_raw(p.raw));
        let s = max + Exact::from_raw(1, "u1.8".parse().unwrap());
        assert_eq!((s.raw, s.frac_bits), ((1 << 17) - 1 + (1 << 8), 16));
        let d = Exact::new(1, -4) - Exact::new(1, 4); // 16 - 1/16
        assert_eq!((d.raw, d.frac_bits), (255, 4));
        assert_eq!(-Exact::new(3, 1), Exact::new(-3, 1));
    }

    #[test]
    fn limits_of_i128_are_reported_not_wrapped() {
        let big = Exact::new(1 << 126, 0);
        assert_eq!(big.checked_add(big), None);
        assert_eq!(big.checked_add(-big), Some(Exact::ZERO));
        assert_eq!(Exact::new(1, 0).checked_add(Exact::new(1, 127)), None);
        // -1 aligned to 127 fraction bits is exactly i128::MIN: still fits.
        let sum = Exact::new(-1, 0).checked_add(Exact::new(1, 127)).unwrap();
        assert_eq!((sum.raw, sum.frac_bits), (i128::MIN + 1, 127));
        assert_eq!(Exact::new(1, i32::MAX).checked_mul(Exact::new(1, 1)), None);
        assert_eq!(Exact::new(1, i32::MIN).checked_mul(Exact::new(1, -1)), None);
        let minus_one = Exact::new(i64::MIN.into(), 63);
        assert_eq!(minus_one * minus_one, Exact::new(1, 0));
    }

    #[test]
    #[should_panic(expected = "exact sum of")]
    fn operator_add_panics_instead_of_wrapping() {
        let _ = Exact::new(i128::MAX, 0) + Exact::new(1, 0);
    }

    #[test]
    #[should_panic(expected = "exact product of")]
    fn operator_mul_panics_instead_of_wrapping() {
        let _ = Exact::new(1 << 64, 0) * Exact::new(1 << 64, 0);
    }

    #[test]
    fn equality_and_order_are_by_value() {
        assert_eq!(Exact::new(4, 3), Exact::new(1, 1));
        assert_eq!(Exact::new(0, 100), Exact::new(0, -100));
        assert!(Exact::new(1, 1) < Exact::new(1, 0));
        assert!(Exact::new(-1, 0) < Exact::new(-1, 1));
        // Alignment would overflow: decided by sign.
        assert!(Exact::new(1, -200) > Exact::new(i128::MAX, 0));
        assert!(Exact::new(-1, -200) < Exact::new(i128::MIN, 0));
        assert!(Exact::new(i128::MAX, 0) < Exact::new(1, -200));
        assert!(Exact::new(1, i32::MAX) > Exact::new(0, i32::MIN));
        assert!(Exact::new(-1, i32::MAX) < Exact::new(0, i32::MIN));
        assert_eq!(Exact::new(1 << 100, 0).normalized(), Exact::new(1, -100));
        assert_eq!(Exact::new(1 << 100, 0).normalized().frac_bits, -100);
        let n = Exact::new(1 << 10, i32::MIN + 3).normalized();
        assert_eq!((n.raw, n.frac_bits), (1 << 7, i32::MIN));
    }

    #[test]
    fn from_f64_is_exact_at_the_extremes() {
        let tiny = Exact::from_f64(f64::from_bits(1)).unwrap();
        assert_eq!((tiny.raw, tiny.frac_bits), (1, 1074));
        let max = Exact::from_f64(f64::MAX).unwrap();
        assert_eq!((max.raw, max.frac_bits), ((1 << 53) - 1, -971));
        let min_normal = Exact::from_f64(-f64::MIN_POSITIVE).unwrap();
        assert_eq!((min_normal.raw, min_normal.frac_bits), (-1, 1022));
        assert_eq!(Exact::from_f64(-0.0), Some(Exact::ZERO));
        // 0.1 is 0x1.999999999999ap-4 = 0x1999999999999a * 2^-56, normalised.
        let tenth = Exact::from_f64(0.1).unwrap();
        assert_eq!((tenth.raw, tenth.frac_bits), (0xc_cccc_cccc_cccd, 55));
        assert_eq!(Exact::from_f64(f64::NEG_INFINITY), None);
    }

    #[test]
    fn to_f64_rounds_once_to_nearest_even() {
        // 2^60 + 2^7 + 1 is just above the tie between 2^60 and 2^60 + 2^8.
        assert_eq!(
            Exact::new((1 << 60) + (1 << 7) + 1, 0).to_f64(),
            2f64.powi(60) + 256.0
        );
        assert_eq!(Exact::new((1 << 60) + (1 << 7), 0).to_f64(), 2f64.powi(60));
        assert_eq!(
            Exact::new((1 << 60) + (3 << 7), 0).to_f64(),
            2f64.powi(60) + 512.0
        );
        assert_eq!(
            Exact::new(-((1 << 60) + (3 << 7)), 0).to_f64(),
            -(2f64.powi(60) + 512.0)
        );
        // Subnormals: 3 * 2^-1076 = 0.75 LSB rounds to 1 LSB; 2^-1075 is a tie to even (0).
        assert_eq!(Exact::new(3, 1076).to_f64(), f64::from_bits(1));
        assert_eq!(Exact::new(1, 1075).to_f64(), 0.0);
        assert_eq!(Exact::new(3, 1075).to_f64(), f64::from_bits(2));
        assert_eq!(Exact::new(-5, 1075).to_f64(), -f64::from_bits(2));
        // The double-rounding trap: (4.5 + 2^-60) * 2^-1074. Rounding the raw to 53 bits first
        // would make it an exact tie, then rounded to even 4; the true nearest is 5.
        let raw = (4i128 << 60) + (1 << 59) + 1;
        assert_eq!(Exact::new(raw, 1134).to_f64(), f64::from_bits(5));
        // (2^100 - 1) * 2^-1160 is just below 2^-1060, a subnormal with 14 bits: rounds up.
        assert_eq!(Exact::new((1 << 100) - 1, 1160).to_f64(), 2f64.powi(-1060));
        assert_eq!(Exact::new(1, i32::MAX).to_f64(), 0.0);
        assert_eq!(Exact::new(1, i32::MIN).to_f64(), f64::INFINITY);
        assert_eq!(Exact::new(-1, -1024).to_f64(), f64::NEG_INFINITY);
        assert_eq!(Exact::new(1, -1023).to_f64(), 2f64.powi(1023));
        assert_eq!(Exact::new(i128::MIN, 127).to_f64(), -1.0);
    }

    proptest! {
        #[test]
        fn f64_round_trips_exactly(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            let exact = Exact::from_f64(x).unwrap();
            prop_assert_eq!(exact.to_f64().to_bits(), if x == 0.0 { 0 } else { bits });
        }

        #[test]
        fn to_f64_agrees_with_the_cast_for_i64_raws(raw in any::<i64>(), frac_bits in -900i32..900) {
            // i64 as f64 rounds to nearest even; the scaling is then exact in this range.
            let expected = raw as f64 * 2f64.powi(-frac_bits);
            prop_assert_eq!(Exact::new(raw.into(), frac_bits).to_f64(), expected);
        }

        #[test]
        fn add_sub_mul_are_exact(a in any::<i64>(), fa in -20i32..20, b in any::<i64>(), fb in -20i32..20) {
            let x = Exact::new(a.into(), fa);
            let y = Exact::new(b.into(), fb);
            // Check against a common denominator of 2^40 computed independently.
            let scale = |raw: i64, f: i32| i128::from(raw) << (40 - f);
            let sum = x + y;
            prop_assert_eq!(sum.frac_bits, fa.max(fb));
            prop_assert_eq!(sum.raw << (40 - sum.frac_bits), scale(a, fa) + scale(b, fb));
            let diff = x - y;
            prop_assert_eq!(diff.raw << (40 - diff.frac_bits), scale(a, fa) - scale(b, fb));
            let prod = x * y;
            prop_assert_eq!(prod.frac_bits, fa + fb);
            prop_assert_eq!(prod.raw, i128::from(a) * i128::from(b));
            prop_assert_eq!(x.cmp(&y), scale(a, fa).cmp(&scale(b, fb)));
            prop_assert_eq!(x.normalized(), x);
        }
    }
}
