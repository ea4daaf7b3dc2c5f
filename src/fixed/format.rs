//! Run-time fixed-point formats (`u1.15`, `s2.16`, `s10.-2` ...) and their notation.
use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::FixedError;
use crate::fixed::exact::pow2;

/// A fixed-point format chosen at run time: signedness, integer bits `I` and fraction bits `F`.
///
/// A raw code `raw` (a `W`-bit integer, `W = I + F`) stands for `raw * 2^-F`. Signed formats
/// are two's complement and count the sign among their integer bits, as `ac_fixed` does:
/// `s2.16` is `ac_fixed<18, 2, true>`, `u1.15` is `ac_fixed<16, 1, false>`.
///
/// `I` and `F` may each be negative or larger than the width, as long as `W = I + F` is in
/// range: `u-2.10` has `W = 8` and holds values in `[0, 2^-2)` with LSB `2^-10`; `s10.-2` has
/// `W = 8`, LSB `4` and holds values in `[-512, 508]`.
///
/// Limits, checked once at construction:
/// * signed: `1 <= W <= 64`; unsigned: `1 <= W <= 63`, so that every raw code fits in `i64`;
/// * `-512 <= F <= 512`, so that [`lsb`](Format::lsb) and [`to_f64`](Format::to_f64) are
///   exact powers of two with no overflow or underflow in `f64`.
///
/// The notation is `u<I>.<F>` or `s<I>.<F>` with decimal `I` and `F`, a `-` allowed before
/// either and no other sign, space or leading zero. [`Display`](fmt::Display) writes the same
/// notation back, and serde reads and writes it as a string.
///
/// # Examples
///
/// ```
/// use specfx::fixed::Format;
///
/// let fmt: Format = "s2.16".parse().unwrap();
/// assert_eq!(fmt, Format::new(true, 2, 16).unwrap());
/// assert_eq!(fmt.width(), 18);
/// assert_eq!((fmt.min_raw(), fmt.max_raw()), (-(1 << 17), (1 << 17) - 1));
/// assert_eq!(fmt.to_f64(-(1 << 17)), -2.0);
/// assert_eq!(fmt.to_string(), "s2.16");
///
/// let odd: Format = "s10.-2".parse().unwrap();
/// assert_eq!((odd.width(), odd.lsb()), (8, 4.0));
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Format {
    signed: bool,
    /// Total width `W`, in `1..=64`.
    width: u8,
    /// Fraction bits `F`, in `-512..=512`.
    frac_bits: i16,
}

/// The largest magnitude allowed for [`Format::frac_bits`].
const MAX_ABS_FRAC_BITS: i64 = 512;

impl Format {
    /// The largest magnitude of [`frac_bits`](Format::frac_bits) a format may have.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert!(Format::new(false, -500, 512).is_ok());
    /// assert!(Format::new(false, -500, 513).is_err());
    /// assert_eq!(Format::MAX_ABS_FRAC_BITS, 512);
    /// ```
    pub const MAX_ABS_FRAC_BITS: i32 = MAX_ABS_FRAC_BITS as i32;

    /// Builds a format from its signedness, integer bits `I` (the sign included when signed)
    /// and fraction bits `F`.
    ///
    /// # Errors
    ///
    /// Fails when `W = I + F` is outside `1..=64` (`1..=63` when unsigned) or when `F` is
    /// outside `-512..=512`.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// let fmt = Format::new(false, 1, 15).unwrap();
    /// assert_eq!(fmt.to_string(), "u1.15");
    /// let err = Format::new(true, 0, 0).unwrap_err();
    /// assert_eq!(err.to_string(), "width (int bits + frac bits) of s0.0 must be in 1..=64, got 0");
    /// ```
    pub fn new(signed: bool, int_bits: i32, frac_bits: i32) -> Result<Format, FixedError> {
        Format::validated(signed, i64::from(int_bits), i64::from(frac_bits))
    }

    /// Builds a signed (two's complement) format; the same as `Format::new(true, ..)`.
    ///
    /// # Errors
    ///
    /// As [`Format::new`].
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!(Format::signed(2, 16).unwrap().to_string(), "s2.16");
    /// ```
    pub fn signed(int_bits: i32, frac_bits: i32) -> Result<Format, FixedError> {
        Format::new(true, int_bits, frac_bits)
    }

    /// Builds an unsigned format; the same as `Format::new(false, ..)`.
    ///
    /// # Errors
    ///
    /// As [`Format::new`].
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!(Format::unsigned(1, 15).unwrap().to_string(), "u1.15");
    /// ```
    pub fn unsigned(int_bits: i32, frac_bits: i32) -> Result<Format, FixedError> {
        Format::new(false, int_bits, frac_bits)
    }

