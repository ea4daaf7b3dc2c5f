//! Where each method fails: every float path and fixed-point datapath evaluated over n and
//! theta, each sample flagged by what goes wrong there, gathered into failure regions and heat
//! maps; plus special inputs (NaN, infinities, just outside [0, 1]) and the overshoot of
//! cosines above 1.
//!
//! The map samples the cosine, not the angle: float paths at every `c = j / 2^c_bits` in
//! [0, 1], fixed-point datapaths at every code of their own input format up to 1.0, so a
//! region's boundary is a code and can be pinned exactly. Each sample is compared with
//! `cos^n(c)` in f64 and flagged by [`Kind`]. Work is split by n across threads and merged in
//! n order, so every figure is deterministic.

use std::fmt;
use std::str::FromStr;

use rayon::prelude::*;
use serde::Serialize;

use crate::engine::{fold_n, Chunk, Codes};
use crate::error::Error;
use crate::fixed::{quantize_f64, Event, Overflow, Rounding};
use crate::nset::NSet;
use crate::pipeline::datapath::STAGE_B;
use crate::pipeline::{Config, Datapath, Variant};
use crate::reference::lobe::{
    affine_lobe, cos_pow, exp_limit, m_of_k, paper_cutoff_cosine, pow_2k, schlick, Cutoff,
};
use crate::reference::method::Method;
use crate::reference::minimax;

/// The default tolerance: one LSB of an 8-bit display, 2^-8.
pub const DEFAULT_TOL: f64 = super::LSB8;

/// Rows of the heat maps: theta from 0 to 90 degrees in steps of one degree.
pub const HEAT_ROWS: usize = 90;

/// Overshoot inputs are `1 + j 2^-23` (j f32 ulps above 1) for j up to this: 2^14 ulps,
/// 1 + 2^-9, the error of a half-precision (fp16) normal.
pub const OVERSHOOT_J_MAX: u32 = 1 << 14;

/// An absolute tolerance on the lobe, written `1 lsb8` (2^-8), `0.5 lsb10` or `0.004`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tolerance {
    /// The text it was parsed from.
    pub text: String,
    /// The value.
    pub value: f64,
}

impl Default for Tolerance {
    fn default() -> Tolerance {
        Tolerance {
            text: "1 lsb8".into(),
            value: DEFAULT_TOL,
        }
    }
}

impl FromStr for Tolerance {
    type Err = Error;
    /// # Examples
    /// ```
    /// use specfx::analysis::stability::Tolerance;
    /// assert_eq!("1 lsb8".parse::<Tolerance>().unwrap().value, 1.0 / 256.0);
    /// assert_eq!("0.5lsb10".parse::<Tolerance>().unwrap().value, 0.5 / 1024.0);
    /// assert_eq!("1e-3".parse::<Tolerance>().unwrap().value, 1e-3);
    /// assert!("-1".parse::<Tolerance>().is_err());
    /// ```
    fn from_str(s: &str) -> Result<Tolerance, Error> {
        let bad = || Error::OutOfRange {
            what: "the tolerance",
            expected: "a positive number, optionally in lsbN (2^-N), e.g. '1 lsb8' or '0.004'"
                .into(),
            got: format!("'{s}'"),
        };
        let t = s.trim();
        let (number, scale) = match t.find("lsb") {
            Some(i) => {
                let bits: i32 = t[i + 3..].trim().parse().map_err(|_| bad())?;
                if !(1..=62).contains(&bits) {
                    return Err(bad());
                }
                (t[..i].trim(), (-f64::from(bits)).exp2())
            }
            None => (t, 1.0),
        };
        let value = number.parse::<f64>().map_err(|_| bad())? * scale;
        if !(value.is_finite() && value > 0.0) {
            return Err(bad());
        }
        Ok(Tolerance {
            text: t.to_string(),
            value,
        })
    }
}

impl fmt::Display for Tolerance {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// What goes wrong at a sample. A sample can carry several kinds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kind {
    /// The lobe is above cos^n by more than the tolerance.
    Over,
    /// The lobe is below cos^n by more than the tolerance.
    Under,
    /// The base of the power is negative and the cutoff lets it through (paper cutoff, none):
    /// an even power of it is a spurious lobe past the zero of the base.
    NegativeBase,
    /// n < m and the lobe is off by more than the tolerance: the base never reaches zero in
    /// the hemisphere, so the lobe does not close at the horizon.
    NBelowM,
    /// A fixed-point stage wrapped around.
    Wrap,
    /// A fixed-point stage saturated (or overflowed to zero).
    Saturate,
    /// The lobe is zero (fixed point) or below the smallest normal number of its float type,
    /// while the value it computes is positive: flushed to zero on hardware without subnormals.
    Underflow,
    /// The lobe decreases as c increases (between neighbouring samples of one n).
    NonMonotonic,
    /// The lobe is NaN or infinite.
    NonFinite,
    /// The datapath cannot hold this n's constants (slope, offset or coefficient).
    Unrepresentable,
}

impl Kind {
    /// Every kind, in report order.
    pub const ALL: [Kind; 10] = [
        Kind::Over,
        Kind::Under,
        Kind::NegativeBase,
        Kind::NBelowM,
        Kind::Wrap,
        Kind::Saturate,
        Kind::Underflow,
        Kind::NonMonotonic,
        Kind::NonFinite,
        Kind::Unrepresentable,
    ];

