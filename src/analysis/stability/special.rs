//! Special inputs of the float paths (NaN, infinities, cosines just outside [0, 1]) and what
//! each path makes of them.

use serde::Serialize;

use crate::error::Error;
use crate::fixed::{quantize_f64, Overflow, Rounding};
use crate::reference::lobe::cos_pow;

use super::*;

/// A special input of the float paths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpecialInput {
    /// How tables name it.
    pub label: &'static str,
    /// The cosine.
    pub c: f64,
}

/// The special inputs: NaN, the infinities, -0, cosines just below 0 and just above 1 as
/// float dot products produce them (an f32 ulp, a few ulps, an fp16 ulp).
pub fn special_inputs() -> Vec<SpecialInput> {
    vec![
        SpecialInput {
            label: "NaN",
            c: f64::NAN,
        },
        SpecialInput {
            label: "+inf",
            c: f64::INFINITY,
        },
        SpecialInput {
            label: "-inf",
            c: f64::NEG_INFINITY,
        },
        SpecialInput {
            label: "-0",
            c: -0.0,
        },
        SpecialInput {
            label: "-2^-24",
            c: -(2f64.powi(-24)),
        },
        SpecialInput {
            label: "-2^-10",
            c: -(2f64.powi(-10)),
        },
        SpecialInput {
            label: "1+2^-23",
            c: 1.0 + 2f64.powi(-23),
        },
        SpecialInput {
            label: "1+2^-20",
            c: 1.0 + 2f64.powi(-20),
        },
        SpecialInput {
            label: "1+2^-10",
            c: 1.0 + 2f64.powi(-10),
        },
    ]
}

/// The exponents of the special-input table.
pub const SPECIAL_N: [u32; 4] = [1, 16, 1024, 4096];

/// What a path makes of a special input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum SpecialVerdict {
    /// Finite, not negative, within the tolerance of cos^n of the input clamped to [0, 1].
    Ok,
    /// A NaN or infinite input gave a finite output in [0, 1 + tol].
    Absorbed,
    /// The output is NaN.
    Nan,
    /// The output is infinite.
    Inf,
    /// The output is negative.
    Negative,
    /// The output is off cos^n(clamp(c, 0, 1)) by more than the tolerance.
    Off,
}

impl SpecialVerdict {
    /// Whether the verdict is a failure.
    pub fn fails(self) -> bool {
        !matches!(self, SpecialVerdict::Ok | SpecialVerdict::Absorbed)
    }

    /// The name used in tables.
    pub fn name(self) -> &'static str {
        match self {
            SpecialVerdict::Ok => "ok",
            SpecialVerdict::Absorbed => "absorbed",
            SpecialVerdict::Nan => "nan",
            SpecialVerdict::Inf => "inf",
            SpecialVerdict::Negative => "negative",
            SpecialVerdict::Off => "off",
        }
    }
}

/// One path's output for one special input and one n.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SpecialOutcome {
    /// The path.
    pub path: String,
    /// The input's label.
    pub input: String,
    /// The exponent.
    pub n: u32,
    /// The output, printed (`NaN`, `inf` and `-inf` as such).
    pub output: String,
    /// The verdict.
    pub verdict: SpecialVerdict,
}

/// Judges an output against what the input asks for.
///
/// # Examples
/// ```
/// use specfx::analysis::stability::{judge, SpecialVerdict};
/// assert_eq!(judge(f64::NAN, 0.0, 16, 1e-3), SpecialVerdict::Absorbed);
/// assert_eq!(judge(f64::NAN, f64::NAN, 16, 1e-3), SpecialVerdict::Nan);
/// assert_eq!(judge(-0.5, -1e-9, 16, 1e-3), SpecialVerdict::Negative);
/// assert_eq!(judge(1.5, 1.0 + 1e-6, 16, 1e-3), SpecialVerdict::Ok);
/// ```
pub fn judge(c: f64, out: f64, n: u32, tol: f64) -> SpecialVerdict {
    if out.is_nan() {
        SpecialVerdict::Nan
    } else if out.is_infinite() {
        SpecialVerdict::Inf
    } else if out < 0.0 {
        SpecialVerdict::Negative
    } else if !c.is_finite() {
        if out <= 1.0 + tol {
            SpecialVerdict::Absorbed
        } else {
            SpecialVerdict::Off
        }
    } else if (out - cos_pow(c.clamp(0.0, 1.0), f64::from(n))).abs() > tol {
        SpecialVerdict::Off
    } else {
        SpecialVerdict::Ok
    }
}

pub(super) fn show(x: f64) -> String {
    if x.is_nan() {
        "NaN".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else {
        format!("{x:e}")
    }
}

/// Every float path's output, and every datapath's lobe (the input converted to its format
/// with rounding to nearest and saturation; NaN and infinities have no fixed-point code and are
/// left out), for every special input and n of [`SPECIAL_N`].
pub fn special_outcomes(paths: &[MapPath], tol: f64) -> Result<Vec<SpecialOutcome>, Error> {
    let mut v = Vec::new();
    for path in paths {
        let fixed = match path {
            // Exponents it cannot hold are skipped.
            MapPath::Fixed(c) => match representable(c, &SPECIAL_N)?.0 {
                Some(dp) => Some(dp),
                None => continue,
            },
            MapPath::Float(_) => None,
        };
        for input in special_inputs() {
            for n in SPECIAL_N {
                let out = match (path, &fixed) {
                    (MapPath::Float(p), _) => p.prepare(n).eval(input.c).value,
                    (MapPath::Fixed(_), Some(dp)) => {
                        let Some(nc) = dp.constants_for(n) else {
                            continue;
                        };
                        let cf = dp.config().c.format;
                        let Some(q) = quantize_f64(input.c, cf, Rounding::Rnd, Overflow::Sat)
                        else {
                            continue;
                        };
                        let last = dp.stage_last_square();
                        let f = dp.stages()[last].format.frac_bits();
                        dp.eval(q.raw, nc).values[last] as f64 * (-f64::from(f)).exp2()
                    }
                    (MapPath::Fixed(_), None) => continue,
                };
                v.push(SpecialOutcome {
                    path: path.name(),
                    input: input.label.to_string(),
                    n,
                    output: show(out),
                    verdict: judge(input.c, out, n, tol),
                });
            }
        }
    }
    Ok(v)
}
