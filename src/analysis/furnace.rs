//! The white-furnace check: the hemispherical-directional reflectance of every normalised form.
//!
//! For an incident direction at polar angle theta_i the reflectance is
//! `rho(theta_i) = ∫_H f_r(w_i, w_o) cos(theta_o) dw_o`; a BRDF conserves energy when it is at
//! most 1 for every theta_i. Each of the six [`Form`]s is a lobe `L(x)` of one cosine `x`
//! (R.w_o for the Phong forms, N.H for the Blinn-Phong forms) times a coefficient; after the
//! azimuth around R (or around N for h) is integrated in closed form, the 2D integral is the
//! 1D integral `∫_0^1 coef L(x) K_form(x, theta_i) dx` ([`kernel`]; derivations in
//! `docs/furnace.md`). The lobe is 0 for `x <= 0`, as the shader's `max(0, x)` makes it.
//!
//! Four paths are integrated per form and exponent ([`FurnacePath`]): f64 cos^n with its
//! classic coefficient, the configuration's f64 lobe (cs_m or its minimax twin, with its
//! cutoff) with the paper's and with the exact coefficient, and the bit-accurate datapath with
//! the form's coefficient, whose output is constant on each input code's interval of x, so its
//! integral is a sum of exact per-interval integrals of K ([`datapath_steps`]).
//!
//! **Invariant:** pure and deterministic: no I/O, work split over (form, n) and gathered in a
//! fixed order, every sum taken sequentially.

use std::f64::consts::{FRAC_PI_4, PI};

use rayon::prelude::*;
use serde::Serialize;

use crate::analysis::check::MAX_CHECK_CODES;
use crate::error::Error;
use crate::nset::NSet;
use crate::pipeline::f64_walk::F64Walk;
use crate::pipeline::{Datapath, NConstants, OutputScratch};
use crate::reference::lobe::{cos_pow, m_of_k, paper_cutoff_cosine, Cutoff};
use crate::reference::normalisation::{classic_coefficient, coefficient, CoefSource, Form};
use crate::reference::quadrature::integrate;

/// A reflectance is flagged when it exceeds `1 + FLAG_TOLERANCE`. The quadratures are
/// accurate to about 1e-12 relative, so a flag is never round-off.
pub const FLAG_TOLERANCE: f64 = 1e-9;

/// Relative tolerance of every adaptive quadrature of the furnace.
pub const REL_TOL: f64 = 1e-12;

/// The default incident angles, in degrees: 0 to 85 in steps of 5. Without a
/// masking-shadowing term the NDF forms gain energy without bound as theta_i nears 90
/// degrees, so the default stops short of it.
pub const DEFAULT_ANGLES: &str = "0..85:5";

/// Values within this (relative) of a curve's largest are ties: the first is its angle.
const MAX_TIE: f64 = 1e-12;

/// The most incident angles a run accepts.
pub const MAX_ANGLES: usize = 1000;

/// The four specular paths of the furnace, in report order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FurnacePath {
    /// f64 cos^n with [`classic_coefficient`].
    F64CosN,
    /// The configuration's f64 lobe with the paper's coefficient ([`CoefSource::Paper`]).
    F64CsMPaper,
    /// The configuration's f64 lobe with the exact coefficient ([`CoefSource::Exact`]).
    F64CsMExact,
    /// The bit-accurate datapath with the form's coefficient from the configuration's source.
    Datapath,
}

impl FurnacePath {
    /// Every path, in report order.
    pub const ALL: [FurnacePath; 4] = [
        FurnacePath::F64CosN,
        FurnacePath::F64CsMPaper,
        FurnacePath::F64CsMExact,
        FurnacePath::Datapath,
    ];

    /// The name used in CSV, JSON and charts.
    pub fn name(self) -> &'static str {
        match self {
            FurnacePath::F64CosN => "f64_cos_n",
            FurnacePath::F64CsMPaper => "f64_cs_m_paper",
            FurnacePath::F64CsMExact => "f64_cs_m_exact",
            FurnacePath::Datapath => "datapath",
        }
    }

    /// A longer label for legends and tables.
    pub fn label(self) -> &'static str {
        match self {
            FurnacePath::F64CosN => "f64 cos^n, classic coef",
            FurnacePath::F64CsMPaper => "f64 cs_m, paper coef",
            FurnacePath::F64CsMExact => "f64 cs_m, exact coef",
            FurnacePath::Datapath => "datapath",
        }
    }
}