    /// The kind's bit in a sample's flags.
    pub fn bit(self) -> u16 {
        1 << (self as u16)
    }

    /// The name used in tables and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Over => "over",
            Kind::Under => "under",
            Kind::NegativeBase => "negative_base",
            Kind::NBelowM => "n_below_m",
            Kind::Wrap => "wrap",
            Kind::Saturate => "saturate",
            Kind::Underflow => "underflow",
            Kind::NonMonotonic => "non_monotonic",
            Kind::NonFinite => "non_finite",
            Kind::Unrepresentable => "unrepresentable",
        }
    }

    /// One sentence saying what the kind means.
    pub fn describe(self) -> &'static str {
        match self {
            Kind::Over => "the lobe is above cos^n by more than the tolerance",
            Kind::Under => "the lobe is below cos^n by more than the tolerance",
            Kind::NegativeBase => "the base is negative and the cutoff lets it through: an even power makes a spurious lobe past the zero of the base",
            Kind::NBelowM => "n < m: the base never reaches zero in the hemisphere, so the lobe does not close at the horizon",
            Kind::Wrap => "a fixed-point stage wrapped around",
            Kind::Saturate => "a fixed-point stage saturated",
            Kind::Underflow => "the lobe is flushed to zero (below the smallest normal float, or below half an LSB) while its value is positive: relative error 100%",
            Kind::NonMonotonic => "the lobe decreases as c increases",
            Kind::NonFinite => "the lobe is NaN or infinite",
            Kind::Unrepresentable => "the datapath cannot hold this n's constants",
        }
    }

    /// Whether the kind is a failure by itself, whatever the size of the error.
    pub fn is_structural(self) -> bool {
        matches!(self, Kind::NonFinite | Kind::Unrepresentable)
    }
}

impl fmt::Display for Kind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

const FAIL_BITS: u16 = (1 << Kind::Over as u16) | (1 << Kind::Under as u16);

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
    fn min_normal(self) -> f64 {
        match self {
            FloatPath::PowF32 => f64::from(f32::MIN_POSITIVE),
            _ => f64::MIN_POSITIVE,
        }
    }

    /// The float paths the map covers by default: powf (f64 and f32), powi, Schlick,
    /// exp(-n(1-c)), cs_m for k = 1..7 with every cutoff, minimax for k = 1..7.
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::stability::FloatPath;
    /// assert_eq!(FloatPath::default_set().len(), 5 + 7 * 3 + 7);
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
pub enum Path {
    /// A software path.
    Float(FloatPath),
    /// A datapath configuration; the map evaluates it at every n of the grid it can hold.
    Fixed(Box<Config>),
}

impl Path {
    /// The path's name (the configuration's name for a datapath).
    pub fn name(&self) -> String {
        match self {
            Path::Float(p) => p.name(),
            Path::Fixed(c) => c.name.clone(),
        }
    }
}

/// The narrow datapath of the map (10-bit input, 9-bit stages, truncation), its overflow mode
/// left as `{overflow}`.
const NARROW: &str = r#"name = "narrow_{name}"
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
pub fn default_paths() -> Vec<Path> {
    let mut v: Vec<Path> = FloatPath::default_set()
        .into_iter()
        .map(Path::Float)
        .collect();
    v.push(Path::Fixed(Box::new(Config::baseline())));
    for overflow in [Overflow::Sat, Overflow::Wrap] {
        v.push(Path::Fixed(Box::new(narrow_datapath(overflow))));
    }
    v
}

/// What the map covers.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Grid {
    /// The exponents.
    pub n: NSet,
    /// Float paths are sampled at `c = j / 2^c_bits`, j = 0..=2^c_bits.
    pub c_bits: u32,
    /// The tolerance on |lobe - cos^n|.
    pub tol: Tolerance,
}

impl Default for Grid {
    /// n = 1..=4096, c in steps of 2^-15 (the baseline's input resolution), 1 lsb8.
    fn default() -> Grid {
        Grid {
            n: NSet::range(1, 4096).expect("valid range"),
            c_bits: 15,
            tol: Tolerance::default(),
        }
    }
}

/// The extent of a region at one n.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct NBounds {
    /// The exponent.
    pub n: u32,
    /// The smallest flagged cosine.
    pub c_lo: f64,
    /// The largest flagged cosine.
    pub c_hi: f64,
    /// Flagged samples at this n.
    pub samples: u64,
}

impl NBounds {
    /// The angle range in degrees, smallest first (theta of `c_hi`, theta of `c_lo`).
    pub fn theta_deg(&self) -> (f64, f64) {
        (
            self.c_hi.clamp(-1.0, 1.0).acos().to_degrees(),
            self.c_lo.clamp(-1.0, 1.0).acos().to_degrees(),
        )
    }
}

