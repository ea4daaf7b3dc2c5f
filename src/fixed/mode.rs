//! Quantization (rounding) and overflow modes, named and behaving as in `ac_fixed`.
use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::error::FixedError;

/// How fraction bits that do not fit in the target format are dropped (`ac_fixed`'s `ac_q_mode`).
///
/// Each mode is written with its `ac_fixed` name without the `AC_` prefix: [`Display`](fmt::Display)
/// and serde use upper case (`RND_CONV`), [`FromStr`] and serde accept upper or lower case
/// (`RND_CONV` or `rnd_conv`, not a mix).
///
/// In the table, `x` is the exact value in units of the target LSB; a *tie* is a value exactly
/// half way between two codes.
///
/// | mode | rule | 2.5 | -2.5 | 2.25 | -2.25 |
/// |---|---|---|---|---|---|
/// | `TRN` | toward -inf (floor; drop the bits) | 2 | -3 | 2 | -3 |
/// | `TRN_ZERO` | toward zero | 2 | -2 | 2 | -2 |
/// | `RND` | nearest, ties toward +inf | 3 | -2 | 2 | -2 |
/// | `RND_ZERO` | nearest, ties toward zero | 2 | -2 | 2 | -2 |
/// | `RND_INF` | nearest, ties away from zero | 3 | -3 | 2 | -2 |
/// | `RND_MIN_INF` | nearest, ties toward -inf | 2 | -3 | 2 | -2 |
/// | `RND_CONV` | nearest, ties to even | 2 | -2 | 2 | -2 |
/// | `RND_CONV_ODD` | nearest, ties to odd | 3 | -3 | 2 | -2 |
///
/// The default is `TRN`, as in `ac_fixed`.
///
/// # Examples
///
/// ```
/// use specfx::fixed::{round_shift_i64, Rounding};
///
/// let mode: Rounding = "rnd_conv".parse().unwrap();
/// assert_eq!(mode, Rounding::RndConv);
/// assert_eq!(mode.to_string(), "RND_CONV");
/// // 5 / 2 = 2.5 is a tie: ties to even gives 2.
/// assert_eq!(round_shift_i64(5, 1, mode), 2);
/// assert_eq!(Rounding::ALL.len(), 8);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub enum Rounding {
    /// `TRN`: toward -inf, i.e. the dropped bits are simply discarded.
    #[default]
    Trn,
    /// `TRN_ZERO`: toward zero (truncation of the magnitude).
    TrnZero,
    /// `RND`: to nearest, ties toward +inf.
    Rnd,
    /// `RND_ZERO`: to nearest, ties toward zero.
    RndZero,
    /// `RND_INF`: to nearest, ties away from zero.
    RndInf,
    /// `RND_MIN_INF`: to nearest, ties toward -inf.
    RndMinInf,
    /// `RND_CONV`: to nearest, ties to even (convergent rounding).
    RndConv,
    /// `RND_CONV_ODD`: to nearest, ties to odd.
    RndConvOdd,
}

impl Rounding {
    /// Every rounding mode, in `ac_fixed`'s documentation order.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Rounding;
    ///
    /// assert_eq!(Rounding::ALL[0], Rounding::Trn);
    /// assert!(Rounding::ALL.contains(&Rounding::RndConvOdd));
    /// ```
    pub const ALL: [Rounding; 8] = [
        Rounding::Trn,
        Rounding::TrnZero,
        Rounding::Rnd,
        Rounding::RndZero,
        Rounding::RndInf,
        Rounding::RndMinInf,
        Rounding::RndConv,
        Rounding::RndConvOdd,
    ];

    /// The `ac_fixed` name of the mode without the `AC_` prefix, in upper case.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Rounding;
    ///
    /// assert_eq!(Rounding::RndMinInf.name(), "RND_MIN_INF");
    /// ```
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Rounding::Trn => "TRN",
            Rounding::TrnZero => "TRN_ZERO",
            Rounding::Rnd => "RND",
            Rounding::RndZero => "RND_ZERO",
            Rounding::RndInf => "RND_INF",
            Rounding::RndMinInf => "RND_MIN_INF",
            Rounding::RndConv => "RND_CONV",
            Rounding::RndConvOdd => "RND_CONV_ODD",
        }
    }
}

impl fmt::Display for Rounding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Rounding {
    type Err = FixedError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Rounding::ALL
            .into_iter()
            .find(|mode| name_matches(mode.name(), s))
            .ok_or_else(|| FixedError::BadRounding { got: s.to_string() })
    }
}

/// What happens when a rounded value does not fit in the target format (`ac_fixed`'s `ac_o_mode`).
///
/// Named like [`Rounding`]: upper case for display and serde, upper or lower case accepted.
///
/// * `WRAP`: keep the low `W` bits (two's complement wrap; modulo `2^W` for unsigned).
/// * `SAT`: clamp to `[min, max]`.
/// * `SAT_ZERO`: any overflow gives 0.
/// * `SAT_SYM`: signed formats clamp to `[-max, max]`, so the most negative code is never
///   produced. As in `ac_fixed`, this also applies to an in-range value equal to the most
///   negative code: it becomes `-max` and counts as a saturation. `ac_fixed` builds that
///   result by setting the most negative code and then its LSB, so for a 1-bit signed format
///   (codes -1 and 0) a negative value gives -1, still reported as a saturation. Unsigned
///   formats behave as with `SAT`.
///
/// The default is `WRAP`, as in `ac_fixed`.
///
/// # Examples
///
/// ```
/// use specfx::fixed::{overflow_i64, Event, Format, Overflow};
///
/// let fmt: Format = "s4.0".parse().unwrap(); // codes -8..=7
/// let mode: Overflow = "SAT_SYM".parse().unwrap();
/// assert_eq!(overflow_i64(-8, fmt, mode).raw, -7);
/// assert_eq!(overflow_i64(-8, fmt, mode).event, Event::Saturated);
/// assert_eq!(overflow_i64(9, fmt, Overflow::Wrap).raw, -7);
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub enum Overflow {
    /// `WRAP`: two's complement wrap to `W` bits (modulo `2^W` for unsigned).
    #[default]
    Wrap,
    /// `SAT`: clamp to `[min, max]`.
    Sat,
    /// `SAT_ZERO`: an overflowing value becomes 0.
    SatZero,
    /// `SAT_SYM`: signed formats clamp to `[-max, max]`; unsigned formats as `SAT`.
    SatSym,
}

