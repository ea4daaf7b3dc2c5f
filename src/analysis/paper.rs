//! Reproduction of every number the paper prints, claim by claim.
//!
//! The printed claims (the only numbers typed in here) are compared with values computed from
//! the reference models: the extremes of Delta(theta, n) = cos^n(theta) - cs16(theta, n) and,
//! for each normalisation form, the maximum of res(n) = |2 pi coef(n) Int(n) - 1| with the
//! paper's coefficient, with a least-squares refit and with the exact closed form.

use serde::Serialize;

use crate::reference::lobe::{cos_pow, cs_m, theta_cr, Cutoff};
use crate::reference::normalisation::{
    clamp_integral_by_quadrature, classic_coefficient, coefficient, paper_coefficient,
    paper_integral, residual, CoefSource, Form, PaperReading,
};

/// The paper's printed max of Delta over n = 16..1024, theta in [0, 1.5].
pub const CLAIM_DELTA_MAX: f64 = 1.7e-2;
/// The paper's printed min of Delta.
pub const CLAIM_DELTA_MIN: f64 = -9.7e-3;
/// The largest theta of the paper's Delta figure (20 theta in [0, 30]).
pub const DELTA_THETA_MAX: f64 = 1.5;
/// The paper's range of n.
pub const PAPER_N: std::ops::RangeInclusive<u32> = 16..=1024;

/// The paper's printed max of res(n) for a form (NDF "as Phong", heightfield "as modified
/// Phong", as the text says).
pub fn claim_res_max(form: Form) -> f64 {
    match form {
        Form::Phong | Form::BlinnPhongNdf => 4.7e-4,
        Form::PhongModified | Form::BlinnPhongHeightfield => 1.3e-3,
        Form::BlinnPhong => 1.5e-3,
        Form::BlinnPhongModified => 9.5e-3,
    }
}

/// Whether a computed value agrees with a printed one to 2 significant digits: both rounded
/// to 2 significant digits are equal.
///
/// # Examples
/// ```
/// use specfx::analysis::paper::agrees_to_two_digits;
/// assert!(agrees_to_two_digits(0.017012, 1.7e-2));
/// assert!(!agrees_to_two_digits(0.0176, 1.7e-2));
/// assert!(!agrees_to_two_digits(-1e-15, -9.7e-3));
/// ```
pub fn agrees_to_two_digits(computed: f64, claim: f64) -> bool {
    format!("{computed:.1e}") == format!("{claim:.1e}")
}

/// Where an extreme of Delta is reached.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Extreme {
    /// The value of Delta.
    pub value: f64,
    /// The exponent n.
    pub n: u32,
    /// The angle theta in radians.
    pub theta: f64,
}

/// The Delta claims.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DeltaClaims {
    /// Computed max of Delta with the paper's cutoff 6/sqrt(n).
    pub max: f64,
    /// Computed min of Delta with the paper's cutoff.
    pub min: f64,
    /// Printed max.
    pub claim_max: f64,
    /// Printed min.
    pub claim_min: f64,
    /// Whether the max reproduces to 2 significant digits.
    pub reproduced_max: bool,
    /// Whether the min reproduces to 2 significant digits.
    pub reproduced_min: bool,
    /// Where the max is reached.
    pub argmax: Extreme,
    /// Where the min is reached.
    pub argmin: Extreme,
    /// The max with the exact cutoff (clamp) instead of 6/sqrt(n).
    pub clamp_max: f64,
    /// The min with the exact cutoff.
    pub clamp_min: f64,
}

/// The least-squares refit `coef(n) = (a n + b)/(K pi)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Refit {
    /// Slope.
    pub a: f64,
    /// Offset.
    pub b: f64,
}

/// One reading of the paper's integral for one form.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReadingResult {
    /// `theta_cr` or `lobe_support`.
    pub reading: &'static str,
    /// max over n of res(n) with the paper's coefficient under this reading.
    pub paper_res_max: f64,
    /// The n where it is reached.
    pub paper_res_argmax_n: u32,
    /// Whether it agrees with the claim to 2 significant digits.
    pub reproduced: bool,
    /// The least-squares refit under this reading.
    pub refit: Refit,
    /// max over n of res(n) with the refit coefficient under this reading.
    pub refit_res_max: f64,
}