/// Every sample of one path flagged with one kind.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Region {
    /// The kind.
    pub kind: Kind,
    /// Flagged samples.
    pub samples: u64,
    /// Of those, samples off by more than the tolerance.
    pub failing: u64,
    /// Whether the region is a failure: some sample in it is off by more than the tolerance,
    /// the lobe falls by more than the tolerance somewhere in it (non-monotonic), or its kind
    /// is a failure by itself (non-finite, unrepresentable).
    pub fails: bool,
    /// The smallest n with a flagged sample.
    pub n_min: u32,
    /// The largest.
    pub n_max: u32,
    /// The smallest flagged cosine (the largest angle).
    pub c_min: f64,
    /// The largest flagged cosine (the smallest angle).
    pub c_max: f64,
    /// The largest |lobe - cos^n| in the region (finite samples).
    pub worst_abs_err: f64,
    /// Its exponent.
    pub worst_n: u32,
    /// Its cosine.
    pub worst_c: f64,
    /// For `non_monotonic`: the largest fall of the lobe between neighbouring samples.
    pub max_drop: f64,
    /// The stages involved (overflow kinds of a datapath).
    pub stages: Vec<String>,
    /// A remark (for `unrepresentable`, the first n's validation error).
    pub note: Option<String>,
    /// The extent at the region's first and last n and at every power of two in between.
    pub at_n: Vec<NBounds>,
    /// The extent at each n with a flagged sample, ascending.
    #[serde(skip)]
    pub per_n: Vec<NBounds>,
}

impl Region {
    /// The extent at `n`, if the region has a sample there.
    pub fn at(&self, n: u32) -> Option<&NBounds> {
        self.per_n
            .binary_search_by_key(&n, |b| b.n)
            .ok()
            .map(|i| &self.per_n[i])
    }
}

/// One heat-map cell: the samples of a column of exponents and one degree of theta.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct Cell {
    /// Samples in the cell.
    pub samples: u32,
    /// The largest |lobe - cos^n| of its finite samples.
    pub max_abs_err: f64,
    /// The union of its samples' kinds ([`Kind::bit`]).
    pub flags: u16,
}

/// A heat map: columns of exponents by rows of one degree of theta.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct HeatMap {
    /// Each column's first and last exponent.
    pub columns: Vec<(u32, u32)>,
    /// `cells[col * HEAT_ROWS + row]`; row r covers theta in [r, r + 1) degrees (90 in the
    /// last).
    pub cells: Vec<Cell>,
}

impl HeatMap {
    /// The cell of a column and a row.
    pub fn cell(&self, col: usize, row: usize) -> &Cell {
        &self.cells[col * HEAT_ROWS + row]
    }
}

/// The map of one path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PathMap {
    /// The path's name.
    pub path: String,
    /// `f64`, `f32` or `fixed`.
    pub precision: String,
    /// The input resolution: fraction bits of the cosine samples.
    pub c_bits: u32,
    /// Samples evaluated.
    pub samples: u64,
    /// The largest |lobe - cos^n| over the map.
    pub max_abs_err: f64,
    /// Its exponent and cosine.
    pub worst_n: u32,
    /// Its cosine.
    pub worst_c: f64,
    /// Every region, in [`Kind::ALL`] order.
    pub regions: Vec<Region>,
    /// For a datapath, the exponents its configuration was designed for (its own `n`, which
    /// the map replaces by the grid's), smallest and largest; its inputs are every code from
    /// 0 to 1.0, theta 0..=90 degrees. `None` for a float path.
    pub design_n: Option<(u32, u32)>,
    /// The heat map.
    #[serde(skip)]
    pub heat: HeatMap,
}

impl PathMap {
    /// The region of a kind, if any sample has it.
    pub fn region(&self, kind: Kind) -> Option<&Region> {
        self.regions.iter().find(|r| r.kind == kind)
    }

    /// Whether the path stays within the tolerance everywhere and has no failing region.
    pub fn passes(&self) -> bool {
        !self.regions.iter().any(|r| r.fails)
    }
}

/// The heat-map row of a cosine.
fn heat_row(c: f64) -> usize {
    let deg = c.clamp(0.0, 1.0).acos().to_degrees();
    (deg.floor() as usize).min(HEAT_ROWS - 1)
}

/// Groups sorted exponents into heat-map columns at least 1/16 octave wide (each n alone
/// while it is that wide by itself).
///
/// # Examples
/// ```
/// use specfx::analysis::stability::heat_columns;
/// let cols = heat_columns(&(1..=40).collect::<Vec<_>>());
/// assert_eq!(cols[0], (1, 1));
/// assert_eq!(cols[21], (22, 22)); // log2(23/22) >= 1/16
/// assert_eq!(cols[22], (23, 24)); // log2(24/23) < 1/16: two exponents
/// ```
pub fn heat_columns(ns: &[u32]) -> Vec<(u32, u32)> {
    let mut cols = Vec::new();
    let mut i = 0;
    while i < ns.len() {
        let first = ns[i];
        let mut j = i;
        while j + 1 < ns.len()
            && (f64::from(ns[j]) + 1.0).log2() - f64::from(first).log2() < 1.0 / 16.0
        {
            j += 1;
        }
        cols.push((first, ns[j]));
        i = j + 1;
    }
    cols
}

/// Per-kind accumulator of one path at one n.
#[derive(Debug, Clone, Copy, PartialEq)]
struct KindAcc {
    samples: u64,
    failing: u64,
    c_lo: f64,
    c_hi: f64,
    worst: f64,
    worst_c: f64,
    stage_mask: u32,
    max_drop: f64,
}

impl KindAcc {
    fn new() -> KindAcc {
        KindAcc {
            samples: 0,
            failing: 0,
            c_lo: f64::INFINITY,
            c_hi: f64::NEG_INFINITY,
            worst: -1.0,
            worst_c: 0.0,
            stage_mask: 0,
            max_drop: 0.0,
        }
    }
}