/// Half-width B of the arc of azimuths phi where `den cos(phi) > num`, for `den >= 0`:
/// `arccos(clamp(num / den, -1, 1))`, and pi or 0 when `den = 0` (the whole circle or none).
fn visible_half_arc(num: f64, den: f64) -> f64 {
    if den > 0.0 {
        (num / den).clamp(-1.0, 1.0).acos()
    } else if num < 0.0 {
        PI
    } else {
        0.0
    }
}

/// The azimuth-integrated kernel `K_form(x, theta_i)`: `rho = ∫_0^1 coef L(x) K dx`.
///
/// With `s = sin theta_i`, `c = cos theta_i`, `r = sqrt(1 - x^2)` and B the half-width of the
/// visible arc of azimuths:
/// - Phong forms (x = R.w_o, visible where `x c + r s cos(beta) > 0`): `phong` `2B`,
///   `phong_modified` `2B x c + 2 r s sin B`;
/// - Blinn-Phong forms (x = N.h, `a = w_i.h = c x + s r cos(phi)`, visible where
///   `2 a x > c`): `blinn_phong` `4 ∫a`, `blinn_phong_modified` `8 x ∫a^2 - 4 c ∫a`, the NDF
///   forms `∫a / c`, with `∫a = 2B c x + 2 s r sin B` and
///   `∫a^2 = 2B c^2 x^2 + 4 c x s r sin B + s^2 r^2 (B + sin(2B)/2)`.
///
/// Zero for `x <= 0`. The NDF forms need `theta_i < 90` degrees.
///
/// # Examples
/// ```
/// use specfx::analysis::furnace::kernel;
/// use specfx::reference::normalisation::Form;
/// use std::f64::consts::PI;
/// // At normal incidence the whole circle of azimuths is visible around R = N.
/// assert_eq!(kernel(Form::Phong, 0.3, 0.0), 2.0 * PI);
/// assert_eq!(kernel(Form::PhongModified, 0.5, 0.0), PI);
/// // Blinn-Phong at normal incidence: h must be within 45 degrees of N.
/// assert_eq!(kernel(Form::BlinnPhong, 0.7, 0.0), 0.0);
/// assert!((kernel(Form::BlinnPhong, 0.8, 0.0) - 8.0 * PI * 0.8).abs() < 1e-14);
/// ```
pub fn kernel(form: Form, x: f64, theta_i: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let x = x.min(1.0);
    let (s, c) = theta_i.sin_cos();
    let r = ((1.0 - x) * (1.0 + x)).sqrt();
    match form {
        Form::Phong | Form::PhongModified => {
            let b = visible_half_arc(-x * c, r * s);
            if form == Form::Phong {
                2.0 * b
            } else {
                2.0 * b * x * c + 2.0 * r * s * b.sin()
            }
        }
        Form::BlinnPhong
        | Form::BlinnPhongModified
        | Form::BlinnPhongNdf
        | Form::BlinnPhongHeightfield => {
            let b = visible_half_arc(c * (1.0 - 2.0 * x * x), 2.0 * x * s * r);
            if b == 0.0 {
                return 0.0;
            }
            let sin_b = b.sin();
            let int_a = 2.0 * b * c * x + 2.0 * s * r * sin_b;
            match form {
                Form::BlinnPhong => 4.0 * int_a,
                Form::BlinnPhongModified => {
                    let int_a2 = 2.0 * b * c * c * x * x
                        + 4.0 * c * x * s * r * sin_b
                        + s * s * r * r * (b + 0.5 * (2.0 * b).sin());
                    8.0 * x * int_a2 - 4.0 * c * int_a
                }
                _ => int_a / c,
            }
        }
    }
}

