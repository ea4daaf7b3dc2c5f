//! Property tests of the f64 reference: bounds, monotonicity, identities and normalisation.

use std::f64::consts::PI;

use proptest::prelude::*;
use specfx::reference::lobe::{cs_m, m_of_k, Cutoff};
use specfx::reference::normalisation::{
    clamp_integral_by_quadrature, coefficient, CoefSource, Form,
};

fn any_form() -> impl Strategy<Value = Form> {
    prop::sample::select(Form::ALL.to_vec())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn cs_m_clamp_is_within_zero_and_one(c in 0.0f64..=1.0, n in 1u32..=4096, k in 1u32..=7) {
        let v = cs_m(c, f64::from(n), k, Cutoff::Clamp);
        prop_assert!((0.0..=1.0).contains(&v), "cs_m({c}, {n}, k={k}) = {v}");
    }

    #[test]
    fn cs_m_clamp_is_non_decreasing_in_c(
        c1 in 0.0f64..=1.0, c2 in 0.0f64..=1.0, n in 1u32..=4096, k in 1u32..=7
    ) {
        let (lo, hi) = if c1 <= c2 { (c1, c2) } else { (c2, c1) };
        let nf = f64::from(n);
        prop_assert!(cs_m(lo, nf, k, Cutoff::Clamp) <= cs_m(hi, nf, k, Cutoff::Clamp));
    }

    #[test]
    fn cs_m_is_c_to_the_n_when_n_equals_m(c in 0.0f64..=1.0, k in 1u32..=7) {
        // n = m: the base (c - 1) + 1 is c up to one rounding of c - 1.
        let m = m_of_k(k);
        let v = cs_m(c, f64::from(m), k, Cutoff::Clamp);
        prop_assert!((v - c.powi(m as i32)).abs() <= 1e-12, "c={c} m={m}: {v}");
    }

    #[test]
    fn exact_coefficients_normalise_by_quadrature(
        form in any_form(), k in 1u32..=7, n in 1u32..=4096
    ) {
        let nf = f64::from(n);
        let coef = coefficient(form, CoefSource::Exact, nf, k);
        let int = clamp_integral_by_quadrature(form, nf, k);
        let res = (2.0 * PI * coef * int - 1.0).abs();
        prop_assert!(res <= 1e-9, "{form} k={k} n={n}: res {res}");
    }
}

/// The same normalisation property on every (form, m, n) with n in 1..=4096: the quadrature of
/// the theta integral is independent of the closed form it checks.
#[test]
fn every_exact_coefficient_integrates_to_one() {
    use rayon::prelude::*;
    let worst = Form::ALL
        .par_iter()
        .flat_map(|&form| {
            (1u32..=7).into_par_iter().flat_map(move |k| {
                (1u32..=4096).into_par_iter().map(move |n| {
                    let nf = f64::from(n);
                    let coef = coefficient(form, CoefSource::Exact, nf, k);
                    let int = clamp_integral_by_quadrature(form, nf, k);
                    ((2.0 * PI * coef * int - 1.0).abs(), form, k, n)
                })
            })
        })
        .reduce(
            || (0.0, Form::Phong, 0, 0),
            |a, b| if b.0 > a.0 { b } else { a },
        );
    assert!(worst.0 <= 1e-9, "worst residual {worst:?}");
}