/// The results for one form.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FormResult {
    /// The form's name.
    pub form: &'static str,
    /// The printed max res.
    pub claim_res_max: f64,
    /// The computed max res with the paper's coefficient, under the reading used.
    pub paper_res_max: f64,
    /// The reading used for `paper_res_max`: the first that reproduces, else `theta_cr`.
    pub reading: &'static str,
    /// Whether `paper_res_max` agrees with the claim.
    pub reproduced: bool,
    /// The refit under the reading used.
    pub refit: Refit,
    /// max res of the refit under the reading used.
    pub refit_res_max: f64,
    /// max over n of res(n) for the exact coefficient against the quadrature of the clamped
    /// cs16 lobe over the whole hemisphere.
    pub exact_res_max: f64,
    /// The same for the classic coefficient of cos^n applied to cs16.
    pub classic_res_max: f64,
    /// Both readings in full.
    pub readings: Vec<ReadingResult>,
}

/// The whole reproduction.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PaperReproduction {
    /// The Delta claims.
    pub delta: DeltaClaims,
    /// One entry per form, in Table 1 order.
    pub forms: Vec<FormResult>,
    /// The smallest n considered.
    pub n_min: u32,
    /// The largest n considered.
    pub n_max: u32,
}

/// Delta(theta, n) with a cutoff rule.
fn delta(theta: f64, n: u32, cutoff: Cutoff) -> f64 {
    let c = theta.cos();
    let n = f64::from(n);
    cos_pow(c, n) - cs_m(c, n, 4, cutoff)
}

/// The extremes of Delta over theta in [0, 1.5] for one n: a grid of 3001 angles, then each
/// extreme refined by golden section between its grid neighbours (and the lobe's cut points
/// added to the grid, where Delta may jump).
fn delta_extremes(n: u32, cutoff: Cutoff) -> (Extreme, Extreme) {
    const N_GRID: usize = 3000;
    let step = DELTA_THETA_MAX / N_GRID as f64;
    let mut thetas: Vec<f64> = (0..=N_GRID).map(|i| step * i as f64).collect();
    for t in [theta_cr(f64::from(n), 4), 6.0 / f64::from(n).sqrt()] {
        if t < DELTA_THETA_MAX {
            thetas.extend([t, t.next_down(), t.next_up()]);
        }
    }
    let vals: Vec<f64> = thetas.iter().map(|&t| delta(t, n, cutoff)).collect();
    let pick = |sign: f64| {
        let i = (0..vals.len())
            .max_by(|&x, &y| (sign * vals[x]).total_cmp(&(sign * vals[y])))
            .expect("non-empty grid");
        let mut best = (thetas[i], vals[i]);
        if i <= N_GRID {
            let lo = (thetas[i] - step).max(0.0);
            let hi = (thetas[i] + step).min(DELTA_THETA_MAX);
            let (t, v) = golden_extreme(|t| sign * delta(t, n, cutoff), lo, hi);
            if v > sign * best.1 {
                best = (t, sign * v);
            }
        }
        Extreme {
            value: best.1,
            n,
            theta: best.0,
        }
    };
    (pick(1.0), pick(-1.0))
}

/// Maximises `f` on [lo, hi] by golden section.
fn golden_extreme(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    const INV_PHI: f64 = 0.618_033_988_749_894_8;
    for _ in 0..80 {
        let x1 = hi - INV_PHI * (hi - lo);
        let x2 = lo + INV_PHI * (hi - lo);
        if f(x1) < f(x2) {
            lo = x1;
        } else {
            hi = x2;
        }
    }
    let t = 0.5 * (lo + hi);
    (t, f(t))
}

/// The Delta claims over the paper's n range.
pub fn delta_claims() -> DeltaClaims {
    let over_n = |cutoff: Cutoff| {
        let mut max = Extreme {
            value: f64::NEG_INFINITY,
            n: 0,
            theta: 0.0,
        };
        let mut min = Extreme {
            value: f64::INFINITY,
            n: 0,
            theta: 0.0,
        };
        for n in PAPER_N {
            let (hi, lo) = delta_extremes(n, cutoff);
            if hi.value > max.value {
                max = hi;
            }
            if lo.value < min.value {
                min = lo;
            }
        }
        (max, min)
    };
    let (max, min) = over_n(Cutoff::Paper);
    let (clamp_max, clamp_min) = over_n(Cutoff::Clamp);
    DeltaClaims {
        max: max.value,
        min: min.value,
        claim_max: CLAIM_DELTA_MAX,
        claim_min: CLAIM_DELTA_MIN,
        reproduced_max: agrees_to_two_digits(max.value, CLAIM_DELTA_MAX),
        reproduced_min: agrees_to_two_digits(min.value, CLAIM_DELTA_MIN),
        argmax: max,
        argmin: min,
        clamp_max: clamp_max.value,
        clamp_min: clamp_min.value,
    }
}