/// The points of (0, 1) where [`kernel`] has a kink or a jump for this theta_i: where the
/// visible arc starts to close. Phong: `x = sin theta_i`. Blinn-Phong: nothing is visible
/// below `x = cos(pi/4 + theta_i/2)` and the whole circle above `x = cos(pi/4 - theta_i/2)`.
///
/// # Examples
/// ```
/// use specfx::analysis::furnace::kernel_breaks;
/// use specfx::reference::normalisation::Form;
/// let t = 30f64.to_radians();
/// assert_eq!(kernel_breaks(Form::Phong, t), vec![t.sin()]);
/// assert_eq!(kernel_breaks(Form::BlinnPhong, 0.0).len(), 2); // 1/sqrt(2) twice
/// ```
pub fn kernel_breaks(form: Form, theta_i: f64) -> Vec<f64> {
    let points = match form {
        Form::Phong | Form::PhongModified => vec![theta_i.sin()],
        _ => vec![
            (FRAC_PI_4 + 0.5 * theta_i).cos(),
            (FRAC_PI_4 - 0.5 * theta_i).cos(),
        ],
    };
    points.into_iter().filter(|&x| x > 0.0 && x < 1.0).collect()
}

/// `∫_0^1 weight(x) K_form(x, theta_i) dx` by adaptive Gauss–Kronrod, split at the kernel's
/// kinks and at `weight_breaks` (the lobe's cutoff): the reflectance of a lobe `weight` that
/// already includes its coefficient.
///
/// # Examples
/// ```
/// use specfx::analysis::furnace::reflectance;
/// use specfx::reference::normalisation::Form;
/// use std::f64::consts::PI;
/// // Modified Phong, cos^n with (n + 2)/(2 pi), at normal incidence: exactly 1.
/// let n = 20.0;
/// let rho = reflectance(Form::PhongModified, 0.0, |x| (n + 2.0) / (2.0 * PI) * x.powf(n), &[]);
/// assert!((rho - 1.0).abs() < 1e-12);
/// ```
pub fn reflectance(
    form: Form,
    theta_i: f64,
    weight: impl Fn(f64) -> f64,
    weight_breaks: &[f64],
) -> f64 {
    let mut breaks = kernel_breaks(form, theta_i);
    breaks.extend_from_slice(weight_breaks);
    let f = |x: f64| {
        let w = weight(x);
        if w == 0.0 {
            0.0
        } else {
            w * kernel(form, x, theta_i)
        }
    };
    integrate(f, 0.0, 1.0, &breaks, 0.0, REL_TOL).value
}

/// A run of input codes with one non-zero datapath output: x in `[lo, hi]` (the union of the
/// codes' rounding intervals, within [0, 1]) gives `value`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// Lower end of the run in x.
    pub lo: f64,
    /// Upper end of the run in x.
    pub hi: f64,
    /// The output, as a real number.
    pub value: f64,
}

/// The datapath's output as a step function of x in [0, 1]: x is quantized as the renderer
/// does (`code = round(x / lsb)`, so code j holds x in `[(j - 1/2) lsb, (j + 1/2) lsb]`),
/// consecutive codes with the same output are merged, and codes whose output is 0 are left
/// out. The outputs come from [`Datapath::eval_outputs_range`].
pub fn datapath_steps(dp: &Datapath, nc: &NConstants) -> Vec<Step> {
    let one = dp.one_code();
    let lsb = dp.config().c.format.lsb();
    let out_format = dp.stages()[dp.stage_out()].format;
    let mut out = vec![0i64; (one + 1) as usize];
    dp.eval_outputs_range(nc, 0..one + 1, &mut out, &mut OutputScratch::default());
    let mut steps = Vec::new();
    let mut start = 0usize;
    while start < out.len() {
        let raw = out[start];
        let mut end = start;
        while end + 1 < out.len() && out[end + 1] == raw {
            end += 1;
        }
        if raw != 0 {
            steps.push(Step {
                lo: ((start as f64 - 0.5) * lsb).max(0.0),
                hi: ((end as f64 + 0.5) * lsb).min(1.0),
                value: out_format.to_f64(raw),
            });
        }
        start = end + 1;
    }
    steps
}

/// `Σ value ∫_lo^hi K_form(x, theta_i) dx` over the steps: the exact reflectance of a step
/// function, each interval integrated by Gauss–Kronrod split at the kernel's kinks.
pub fn reflectance_of_steps(form: Form, theta_i: f64, steps: &[Step]) -> f64 {
    let breaks = kernel_breaks(form, theta_i);
    steps
        .iter()
        .map(|st| {
            let k = integrate(
                |x| kernel(form, x, theta_i),
                st.lo,
                st.hi,
                &breaks,
                0.0,
                REL_TOL,
            );
            st.value * k.value
        })
        .sum()
}

