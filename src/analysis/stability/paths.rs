//! The paths a stability map evaluates: float paths (`FloatPath`, prepared per n) and
//! fixed-point datapaths, and the default set of the map.

use crate::fixed::Overflow;
use crate::pipeline::Config;
use crate::reference::lobe::{
    affine_lobe, cos_pow, exp_limit, m_of_k, paper_cutoff_cosine, pow_2k, schlick, Cutoff,
};
use crate::reference::method::Method;
use crate::reference::minimax;

/// A software path computing the lobe in floating point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FloatPath {
    /// One of the f64 reference methods (`powf` is [`Method::CosPow`]).
    Method(Method),
    /// `c.powi(n)`: repeated squaring and multiplication in f64.
    PowI,
    /// `(c as f32).powf(n as f32)`: a shader's `pow` in single precision.
    PowF32,
}

impl FloatPath {
    /// The path's name: `powf`, `powf_f32`, `powi`, `schlick`, `exp_limit`, `cs16_clamp`,
    /// `minimax16`, ...
    pub fn name(self) -> String {
        match self {
            FloatPath::Method(Method::CosPow) => "powf".into(),
            FloatPath::Method(m) => m.name(),
            FloatPath::PowI => "powi".into(),
            FloatPath::PowF32 => "powf_f32".into(),
        }
    }

    /// `f64` or `f32`.
    pub fn precision(self) -> &'static str {
        match self {
            FloatPath::PowF32 => "f32",
            _ => "f64",
        }
    }

    /// The smallest positive normal number of the path's float type.
    pub(super) fn min_normal(self) -> f64 {
        match self {
            FloatPath::PowF32 => f64::from(f32::MIN_POSITIVE),
            _ => f64::MIN_POSITIVE,
        }
    }

    /// The float paths the map covers by default: powf (f64 and f32), powi, Schlick,
    /// exp(-n(1-c)), cs_m for k = 1..7 with every cutoff, minimax for k = 1..7, and minimax
    /// with a per-n depth up to m = 64 (each n at its best m(n): the 0.5 lsb8 family; missing
    /// past the minimax table's last n).
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::stability::FloatPath;
    /// assert_eq!(FloatPath::default_set().len(), 5 + 7 * 3 + 7 + 1);
    /// ```
    pub fn default_set() -> Vec<FloatPath> {
        let mut v = vec![
            FloatPath::Method(Method::CosPow),
            FloatPath::PowF32,
            FloatPath::PowI,
            FloatPath::Method(Method::Schlick),
            FloatPath::Method(Method::ExpLimit),
        ];
        for k in crate::reference::lobe::K_RANGE {
            for cutoff in Cutoff::ALL {
                v.push(FloatPath::Method(Method::CsM { k, cutoff }));
            }
        }
        for k in crate::reference::lobe::K_RANGE {
            v.push(FloatPath::Method(Method::Minimax { k }));
        }
        v.push(FloatPath::Method(Method::MinimaxPerN { k: 6 }));
        v
    }

    /// The path prepared for one n (constants looked up once).
    pub fn prepare(self, n: u32) -> Prepared {
        let nf = f64::from(n);
        match self {
            FloatPath::Method(Method::CosPow) => Prepared::CosPow(nf),
            FloatPath::PowI => Prepared::PowI(n as i32),
            FloatPath::PowF32 => Prepared::PowF32(n as f32),
            FloatPath::Method(Method::Schlick) => Prepared::Schlick(nf),
            FloatPath::Method(Method::ExpLimit) => Prepared::Exp(nf),
            FloatPath::Method(Method::CsM { k, cutoff }) => Prepared::CsM {
                slope: nf / f64::from(m_of_k(k)),
                k,
                cutoff,
                threshold: paper_cutoff_cosine(nf),
            },
            FloatPath::Method(Method::Minimax { k }) => match minimax::constants(n, k) {
                Ok(fit) => Prepared::Minimax {
                    a: fit.a,
                    b: fit.b,
                    k,
                },
                Err(_) => Prepared::Missing,
            },
            FloatPath::Method(Method::MinimaxPerN { k }) => {
                match minimax::best_depth(n, k, false).and_then(|j| minimax::constants(n, j).ok()) {
                    Some(fit) => Prepared::Minimax {
                        a: fit.a,
                        b: fit.b,
                        k: fit.k,
                    },
                    None => Prepared::Missing,
                }
            }
        }
    }
}

/// A float path with its per-n constants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Prepared {
    /// powf in f64, 0 for c <= 0.
    CosPow(f64),
    /// powi in f64.
    PowI(i32),
    /// powf in f32.
    PowF32(f32),
    /// Schlick's rational.
    Schlick(f64),
    /// exp(-n(1-c)).
    Exp(f64),
    /// cs_m with a cutoff; `threshold` is the paper cutoff's cosine.
    CsM {
        /// The slope n/m.
        slope: f64,
        /// Squarings.
        k: u32,
        /// Cutoff rule.
        cutoff: Cutoff,
        /// cos(6/sqrt(n)).
        threshold: f64,
    },
    /// The minimax lobe.
    Minimax {
        /// A(n).
        a: f64,
        /// B(n).
        b: f64,
        /// Squarings.
        k: u32,
    },
    /// No minimax entry for this n: NaN.
    Missing,
}