/// One path at one n: per-kind accumulators and its heat rows.
#[derive(Debug, Clone)]
struct NAcc {
    kinds: [KindAcc; 10],
    rows: [Cell; HEAT_ROWS],
    samples: u64,
    max_abs_err: f64,
    worst_c: f64,
    unrepresentable: bool,
}

impl NAcc {
    fn new() -> NAcc {
        NAcc {
            kinds: [KindAcc::new(); 10],
            rows: [Cell::default(); HEAT_ROWS],
            samples: 0,
            max_abs_err: -1.0,
            worst_c: 0.0,
            unrepresentable: false,
        }
    }

    /// Records one sample: its cosine, heat row, error, flags, overflowing stages and how much
    /// the lobe fell from the sample before.
    #[inline]
    fn add(&mut self, c: f64, row: usize, err: f64, flags: u16, stage_mask: u32, drop: f64) {
        self.samples += 1;
        let abs = err.abs();
        let cell = &mut self.rows[row];
        cell.samples += 1;
        cell.flags |= flags;
        if abs > cell.max_abs_err {
            cell.max_abs_err = abs;
        }
        if abs > self.max_abs_err {
            self.max_abs_err = abs;
            self.worst_c = c;
        }
        if flags == 0 {
            return;
        }
        let failing = flags & FAIL_BITS != 0;
        let mut bits = flags;
        while bits != 0 {
            let i = bits.trailing_zeros() as usize;
            bits &= bits - 1;
            let k = &mut self.kinds[i];
            k.samples += 1;
            k.failing += u64::from(failing);
            k.c_lo = k.c_lo.min(c);
            k.c_hi = k.c_hi.max(c);
            if abs > k.worst {
                k.worst = abs;
                k.worst_c = c;
            }
            if i == Kind::Wrap as usize || i == Kind::Saturate as usize {
                k.stage_mask |= stage_mask;
            }
            if i == Kind::NonMonotonic as usize {
                k.max_drop = k.max_drop.max(drop);
            }
        }
    }
}

/// Flags of an error against the tolerance.
#[inline]
fn error_flags(err: f64, tol: f64) -> u16 {
    if err > tol {
        Kind::Over.bit()
    } else if err < -tol {
        Kind::Under.bit()
    } else {
        0
    }
}

/// Evaluates one float path at one n over the grid of cosines.
fn float_column(
    path: FloatPath,
    n: u32,
    cs: &[f64],
    rows: &[usize],
    reference: &[f64],
    tol: f64,
) -> NAcc {
    let p = path.prepare(n);
    let m = match path {
        FloatPath::Method(Method::CsM { k, .. }) => Some(m_of_k(k)),
        _ => None,
    };
    let n_below_m = m.is_some_and(|m| n < m);
    let min_normal = path.min_normal();
    let mut acc = NAcc::new();
    let mut prev = f64::NAN;
    let is_powf = matches!(p, Prepared::CosPow(_));
    for (j, &c) in cs.iter().enumerate() {
        // powf is the reference itself: the same call on the same input.
        let s = if is_powf {
            FloatSample {
                value: reference[j],
                base: None,
                exact_positive: c > 0.0,
            }
        } else {
            p.eval(c)
        };
        let v = s.value;
        let err = v - reference[j];
        let mut flags = if v.is_finite() {
            error_flags(err, tol)
        } else {
            Kind::NonFinite.bit()
        };
        if n_below_m && flags & FAIL_BITS != 0 {
            flags |= Kind::NBelowM.bit();
        }
        if s.base.is_some_and(|b| b < 0.0) && v != 0.0 {
            flags |= Kind::NegativeBase.bit();
        }
        if s.exact_positive && v.abs() < min_normal {
            flags |= Kind::Underflow.bit();
        }
        let drop = prev - v;
        if drop > 0.0 {
            flags |= Kind::NonMonotonic.bit();
        }
        prev = v;
        acc.add(
            c,
            rows[j],
            if err.is_finite() { err } else { 0.0 },
            flags,
            0,
            drop,
        );
    }
    acc
}

/// A fixed-point path prepared for the map: the datapath over the representable exponents.
struct FixedPlan {
    dp: Option<Datapath>,
    /// Why the first exponent the datapath cannot hold is refused.
    reason: Option<String>,
    lobe_scale: f64,
    out_scale: f64,
    /// Every code from 0 up to 1.0.
    codes: Codes,
    cs: Vec<f64>,
    rows: Vec<usize>,
}

/// The datapath of `config` over the exponents of `ns` it can hold (`None` if it holds none),
/// with why the first one it cannot hold is refused. An error that names no exponent is the
/// configuration's own and is returned.
fn representable(config: &Config, ns: &[u32]) -> Result<(Option<Datapath>, Option<String>), Error> {
    let mut good = Vec::new();
    let mut reason = None;
    for &n in ns {
        let mut cfg = config.clone();
        cfg.n = NSet::range(n, n)?;
        if let Err(e) = Datapath::new(cfg) {
            let text = e.to_string();
            if !text.contains(&format!("n = {n}")) {
                return Err(e);
            }
            reason.get_or_insert(text);
        } else {
            good.push(n);
        }
    }
    if good.is_empty() {
        return Ok((None, reason));
    }
    let mut cfg = config.clone();
    cfg.n = NSet::from_values(&good)?;
    Ok((Some(Datapath::new(cfg)?), reason))
}

