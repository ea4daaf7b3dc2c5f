//! Where each method fails: every float path and fixed-point datapath evaluated over n and
//! theta, each sample flagged by what goes wrong there, gathered into failure regions and heat
//! maps; plus special inputs (NaN, infinities, just outside [0, 1]) and the overshoot of
//! cosines above 1.
//!
//! The map samples the cosine, not the angle: float paths at every `c = j / 2^c_bits` in
//! [0, 1], fixed-point datapaths at every code of their own input format up to 1.0, so a
//! region's boundary is a code and can be pinned exactly. Each sample is compared with
//! `cos^n(c)` in f64 and flagged by [`Kind`]. Work is split by n across threads and merged in
//! n order, so every figure is deterministic.
//!
//! The map itself is `map.rs` (samples folded per n into regions and heat maps), the paths it
//! evaluates `paths.rs`, the special inputs `special.rs`, the overshoot above 1 `overshoot.rs`.

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use crate::error::Error;
use crate::nset::NSet;

mod map;
mod overshoot;
mod paths;
mod special;

pub use map::*;
pub use overshoot::*;
pub use paths::*;
pub use special::*;

/// The default tolerance: one LSB of an 8-bit display, 2^-8.
pub const DEFAULT_TOL: f64 = super::LSB8;

/// Rows of the heat maps: theta from 0 to 90 degrees in steps of one degree.
pub const HEAT_ROWS: usize = 90;

/// Overshoot inputs are `1 + j 2^-23` (j f32 ulps above 1) for j up to this: 2^14 ulps,
/// 1 + 2^-9, the error of a half-precision (fp16) normal.
pub const OVERSHOOT_J_MAX: u32 = 1 << 14;

/// An absolute tolerance on the lobe, written `1 lsb8` (2^-8), `0.5 lsb10` or `0.004`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tolerance {
    /// The text it was parsed from.
    pub text: String,
    /// The value.
    pub value: f64,
}

impl Default for Tolerance {
    fn default() -> Tolerance {
        Tolerance {
            text: "1 lsb8".into(),
            value: DEFAULT_TOL,
        }
    }
}

impl FromStr for Tolerance {
    type Err = Error;
    /// # Examples
    /// ```
    /// use specfx::analysis::stability::Tolerance;
    /// assert_eq!("1 lsb8".parse::<Tolerance>().unwrap().value, 1.0 / 256.0);
    /// assert_eq!("0.5lsb10".parse::<Tolerance>().unwrap().value, 0.5 / 1024.0);
    /// assert_eq!("1e-3".parse::<Tolerance>().unwrap().value, 1e-3);
    /// assert!("-1".parse::<Tolerance>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Tolerance, Error> {
        let bad = || Error::OutOfRange {
            what: "the tolerance",
            expected: "a positive number, optionally in lsbN (2^-N), e.g. '1 lsb8' or '0.004'"
                .into(),
            got: format!("'{s}'"),
        };
        let t = s.trim();
        let (number, scale) = match t.find("lsb") {
            Some(i) => {
                let bits: i32 = t[i + 3..].trim().parse().map_err(|_| bad())?;
                if !(1..=62).contains(&bits) {
                    return Err(bad());
                }
                (t[..i].trim(), (-f64::from(bits)).exp2())
            }
            None => (t, 1.0),
        };
        let value = number.parse::<f64>().map_err(|_| bad())? * scale;
        if !(value.is_finite() && value > 0.0) {
            return Err(bad());
        }
        Ok(Tolerance {
            text: t.to_string(),
            value,
        })
    }
}

impl fmt::Display for Tolerance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// What goes wrong at a sample. A sample can carry several kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// The lobe is above cos^n by more than the tolerance.
    Over,
    /// The lobe is below cos^n by more than the tolerance.
    Under,
    /// The base of the power is negative and the cutoff lets it through (paper cutoff, none):
    /// an even power of it is a spurious lobe past the zero of the base.
    NegativeBase,
    /// n < m and the lobe is off by more than the tolerance: the base never reaches zero in
    /// the hemisphere, so the lobe does not close at the horizon.
    NBelowM,
    /// A fixed-point stage wrapped around.
    Wrap,
    /// A fixed-point stage saturated (or overflowed to zero).
    Saturate,
    /// The lobe is zero (fixed point) or below the smallest normal number of its float type,
    /// while the value it computes is positive: flushed to zero on hardware without subnormals.
    Underflow,
    /// The lobe decreases as c increases (between neighbouring samples of one n).
    NonMonotonic,
    /// The lobe is NaN or infinite.
    NonFinite,
    /// The datapath cannot hold this n's constants (slope, offset or coefficient).
    Unrepresentable,
}

impl Kind {
    /// Every kind, in report order.
    pub const ALL: [Kind; 10] = [
        Kind::Over,
        Kind::Under,
        Kind::NegativeBase,
        Kind::NBelowM,
        Kind::Wrap,
        Kind::Saturate,
        Kind::Underflow,
        Kind::NonMonotonic,
        Kind::NonFinite,
        Kind::Unrepresentable,
    ];

    /// The kind's bit in a sample's flags.
    pub fn bit(self) -> u16 {
        1 << (self as u16)
    }