/// The default exponents of a configuration's n set: its powers of two, its minimum and its
/// maximum (baseline: 16, 32, 64, 128, 256, 512, 1024).
///
/// # Examples
/// ```
/// use specfx::analysis::furnace::default_exponents;
/// let set = "10..=100".parse().unwrap();
/// assert_eq!(default_exponents(&set), vec![10, 16, 32, 64, 100]);
/// ```
pub fn default_exponents(set: &NSet) -> Vec<u32> {
    set.values()
        .iter()
        .copied()
        .filter(|&n| n.is_power_of_two() || n == set.min() || n == set.max())
        .collect()
}

fn angles_error(got: &str) -> Error {
    Error::OutOfRange {
        what: "angles",
        expected: format!(
            "degrees in [0, 90), at most {MAX_ANGLES}, as a comma list (0,30,60) or ranges with a step (0..85:5, both ends included)"
        ),
        got: format!("'{got}'"),
    }
}

/// Parses incident angles in degrees: a comma list of numbers and ranges `a..b:step` (or
/// `a..=b:step`; both ends included when the step lands on b). The result is sorted and
/// duplicate-free; every angle is in [0, 90).
///
/// # Examples
/// ```
/// use specfx::analysis::furnace::parse_angles;
/// assert_eq!(parse_angles("0..15:5").unwrap(), vec![0.0, 5.0, 10.0, 15.0]);
/// assert_eq!(parse_angles("60,0,30,0").unwrap(), vec![0.0, 30.0, 60.0]);
/// assert!(parse_angles("0..90:10").is_err()); // 90 degrees is grazing
/// ```
pub fn parse_angles(text: &str) -> Result<Vec<f64>, Error> {
    let bad = || angles_error(text);
    let number = |s: &str| -> Result<f64, Error> {
        let v: f64 = s.trim().parse().map_err(|_| bad())?;
        if v.is_finite() && (0.0..90.0).contains(&v) {
            Ok(v + 0.0) // -0 becomes 0
        } else {
            Err(bad())
        }
    };
    let mut angles = Vec::new();
    for item in text.split(',') {
        let item = item.trim();
        if let Some((range, step)) = item.split_once(':') {
            let (lo, hi) = range.split_once("..").ok_or_else(bad)?;
            let hi = hi.strip_prefix('=').unwrap_or(hi);
            let (lo, hi) = (number(lo)?, number(hi)?);
            let step: f64 = step.trim().parse().map_err(|_| bad())?;
            if !(step.is_finite() && step > 0.0) || hi < lo {
                return Err(bad());
            }
            let count = ((hi - lo) / step * (1.0 + 1e-12)).floor() as usize + 1;
            if count > MAX_ANGLES {
                return Err(bad());
            }
            angles.extend((0..count).map(|j| lo + j as f64 * step));
        } else {
            angles.push(number(item)?);
        }
        if angles.len() > MAX_ANGLES {
            return Err(bad());
        }
    }
    angles.sort_by(f64::total_cmp);
    angles.dedup();
    Ok(angles)
}

/// What a furnace run evaluates: exponents (inside the configuration's n set) and incident
/// angles in degrees, validated.
#[derive(Debug, Clone, PartialEq)]
pub struct FurnaceSettings {
    ns: Vec<u32>,
    angles_deg: Vec<f64>,
}