fn fixed_plan(config: &Config, ns: &[u32]) -> Result<FixedPlan, Error> {
    let (dp, reason) = representable(config, ns)?;
    let (codes, lobe_scale, out_scale, c_scale) = match &dp {
        Some(dp) => {
            let scale =
                |stage_idx: usize| (-f64::from(dp.stages()[stage_idx].format.frac_bits())).exp2();
            (
                Codes::new(dp, (0..=dp.one_code()).collect()),
                scale(dp.stage_last_square()),
                scale(dp.stage_out()),
                (-f64::from(dp.config().c.format.frac_bits())).exp2(),
            )
        }
        None => (
            Codes {
                codes: Vec::new(),
                ln_c: Vec::new(),
            },
            1.0,
            1.0,
            1.0,
        ),
    };
    let cs: Vec<f64> = codes.codes.iter().map(|&c| c as f64 * c_scale).collect();
    let rows = cs.iter().map(|&c| heat_row(c)).collect();
    Ok(FixedPlan {
        dp,
        reason,
        lobe_scale,
        out_scale,
        codes,
        cs,
        rows,
    })
}

/// A fixed path's accumulator of one n: the map's figures and the previous element's lobe and
/// output (monotonicity runs across chunks).
struct FixedAcc {
    acc: NAcc,
    prev_lobe: i64,
    prev_out: i64,
}

/// Folds one chunk of the engine's stream into a fixed path's accumulator.
fn fixed_chunk(plan: &FixedPlan, dp: &Datapath, tol: f64, fa: &mut FixedAcc, chunk: &Chunk<'_>) {
    let nc = chunk.nc;
    let n = nc.n;
    let cfg = dp.config();
    let n_below_m = cfg.variant == Variant::Plain && n < m_of_k(cfg.k);
    let nf = f64::from(n);
    let cols = chunk.probes;
    let last = dp.stage_last_square();
    let out = dp.stage_out();
    // The stream visits plan.codes, which start at code 0: a code is its own index.
    for (i, &code) in chunk.codes.iter().enumerate() {
        let j = code as usize;
        let c = plan.cs[j];
        let lobe_raw = cols.values[last][i];
        let out_raw = cols.values[out][i];
        let b_raw = cols.values[STAGE_B][i];
        let lobe = lobe_raw as f64 * plan.lobe_scale;
        let err = lobe - cos_pow(c, nf);
        let mut flags = error_flags(err, tol);
        if n_below_m && flags & FAIL_BITS != 0 {
            flags |= Kind::NBelowM.bit();
        }
        if b_raw < 0 && lobe_raw != 0 {
            flags |= Kind::NegativeBase.bit();
        }
        if b_raw != 0 && lobe_raw == 0 {
            flags |= Kind::Underflow.bit();
        }
        // The fall in lobe units (an output fall is divided by the coefficient).
        let mut drop = 0.0;
        if lobe_raw < fa.prev_lobe || out_raw < fa.prev_out {
            flags |= Kind::NonMonotonic.bit();
            drop = ((fa.prev_lobe - lobe_raw) as f64 * plan.lobe_scale)
                .max((fa.prev_out - out_raw) as f64 * plan.out_scale / nc.coef);
        }
        fa.prev_lobe = lobe_raw;
        fa.prev_out = out_raw;
        let mut stage_mask = 0u32;
        if chunk.any_event() {
            for (stage_idx, e) in chunk.events(i).iter().enumerate() {
                match e {
                    Event::None => {}
                    Event::Wrapped => {
                        flags |= Kind::Wrap.bit();
                        stage_mask |= 1 << stage_idx;
                    }
                    Event::Saturated | Event::Zeroed => {
                        flags |= Kind::Saturate.bit();
                        stage_mask |= 1 << stage_idx;
                    }
                }
            }
        }
        fa.acc.add(c, plan.rows[j], err, flags, stage_mask, drop);
    }
}

/// The accumulators of a fixed path for every n of the grid, in grid order: the engine's
/// stream over the n its datapath holds, an unrepresentable accumulator for the others.
fn fixed_columns(plan: &FixedPlan, ns: &[u32], tol: f64, done: &(dyn Fn() + Sync)) -> Vec<NAcc> {
    let unrepresentable = || NAcc {
        unrepresentable: true,
        ..NAcc::new()
    };
    let Some(dp) = &plan.dp else {
        ns.iter().for_each(|_| done());
        return ns.iter().map(|_| unrepresentable()).collect();
    };
    let per_n = fold_n(
        dp,
        &plan.codes,
        |_| FixedAcc {
            acc: NAcc::new(),
            prev_lobe: i64::MIN,
            prev_out: i64::MIN,
        },
        |fa, chunk| fixed_chunk(plan, dp, tol, fa, chunk),
        done,
    );
    let mut held = dp.constants().iter().map(|nc| nc.n).zip(per_n).peekable();
    ns.iter()
        .map(|&n| match held.peek() {
            Some(&(m, _)) if m == n => held.next().expect("peeked").1.acc,
            _ => {
                done();
                unrepresentable()
            }
        })
        .collect()
}

/// Folds the per-n accumulators of one path, in n order, into its map.
/// What [`assemble`] needs to know of a path besides its accumulators.
struct PathMeta {
    name: String,
    design_n: Option<(u32, u32)>,
    precision: &'static str,
    c_bits: u32,
    stage_names: Vec<String>,
    reason: Option<String>,
}

