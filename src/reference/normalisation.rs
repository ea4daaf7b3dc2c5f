//! Energy-conserving normalisation: the six forms of the paper's Table 1 and their coefficients.
//!
//! A form is a lobe L (cos^n or cs_m) weighted over the hemisphere; its coefficient coef(n) is
//! defined by `2 pi coef(n) Int(n) = 1`. Three sources of coefficient exist: `classic` (exact for
//! cos^n), `paper` (Table 1 as printed, for cs16) and `exact` (closed form for cs_m, derived in
//! `docs/normalisation.md`). [`hemisphere_integral`] computes Int(n) by adaptive quadrature of the
//! original theta integral and is the independent check of the closed forms.

use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_2, PI};

use serde::{Deserialize, Serialize};

use crate::reference::lobe::{m_of_k, PAPER_CUTOFF_CONSTANT};
use crate::reference::quadrature::integrate;

/// The six normalisation forms of the paper's Table 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Form {
    /// Phong RDF: L(cos theta) sin theta.
    Phong,
    /// Modified Phong: L(cos theta) cos theta sin theta.
    PhongModified,
    /// Blinn-Phong RDF: L(cos(theta/2)) sin theta.
    BlinnPhong,
    /// Modified Blinn-Phong: L(cos(theta/2)) cos theta sin theta.
    BlinnPhongModified,
    /// Blinn-Phong NDF: L(cos alpha) sin alpha (the same integral as Phong).
    BlinnPhongNdf,
    /// Blinn-Phong heightfield: L(cos alpha) cos alpha sin alpha (the same as modified Phong).
    BlinnPhongHeightfield,
}

impl Form {
    /// Every form, in the order of the paper's Table 1.
    pub const ALL: [Form; 6] = [
        Form::Phong,
        Form::PhongModified,
        Form::BlinnPhong,
        Form::BlinnPhongModified,
        Form::BlinnPhongNdf,
        Form::BlinnPhongHeightfield,
    ];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Form::Phong => "phong",
            Form::PhongModified => "phong_modified",
            Form::BlinnPhong => "blinn_phong",
            Form::BlinnPhongModified => "blinn_phong_modified",
            Form::BlinnPhongNdf => "blinn_phong_ndf",
            Form::BlinnPhongHeightfield => "blinn_phong_heightfield",
        }
    }

    /// Whether the lobe is evaluated at the half angle theta/2 (the Blinn RDF forms).
    pub fn half_angle(self) -> bool {
        matches!(self, Form::BlinnPhong | Form::BlinnPhongModified)
    }

    /// Whether the integrand carries the extra cos theta (the "modified" forms).
    pub fn cosine_weighted(self) -> bool {
        matches!(
            self,
            Form::PhongModified | Form::BlinnPhongModified | Form::BlinnPhongHeightfield
        )
    }

    /// The denominator constant K of the paper's fit `(a n + b)/(K pi)`: 2 for the Phong
    /// forms, 8 for the Blinn-Phong RDF forms.
    pub fn fit_denominator(self) -> f64 {
        if self.half_angle() {
            8.0
        } else {
            2.0
        }
    }
}

crate::names::named_enum!(
    Form,
    "form",
    "phong, phong_modified, blinn_phong, blinn_phong_modified, blinn_phong_ndf or blinn_phong_heightfield"
);

/// Where a coefficient comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CoefSource {
    /// Exact for cos^n (the Blinn-Phong forms in their exact 2^(-n/2) form).
    Classic,
    /// Table 1 of the paper as printed (fitted for cs16; the same formula for every m).
    Paper,
    /// The exact closed form for cs_m with the clamp cutoff, every m and every n >= 1.
    Exact,
}

impl CoefSource {
    /// Every source.
    pub const ALL: [CoefSource; 3] = [CoefSource::Classic, CoefSource::Paper, CoefSource::Exact];

    /// The name used on the command line and in reports.
    pub fn name(self) -> &'static str {
        match self {
            CoefSource::Classic => "classic",
            CoefSource::Paper => "paper",
            CoefSource::Exact => "exact",
        }
    }
}