    fn validated(signed: bool, int_bits: i64, frac_bits: i64) -> Result<Format, FixedError> {
        let notation = || format!("{}{}.{}", sign_letter(signed), int_bits, frac_bits);
        let width = int_bits + frac_bits;
        let max = if signed { 64 } else { 63 };
        if !(1..=64).contains(&width) {
            return Err(FixedError::Width {
                notation: notation(),
                got: width,
                max,
            });
        }
        if !signed && width == 64 {
            return Err(FixedError::UnsignedWidth {
                notation: notation(),
                got: width,
            });
        }
        if !(-MAX_ABS_FRAC_BITS..=MAX_ABS_FRAC_BITS).contains(&frac_bits) {
            return Err(FixedError::FracBits {
                notation: notation(),
                got: frac_bits,
            });
        }
        Ok(Format {
            signed,
            width: width as u8,
            frac_bits: frac_bits as i16,
        })
    }

    /// Total width `W = I + F` in bits, in `1..=64`.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!("u-2.10".parse::<Format>().unwrap().width(), 8);
    /// ```
    #[must_use]
    #[inline]
    pub const fn width(self) -> u32 {
        self.width as u32
    }

    /// True for two's complement formats (`s...`), false for unsigned ones (`u...`).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert!("s1.15".parse::<Format>().unwrap().is_signed());
    /// assert!(!"u1.15".parse::<Format>().unwrap().is_signed());
    /// ```
    #[must_use]
    #[inline]
    pub const fn is_signed(self) -> bool {
        self.signed
    }

    /// Integer bits `I = W - F`, the sign bit included for signed formats; may be negative.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!("u-2.10".parse::<Format>().unwrap().int_bits(), -2);
    /// ```
    #[must_use]
    #[inline]
    pub const fn int_bits(self) -> i32 {
        self.width as i32 - self.frac_bits as i32
    }

    /// Fraction bits `F`: a raw code stands for `raw * 2^-F`. May be negative or exceed `W`.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!("s10.-2".parse::<Format>().unwrap().frac_bits(), -2);
    /// ```
    #[must_use]
    #[inline]
    pub const fn frac_bits(self) -> i32 {
        self.frac_bits as i32
    }

    /// The smallest raw code: `-2^(W-1)` when signed, 0 when unsigned.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!("s1.7".parse::<Format>().unwrap().min_raw(), -128);
    /// assert_eq!("s64.0".parse::<Format>().unwrap().min_raw(), i64::MIN);
    /// assert_eq!("u1.7".parse::<Format>().unwrap().min_raw(), 0);
    /// ```
    #[must_use]
    #[inline]
    pub const fn min_raw(self) -> i64 {
        if self.signed {
            i64::MIN >> (64 - self.width as u32)
        } else {
            0
        }
    }

    /// The largest raw code: `2^(W-1) - 1` when signed, `2^W - 1` when unsigned.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!("s1.7".parse::<Format>().unwrap().max_raw(), 127);
    /// assert_eq!("u1.7".parse::<Format>().unwrap().max_raw(), 255);
    /// assert_eq!("u63.0".parse::<Format>().unwrap().max_raw(), i64::MAX);
    /// ```
    #[must_use]
    #[inline]
    pub const fn max_raw(self) -> i64 {
        if self.signed {
            i64::MAX >> (64 - self.width as u32)
        } else {
            i64::MAX >> (63 - self.width as u32)
        }
    }

    /// True when `raw` is a code of this format, i.e. `min_raw() <= raw <= max_raw()`.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// let fmt: Format = "s4.0".parse().unwrap();
    /// assert!(fmt.contains_raw(-8) && fmt.contains_raw(7));
    /// assert!(!fmt.contains_raw(8) && !fmt.contains_raw(-9));
    /// ```
    #[must_use]
    #[inline]
    pub const fn contains_raw(self, raw: i128) -> bool {
        self.min_raw() as i128 <= raw && raw <= self.max_raw() as i128
    }

    /// The value of one LSB, `2^-F`, exactly.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!("u1.15".parse::<Format>().unwrap().lsb(), 1.0 / 32768.0);
    /// assert_eq!("s10.-2".parse::<Format>().unwrap().lsb(), 4.0);
    /// ```
    #[must_use]
    #[inline]
    pub fn lsb(self) -> f64 {
        pow2(-self.frac_bits())
    }