    /// The name used in tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Over => "over",
            Kind::Under => "under",
            Kind::NegativeBase => "negative_base",
            Kind::NBelowM => "n_below_m",
            Kind::Wrap => "wrap",
            Kind::Saturate => "saturate",
            Kind::Underflow => "underflow",
            Kind::NonMonotonic => "non_monotonic",
            Kind::NonFinite => "non_finite",
            Kind::Unrepresentable => "unrepresentable",
        }
    }

    /// One sentence saying what the kind means.
    pub fn describe(self) -> &'static str {
        match self {
            Kind::Over => "the lobe is above cos^n by more than the tolerance",
            Kind::Under => "the lobe is below cos^n by more than the tolerance",
            Kind::NegativeBase => {
                "the base is negative and the cutoff lets it through: an even power makes a spurious lobe past the zero of the base"
            }
            Kind::NBelowM => {
                "n < m: the base never reaches zero in the hemisphere, so the lobe does not close at the horizon"
            }
            Kind::Wrap => "a fixed-point stage wrapped around",
            Kind::Saturate => "a fixed-point stage saturated",
            Kind::Underflow => {
                "the lobe is flushed to zero (below the smallest normal float, or below half an LSB) while its value is positive: relative error 100%"
            }
            Kind::NonMonotonic => "the lobe decreases as c increases",
            Kind::NonFinite => "the lobe is NaN or infinite",
            Kind::Unrepresentable => "the datapath cannot hold this n's constants",
        }
    }

    /// Whether the kind is a failure by itself, whatever the size of the error.
    pub fn is_structural(self) -> bool {
        matches!(self, Kind::NonFinite | Kind::Unrepresentable)
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

const FAIL_BITS: u16 = (1 << Kind::Over as u16) | (1 << Kind::Under as u16);

/// What the map covers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Grid {
    /// The exponents.
    pub n: NSet,
    /// Float paths are sampled at `c = j / 2^c_bits`, j = 0..=2^c_bits.
    pub c_bits: u32,
    /// The tolerance on |lobe - cos^n|.
    pub tol: Tolerance,
}

impl Default for Grid {
    /// n = 1..=4096, c in steps of 2^-15 (the baseline's input resolution), 1 lsb8.
    fn default() -> Grid {
        Grid {
            n: NSet::range(1, 4096).expect("valid range"),
            c_bits: 15,
            tol: Tolerance::default(),
        }
    }
}

/// The extent of a region at one n.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NBounds {
    /// The exponent.
    pub n: u32,
    /// The smallest flagged cosine.
    pub c_lo: f64,
    /// The largest flagged cosine.
    pub c_hi: f64,
    /// Flagged samples at this n.
    pub samples: u64,
}

impl NBounds {
    /// The angle range in degrees, smallest first (theta of `c_hi`, theta of `c_lo`).
    pub fn theta_deg(&self) -> (f64, f64) {
        (
            self.c_hi.clamp(-1.0, 1.0).acos().to_degrees(),
            self.c_lo.clamp(-1.0, 1.0).acos().to_degrees(),
        )
    }
}

/// Everything `specfx stability` computes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StabilityReport {
    /// The grid.
    pub grid: Grid,
    /// One map per path.
    pub maps: Vec<PathMap>,
    /// The special inputs.
    pub special: Vec<SpecialOutcome>,
    /// The overshoot thresholds of the float paths.
    pub overshoot: Vec<Overshoot>,
}

/// Maps, special inputs and overshoot of every path.
pub fn analyse(
    paths: &[MapPath],
    grid: &Grid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<StabilityReport, Error> {
    let maps = map(paths, grid, progress)?;
    Ok(StabilityReport {
        grid: grid.clone(),
        maps,
        special: special_outcomes(paths, grid.tol.value)?,
        overshoot: overshoot(paths, grid),
    })
}

/// What determines a stability map, for its provenance: its paths (float paths by name,
/// datapaths by their configuration), the exponents, the sampling of c and the tolerance.
pub fn inputs(paths: &[MapPath], grid: &Grid) -> crate::provenance::Inputs {
    let floats: Vec<String> = paths
        .iter()
        .filter_map(|p| match p {
            MapPath::Float(f) => Some(f.name().to_string()),
            MapPath::Fixed(_) => None,
        })
        .collect();
    let mut inputs = crate::provenance::Inputs::new("stability")
        .option("float", floats)
        .option("n", crate::provenance::canonical_nset(&grid.n))
        .option("c_bits", grid.c_bits)
        .option("tol", grid.tol.value);
    for p in paths {
        if let MapPath::Fixed(config) = p {
            inputs = inputs.config(config);
        }
    }
    inputs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heat_rows_cover_zero_to_ninety_degrees() {
        assert_eq!(heat_row(1.0), 0);
        assert_eq!(heat_row(0.0), HEAT_ROWS - 1);
        // cos(45.5 degrees) is in row 45.
        assert_eq!(heat_row(45.5f64.to_radians().cos()), 45);
    }

    #[test]
    fn columns_partition_the_exponents() {
        let ns: Vec<u32> = (1..=4096).collect();
        let cols = heat_columns(&ns);
        assert_eq!(cols.first(), Some(&(1, 1)));
        assert_eq!(cols.last().map(|c| c.1), Some(4096));
        for w in cols.windows(2) {
            assert_eq!(w[0].1 + 1, w[1].0);
        }
        // 22 single columns (while log2((n+1)/n) >= 1/16), then about 1/16 octave each over
        // the 7.5 octaves from 23 to 4096.
        assert!((125..=140).contains(&cols.len()), "{}", cols.len());
    }

    #[test]
    fn tolerance_errors_name_what_was_expected() {
        let e = "lsb".parse::<Tolerance>().unwrap_err().to_string();
        assert!(
            e.starts_with("the tolerance must be a positive number"),
            "{e}"
        );
    }
}