impl FurnaceSettings {
    /// Validates the settings for a datapath: `ns` (default: [`default_exponents`]) must lie in
    /// the configuration's n set, the angles in [0, 90) (at least one), and the input format
    /// must have at most [`MAX_CHECK_CODES`] codes up to 1.0.
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::furnace::FurnaceSettings;
    /// use specfx::pipeline::{Config, Datapath};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let s = FurnaceSettings::new(&dp, None, vec![0.0]).unwrap();
    /// assert_eq!(s.ns(), &[16, 32, 64, 128, 256, 512, 1024]);
    /// let err = FurnaceSettings::new(&dp, Some(&"8,16".parse().unwrap()), vec![0.0]);
    /// assert_eq!(
    ///     err.unwrap_err().to_string(),
    ///     "exponents must be in the configuration's n set 16..=1024, got 8"
    /// );
    /// ```
    pub fn new(
        dp: &Datapath,
        ns: Option<&NSet>,
        angles_deg: Vec<f64>,
    ) -> Result<FurnaceSettings, Error> {
        let set = &dp.config().n;
        let ns = match ns {
            None => default_exponents(set),
            Some(ns) => {
                let outside: Vec<String> = ns
                    .values()
                    .iter()
                    .filter(|n| set.values().binary_search(n).is_err())
                    .map(|n| n.to_string())
                    .collect();
                if !outside.is_empty() {
                    return Err(Error::OutOfRange {
                        what: "exponents",
                        expected: format!("in the configuration's n set {set}"),
                        got: outside.join(", "),
                    });
                }
                ns.values().to_vec()
            }
        };
        if angles_deg.is_empty()
            || angles_deg.len() > MAX_ANGLES
            || angles_deg
                .iter()
                .any(|a| !(a.is_finite() && (0.0..90.0).contains(a)))
        {
            let got: Vec<String> = angles_deg.iter().map(|a| a.to_string()).collect();
            return Err(angles_error(&got.join(",")));
        }
        let n_codes = dp.one_code() as u64 + 1;
        if n_codes > MAX_CHECK_CODES {
            return Err(Error::TooManyCodes {
                format: dp.config().c.format.to_string(),
                n_codes,
                limit: MAX_CHECK_CODES,
            });
        }
        let mut angles_deg = angles_deg;
        angles_deg.sort_by(f64::total_cmp);
        angles_deg.dedup();
        Ok(FurnaceSettings { ns, angles_deg })
    }

    /// The exponents, ascending.
    pub fn ns(&self) -> &[u32] {
        &self.ns
    }

    /// The incident angles in degrees, ascending.
    pub fn angles_deg(&self) -> &[f64] {
        &self.angles_deg
    }
}

/// The reflectance of one path for one form and exponent, at every incident angle.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Curve {
    /// The exponent.
    pub n: u32,
    /// The path.
    pub path: FurnacePath,
    /// The coefficient the path uses (the datapath's as stored in its format).
    pub coef: f64,
    /// rho(0), at normal incidence (computed whether or not 0 is among the angles).
    pub rho_normal: f64,
    /// rho at each angle of the run.
    pub rho: Vec<f64>,
    /// The largest rho over the angles.
    pub max: f64,
    /// The angle of the largest rho in degrees: the first within 1e-12 of it.
    pub max_angle_deg: f64,
    /// The angles where rho exceeds `1 + FLAG_TOLERANCE`.
    pub flagged_angles_deg: Vec<f64>,
}

/// Every curve of one form.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FormFurnace {
    /// The form.
    pub form: Form,
    /// Why the datapath with this form's coefficient cannot be built (its validation error),
    /// if it cannot; its curves are then missing.
    pub datapath_unavailable: Option<String>,
    /// Per exponent (ascending), the curves of each path in [`FurnacePath::ALL`] order.
    pub curves: Vec<Curve>,
}

/// The furnace of a configuration: every form, exponent and path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FurnaceReport {
    /// The configuration's name.
    pub config: String,
    /// Its variant (`plain` or `minimax`).
    pub variant: String,
    /// Its number of squarings k (m = 2^k).
    pub k: u32,
    /// m = 2^k.
    pub m: u32,
    /// Its cutoff.
    pub cutoff: Cutoff,
    /// The coefficient source of the datapath path.
    pub datapath_coef_source: CoefSource,
    /// The input format.
    pub c_format: String,
    /// The output format.
    pub out_format: String,
    /// The exponents.
    pub ns: Vec<u32>,
    /// The incident angles in degrees.
    pub angles_deg: Vec<f64>,
    /// See [`FLAG_TOLERANCE`].
    pub flag_tolerance: f64,
    /// The six forms, in [`Form::ALL`] order.
    pub forms: Vec<FormFurnace>,
}