    /// The value of a raw code, `raw * 2^-F`, rounded to the nearest `f64` (ties to even).
    ///
    /// Exact whenever `raw` has at most 53 significant bits, so always exact for widths up to
    /// 53. `raw` is not checked against the format's range.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// let fmt: Format = "u1.15".parse().unwrap();
    /// assert_eq!(fmt.to_f64(0x8000), 1.0);
    /// assert_eq!(fmt.to_f64(fmt.max_raw()), 2.0 - 1.0 / 32768.0);
    /// ```
    #[must_use]
    #[inline]
    pub fn to_f64(self, raw: i64) -> f64 {
        // |raw| as f64 is rounded once (nearest, ties to even) and is either 0 or at least 1;
        // scaling by 2^-F with |F| <= 512 stays in the normal range, so it is exact.
        raw as f64 * self.lsb()
    }

    /// The smallest value of the format, `min_raw() * 2^-F`.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!("s2.16".parse::<Format>().unwrap().min_value(), -2.0);
    /// ```
    #[must_use]
    pub fn min_value(self) -> f64 {
        self.to_f64(self.min_raw())
    }

    /// The largest value of the format, `max_raw() * 2^-F` (rounded to `f64` for `W > 53`).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// assert_eq!("u2.2".parse::<Format>().unwrap().max_value(), 3.75);
    /// ```
    #[must_use]
    pub fn max_value(self) -> f64 {
        self.to_f64(self.max_raw())
    }

    /// The format that holds every exact product of a value of `self` and one of `rhs`, by
    /// `ac_fixed`'s rule: `W = W1 + W2`, `I = I1 + I2`, signed if either is.
    ///
    /// Bit growth: `u1.16 x u1.16 -> u2.32`, `s1.15 x s1.15 -> s2.30`, `u1.15 x s1.15 -> s2.30`.
    ///
    /// # Errors
    ///
    /// Fails when the product format is wider than a [`Format`] may be (see [`Format::new`]);
    /// the exact product still exists as an [`Exact`](crate::fixed::Exact).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// let u: Format = "u1.16".parse().unwrap();
    /// assert_eq!(u.mul_format(u).unwrap().to_string(), "u2.32");
    /// let s: Format = "s1.15".parse().unwrap();
    /// assert_eq!(u.mul_format(s).unwrap().to_string(), "s2.31");
    /// ```
    pub fn mul_format(self, rhs: Format) -> Result<Format, FixedError> {
        Format::validated(
            self.signed || rhs.signed,
            i64::from(self.int_bits()) + i64::from(rhs.int_bits()),
            i64::from(self.frac_bits()) + i64::from(rhs.frac_bits()),
        )
    }

    /// The format that holds every exact sum of a value of `self` and one of `rhs`, by
    /// `ac_fixed`'s rule: `F = max(F1, F2)`, `I = max(I1 + (S2 && !S1), I2 + (S1 && !S2)) + 1`,
    /// signed if either is.
    ///
    /// Bit growth: `u1.16 + u1.16 -> u2.16`, `s1.15 + s1.15 -> s2.15`, `u1.8 + s1.8 -> s3.8`.
    ///
    /// # Errors
    ///
    /// Fails when the sum format is wider than a [`Format`] may be (see [`Format::new`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// let a: Format = "u1.16".parse().unwrap();
    /// let b: Format = "s3.4".parse().unwrap();
    /// assert_eq!(a.add_format(a).unwrap().to_string(), "u2.16");
    /// assert_eq!(a.add_format(b).unwrap().to_string(), "s4.16");
    /// ```
    pub fn add_format(self, rhs: Format) -> Result<Format, FixedError> {
        let (int_bits, frac_bits) = self.sum_bits(rhs);
        Format::validated(self.signed || rhs.signed, int_bits, frac_bits)
    }

    /// The format that holds every exact difference `self - rhs`, by `ac_fixed`'s rule: as
    /// [`add_format`](Format::add_format) but always signed.
    ///
    /// Bit growth: `u1.16 - u1.16 -> s2.16`, `s1.15 - s1.15 -> s2.15`.
    ///
    /// # Errors
    ///
    /// Fails when the difference format is wider than a [`Format`] may be (see [`Format::new`]).
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Format;
    ///
    /// let a: Format = "u1.16".parse().unwrap();
    /// assert_eq!(a.sub_format(a).unwrap().to_string(), "s2.16");
    /// ```
    pub fn sub_format(self, rhs: Format) -> Result<Format, FixedError> {
        let (int_bits, frac_bits) = self.sum_bits(rhs);
        Format::validated(true, int_bits, frac_bits)
    }