crate::names::named_enum!(CoefSource, "coefficient source", "classic, paper or exact");

/// coef(n) for a form and source; `k` (m = 2^k) matters only for [`CoefSource::Exact`].
///
/// # Examples
/// ```
/// use specfx::reference::normalisation::{coefficient, CoefSource, Form};
/// use std::f64::consts::PI;
/// let n = 64.0;
/// assert_eq!(coefficient(Form::Phong, CoefSource::Classic, n, 4), 65.0 / (2.0 * PI));
/// // For n >= m the exact Phong coefficient is (m + 1)/m * n/(2 pi) = 17 n / (32 pi).
/// let exact = coefficient(Form::Phong, CoefSource::Exact, n, 4);
/// assert!((exact / (17.0 * n / (32.0 * PI)) - 1.0).abs() < 1e-14);
/// ```
pub fn coefficient(form: Form, source: CoefSource, n: f64, k: u32) -> f64 {
    match source {
        CoefSource::Classic => classic_coefficient(form, n),
        CoefSource::Paper => paper_coefficient(form, n),
        CoefSource::Exact => 1.0 / (2.0 * PI * exact_integral(form, n, k)),
    }
}

/// The exact coefficient of cos^n for each form.
pub fn classic_coefficient(form: Form, n: f64) -> f64 {
    let s = (-n / 2.0).exp2();
    match form {
        Form::Phong | Form::BlinnPhongNdf => (n + 1.0) / (2.0 * PI),
        Form::PhongModified | Form::BlinnPhongHeightfield => (n + 2.0) / (2.0 * PI),
        Form::BlinnPhong => (n + 2.0) / (4.0 * PI * (2.0 - s)),
        // The paper's Table 1 prints 4 pi here, which contradicts its own bounds
        // (n+6)/(8 pi) < coef < (n+8)/(8 pi); 8 pi is the value of the integral.
        Form::BlinnPhongModified => (n + 2.0) * (n + 4.0) / (8.0 * PI * (n + s)),
    }
}

/// The paper's Table 1 coefficients for cs16, as printed.
pub fn paper_coefficient(form: Form, n: f64) -> f64 {
    match form {
        Form::Phong | Form::BlinnPhongNdf => 1.063 * n / (2.0 * PI),
        Form::PhongModified | Form::BlinnPhongHeightfield => (1.063 * n + 1.0) / (2.0 * PI),
        Form::BlinnPhong => (1.068 * n + 0.96) / (8.0 * PI),
        Form::BlinnPhongModified => (1.027 * n + 4.8) / (8.0 * PI),
    }
}

/// `1 - x^p` for x in [0, 1], accurate when x is close to 1.
fn one_minus_pow(x: f64, p: f64) -> f64 {
    if x <= 0.0 {
        1.0
    } else {
        -(p * x.ln()).exp_m1()
    }
}

/// `M_j = ∫_lo^1 c^j max(0, r (c - 1) + 1)^m dc` in closed form, as a sum of non-negative
/// terms (see `docs/normalisation.md`).
fn moment(j: u32, lo: f64, n: f64, m: u32) -> f64 {
    let r = n / f64::from(m);
    let mf = f64::from(m);
    if r >= 1.0 {
        // c = alpha + beta v with v the base, alpha = 1 - 1/r, beta = 1/r, dc = dv / r.
        let alpha = 1.0 - 1.0 / r;
        let beta = 1.0 / r;
        let v_lo = (r * (lo - 1.0) + 1.0).max(0.0);
        let mut binom = 1.0;
        let mut sum = 0.0;
        for i in 0..=j {
            let p = mf + f64::from(i) + 1.0;
            sum +=
                binom * alpha.powi((j - i) as i32) * beta.powi(i as i32) * one_minus_pow(v_lo, p)
                    / p;
            binom = binom * f64::from(j - i) / f64::from(i + 1);
        }
        sum / r
    } else {
        // base = b0 + r c with b0 = 1 - r in (0, 1): expand the m-th power in c.
        let b0 = 1.0 - r;
        let mut binom = 1.0;
        let mut sum = 0.0;
        for i in 0..=m {
            let p = f64::from(i + j) + 1.0;
            sum += binom * b0.powi((m - i) as i32) * r.powi(i as i32) * one_minus_pow(lo, p) / p;
            binom = binom * f64::from(m - i) / f64::from(i + 1);
        }
        sum
    }
}