fn assemble(meta: PathMeta, ns: &[u32], accs: Vec<NAcc>, tol: f64) -> PathMap {
    let PathMeta {
        name,
        design_n,
        precision,
        c_bits,
        stage_names,
        reason,
    } = meta;
    let stage_names = &stage_names[..];
    let columns = heat_columns(ns);
    let mut cells = vec![Cell::default(); columns.len() * HEAT_ROWS];
    let mut col = 0;
    let mut regions: Vec<Option<Region>> = vec![None; Kind::ALL.len()];
    let mut samples = 0;
    let (mut max_abs_err, mut worst_n, mut worst_c) = (0.0, ns[0], 1.0);
    for (&n, acc) in ns.iter().zip(accs) {
        while n > columns[col].1 {
            col += 1;
        }
        samples += acc.samples;
        if acc.max_abs_err > max_abs_err {
            max_abs_err = acc.max_abs_err;
            worst_n = n;
            worst_c = acc.worst_c;
        }
        for (row, r) in acc.rows.iter().enumerate() {
            let cell = &mut cells[col * HEAT_ROWS + row];
            cell.samples += r.samples;
            cell.flags |= r.flags;
            cell.max_abs_err = cell.max_abs_err.max(r.max_abs_err);
        }
        let mut kinds = acc.kinds;
        if acc.unrepresentable {
            let k = &mut kinds[Kind::Unrepresentable as usize];
            k.samples = 1;
            k.c_lo = 0.0;
            k.c_hi = 1.0;
            for row in 0..HEAT_ROWS {
                cells[col * HEAT_ROWS + row].flags |= Kind::Unrepresentable.bit();
            }
        }
        for (i, k) in kinds.iter().enumerate() {
            if k.samples == 0 {
                continue;
            }
            let kind = Kind::ALL[i];
            let reg = regions[i].get_or_insert_with(|| Region {
                kind,
                samples: 0,
                failing: 0,
                fails: false,
                n_min: n,
                n_max: n,
                c_min: k.c_lo,
                c_max: k.c_hi,
                worst_abs_err: -1.0,
                worst_n: n,
                worst_c: k.worst_c,
                max_drop: 0.0,
                stages: Vec::new(),
                note: None,
                at_n: Vec::new(),
                per_n: Vec::new(),
            });
            reg.samples += k.samples;
            reg.failing += k.failing;
            reg.n_max = n;
            reg.c_min = reg.c_min.min(k.c_lo);
            reg.c_max = reg.c_max.max(k.c_hi);
            reg.max_drop = reg.max_drop.max(k.max_drop);
            if k.worst > reg.worst_abs_err {
                reg.worst_abs_err = k.worst;
                reg.worst_n = n;
                reg.worst_c = k.worst_c;
            }
            for (stage_idx, stage) in stage_names.iter().enumerate() {
                if k.stage_mask & (1 << stage_idx) != 0 && !reg.stages.contains(stage) {
                    reg.stages.push(stage.clone());
                }
            }
            reg.per_n.push(NBounds {
                n,
                c_lo: k.c_lo,
                c_hi: k.c_hi,
                samples: k.samples,
            });
        }
    }
    let regions = regions
        .into_iter()
        .flatten()
        .map(|mut r| {
            r.worst_abs_err = r.worst_abs_err.max(0.0);
            r.fails = r.failing > 0
                || r.kind.is_structural()
                || (r.kind == Kind::NonMonotonic && r.max_drop > tol);
            if r.kind == Kind::Unrepresentable {
                r.note = reason.clone();
                r.samples = 0;
            }
            r.at_n = r
                .per_n
                .iter()
                .filter(|b| b.n.is_power_of_two() || b.n == r.n_min || b.n == r.n_max)
                .copied()
                .collect();
            // Keep the stages in pipeline order.
            r.stages.sort_by_key(|s| {
                stage_names
                    .iter()
                    .position(|x| x == s)
                    .unwrap_or(usize::MAX)
            });
            r
        })
        .collect();
    PathMap {
        path: name,
        design_n,
        precision: precision.to_string(),
        c_bits,
        samples,
        max_abs_err,
        worst_n,
        worst_c,
        regions,
        heat: HeatMap { columns, cells },
    }
}

/// The float grid: every `j / 2^c_bits` in [0, 1].
///
/// # Examples
/// ```
/// assert_eq!(specfx::analysis::stability::float_cosines(2), [0.0, 0.25, 0.5, 0.75, 1.0]);
/// ```
pub fn float_cosines(c_bits: u32) -> Vec<f64> {
    let steps = 1u64 << c_bits;
    (0..=steps)
        .map(|j| j as f64 / steps as f64)
        .collect::<Vec<f64>>()
}

/// How many exponents are evaluated in parallel between two progress reports.
const CHUNK: usize = 64;

/// The most samples one map may take (2^34, a few minutes on two cores): see [`samples`].
pub const MAX_SAMPLES: u64 = 1 << 34;

