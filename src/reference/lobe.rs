//! f64 lobe models: cos^n, Schlick's rational, the exponential limit, cs_m and its minimax twin.
//!
//! Every function takes the cosine `c` (R.V for Phong, N.H for Blinn) and the specular
//! exponent `n`, and evaluates in plain f64. These are the oracles the fixed-point datapath is
//! compared with; they never use fixed-point types.

use serde::{Deserialize, Serialize};

/// The largest number of squarings, as a literal for [`K_MAX`] and [`K_RANGE_TEXT`].
macro_rules! k_max {
    () => {
        7
    };
}

/// The largest number of squarings k (m = 2^k = 128).
pub const K_MAX: u32 = k_max!();
/// The number of squarings k supported by cs_m (m = 2^k).
pub const K_RANGE: std::ops::RangeInclusive<u32> = 1..=K_MAX;
/// [`K_RANGE`] as messages and defaults write it: `1..=7`.
pub const K_RANGE_TEXT: &str = concat!("1..=", k_max!());

/// The constant of the paper's approximate cutoff angle theta = 6 / sqrt(n).
pub const PAPER_CUTOFF_CONSTANT: f64 = 6.0;

/// How cs_m treats the region where its base `(n/m)(c - 1) + 1` is negative.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Cutoff {
    /// `max(0, base)^m`: the exact cut at theta_cr = arccos((n - m)/n); free in hardware
    /// (the sign bit of the base).
    Clamp,
    /// The paper's rule: zero for theta > 6/sqrt(n), `base^m` before it (the base may be
    /// negative just before the cut, as printed). The constant 6 is the paper's, for every m.
    Paper,
    /// `base^m` everywhere: an even power of a negative base grows again past theta_cr.
    None,
}

impl Cutoff {
    /// Every cutoff mode, in documentation order.
    pub const ALL: [Cutoff; 3] = [Cutoff::Clamp, Cutoff::Paper, Cutoff::None];

    /// The name used on the command line, in TOML and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Cutoff::Clamp => "clamp",
            Cutoff::Paper => "paper",
            Cutoff::None => "none",
        }
    }

    /// Whether a datapath cuts its base to zero: the clamp when the exact sum `t + offset` is
    /// negative, the paper rule when the input is below its threshold, `none` never. This is
    /// the one place the datapaths' cutoff rule is written; every model of a datapath (bit
    /// accurate, batch, `f64`, mixed) asks it.
    ///
    /// # Examples
    /// ```
    /// use specfx::reference::lobe::Cutoff;
    /// assert!(Cutoff::Clamp.cuts(true, false));
    /// assert!(!Cutoff::Clamp.cuts(false, true));
    /// assert!(Cutoff::Paper.cuts(false, true));
    /// assert!(!Cutoff::None.cuts(true, true));
    /// ```
    #[inline]
    pub fn cuts(self, sum_is_negative: bool, below_threshold: bool) -> bool {
        match self {
            Cutoff::Clamp => sum_is_negative,
            Cutoff::Paper => below_threshold,
            Cutoff::None => false,
        }
    }
}

crate::names::named_enum!(Cutoff, "cutoff", "clamp, paper or none");

/// `m = 2^k`, the exponent reached by `k` squarings.
///
/// # Examples
/// ```
/// assert_eq!(specfx::reference::lobe::m_of_k(4), 16);
/// ```
pub fn m_of_k(k: u32) -> u32 {
    1 << k
}

/// `x^(2^k)` by `k` successive squarings, exactly as the datapath computes it.
///
/// # Examples
/// ```
/// use specfx::reference::lobe::pow_2k;
/// assert_eq!(pow_2k(0.5, 4), 0.5f64.powi(16));
/// ```
#[inline]
pub fn pow_2k(x: f64, k: u32) -> f64 {
    let mut y = x;
    for _ in 0..k {
        y *= y;
    }
    y
}