    fn sum_bits(self, rhs: Format) -> (i64, i64) {
        let lhs_int = i64::from(self.int_bits()) + i64::from(rhs.signed && !self.signed);
        let rhs_int = i64::from(rhs.int_bits()) + i64::from(self.signed && !rhs.signed);
        (
            lhs_int.max(rhs_int) + 1,
            i64::from(self.frac_bits().max(rhs.frac_bits())),
        )
    }
}

fn sign_letter(signed: bool) -> char {
    if signed {
        's'
    } else {
        'u'
    }
}

impl fmt::Display for Format {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{}{}.{}",
            sign_letter(self.signed),
            self.int_bits(),
            self.frac_bits()
        )
    }
}

/// Parses a decimal integer with an optional leading `-`, no leading zeros, no `-0`, and at
/// most 18 digits (so that it fits in `i64` and a sum of two does too).
fn parse_strict_int(text: &str) -> Option<i64> {
    let (negative, digits) = match text.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, text),
    };
    let well_formed = !digits.is_empty()
        && digits.len() <= 18
        && digits.bytes().all(|b| b.is_ascii_digit())
        && (digits == "0" || !digits.starts_with('0'))
        && !(negative && digits == "0");
    if !well_formed {
        return None;
    }
    let magnitude: i64 = digits.parse().ok()?;
    Some(if negative { -magnitude } else { magnitude })
}

impl FromStr for Format {
    type Err = FixedError;

    /// Parses `u<I>.<F>` or `s<I>.<F>` strictly (see [`Format`]).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let bad = || FixedError::BadNotation { got: s.to_string() };
        let signed = match s.as_bytes().first() {
            Some(b's') => true,
            Some(b'u') => false,
            _ => return Err(bad()),
        };
        let (int_text, frac_text) = s[1..].split_once('.').ok_or_else(bad)?;
        let int_bits = parse_strict_int(int_text).ok_or_else(bad)?;
        let frac_bits = parse_strict_int(frac_text).ok_or_else(bad)?;
        Format::validated(signed, int_bits, frac_bits)
    }
}

impl Serialize for Format {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Format {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = String::deserialize(deserializer)?;
        text.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fmt(text: &str) -> Format {
        text.parse().unwrap()
    }

    #[test]
    fn parses_the_examples_of_the_spec() {
        // (text, signed, I, F, W)
        let cases = [
            ("u1.15", false, 1, 15, 16),
            ("s2.16", true, 2, 16, 18),
            ("u-2.10", false, -2, 10, 8),
            ("s10.-2", true, 10, -2, 8),
            ("s64.0", true, 64, 0, 64),
            ("s0.64", true, 0, 64, 64),
            ("u63.0", false, 63, 0, 63),
            ("u0.1", false, 0, 1, 1),
            ("s1.0", true, 1, 0, 1),
            ("u-500.512", false, -500, 512, 12),
            ("s520.-512", true, 520, -512, 8),
        ];
        for (text, signed, int_bits, frac_bits, width) in cases {
            let f = fmt(text);
            assert_eq!(f.is_signed(), signed, "{text}");
            assert_eq!(f.int_bits(), int_bits, "{text}");
            assert_eq!(f.frac_bits(), frac_bits, "{text}");
            assert_eq!(f.width(), width, "{text}");
            assert_eq!(f.to_string(), text);
            assert_eq!(Format::new(signed, int_bits, frac_bits), Ok(f));
        }
    }

    #[test]
    fn rejects_text_that_is_not_the_notation() {
        let bad = [
            "",
            "x1.2",
            "U1.15",
            "S1.15",
            "u",
            "u1",
            "u1.",
            "u.15",
            "u1,15",
            "u1.15 ",
            " u1.15",
            "u+1.15",
            "u1.+15",
            "u01.15",
            "u1.015",
            "u-0.8",
            "s8.-0",
            "u1.1.1",
            "u1e1.0",
            "u--1.9",
            "u1.15x",
            "u١.15",
            "s1234567890123456789.0",
        ];
        for text in bad {
            let err = text.parse::<Format>().unwrap_err();
            assert_eq!(
                err,
                FixedError::BadNotation {
                    got: text.to_string()
                },
                "{text:?}"
            );
        }
        assert_eq!(
            "x1.2".parse::<Format>().unwrap_err().to_string(),
            "format must look like u1.15 or s2.16, got 'x1.2'"
        );
    }