impl Overflow {
    /// Every overflow mode, in `ac_fixed`'s documentation order.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Overflow;
    ///
    /// assert_eq!(Overflow::ALL, [Overflow::Wrap, Overflow::Sat, Overflow::SatZero, Overflow::SatSym]);
    /// ```
    pub const ALL: [Overflow; 4] = [
        Overflow::Wrap,
        Overflow::Sat,
        Overflow::SatZero,
        Overflow::SatSym,
    ];

    /// The `ac_fixed` name of the mode without the `AC_` prefix, in upper case.
    ///
    /// # Examples
    ///
    /// ```
    /// use specfx::fixed::Overflow;
    ///
    /// assert_eq!(Overflow::SatZero.name(), "SAT_ZERO");
    /// ```
    #[must_use]
    pub const fn name(self) -> &'static str {
        match self {
            Overflow::Wrap => "WRAP",
            Overflow::Sat => "SAT",
            Overflow::SatZero => "SAT_ZERO",
            Overflow::SatSym => "SAT_SYM",
        }
    }
}

impl fmt::Display for Overflow {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Overflow {
    type Err = FixedError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Overflow::ALL
            .into_iter()
            .find(|mode| name_matches(mode.name(), s))
            .ok_or_else(|| FixedError::BadOverflow { got: s.to_string() })
    }
}

/// True when `given` is `upper` written all in upper case or all in lower case.
fn name_matches(upper: &str, given: &str) -> bool {
    given == upper || given == upper.to_ascii_lowercase()
}

macro_rules! serde_as_name {
    ($Mode:ty) => {
        impl Serialize for $Mode {
            fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
                serializer.serialize_str(self.name())
            }
        }

        impl<'de> Deserialize<'de> for $Mode {
            fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
                let text = String::deserialize(deserializer)?;
                text.parse().map_err(serde::de::Error::custom)
            }
        }
    };
}

serde_as_name!(Rounding);
serde_as_name!(Overflow);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_names_are_the_ac_fixed_names() {
        let expected = [
            (Rounding::Trn, "TRN"),
            (Rounding::TrnZero, "TRN_ZERO"),
            (Rounding::Rnd, "RND"),
            (Rounding::RndZero, "RND_ZERO"),
            (Rounding::RndInf, "RND_INF"),
            (Rounding::RndMinInf, "RND_MIN_INF"),
            (Rounding::RndConv, "RND_CONV"),
            (Rounding::RndConvOdd, "RND_CONV_ODD"),
        ];
        assert_eq!(Rounding::ALL.to_vec(), expected.map(|(m, _)| m).to_vec());
        for (mode, name) in expected {
            assert_eq!(mode.to_string(), name);
            assert_eq!(name.parse::<Rounding>(), Ok(mode));
            assert_eq!(name.to_ascii_lowercase().parse::<Rounding>(), Ok(mode));
        }
    }

    #[test]
    fn overflow_names_are_the_ac_fixed_names() {
        let expected = [
            (Overflow::Wrap, "WRAP"),
            (Overflow::Sat, "SAT"),
            (Overflow::SatZero, "SAT_ZERO"),
            (Overflow::SatSym, "SAT_SYM"),
        ];
        assert_eq!(Overflow::ALL.to_vec(), expected.map(|(m, _)| m).to_vec());
        for (mode, name) in expected {
            assert_eq!(mode.to_string(), name);
            assert_eq!(name.parse::<Overflow>(), Ok(mode));
            assert_eq!(name.to_ascii_lowercase().parse::<Overflow>(), Ok(mode));
        }
    }

    #[test]
    fn defaults_are_those_of_ac_fixed() {
        assert_eq!(Rounding::default(), Rounding::Trn);
        assert_eq!(Overflow::default(), Overflow::Wrap);
    }

    #[test]
    fn bad_mode_names_are_rejected_with_the_text_given() {
        for bad in ["", "AC_RND", "Rnd_Conv", "RND_CONV ", "round", "RNDCONV"] {
            let err = bad.parse::<Rounding>().unwrap_err();
            assert_eq!(
                err,
                FixedError::BadRounding {
                    got: bad.to_string()
                }
            );
        }
        assert_eq!(
            "ac_rnd".parse::<Rounding>().unwrap_err().to_string(),
            "rounding mode must be one of TRN, TRN_ZERO, RND, RND_ZERO, RND_INF, RND_MIN_INF, \
             RND_CONV, RND_CONV_ODD (upper or lower case), got 'ac_rnd'"
        );
        for bad in ["", "AC_SAT", "Sat", "SATURATE", "wrap "] {
            let err = bad.parse::<Overflow>().unwrap_err();
            assert_eq!(
                err,
                FixedError::BadOverflow {
                    got: bad.to_string()
                }
            );
        }
        assert_eq!(
            "clamp".parse::<Overflow>().unwrap_err().to_string(),
            "overflow mode must be one of WRAP, SAT, SAT_ZERO, SAT_SYM (upper or lower case), \
             got 'clamp'"
        );
    }
}