/// `cos^n`: Phong's lobe on R.V, Blinn's on N.H. Negative cosines (the back hemisphere) give 0.
///
/// # Examples
/// ```
/// use specfx::reference::lobe::cos_pow;
/// assert_eq!(cos_pow(0.5, 2.0), 0.25);
/// assert_eq!(cos_pow(-0.5, 2.0), 0.0);
/// ```
#[inline]
pub fn cos_pow(c: f64, n: f64) -> f64 {
    if c <= 0.0 {
        0.0
    } else {
        c.powf(n)
    }
}

/// Schlick's rational replacement `c / (n - n c + c)` (one division).
///
/// # Examples
/// ```
/// use specfx::reference::lobe::schlick;
/// assert_eq!(schlick(1.0, 64.0), 1.0);
/// assert_eq!(schlick(0.0, 64.0), 0.0);
/// ```
#[inline]
pub fn schlick(c: f64, n: f64) -> f64 {
    c / (n - n * c + c)
}

/// The large-n limit of cos^n: `exp(-n (1 - c))`.
///
/// # Examples
/// ```
/// use specfx::reference::lobe::exp_limit;
/// assert_eq!(exp_limit(1.0, 100.0), 1.0);
/// ```
#[inline]
pub fn exp_limit(c: f64, n: f64) -> f64 {
    (-n * (1.0 - c)).exp()
}

/// The base `(n/m)(c - 1) + 1` of cs_m.
#[inline]
pub fn cs_base(c: f64, n: f64, k: u32) -> f64 {
    (n / f64::from(m_of_k(k))) * (c - 1.0) + 1.0
}

/// The cosine below which the paper's cutoff makes cs_m zero: `cos(min(6/sqrt(n), pi))`.
#[inline]
pub fn paper_cutoff_cosine(n: f64) -> f64 {
    (PAPER_CUTOFF_CONSTANT / n.sqrt())
        .min(std::f64::consts::PI)
        .cos()
}

/// cs_m(c, n) = base^m with m = 2^k and the given cutoff rule.
///
/// # Examples
/// ```
/// use specfx::reference::lobe::{cs_m, Cutoff};
/// // n = m: the base is c itself, so cs_m = c^m.
/// assert_eq!(cs_m(0.5, 16.0, 4, Cutoff::Clamp), 0.5f64.powi(16));
/// // Past theta_cr the clamp gives zero, `none` lets the even power grow again.
/// assert_eq!(cs_m(0.0, 64.0, 4, Cutoff::Clamp), 0.0);
/// assert_eq!(cs_m(0.0, 64.0, 4, Cutoff::None), 3f64.powi(16));
/// ```
#[inline]
pub fn cs_m(c: f64, n: f64, k: u32, cutoff: Cutoff) -> f64 {
    let base = cs_base(c, n, k);
    // The clamp's max(0, base) also maps a NaN base to 0; the threshold is computed only for
    // the paper cutoff, the one rule that reads it.
    let below = cutoff == Cutoff::Paper && c < paper_cutoff_cosine(n);
    if cutoff.cuts(base.is_nan() || base < 0.0, below) {
        0.0
    } else {
        pow_2k(base, k)
    }
}

/// The minimax-shaped lobe `max(0, a c + b)^m` with m = 2^k.
///
/// # Examples
/// ```
/// use specfx::reference::lobe::affine_lobe;
/// assert_eq!(affine_lobe(1.0, 2.0, -1.0, 3), 1.0);
/// assert_eq!(affine_lobe(0.25, 2.0, -1.0, 3), 0.0);
/// ```
#[inline]
pub fn affine_lobe(c: f64, a: f64, b: f64, k: u32) -> f64 {
    pow_2k((a * c + b).max(0.0), k)
}

/// The angle theta_cr = arccos(1 - m/n) where the base of cs_m reaches zero; pi/2 and beyond
/// are reported as they are (n <= m keeps the whole hemisphere).
pub fn theta_cr(n: f64, k: u32) -> f64 {
    (1.0 - f64::from(m_of_k(k)) / n).clamp(-1.0, 1.0).acos()
}