/// Ordinary least squares of `y = a x + b`.
///
/// # Examples
/// ```
/// use specfx::analysis::paper::least_squares_line;
/// let (a, b) = least_squares_line(&[1.0, 2.0, 3.0], &[3.0, 5.0, 7.0]);
/// assert!((a - 2.0).abs() < 1e-12 && (b - 1.0).abs() < 1e-12);
/// ```
pub fn least_squares_line(x: &[f64], y: &[f64]) -> (f64, f64) {
    let len = x.len() as f64;
    let mx = x.iter().sum::<f64>() / len;
    let my = y.iter().sum::<f64>() / len;
    let sxy: f64 = x.iter().zip(y).map(|(xi, yi)| (xi - mx) * (yi - my)).sum();
    let sxx: f64 = x.iter().map(|xi| (xi - mx) * (xi - mx)).sum();
    let a = sxy / sxx;
    (a, my - a * mx)
}

/// Max of `res` over the n range, and where.
fn max_res(ns: &[u32], res: impl Fn(usize) -> f64) -> (f64, u32) {
    ns.iter()
        .enumerate()
        .map(|(i, &n)| (res(i), n))
        .fold((f64::NEG_INFINITY, 0), |a, b| if b.0 > a.0 { b } else { a })
}

/// The reproduction of one form's claims.
pub fn form_result(form: Form) -> FormResult {
    let ns: Vec<u32> = PAPER_N.collect();
    let nf: Vec<f64> = ns.iter().map(|&n| f64::from(n)).collect();
    let kk = form.fit_denominator();
    let claim = claim_res_max(form);
    let readings: Vec<ReadingResult> = PaperReading::ALL
        .iter()
        .map(|&reading| {
            let ints: Vec<f64> = nf
                .iter()
                .map(|&n| paper_integral(form, n, reading))
                .collect();
            let (paper_res_max, paper_res_argmax_n) =
                max_res(&ns, |i| residual(paper_coefficient(form, nf[i]), ints[i]));
            // coef = (a n + b)/(K pi) = 1/(2 pi Int)  <=>  a n + b = K / (2 Int).
            let target: Vec<f64> = ints.iter().map(|int| kk / (2.0 * int)).collect();
            let (a, b) = least_squares_line(&nf, &target);
            let (refit_res_max, _) = max_res(&ns, |i| {
                residual((a * nf[i] + b) / (kk * std::f64::consts::PI), ints[i])
            });
            ReadingResult {
                reading: reading.name(),
                paper_res_max,
                paper_res_argmax_n,
                reproduced: agrees_to_two_digits(paper_res_max, claim),
                refit: Refit { a, b },
                refit_res_max,
            }
        })
        .collect();
    let used = readings
        .iter()
        .find(|r| r.reproduced)
        .unwrap_or(&readings[0])
        .clone();
    let clamp_ints: Vec<f64> = nf
        .iter()
        .map(|&n| clamp_integral_by_quadrature(form, n, 4))
        .collect();
    let (exact_res_max, _) = max_res(&ns, |i| {
        residual(
            coefficient(form, CoefSource::Exact, nf[i], 4),
            clamp_ints[i],
        )
    });
    let (classic_res_max, _) = max_res(&ns, |i| {
        residual(classic_coefficient(form, nf[i]), clamp_ints[i])
    });
    FormResult {
        form: form.name(),
        claim_res_max: claim,
        paper_res_max: used.paper_res_max,
        reading: used.reading,
        reproduced: used.reproduced,
        refit: used.refit,
        refit_res_max: used.refit_res_max,
        exact_res_max,
        classic_res_max,
        readings,
    }
}

/// Reproduces every claim of the paper.
pub fn reproduce() -> PaperReproduction {
    PaperReproduction {
        delta: delta_claims(),
        forms: Form::ALL.iter().map(|&f| form_result(f)).collect(),
        n_min: *PAPER_N.start(),
        n_max: *PAPER_N.end(),
    }
}