fn curve(
    n: u32,
    path: FurnacePath,
    coef: f64,
    angles_deg: &[f64],
    rho_at: impl Fn(f64) -> f64,
) -> Curve {
    let rho: Vec<f64> = angles_deg.iter().map(|a| rho_at(a.to_radians())).collect();
    let rho_normal = match angles_deg.iter().position(|&a| a == 0.0) {
        Some(i) => rho[i],
        None => rho_at(0.0),
    };
    // The first angle within round-off of the largest value: a plateau (a lobe wholly
    // visible) reports where it starts, not where round-off happens to peak.
    let max = rho.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let max_i = rho
        .iter()
        .position(|&v| v >= max - MAX_TIE * max.abs().max(1.0))
        .unwrap_or(0);
    let flagged_angles_deg = angles_deg
        .iter()
        .zip(&rho)
        .filter(|&(_, &v)| v > 1.0 + FLAG_TOLERANCE)
        .map(|(&a, _)| a)
        .collect();
    Curve {
        n,
        path,
        coef,
        rho_normal,
        max: rho[max_i],
        max_angle_deg: angles_deg[max_i],
        flagged_angles_deg,
        rho,
    }
}

/// The x of (0, 1) where the configuration's f64 lobe has a kink or a jump: where its base
/// reaches zero, and the paper cutoff's angle.
fn lobe_breaks(dp: &Datapath, nc: &NConstants) -> Vec<f64> {
    let mut v = Vec::new();
    if nc.slope != 0.0 {
        v.push(1.0 - nc.offset / nc.slope);
    }
    if dp.config().cutoff == Cutoff::Paper {
        v.push(paper_cutoff_cosine(f64::from(nc.n)));
    }
    v.retain(|&x| x > 0.0 && x < 1.0);
    v
}

/// The curves of one form and exponent, every path in order.
fn curves_of(
    dp: &Datapath,
    dp_form: Option<&Datapath>,
    form: Form,
    n: u32,
    angles_deg: &[f64],
) -> Vec<Curve> {
    let nf = f64::from(n);
    let k = dp.config().k;
    let nc = dp
        .constants_for(n)
        .expect("settings hold exponents of the set");
    let mut curves = Vec::with_capacity(4);

    let classic = classic_coefficient(form, nf);
    // cos^n has no cutoff; its scale points help the quadrature find a narrow peak.
    let scale: Vec<f64> = [1.0 - 1.0 / nf, 1.0 - 10.0 / nf]
        .into_iter()
        .filter(|&x| x > 0.0 && x < 1.0)
        .collect();
    curves.push(curve(n, FurnacePath::F64CosN, classic, angles_deg, |t| {
        reflectance(form, t, |x| classic * cos_pow(x, nf), &scale)
    }));

    let paper_cut = paper_cutoff_cosine(nf);
    let is_paper = dp.config().cutoff == Cutoff::Paper;
    let lobe = |x: f64| {
        let below = is_paper && x < paper_cut;
        F64Walk::new(dp, nc, x, below, 0).run().0
    };
    let breaks = lobe_breaks(dp, nc);
    for (path, source) in [
        (FurnacePath::F64CsMPaper, CoefSource::Paper),
        (FurnacePath::F64CsMExact, CoefSource::Exact),
    ] {
        let coef = coefficient(form, source, nf, k);
        curves.push(curve(n, path, coef, angles_deg, |t| {
            reflectance(form, t, |x| coef * lobe(x), &breaks)
        }));
    }

    if let Some(dpf) = dp_form {
        let ncf = dpf
            .constants_for(n)
            .expect("the form's datapath holds every n");
        let steps = datapath_steps(dpf, ncf);
        let coef = dpf.config().coef.format.to_f64(ncf.coef_raw);
        curves.push(curve(n, FurnacePath::Datapath, coef, angles_deg, |t| {
            reflectance_of_steps(form, t, &steps)
        }));
    }
    curves
}

/// Runs the furnace of `dp`'s configuration: every form, every exponent and angle of
/// `settings`, the four paths. The datapath path of a form uses the configuration with
/// `coef.form` replaced by the form and the n set by the settings' exponents; when that
/// configuration does not validate, the form records the error and has no datapath curves.
pub fn furnace(dp: &Datapath, settings: &FurnaceSettings) -> FurnaceReport {
    furnace_with_progress(dp, settings, &|_, _| {})
}

