//! The software methods that approximate cos^n, as one enum that can be named and evaluated.

use std::fmt;

use serde::Serialize;

use crate::reference::lobe::{affine_lobe, cos_pow, cs_m, exp_limit, m_of_k, schlick, Cutoff};
use crate::reference::minimax;

/// One way of computing (an approximation of) cos^n in f64.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Method {
    /// cos^n itself (the target).
    CosPow,
    /// `(n/m)(c - 1) + 1` raised to m = 2^k, with a cutoff rule.
    CsM {
        /// Number of squarings.
        k: u32,
        /// Cutoff rule.
        cutoff: Cutoff,
    },
    /// `max(0, A(n) c + B(n))^m` with the cached minimax constants.
    Minimax {
        /// Number of squarings.
        k: u32,
    },
    /// Minimax with a per-n depth: `max(0, A(n) c + B(n))^(2^j)`, j = j(n) <= k the depth
    /// with the smallest floor ([`minimax::best_depth`], `depth = "best"`).
    MinimaxPerN {
        /// The most squarings.
        k: u32,
    },
    /// Schlick's rational `c / (n - n c + c)`.
    Schlick,
    /// The exponential limit `exp(-n (1 - c))`.
    ExpLimit,
}

impl Method {
    /// Evaluates the method at cosine `c` and integer exponent `n`.
    ///
    /// Minimax needs a cached entry (n <= 4096); outside the table it evaluates to NaN.
    ///
    /// # Examples
    /// ```
    /// use specfx::reference::method::Method;
    /// use specfx::reference::lobe::Cutoff;
    /// let m = Method::CsM { k: 4, cutoff: Cutoff::Clamp };
    /// assert_eq!(m.eval(1.0, 100), 1.0);
    /// assert_eq!(m.name(), "cs16_clamp");
    /// ```
    pub fn eval(self, c: f64, n: u32) -> f64 {
        let nf = f64::from(n);
        match self {
            Method::CosPow => cos_pow(c, nf),
            Method::CsM { k, cutoff } => cs_m(c, nf, k, cutoff),
            Method::Minimax { k } => match minimax::constants(n, k) {
                Ok(fit) => affine_lobe(c, fit.a, fit.b, k),
                Err(_) => f64::NAN,
            },
            Method::MinimaxPerN { k } => {
                match minimax::best_depth(n, k, false).and_then(|j| minimax::constants(n, j).ok()) {
                    Some(fit) => affine_lobe(c, fit.a, fit.b, fit.k),
                    None => f64::NAN,
                }
            }
            Method::Schlick => schlick(c, nf),
            Method::ExpLimit => exp_limit(c, nf),
        }
    }

    /// A short stable name, e.g. `cs16_clamp`, `minimax16`, `minimax64_per_n` (per-n depth up
    /// to m = 64), `schlick`.
    pub fn name(self) -> String {
        match self {
            Method::CosPow => "cos_pow".to_string(),
            Method::CsM { k, cutoff } => format!("cs{}_{}", m_of_k(k), cutoff),
            Method::Minimax { k } => format!("minimax{}", m_of_k(k)),
            Method::MinimaxPerN { k } => format!("minimax{}_per_n", m_of_k(k)),
            Method::Schlick => "schlick".to_string(),
            Method::ExpLimit => "exp_limit".to_string(),
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}