    #[test]
    fn rejects_widths_out_of_range_with_expected_and_got() {
        let cases = [
            (
                "s0.0",
                "width (int bits + frac bits) of s0.0 must be in 1..=64, got 0",
            ),
            (
                "u3.-3",
                "width (int bits + frac bits) of u3.-3 must be in 1..=63, got 0",
            ),
            (
                "s-5.2",
                "width (int bits + frac bits) of s-5.2 must be in 1..=64, got -3",
            ),
            (
                "s1.64",
                "width (int bits + frac bits) of s1.64 must be in 1..=64, got 65",
            ),
            (
                "u40.40",
                "width (int bits + frac bits) of u40.40 must be in 1..=63, got 80",
            ),
            (
                "u1.63",
                "width (int bits + frac bits) of unsigned u1.63 must be at most 63 so that raws \
                 fit in i64, got 64",
            ),
            (
                "s-600.601",
                "frac bits of s-600.601 must be in -512..=512, got 601",
            ),
            (
                "u514.-513",
                "frac bits of u514.-513 must be in -512..=512, got -513",
            ),
        ];
        for (text, message) in cases {
            assert_eq!(text.parse::<Format>().unwrap_err().to_string(), message);
        }
        assert_eq!(
            Format::new(false, 64, 0),
            Err(FixedError::UnsignedWidth {
                notation: "u64.0".to_string(),
                got: 64
            })
        );
        assert_eq!(
            Format::new(true, i32::MAX, i32::MAX),
            Err(FixedError::Width {
                notation: format!("s{}.{}", i32::MAX, i32::MAX),
                got: 2 * i64::from(i32::MAX),
                max: 64
            })
        );
    }

    #[test]
    fn raw_ranges_at_every_width() {
        for width in 1..=64u32 {
            let w = width as i32;
            let s = Format::new(true, w - 3, 3).unwrap();
            let expected_min = -(1i128 << (width - 1));
            let expected_max = (1i128 << (width - 1)) - 1;
            assert_eq!(i128::from(s.min_raw()), expected_min, "s width {width}");
            assert_eq!(i128::from(s.max_raw()), expected_max, "s width {width}");
            assert!(s.contains_raw(expected_min) && s.contains_raw(expected_max));
            assert!(!s.contains_raw(expected_min - 1) && !s.contains_raw(expected_max + 1));
            if width <= 63 {
                let u = Format::new(false, w + 5, -5).unwrap();
                assert_eq!(u.min_raw(), 0, "u width {width}");
                assert_eq!(
                    i128::from(u.max_raw()),
                    (1i128 << width) - 1,
                    "u width {width}"
                );
                assert!(!u.contains_raw(-1) && !u.contains_raw(1i128 << width));
            }
        }
    }

    #[test]
    fn values_and_lsb() {
        assert_eq!(fmt("u1.15").lsb(), 2f64.powi(-15));
        assert_eq!(fmt("s10.-2").lsb(), 4.0);
        assert_eq!(fmt("s10.-2").max_value(), 508.0);
        assert_eq!(fmt("s10.-2").min_value(), -512.0);
        assert_eq!(fmt("u-2.10").max_value(), 0.25 - 2f64.powi(-10));
        assert_eq!(fmt("s2.16").to_f64(-1), -(2f64.powi(-16)));
        assert_eq!(fmt("u-500.512").lsb(), 2f64.powi(-512));
        assert_eq!(fmt("s520.-512").lsb(), 2f64.powi(512));
        // 2^63 - 1 rounds to 2^63 in f64 (nearest).
        assert_eq!(fmt("s64.0").max_value(), 2f64.powi(63));
        assert_eq!(fmt("s0.64").min_value(), -0.5);
    }

    #[test]
    fn bit_growth_follows_ac_fixed() {
        let cases = [
            ("u1.16", "u1.16", "u2.32", "u2.16", "s2.16"),
            ("s1.15", "s1.15", "s2.30", "s2.15", "s2.15"),
            ("u1.8", "s1.8", "s2.16", "s3.8", "s3.8"),
            ("s1.8", "u1.8", "s2.16", "s3.8", "s3.8"),
            ("u-2.10", "s10.-2", "s8.8", "s11.10", "s11.10"),
        ];
        for (a, b, mul, add, sub) in cases {
            assert_eq!(
                fmt(a).mul_format(fmt(b)).unwrap().to_string(),
                mul,
                "{a} * {b}"
            );
            assert_eq!(
                fmt(a).add_format(fmt(b)).unwrap().to_string(),
                add,
                "{a} + {b}"
            );
            assert_eq!(
                fmt(a).sub_format(fmt(b)).unwrap().to_string(),
                sub,
                "{a} - {b}"
            );
        }
        assert!(fmt("s1.40").mul_format(fmt("s1.40")).is_err());
        assert!(fmt("s64.0").add_format(fmt("s1.0")).is_err());
    }
}