/// How many samples [`map`] takes on `grid`: each float path at every exponent and each of its
/// `2^c_bits + 1` cosines, each datapath at every exponent and each of its input codes in
/// [0, 1] (`2^f + 1` for `f` fraction bits). Saturates at `u64::MAX`.
///
/// # Examples
/// ```
/// use specfx::analysis::stability::{samples, FloatPath, Grid, Path};
/// let grid = Grid { n: "1..=10".parse().unwrap(), c_bits: 4, ..Grid::default() };
/// let paths = [Path::Float(FloatPath::PowI), Path::Float(FloatPath::PowF32)];
/// assert_eq!(samples(&paths, &grid), 2 * 10 * 17);
/// ```
pub fn samples(paths: &[Path], grid: &Grid) -> u64 {
    let ns = grid.n.values().len() as u128;
    let codes = |bits: i64| (1u128 << bits.clamp(0, 100)) + 1;
    let total: u128 = paths
        .iter()
        .map(|p| match p {
            Path::Float(_) => codes(i64::from(grid.c_bits)),
            Path::Fixed(c) => codes(i64::from(c.c.format.frac_bits())),
        })
        .map(|per_n| per_n * ns)
        .sum();
    u64::try_from(total).unwrap_or(u64::MAX)
}

/// Maps every path over the grid. `progress(done, total)` is called after each chunk of
/// exponents (of the float paths together, then of each datapath).
///
/// Fails only on a datapath configuration that is invalid whatever n is.
///
/// # Examples
/// ```
/// use specfx::analysis::stability::{map, FloatPath, Grid, Kind, Path};
/// use specfx::reference::lobe::Cutoff;
/// use specfx::reference::method::Method;
/// let grid = Grid { n: "1..=20".parse().unwrap(), c_bits: 8, ..Grid::default() };
/// let paths = [Path::Float(FloatPath::Method(Method::CsM { k: 4, cutoff: Cutoff::Clamp }))];
/// let maps = map(&paths, &grid, &|_, _| {}).unwrap();
/// // cs16 with n = 1: (1 - (1 - c)/16)^16 at c = 0 is (15/16)^16 = 0.356, cos^1 is 0.
/// let r = maps[0].region(Kind::NBelowM).unwrap();
/// assert_eq!(r.n_min, 1);
/// assert!(r.n_max < 16);
/// ```
pub fn map(
    paths: &[Path],
    grid: &Grid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Vec<PathMap>, Error> {
    if !(1..=24).contains(&grid.c_bits) {
        return Err(Error::OutOfRange {
            what: "c_bits",
            expected: "in 1..=24".into(),
            got: grid.c_bits.to_string(),
        });
    }
    let work = samples(paths, grid);
    if work > MAX_SAMPLES {
        return Err(Error::OutOfRange {
            what: "samples (exponents x cosines, summed over the paths)",
            expected: format!("at most 2^34 = {MAX_SAMPLES}"),
            got: work.to_string(),
        });
    }
    let ns = grid.n.values();
    let tol = grid.tol.value;
    let floats: Vec<FloatPath> = paths
        .iter()
        .filter_map(|p| match p {
            Path::Float(f) => Some(*f),
            Path::Fixed(_) => None,
        })
        .collect();
    let plans: Vec<(&Config, FixedPlan)> = paths
        .iter()
        .filter_map(|p| match p {
            Path::Fixed(c) => Some(c.as_ref()),
            Path::Float(_) => None,
        })
        .map(|c| fixed_plan(c, ns).map(|p| (c, p)))
        .collect::<Result<_, _>>()?;
    let total = if floats.is_empty() { 0 } else { ns.len() } + plans.len() * ns.len();
    let mut done = 0;

    let mut float_accs: Vec<Vec<NAcc>> = vec![Vec::with_capacity(ns.len()); floats.len()];
    if !floats.is_empty() {
        let cs = float_cosines(grid.c_bits);
        let rows: Vec<usize> = cs.iter().map(|&c| heat_row(c)).collect();
        for chunk in ns.chunks(CHUNK) {
            let per_n: Vec<Vec<NAcc>> = chunk
                .par_iter()
                .map(|&n| {
                    let nf = f64::from(n);
                    let reference: Vec<f64> = cs.iter().map(|&c| cos_pow(c, nf)).collect();
                    floats
                        .iter()
                        .map(|&p| float_column(p, n, &cs, &rows, &reference, tol))
                        .collect()
                })
                .collect();
            for accs in per_n {
                for (i, a) in accs.into_iter().enumerate() {
                    float_accs[i].push(a);
                }
            }
            done += chunk.len();
            progress(done, total);
        }
    }
    let mut float_maps = floats
        .iter()
        .zip(float_accs)
        .map(|(p, accs)| {
            let meta = PathMeta {
                name: p.name(),
                design_n: None,
                precision: p.precision(),
                c_bits: grid.c_bits,
                stage_names: Vec::new(),
                reason: None,
            };
            assemble(meta, ns, accs, tol)
        })
        .collect::<Vec<_>>()
        .into_iter();

    let mut fixed_maps = Vec::new();
    for (config, plan) in &plans {
        let base = done;
        let finished = std::sync::atomic::AtomicUsize::new(0);
        let accs = fixed_columns(plan, ns, tol, &|| {
            let now = finished.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
            progress(base + now, total);
        });
        done += ns.len();
        let stage_names: Vec<String> = plan
            .dp
            .as_ref()
            .map(|dp| dp.stages().iter().map(|s| s.name.clone()).collect())
            .unwrap_or_default();
        let c_bits = config.c.format.frac_bits().max(0) as u32;
        let meta = PathMeta {
            name: config.name.clone(),
            design_n: Some((config.n.min(), config.n.max())),
            precision: "fixed",
            c_bits,
            stage_names,
            reason: plan.reason.clone(),
        };
        fixed_maps.push(assemble(meta, ns, accs, tol));
    }
    let mut fixed_maps = fixed_maps.into_iter();
    // Back in the order the paths were given.
    Ok(paths
        .iter()
        .map(|p| match p {
            Path::Float(_) => float_maps.next().expect("one map per float path"),
            Path::Fixed(_) => fixed_maps.next().expect("one map per datapath"),
        })
        .collect())
}

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
pub enum Verdict {
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

impl Verdict {
    /// Whether the verdict is a failure.
    pub fn fails(self) -> bool {
        !matches!(self, Verdict::Ok | Verdict::Absorbed)
    }

    /// The name used in tables.
    pub fn name(self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::Absorbed => "absorbed",
            Verdict::Nan => "nan",
            Verdict::Inf => "inf",
            Verdict::Negative => "negative",
            Verdict::Off => "off",
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
    pub verdict: Verdict,
}

/// Judges an output against what the input asks for.
///
/// # Examples
/// ```
/// use specfx::analysis::stability::{judge, Verdict};
/// assert_eq!(judge(f64::NAN, 0.0, 16, 1e-3), Verdict::Absorbed);
/// assert_eq!(judge(f64::NAN, f64::NAN, 16, 1e-3), Verdict::Nan);
/// assert_eq!(judge(-0.5, -1e-9, 16, 1e-3), Verdict::Negative);
/// assert_eq!(judge(1.5, 1.0 + 1e-6, 16, 1e-3), Verdict::Ok);
/// ```
pub fn judge(c: f64, out: f64, n: u32, tol: f64) -> Verdict {
    if out.is_nan() {
        Verdict::Nan
    } else if out.is_infinite() {
        Verdict::Inf
    } else if out < 0.0 {
        Verdict::Negative
    } else if !c.is_finite() {
        if out <= 1.0 + tol {
            Verdict::Absorbed
        } else {
            Verdict::Off
        }
    } else if (out - cos_pow(c.clamp(0.0, 1.0), f64::from(n))).abs() > tol {
        Verdict::Off
    } else {
        Verdict::Ok
    }
}

fn show(x: f64) -> String {
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
pub fn special_outcomes(paths: &[Path], tol: f64) -> Result<Vec<SpecialOutcome>, Error> {
    let mut v = Vec::new();
    for path in paths {
        let fixed = match path {
            // Exponents it cannot hold are skipped.
            Path::Fixed(c) => match representable(c, &SPECIAL_N)?.0 {
                Some(dp) => Some(dp),
                None => continue,
            },
            Path::Float(_) => None,
        };
        for input in special_inputs() {
            for n in SPECIAL_N {
                let out = match (path, &fixed) {
                    (Path::Float(p), _) => p.prepare(n).eval(input.c).value,
                    (Path::Fixed(_), Some(dp)) => {
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
                    (Path::Fixed(_), None) => continue,
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

/// Whether a float path's output at `1 + j 2^-23` overshoots: not finite, negative, or above
/// its own value at c = 1 by more than `tol`.
fn overshoots(p: &Prepared, at_one: f64, j: u32, tol: f64) -> bool {
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
pub fn overshoot(paths: &[Path], grid: &Grid) -> Vec<Overshoot> {
    let ns = grid.n.values();
    paths
        .iter()
        .filter_map(|p| match p {
            Path::Float(f) => Some(*f),
            Path::Fixed(_) => None,
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

/// Everything `specfx stability` computes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StabilityReport {
    /// The grid.
    pub grid: Grid,
    /// One map per path.
    pub maps: Vec<PathMap>,
    /// The special inputs.
    pub special: Vec<SpecialOutcome>,
    /// The overshoot thresholds of the float paths.
    pub overshoot: Vec<Overshoot>,
}

/// Maps, special inputs and overshoot of every path.
pub fn analyse(
    paths: &[Path],
    grid: &Grid,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<StabilityReport, Error> {
    let maps = map(paths, grid, progress)?;
    Ok(StabilityReport {
        grid: grid.clone(),
        maps,
        special: special_outcomes(paths, grid.tol.value)?,
        overshoot: overshoot(paths, grid),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn heat_rows_cover_zero_to_ninety_degrees() {
        assert_eq!(heat_row(1.0), 0);
        assert_eq!(heat_row(0.0), HEAT_ROWS - 1);
        // cos(45.5 degrees) is in row 45.
        assert_eq!(heat_row(45.5f64.to_radians().cos()), 45);
    }

    #[test]
    fn columns_partition_the_exponents() {
        let ns: Vec<u32> = (1..=4096).collect();
        let cols = heat_columns(&ns);
        assert_eq!(cols.first(), Some(&(1, 1)));
        assert_eq!(cols.last().map(|c| c.1), Some(4096));
        for w in cols.windows(2) {
            assert_eq!(w[0].1 + 1, w[1].0);
        }
        // 22 single columns (while log2((n+1)/n) >= 1/16), then about 1/16 octave each over
        // the 7.5 octaves from 23 to 4096.
        assert!((125..=140).contains(&cols.len()), "{}", cols.len());
    }

    #[test]
    fn tolerance_errors_name_what_was_expected() {
        let e = "lsb".parse::<Tolerance>().unwrap_err().to_string();
        assert!(
            e.starts_with("the tolerance must be a positive number"),
            "{e}"
        );
    }
}