/// [`furnace`], calling `progress(done, total)` as each (form, exponent) pair of the `total`
/// finishes (from the worker threads, in any order; the report is the same).
pub fn furnace_with_progress(
    dp: &Datapath,
    settings: &FurnaceSettings,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> FurnaceReport {
    let cfg = dp.config();
    let ns_set = NSet::from_values(&settings.ns).expect("validated exponents form a set");
    let form_datapaths: Vec<Result<Datapath, String>> = Form::ALL
        .iter()
        .map(|&form| {
            let mut c = cfg.clone();
            c.coef.form = form;
            c.n = ns_set.clone();
            Datapath::new(c).map_err(|e| e.to_string())
        })
        .collect();
    let tasks: Vec<(usize, u32)> = (0..Form::ALL.len())
        .flat_map(|fi| settings.ns.iter().map(move |&n| (fi, n)))
        .collect();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<Vec<Curve>> = tasks
        .par_iter()
        .map(|&(fi, n)| {
            let curves = curves_of(
                dp,
                form_datapaths[fi].as_ref().ok(),
                Form::ALL[fi],
                n,
                &settings.angles_deg,
            );
            let now = done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(now, tasks.len());
            curves
        })
        .collect();
    let mut forms: Vec<FormFurnace> = Form::ALL
        .iter()
        .zip(&form_datapaths)
        .map(|(&form, d)| FormFurnace {
            form,
            datapath_unavailable: d.as_ref().err().cloned(),
            curves: Vec::new(),
        })
        .collect();
    for ((fi, _), curves) in tasks.into_iter().zip(results) {
        forms[fi].curves.extend(curves);
    }
    FurnaceReport {
        config: cfg.name.clone(),
        variant: cfg.variant.name().to_string(),
        k: cfg.k,
        m: m_of_k(cfg.k),
        cutoff: cfg.cutoff,
        datapath_coef_source: cfg.coef.source,
        c_format: cfg.c.format.to_string(),
        out_format: cfg.out.format.to_string(),
        ns: settings.ns.clone(),
        angles_deg: settings.angles_deg.clone(),
        flag_tolerance: FLAG_TOLERANCE,
        forms,
    }
}

/// The largest reflectance of a form: where it is and what it is.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Worst {
    /// The exponent.
    pub n: u32,
    /// The path.
    pub path: FurnacePath,
    /// The incident angle in degrees.
    pub theta_deg: f64,
    /// The reflectance.
    pub rho: f64,
}

/// How far one path's rho(0) is from 1 over the exponents: the largest `|rho(0) - 1|`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Deviation {
    /// The path.
    pub path: FurnacePath,
    /// The coefficient source of the path.
    pub coef_source: CoefSource,
    /// The largest `|rho(0) - 1|` over the exponents.
    pub max_abs: f64,
    /// rho(0) where it is reached.
    pub rho_normal: f64,
    /// The exponent where it is reached (the first, ascending).
    pub n: u32,
}

/// The summary of one form.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FormSummary {
    /// The form.
    pub form: Form,
    /// The largest reflectance over exponents, paths and angles.
    pub worst: Option<Worst>,
    /// Curves with at least one flagged angle.
    pub n_flagged_curves: usize,
    /// Flagged (exponent, path, angle) values.
    pub n_flagged_values: usize,
    /// Per path, how far rho(0) is from 1.
    pub deviations: Vec<Deviation>,
    /// See [`FormFurnace::datapath_unavailable`].
    pub datapath_unavailable: Option<String>,
}

impl FurnaceReport {
    /// The coefficient source of a path.
    pub fn coef_source(&self, path: FurnacePath) -> CoefSource {
        match path {
            FurnacePath::F64CosN => CoefSource::Classic,
            FurnacePath::F64CsMPaper => CoefSource::Paper,
            FurnacePath::F64CsMExact => CoefSource::Exact,
            FurnacePath::Datapath => self.datapath_coef_source,
        }
    }

