//! The overshoot of cosines above 1: from which `1 + j 2^-23` each float path's output rises
//! above its value at 1 by more than the tolerance.

use rayon::prelude::*;
use serde::Serialize;

use super::*;

/// Whether a float path's output at `1 + j 2^-23` overshoots: not finite, negative, or above
/// its own value at c = 1 by more than `tol`.
pub(super) fn overshoots(p: &Prepared, at_one: f64, j: u32, tol: f64) -> bool {
    let v = p.eval(1.0 + f64::from(j) * 2f64.powi(-23)).value;
    !v.is_finite() || v < 0.0 || v - at_one > tol
}

/// The smallest j in 1..=[`OVERSHOOT_J_MAX`] whose input `1 + j 2^-23` makes the path
/// overshoot, found by bisection (every path's overshoot grows with j).
///
/// # Examples
/// ```
/// use specfx::analysis::stability::{overshoot_threshold, FloatPath};
/// use specfx::reference::method::Method;
/// // powf: c^4096 - 1 > 2^-8 from c = 1 + 8 * 2^-23 on.
/// let j = overshoot_threshold(FloatPath::Method(Method::CosPow), 4096, 1.0 / 256.0);
/// assert_eq!(j, Some(8));
/// ```
pub fn overshoot_threshold(path: FloatPath, n: u32, tol: f64) -> Option<u32> {
    let p = path.prepare(n);
    let at_one = p.eval(1.0).value;
    if !overshoots(&p, at_one, OVERSHOOT_J_MAX, tol) {
        return None;
    }
    let (mut lo, mut hi) = (0u32, OVERSHOOT_J_MAX); // lo passes (or is 0), hi overshoots
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if overshoots(&p, at_one, mid, tol) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    Some(hi)
}

/// The overshoot of one float path: the smallest overshooting j at each n.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Overshoot {
    /// The path.
    pub path: String,
    /// The smallest n with an overshoot within [`OVERSHOOT_J_MAX`] ulps, if any.
    pub n_min: Option<u32>,
    /// The threshold j at the largest n of the grid.
    pub j_at_n_max: Option<u32>,
    /// `(n, j)` for every n of the grid.
    #[serde(skip)]
    pub per_n: Vec<(u32, Option<u32>)>,
}

/// The overshoot thresholds of every float path over the grid's exponents.
pub fn overshoot(paths: &[MapPath], grid: &Grid) -> Vec<Overshoot> {
    let ns = grid.n.values();
    paths
        .iter()
        .filter_map(|p| match p {
            MapPath::Float(f) => Some(*f),
            MapPath::Fixed(_) => None,
        })
        .map(|f| {
            let per_n: Vec<(u32, Option<u32>)> = ns
                .par_iter()
                .map(|&n| (n, overshoot_threshold(f, n, grid.tol.value)))
                .collect();
            Overshoot {
                path: f.name(),
                n_min: per_n.iter().find(|(_, j)| j.is_some()).map(|&(n, _)| n),
                j_at_n_max: per_n.last().and_then(|&(_, j)| j),
                per_n,
            }
        })
        .collect()
}
