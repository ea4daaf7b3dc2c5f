//! Maximum error of each reference method against cos^n, per exponent.

use rayon::prelude::*;
use serde::Serialize;

use crate::reference::lobe::Cutoff;
use crate::reference::method::Method;
use crate::reference::minimax::sup_abs_error;

/// The methods the main report compares: cs_m (clamp) and minimax for k = 2..=7, minimax with
/// a per-n depth up to m = 32, 64 and 128 (each n at its best m(n), `depth = "best"`), cs16 with
/// the paper's cutoff, Schlick and the exponential limit.
pub fn report_methods() -> Vec<Method> {
    let mut v: Vec<Method> = (2..=crate::reference::lobe::K_MAX)
        .map(|k| Method::CsM {
            k,
            cutoff: Cutoff::Clamp,
        })
        .collect();
    v.push(Method::CsM {
        k: 4,
        cutoff: Cutoff::Paper,
    });
    v.extend((2..=crate::reference::lobe::K_MAX).map(|k| Method::Minimax { k }));
    v.extend((5..=crate::reference::lobe::K_MAX).map(|k| Method::MinimaxPerN { k }));
    v.push(Method::Schlick);
    v.push(Method::ExpLimit);
    v
}

/// The error of one method over a set of exponents.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodErrors {
    /// The method's name.
    pub method: String,
    /// max over n and c of |method - cos^n|.
    pub max_abs_err: f64,
    /// The n where it is reached.
    pub argmax_n: u32,
    /// The c where it is reached.
    pub argmax_c: f64,
    /// max over c for each n, in the order of the exponents given.
    pub per_n: Vec<f64>,
}

/// For each method, max over c in [0, 1] of |method(c, n) - c^n| for each n (see
/// [`sup_abs_error`] for how the supremum is found).
///
/// # Examples
/// ```
/// use specfx::analysis::methods::max_errors;
/// use specfx::reference::method::Method;
/// // Schlick at n = 1 is exact: c / (1 - c + c) = c.
/// let e = max_errors(&[Method::Schlick], &[1]);
/// assert!(e[0].max_abs_err < 1e-15);
/// ```
pub fn max_errors(methods: &[Method], ns: &[u32]) -> Vec<MethodErrors> {
    methods
        .iter()
        .map(|&method| {
            let per: Vec<(f64, f64)> = ns
                .par_iter()
                .map(|&n| sup_abs_error(n, 0.0, |c| method.eval(c, n)))
                .collect();
            let (i, &(max_abs_err, argmax_c)) = per
                .iter()
                .enumerate()
                .max_by(|a, b| a.1 .0.total_cmp(&b.1 .0))
                .expect("at least one exponent");
            MethodErrors {
                method: method.name(),
                max_abs_err,
                argmax_n: ns[i],
                argmax_c,
                per_n: per.iter().map(|p| p.0).collect(),
            }
        })
        .collect()
}