    /// One summary per form, in report order.
    pub fn summary(&self) -> Vec<FormSummary> {
        self.forms
            .iter()
            .map(|f| {
                let mut worst: Option<Worst> = None;
                for c in &f.curves {
                    let better =
                        worst.is_none_or(|w| c.max > w.rho + MAX_TIE * w.rho.abs().max(1.0));
                    if better {
                        worst = Some(Worst {
                            n: c.n,
                            path: c.path,
                            theta_deg: c.max_angle_deg,
                            rho: c.max,
                        });
                    }
                }
                let deviations = FurnacePath::ALL
                    .iter()
                    .filter_map(|&path| {
                        let mut best: Option<Deviation> = None;
                        for c in f.curves.iter().filter(|c| c.path == path) {
                            let d = (c.rho_normal - 1.0).abs();
                            if best.is_none_or(|b| d > b.max_abs + MAX_TIE) {
                                best = Some(Deviation {
                                    path,
                                    coef_source: self.coef_source(path),
                                    max_abs: d,
                                    rho_normal: c.rho_normal,
                                    n: c.n,
                                });
                            }
                        }
                        best
                    })
                    .collect();
                FormSummary {
                    form: f.form,
                    worst,
                    n_flagged_curves: f
                        .curves
                        .iter()
                        .filter(|c| !c.flagged_angles_deg.is_empty())
                        .count(),
                    n_flagged_values: f.curves.iter().map(|c| c.flagged_angles_deg.len()).sum(),
                    deviations,
                    datapath_unavailable: f.datapath_unavailable.clone(),
                }
            })
            .collect()
    }
}

/// What determines a furnace, for its provenance: the datapath, the exponents and the angles.
pub fn inputs(dp: &Datapath, settings: &FurnaceSettings) -> crate::provenance::Inputs {
    crate::provenance::Inputs::new("furnace")
        .config(dp.config())
        .option("n", settings.ns().to_vec())
        .option("angles", settings.angles_deg().to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_at_normal_incidence_are_the_paper_integrands_times_two_pi() {
        // Hand values: Phong 2 pi, modified 2 pi x; Blinn 8 pi x and 2 pi (8 x^3 - 4 x) above
        // 1/sqrt(2); NDF 2 pi x above 1/sqrt(2).
        for x in [0.2, 0.5, 0.75, 0.9, 1.0] {
            let above = x > std::f64::consts::FRAC_1_SQRT_2;
            let tp = 2.0 * PI;
            let cases = [
                (Form::Phong, tp),
                (Form::PhongModified, tp * x),
                (Form::BlinnPhong, if above { 4.0 * tp * x } else { 0.0 }),
                (
                    Form::BlinnPhongModified,
                    if above {
                        tp * (8.0 * x * x * x - 4.0 * x)
                    } else {
                        0.0
                    },
                ),
                (Form::BlinnPhongNdf, if above { tp * x } else { 0.0 }),
                (
                    Form::BlinnPhongHeightfield,
                    if above { tp * x } else { 0.0 },
                ),
            ];
            for (form, want) in cases {
                let got = kernel(form, x, 0.0);
                assert!((got - want).abs() < 1e-13, "{form} x={x}: {got} vs {want}");
            }
        }
    }

    #[test]
    fn progress_counts_every_form_and_exponent_once() {
        // 6 forms x 2 exponents = 12 pairs, each reported once, the last at 12 of 12.
        let dp = Datapath::new(crate::pipeline::Config::baseline()).unwrap();
        let settings =
            FurnaceSettings::new(&dp, Some(&"16,64".parse().unwrap()), vec![0.0]).unwrap();
        let seen = std::sync::Mutex::new(Vec::new());
        let report = furnace_with_progress(&dp, &settings, &|done, total| {
            seen.lock().unwrap().push((done, total));
        });
        let mut seen = seen.into_inner().unwrap();
        seen.sort();
        let want: Vec<(usize, usize)> = (1..=12).map(|d| (d, 12)).collect();
        assert_eq!(seen, want);
        assert_eq!(report.forms.len(), 6);
    }

    #[test]
    fn angles_parse_lists_and_ranges_and_refuse_the_rest() {
        assert_eq!(
            parse_angles("0..=10:5,7").unwrap(),
            vec![0.0, 5.0, 7.0, 10.0]
        );
        assert_eq!(parse_angles("0..0.3:0.1").unwrap().len(), 4);
        for bad in [
            "",
            "a",
            "0..10",
            "0..10:0",
            "10..0:1",
            "-1",
            "90",
            "nan",
            "0..89:0.01",
        ] {
            let e = parse_angles(bad).unwrap_err().to_string();
            assert!(
                e.starts_with("angles must be degrees in [0, 90)"),
                "{bad}: {e}"
            );
        }
    }
}