/// A 3-vector of f64, for the vector forms of the lobes.
pub type Vec3 = [f64; 3];

fn dot(a: Vec3, b: Vec3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(a: Vec3) -> Vec3 {
    let len = dot(a, a).sqrt();
    [a[0] / len, a[1] / len, a[2] / len]
}

/// Phong's cosine R.V, with R = 2 (L.N) N - L; all inputs unit vectors pointing away from
/// the surface.
///
/// # Examples
/// ```
/// use specfx::reference::lobe::phong_cosine;
/// let up = [0.0, 0.0, 1.0];
/// assert!((phong_cosine(up, up, up) - 1.0).abs() < 1e-15);
/// ```
pub fn phong_cosine(light: Vec3, normal: Vec3, view: Vec3) -> f64 {
    let ln = dot(light, normal);
    let r = [
        2.0 * ln * normal[0] - light[0],
        2.0 * ln * normal[1] - light[1],
        2.0 * ln * normal[2] - light[2],
    ];
    dot(r, view)
}

/// Blinn's cosine N.H, with H = (L + V)/|L + V|.
///
/// # Examples
/// ```
/// use specfx::reference::lobe::blinn_cosine;
/// let up = [0.0, 0.0, 1.0];
/// assert!((blinn_cosine(up, up, up) - 1.0).abs() < 1e-15);
/// ```
pub fn blinn_cosine(light: Vec3, normal: Vec3, view: Vec3) -> f64 {
    let h = normalize([light[0] + view[0], light[1] + view[1], light[2] + view[2]]);
    dot(normal, h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn theta_cr_matches_the_zero_of_the_base() {
        for n in [16.0, 17.0, 100.0, 1024.0] {
            let t = theta_cr(n, 4);
            assert!(cs_base(t.cos(), n, 4).abs() < 1e-13, "n = {n}");
        }
        assert_eq!(theta_cr(16.0, 4), std::f64::consts::FRAC_PI_2);
    }

    #[test]
    fn paper_cutoff_keeps_negative_bases_before_six_over_sqrt_n() {
        // n = 1024: theta_cr = arccos(1 - 1/64) ≈ 0.17689 < 6/32 = 0.1875.
        let n = 1024.0;
        let c = 0.18f64.cos();
        assert!(cs_base(c, n, 4) < 0.0);
        assert_eq!(cs_m(c, n, 4, Cutoff::Clamp), 0.0);
        let printed = cs_m(c, n, 4, Cutoff::Paper);
        assert!(printed > 0.0 && printed < 1e-12);
        assert_eq!(cs_m(0.19f64.cos(), n, 4, Cutoff::Paper), 0.0);
    }

    #[test]
    fn blinn_cosine_is_the_half_angle_cosine() {
        // L and V at ±θ from N in one plane: N.H = 1, R.V = cos(2θ).
        let th: f64 = 0.3;
        let l = [th.sin(), 0.0, th.cos()];
        let v = [-th.sin(), 0.0, th.cos()];
        let nrm = [0.0, 0.0, 1.0];
        assert!((blinn_cosine(l, nrm, v) - 1.0).abs() < 1e-15);
        assert!((phong_cosine(l, nrm, v) - 1.0).abs() < 1e-15);
        // V along N: R.V = cos(θ) for L at θ... R is at -θ, V at 0: R.V = cos θ; N.H = cos(θ/2).
        let v = nrm;
        assert!((phong_cosine(l, nrm, v) - th.cos()).abs() < 1e-15);
        assert!((blinn_cosine(l, nrm, v) - (th / 2.0).cos()).abs() < 1e-15);
    }

    #[test]
    fn cutoff_names_round_trip() {
        for c in Cutoff::ALL {
            assert_eq!(c.name().parse::<Cutoff>().unwrap(), c);
        }
        assert!("Clamp".parse::<Cutoff>().is_ok());
        let err = "sharp".parse::<Cutoff>().unwrap_err().to_string();
        assert_eq!(err, "unknown cutoff 'sharp': expected clamp, paper or none");
    }
}