/// Int(n) of a form for cs_m with the clamp cutoff, in closed form, over the whole hemisphere
/// (the lobe truncated by it where theta_cr exceeds pi/2).
///
/// # Examples
/// ```
/// use specfx::reference::normalisation::{exact_integral, Form};
/// // Phong, n >= m: Int = m / (n (m + 1)).
/// let int = exact_integral(Form::Phong, 100.0, 4);
/// assert!((int - 16.0 / (100.0 * 17.0)).abs() < 1e-16);
/// ```
pub fn exact_integral(form: Form, n: f64, k: u32) -> f64 {
    let m = m_of_k(k);
    match form {
        Form::Phong | Form::BlinnPhongNdf => moment(0, 0.0, n, m),
        Form::PhongModified | Form::BlinnPhongHeightfield => moment(1, 0.0, n, m),
        Form::BlinnPhong => 4.0 * moment(1, FRAC_1_SQRT_2, n, m),
        Form::BlinnPhongModified => {
            8.0 * moment(3, FRAC_1_SQRT_2, n, m) - 4.0 * moment(1, FRAC_1_SQRT_2, n, m)
        }
    }
}

/// Int(n) of a form for any lobe `lobe(c)`, by adaptive quadrature of the theta integral
/// `∫_0^upper lobe(cos(theta')) w(theta) sin(theta) dtheta` with theta' = theta/2 for the
/// half-angle forms and w = cos theta for the modified forms.
///
/// `lobe_breaks` are the angles theta' where the lobe has a kink or a jump (its cutoff); they
/// become quadrature breakpoints. The relative tolerance is 1e-13.
///
/// # Examples
/// ```
/// use specfx::reference::normalisation::{hemisphere_integral, Form};
/// use std::f64::consts::FRAC_PI_2;
/// let int = hemisphere_integral(Form::Phong, |c| c.powi(10), FRAC_PI_2, &[]);
/// assert!((int - 1.0 / 11.0).abs() < 1e-14);
/// ```
pub fn hemisphere_integral(
    form: Form,
    lobe: impl Fn(f64) -> f64,
    upper: f64,
    lobe_breaks: &[f64],
) -> f64 {
    let half = form.half_angle();
    let weighted = form.cosine_weighted();
    let integrand = |theta: f64| {
        let arg = if half { 0.5 * theta } else { theta };
        let w = if weighted { theta.cos() } else { 1.0 };
        lobe(arg.cos()) * w * theta.sin()
    };
    let breaks: Vec<f64> = lobe_breaks
        .iter()
        .map(|&t| if half { 2.0 * t } else { t })
        .collect();
    integrate(integrand, 0.0, upper, &breaks, 1e-300, 1e-13).value
}

/// The upper limit of the theta integral under each reading of the paper's text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PaperReading {
    /// The text as written: theta from 0 to theta_cr(n) = 6/sqrt(n) for every form, which
    /// truncates the half-angle lobes (they extend to theta = 12/sqrt(n)).
    ThetaCr,
    /// Up to where the lobe itself stops: theta' = theta/2 <= 6/sqrt(n) for the half-angle
    /// forms, theta <= 6/sqrt(n) for the others.
    LobeSupport,
}

impl PaperReading {
    /// Both readings.
    pub const ALL: [PaperReading; 2] = [PaperReading::ThetaCr, PaperReading::LobeSupport];

    /// The name used in reports.
    pub fn name(self) -> &'static str {
        match self {
            PaperReading::ThetaCr => "theta_cr",
            PaperReading::LobeSupport => "lobe_support",
        }
    }

    /// The upper limit of theta for a form and exponent.
    pub fn upper_limit(self, form: Form, n: f64) -> f64 {
        let cut = PAPER_CUTOFF_CONSTANT / n.sqrt();
        let upper = match self {
            PaperReading::ThetaCr => cut,
            PaperReading::LobeSupport if form.half_angle() => 2.0 * cut,
            PaperReading::LobeSupport => cut,
        };
        upper.min(FRAC_PI_2)
    }
}