/// One float evaluation: the value and what the path computed on the way.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloatSample {
    /// The lobe.
    pub value: f64,
    /// The base of the power (cs_m and minimax), if the path has one.
    pub base: Option<f64>,
    /// Whether the exact value of what the path computes is positive (so that a zero is an
    /// underflow, not a cut).
    pub exact_positive: bool,
}

impl Prepared {
    /// Evaluates at cosine `c`, exactly as [`Method::eval`] does for the reference methods.
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::stability::FloatPath;
    /// use specfx::reference::lobe::Cutoff;
    /// use specfx::reference::method::Method;
    /// let p = FloatPath::Method(Method::CsM { k: 4, cutoff: Cutoff::Clamp }).prepare(64);
    /// let s = p.eval(0.5);
    /// assert_eq!((s.value, s.base, s.exact_positive), (0.0, Some(-1.0), false));
    /// ```
    #[inline]
    pub fn eval(&self, c: f64) -> FloatSample {
        let plain = |value: f64, exact_positive: bool| FloatSample {
            value,
            base: None,
            exact_positive,
        };
        match *self {
            Prepared::CosPow(n) => plain(cos_pow(c, n), c > 0.0),
            Prepared::PowI(n) => plain(c.powi(n), c != 0.0),
            Prepared::PowF32(n) => plain(f64::from((c as f32).powf(n)), c > 0.0),
            Prepared::Schlick(n) => plain(schlick(c, n), c > 0.0),
            Prepared::Exp(n) => plain(exp_limit(c, n), true),
            Prepared::CsM {
                slope,
                k,
                cutoff,
                threshold,
            } => {
                // As `cs_base`: (n/m)(c - 1) + 1.
                let base = slope * (c - 1.0) + 1.0;
                // A clamped base of 0 (or NaN) counts as cut: its value is 0 either way.
                let cut = cutoff.cuts(base <= 0.0 || base.is_nan(), c < threshold);
                let value = if cut { 0.0 } else { pow_2k(base, k) };
                FloatSample {
                    value,
                    base: Some(base),
                    exact_positive: !cut && base != 0.0,
                }
            }
            Prepared::Minimax { a, b, k } => {
                let base = a * c + b;
                FloatSample {
                    value: affine_lobe(c, a, b, k),
                    base: Some(base),
                    exact_positive: base > 0.0,
                }
            }
            Prepared::Missing => plain(f64::NAN, false),
        }
    }
}

/// A path of the map: a float path or a fixed-point datapath.
#[derive(Debug, Clone)]
pub enum MapPath {
    /// A software path.
    Float(FloatPath),
    /// A datapath configuration; the map evaluates it at every n of the grid it can hold.
    Fixed(Box<Config>),
}

impl MapPath {
    /// The path's name (the configuration's name for a datapath).
    pub fn name(&self) -> String {
        match self {
            MapPath::Float(p) => p.name(),
            MapPath::Fixed(c) => c.name.clone(),
        }
    }
}

/// The narrow datapath of the map (10-bit input, 9-bit stages, truncation), its overflow mode
/// left as `{overflow}`.
pub(super) const NARROW: &str = r#"name = "narrow_{name}"
[c]
format = "u1.9"
[d]
format = "s1.9"
[t]
format = "s3.8"
rounding = "TRN"
overflow = "{overflow}"
[b]
format = "u1.8"
rounding = "TRN"
overflow = "{overflow}"
[square]
format = "u1.8"
rounding = "TRN"
overflow = "{overflow}"
[coef]
format = "u10.6"
rounding = "TRN"
[out]
format = "u10.6"
rounding = "TRN"
overflow = "{overflow}"
"#;

/// The narrow datapath of the map with saturation (`narrow_sat`) or wrap-around
/// (`narrow_wrap`) in every stage: a 10-bit input, 9-bit stages, truncation, and a `u10.6`
/// coefficient that holds every n up to 4096.
///
/// # Examples
/// ```
/// use specfx::analysis::stability::narrow_datapath;
/// use specfx::fixed::Overflow;
/// let c = narrow_datapath(Overflow::Wrap);
/// assert_eq!((c.name.as_str(), c.t.format.to_string()), ("narrow_wrap", "s3.8".to_string()));
/// ```
pub fn narrow_datapath(overflow: Overflow) -> Config {
    let text = NARROW
        .replace("{name}", &overflow.to_string().to_lowercase())
        .replace("{overflow}", &overflow.to_string());
    Config::from_toml(&text).expect("the built-in narrow datapath is valid")
}

/// The default paths: every float path of [`FloatPath::default_set`], then `baseline`,
/// `narrow_sat` and `narrow_wrap` ([`narrow_datapath`]).
pub fn default_paths() -> Vec<MapPath> {
    let mut v: Vec<MapPath> = FloatPath::default_set()
        .into_iter()
        .map(MapPath::Float)
        .collect();
    v.push(MapPath::Fixed(Box::new(Config::baseline())));
    for overflow in [Overflow::Sat, Overflow::Wrap] {
        v.push(MapPath::Fixed(Box::new(narrow_datapath(overflow))));
    }
    v
}