/// Int(n) of cs16 as the paper computes it: the lobe `base^16` (paper cutoff, so the base
/// may be slightly negative before 6/sqrt(n)), integrated up to the reading's upper limit.
pub fn paper_integral(form: Form, n: f64, reading: PaperReading) -> f64 {
    let k = 4;
    let m = f64::from(m_of_k(k));
    let lobe = |c: f64| crate::reference::lobe::pow_2k((n / m) * (c - 1.0) + 1.0, k);
    hemisphere_integral(form, lobe, reading.upper_limit(form, n), &[])
}

/// Int(n) of cs_m with the clamp cutoff over the whole hemisphere, by quadrature: the
/// independent check of [`exact_integral`].
pub fn clamp_integral_by_quadrature(form: Form, n: f64, k: u32) -> f64 {
    let lobe =
        |c: f64| crate::reference::lobe::cs_m(c, n, k, crate::reference::lobe::Cutoff::Clamp);
    let theta_cr = crate::reference::lobe::theta_cr(n, k);
    hemisphere_integral(form, lobe, FRAC_PI_2, &[theta_cr])
}

/// The normalisation residual `|2 pi coef Int - 1|`.
pub fn residual(coef: f64, integral: f64) -> f64 {
    (2.0 * PI * coef * integral - 1.0).abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classic_coefficients_normalise_cos_pow_by_quadrature() {
        for form in Form::ALL {
            for n in [1.0, 2.0, 7.0, 16.0, 100.0, 1000.0] {
                let int = hemisphere_integral(form, |c| c.powf(n), FRAC_PI_2, &[]);
                let res = residual(classic_coefficient(form, n), int);
                assert!(res < 1e-11, "{form} n={n}: res {res}");
            }
        }
    }

    #[test]
    fn phong_exact_is_seventeen_sixteenths_for_n_at_least_m() {
        // Hand derivation: ∫_0^1 max(0, r(c-1)+1)^16 dc = 1/(17 r) = 16/(17 n).
        for n in [16.0, 17.0, 500.0, 1024.0] {
            let coef = coefficient(Form::Phong, CoefSource::Exact, n, 4);
            assert!((coef * 2.0 * PI / n - 17.0 / 16.0).abs() < 1e-14);
        }
    }

    #[test]
    fn phong_exact_below_m_is_the_full_polynomial_integral() {
        // n = 8, m = 16: base = (1 + c)/2, ∫_0^1 ((1+c)/2)^16 dc = 2 (1 - 2^-17)/17.
        let int = exact_integral(Form::Phong, 8.0, 4);
        let want = 2.0 * (1.0 - 2f64.powi(-17)) / 17.0;
        assert!((int - want).abs() < 1e-16, "{int} vs {want}");
    }

    #[test]
    fn closed_forms_match_quadrature_including_truncation() {
        for form in Form::ALL {
            for k in [1, 4, 7] {
                for n in [1.0, 2.0, 3.0, 15.0, 16.0, 54.0, 55.0, 300.0, 437.0, 4096.0] {
                    let closed = exact_integral(form, n, k);
                    let quad = clamp_integral_by_quadrature(form, n, k);
                    assert!(
                        ((closed - quad) / quad).abs() < 1e-11,
                        "{form} k={k} n={n}: {closed} vs {quad}"
                    );
                }
            }
        }
    }

    #[test]
    fn names_round_trip_and_errors_are_clear() {
        for f in Form::ALL {
            assert_eq!(f.name().parse::<Form>().unwrap(), f);
        }
        for s in CoefSource::ALL {
            assert_eq!(s.name().parse::<CoefSource>().unwrap(), s);
        }
        let e = "fancy".parse::<CoefSource>().unwrap_err().to_string();
        assert_eq!(
            e,
            "unknown coefficient source 'fancy': expected classic, paper or exact"
        );
    }
}
