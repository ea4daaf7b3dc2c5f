//! The validated datapath and its bit-accurate evaluation: per-n constants, stages and probes.
//!
//! [`Datapath::new`] validates a [`Config`] once (every format can hold what it must, every
//! exact intermediate fits in `i128`, every per-n constant fits its format). After that,
//! [`Datapath::eval`] cannot fail: overflow is modelled by each stage's mode and reported as an
//! [`Event`] in the [`Probes`].

use crate::error::Error;
use crate::fixed::{quantize, Event, Exact, Format, Overflow};
use crate::pipeline::config::{Config, Depth, Variant};
use crate::pipeline::fast::BatchPlan;
use crate::pipeline::walk::Stage;
use crate::reference::lobe::{m_of_k, Cutoff, PAPER_CUTOFF_CONSTANT};
use crate::reference::minimax;
use crate::reference::normalisation::coefficient;

mod batch;
mod cut;
mod eval;

use batch::ChainTable;
pub use batch::{OutputScratch, ProbeColumns, MAX_CHAIN_TABLE};
pub use cut::first_code_where;

/// The most stages a datapath can have: d, t, b, seven squarings, coef and out.
pub const MAX_STAGES: usize = 3 + crate::reference::lobe::K_MAX as usize + 2;

/// Index of the d = c - 1 probe.
pub const STAGE_D: usize = 0;
/// Index of the t = d * slope probe.
pub const STAGE_T: usize = 1;
/// Index of the b = t + offset (after the cutoff) probe.
pub const STAGE_B: usize = 2;
/// Index of the first squaring's probe; squaring i (0-based) is at `STAGE_SQ0 + i`.
pub const STAGE_SQ0: usize = 3;

/// Widest exact intermediate the model computes, in bits (it lives in an `i128`).
const MAX_EXACT_BITS: u32 = 126;

/// A stage as reports and vector files name it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StageInfo {
    /// The stage.
    pub stage: Stage,
    /// Its name: `d`, `t`, `b`, `sq1`..`sqk`, `coef` or `out`.
    pub name: String,
    /// The format of the stage's value.
    pub format: Format,
}

/// The constants of one exponent n, as the datapath stores them, with their f64 originals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NConstants {
    /// The exponent.
    pub n: u32,
    /// The squaring stages that square at this n, j(n) in 1..=k; the rest pass their input
    /// through (k for a fixed depth).
    pub depth: u32,
    /// Raw slope: n << (k - j(n)) (plain: the value n / 2^j(n) with k fraction bits) or A(n)
    /// quantized (minimax).
    pub slope_raw: i64,
    /// Fraction bits of the slope: k (plain, the shift by k) or those of A's format.
    pub slope_frac: i32,
    /// Raw offset: 1 (plain) or A(n) + B(n) quantized (minimax).
    pub offset_raw: i64,
    /// Fraction bits of the offset.
    pub offset_frac: i32,
    /// Paper cutoff: the base is zero when the input code is below this code.
    pub threshold: Option<i64>,
    /// Raw coefficient in the coefficient's format.
    pub coef_raw: i64,
    /// The slope before quantization (n/m, or A(n)).
    pub slope: f64,
    /// The offset before quantization (1, or A(n) + B(n)).
    pub offset: f64,
    /// The coefficient before quantization.
    pub coef: f64,
}

/// Every stage's value for one evaluation, indexed like [`Datapath::stages`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Probes {
    /// Raw values in each stage's format (unused slots are 0).
    pub values: [i64; MAX_STAGES],
    /// The overflow event of each stage's quantization.
    pub events: [Event; MAX_STAGES],
    /// The cutoff forced the base to zero (negative base clamped, or paper threshold).
    pub cut: bool,
    /// The input was above 1.0 and clamped to 1.0.
    pub input_clamped: bool,
}

impl Default for Probes {
    fn default() -> Probes {
        Probes {
            values: [0; MAX_STAGES],
            events: [Event::None; MAX_STAGES],
            cut: false,
            input_clamped: false,
        }
    }
}

/// A validated datapath: the configuration, its stages and its per-n constants.
#[derive(Debug, Clone)]
pub struct Datapath {
    config: Config,
    stages: Vec<StageInfo>,
    constants: Vec<NConstants>,
    one_raw: i64,
    d_shift: u32,
    plan: BatchPlan,
    /// The squaring chain tabulated by b's code, one per depth j (index j), built on first use.
    chain: [std::sync::OnceLock<Option<ChainTable>>; crate::reference::lobe::K_MAX as usize + 1],
    cut_is_prefix: bool,
    lobe_monotone: bool,
}

/// Where the cutoff can force the base to zero, as far as the configuration proves it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CutStructure {
    /// Never (`cutoff = "none"`).
    Never,
    /// On a prefix of the input codes for every n: the paper cutoff, or the clamp behind a
    /// saturating t with non-negative slopes.
    Prefix,
    /// Anywhere: the clamp behind a t that wraps or overflows to zero.
    Scan,
}

fn config_error(key: &str, problem: String) -> Error {
    Error::Config {
        key: key.to_string(),
        problem,
    }
}

/// Bits needed for the magnitude of a product of raws of widths `a` and `b`.
fn product_bits(a: u32, b: u32) -> u32 {
    a + b
}

/// Width of the exact sum of two formats aligned on the larger fraction.
fn sum_bits(a: Format, b: Format) -> u32 {
    let frac = a.frac_bits().max(b.frac_bits());
    let int = a.int_bits().max(b.int_bits());
    u32::try_from(i64::from(int) + i64::from(frac) + 1).unwrap_or(u32::MAX)
}

/// Rounds an f64 constant into a format; it must fit, or the error names the configuration
/// `key` and says which constant (`what`, e.g. `coef(n = 500)`) does not fit.
fn constant_raw(
    value: Exact,
    format: Format,
    rounding: crate::fixed::Rounding,
    key: &str,
    what: impl FnOnce() -> String,
) -> Result<i64, Error> {
    let q = quantize(value, format, rounding, Overflow::Sat);
    if q.event == Event::None {
        Ok(q.raw)
    } else {
        Err(config_error(
            key,
            format!(
                "{} = {} does not fit {format} (range {}..={})",
                what(),
                value.to_f64(),
                format.min_value(),
                format.max_value()
            ),
        ))
    }
}

impl Datapath {
    /// Validates a configuration and computes its per-n constants.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// assert_eq!(dp.stages().len(), 9); // d, t, b, sq1..sq4, coef, out
    /// let mut bad = Config::baseline();
    /// bad.c.format = "u0.16".parse().unwrap();
    /// assert_eq!(
    ///     Datapath::new(bad).unwrap_err().to_string(),
    ///     "c.format: must represent 1.0 exactly, got u0.16"
    /// );
    /// ```
    pub fn new(config: Config) -> Result<Datapath, Error> {
        super::config::check_name(&config.name).map_err(|e| config_error("name", e))?;
        let k = config.k;
        if !crate::reference::lobe::K_RANGE.contains(&k) {
            return Err(config_error(
                "k",
                format!(
                    "expected a number of squarings in {}, got {k}",
                    crate::reference::lobe::K_RANGE_TEXT
                ),
            ));
        }
        for (key, value) in [
            ("latency.sub", config.latency.sub),
            ("latency.mul", config.latency.mul),
            ("latency.add", config.latency.add),
        ] {
            if !(1..=8).contains(&value) {
                return Err(config_error(
                    key,
                    format!("expected a register latency in 1..=8, got {value}"),
                ));
            }
        }
        if config.square.len() != k as usize {
            return Err(config_error(
                "square",
                format!(
                    "expected k = {k} squaring stages, got {}",
                    config.square.len()
                ),
            ));
        }
        // The input must hold 1.0 exactly (values above it are clamped to it).
        let cf = config.c.format;
        if cf.frac_bits() < 0 || cf.frac_bits() > 62 || cf.max_raw() < (1i64 << cf.frac_bits()) {
            return Err(config_error(
                "c.format",
                format!("must represent 1.0 exactly, got {cf}"),
            ));
        }
        let one_raw = 1i64 << cf.frac_bits();
        // d = c - 1 must be exact for every clamped input.
        let df = config.d.format;
        let d_shift = df.frac_bits() - cf.frac_bits();
        // Printed exactly: through f64, c - 1 of s64.0 would read as a value s64.0 holds.
        let d_min_text = exact_decimal(
            i128::from(cf.min_raw()) - i128::from(one_raw),
            cf.frac_bits() as u32,
        );
        // The bound is compared exactly (in i128): through f64, c - 1 of s64.0 would pass.
        let d_exact = (0..=62).contains(&d_shift)
            && df.max_value() >= 0.0
            && (i128::from(cf.min_raw()) - i128::from(one_raw)) << d_shift
                >= i128::from(df.min_raw());
        if !d_exact {
            return Err(config_error(
                "d.format",
                format!(
                    "must hold c - 1 exactly for every input of {cf} (at least {} fraction bits, range down to {d_min_text}), got {df}",
                    cf.frac_bits()
                ),
            ));
        }
        let d_shift = d_shift as u32;
        check_depth(&config)?;

        let mut constants = Vec::with_capacity(config.n.len());
        for &n in config.n.values() {
            constants.push(Self::constants_of(&config, n, one_raw)?);
        }

        // Every exact intermediate must fit in an i128.
        let slope_bits = match config.variant {
            Variant::Plain => config.constant_formats().0.width() + 1,
            Variant::Minimax => config.minimax.a_format.width(),
        };
        let offset_format = match config.variant {
            Variant::Plain => Format::unsigned(2, 0).expect("valid"),
            Variant::Minimax => config.minimax.offset_format,
        };
        // Each check names the stage whose exact input it is: t (d * slope), b (t + offset),
        // square[i] (the square of the stage before it), out (sq_k * coef).
        let mut checks = vec![
            ("t".to_string(), product_bits(df.width(), slope_bits)),
            ("b".to_string(), sum_bits(config.t.format, offset_format)),
        ];
        let mut prev = config.b.format;
        for (i, sq) in config.square.iter().enumerate() {
            checks.push((
                format!("square[{}]", i + 1),
                product_bits(prev.width(), prev.width()),
            ));
            prev = sq.format;
        }
        checks.push((
            "out".to_string(),
            product_bits(prev.width(), config.coef.format.width()),
        ));
        for (stage, bits) in checks {
            if bits > MAX_EXACT_BITS {
                return Err(config_error(
                    &stage,
                    format!(
                        "the stage's exact input would need {bits} bits; the model computes at most {MAX_EXACT_BITS}: narrow the formats feeding it"
                    ),
                ));
            }
        }

        let stages = Stage::all(k as usize)
            .into_iter()
            .map(|stage| StageInfo {
                stage,
                name: stage.to_string(),
                format: match stage {
                    Stage::D => df,
                    Stage::T => config.t.format,
                    Stage::B => config.b.format,
                    Stage::Square(i) => config.square[i].format,
                    Stage::Coef => config.coef.format,
                    Stage::Out => config.out.format,
                },
            })
            .collect();
        let plan = Self::batch_plan(&config, &constants);
        // t is non-decreasing in c when every slope is >= 0 and t saturates (every rounding
        // mode is monotone; WRAP and SAT_ZERO are not): then so is t + offset, and the clamp
        // cuts a prefix of the codes. The paper cutoff cuts the codes below a threshold.
        let cut_is_prefix = match config.cutoff {
            Cutoff::Paper => true,
            Cutoff::Clamp => {
                matches!(config.t.overflow, Overflow::Sat | Overflow::SatSym)
                    && constants.iter().all(|c| c.slope_raw >= 0)
            }
            Cutoff::None => false,
        };
        let mut dp = Datapath {
            config,
            stages,
            constants,
            one_raw,
            d_shift,
            plan,
            chain: std::array::from_fn(|_| std::sync::OnceLock::new()),
            cut_is_prefix,
            lobe_monotone: false,
        };
        dp.lobe_monotone = dp.prove_lobe_monotone();
        Ok(dp)
    }

    fn constants_of(config: &Config, n: u32, one_raw: i64) -> Result<NConstants, Error> {
        let k = config.k;
        // The lobe used at n: m(n) = 2^j(n) squarings, its constants and its coefficient.
        let j = config.depth_of(n);
        let nf = f64::from(n);
        let (slope_raw, slope_frac, offset_raw, offset_frac, slope, offset) = match config.variant {
            Variant::Plain => (
                i64::from(n) << (k - j),
                k as i32,
                1,
                0,
                nf / f64::from(m_of_k(j)),
                1.0,
            ),
            Variant::Minimax => {
                let fit = minimax::constants(n, j).map_err(|e| {
                    config_error(
                        "n",
                        format!("the minimax variant needs a cached entry: {e}"),
                    )
                })?;
                let mm = &config.minimax;
                let a = Exact::from_f64(fit.a).expect("finite table entry");
                let b = Exact::from_f64(fit.b).expect("finite table entry");
                let a_raw = constant_raw(a, mm.a_format, mm.rounding, "minimax.a_format", || {
                    format!("A(n = {n})")
                })?;
                let off_raw = constant_raw(
                    a + b,
                    mm.offset_format,
                    mm.rounding,
                    "minimax.offset_format",
                    || format!("A(n = {n}) + B(n = {n})"),
                )?;
                (
                    a_raw,
                    mm.a_format.frac_bits(),
                    off_raw,
                    mm.offset_format.frac_bits(),
                    fit.a,
                    fit.a + fit.b,
                )
            }
        };
        let coef = coefficient(config.coef.form, config.coef.source, nf, j);
        let coef_exact = Exact::from_f64(coef).ok_or_else(|| {
            config_error(
                "coef.source",
                format!("coef(n = {n}) is not finite: {coef}"),
            )
        })?;
        let coef_raw = constant_raw(
            coef_exact,
            config.coef.format,
            config.coef.rounding,
            "coef.format",
            || format!("coef(n = {n})"),
        )?;
        let threshold = match config.cutoff {
            Cutoff::Paper => Some(paper_threshold(n, config.c.format, one_raw)),
            Cutoff::Clamp | Cutoff::None => None,
        };
        Ok(NConstants {
            n,
            depth: j,
            slope_raw,
            slope_frac,
            offset_raw,
            offset_frac,
            threshold,
            coef_raw,
            slope,
            offset,
            coef,
        })
    }

    /// The configuration this datapath was built from.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// The stages in pipeline order: d, t, b, sq1..sqk, coef, out.
    pub fn stages(&self) -> &[StageInfo] {
        &self.stages
    }

    /// Index of the k-th (last) squaring's probe.
    pub fn stage_last_square(&self) -> usize {
        STAGE_SQ0 + self.config.k as usize - 1
    }

    /// The first squaring stage (0-based) that some exponent of the set bypasses: the
    /// smallest depth j(n) over the set, k when every n squares k times. Stages from it on
    /// need a bypass multiplexer; the depth field travels with the data as far as them.
    pub fn bypass_from(&self) -> usize {
        self.constants
            .iter()
            .map(|c| c.depth as usize)
            .min()
            .unwrap_or(self.config.k as usize)
    }

    /// Index of the coefficient probe.
    pub fn stage_coef(&self) -> usize {
        STAGE_SQ0 + self.config.k as usize
    }

    /// The width in bits of the widest stage format (the shared register of the folded unit).
    pub fn widest_stage_bits(&self) -> u32 {
        self.stages
            .iter()
            .map(|s| s.format.width())
            .max()
            .unwrap_or(1)
    }

    /// Index of the output probe.
    pub fn stage_out(&self) -> usize {
        STAGE_SQ0 + self.config.k as usize + 1
    }

    /// The per-n constants, in the order of the configuration's n set.
    pub fn constants(&self) -> &[NConstants] {
        &self.constants
    }

    /// The constants of one n of the set.
    pub fn constants_for(&self, n: u32) -> Option<&NConstants> {
        self.config
            .n
            .values()
            .binary_search(&n)
            .ok()
            .map(|i| &self.constants[i])
    }

    /// The constants of `n`, or [`Error::Domain`] naming the input (`what`, e.g. `n` or
    /// `n[3]`) when `n` is not in the configuration's set: what a testbench's call is checked
    /// with.
    pub fn constants_checked(&self, n: u32, what: &str) -> Result<&NConstants, Error> {
        self.constants_for(n).ok_or_else(|| Error::Domain {
            message: format!(
                "{what} = {n} is not in the configuration's exponent set {}",
                self.config.n
            ),
        })
    }

    /// Refuses, with [`Error::Domain`], a code outside the input format (`what` names it,
    /// e.g. `c` or `c[3]`).
    pub fn check_code(&self, c_raw: i64, what: &str) -> Result<(), Error> {
        let codes = self.input_codes();
        if codes.contains(&c_raw) {
            return Ok(());
        }
        Err(Error::Domain {
            message: format!(
                "{what} = {c_raw} is not a code of the input format {} (expected {}..={})",
                self.config.c.format,
                codes.start(),
                codes.end()
            ),
        })
    }

    /// The raw input code of 1.0.
    pub fn one_code(&self) -> i64 {
        self.one_raw
    }

    /// Every raw input code of the input format.
    pub fn input_codes(&self) -> std::ops::RangeInclusive<i64> {
        let f = self.config.c.format;
        f.min_raw()..=f.max_raw()
    }
}

/// Refuses a depth rule that does not give every exponent of the set a depth in 1..=k.
fn check_depth(config: &Config) -> Result<(), Error> {
    let k = config.k;
    let (n_min, n_max) = (config.n.min(), config.n.max());
    match &config.depth {
        Depth::Fixed => Ok(()),
        Depth::Best if n_max > minimax::TABLE_N_MAX => Err(config_error(
            "depth",
            format!(
                "\"best\" ranks the depths by the minimax table's floors, which end at n = {}; the set reaches n = {n_max}",
                minimax::TABLE_N_MAX
            ),
        )),
        Depth::Best => Ok(()),
        Depth::Steps(steps) => {
            let Some(first) = steps.first() else {
                return Err(config_error(
                    "depth",
                    "expected at least one { from = N, j = J } step".to_string(),
                ));
            };
            if first.from > n_min {
                return Err(config_error(
                    "depth",
                    format!(
                        "the first step starts at n = {}, after the set's first exponent {n_min}: expected from <= {n_min}",
                        first.from
                    ),
                ));
            }
            for (i, step) in steps.iter().enumerate() {
                if !(1..=k).contains(&step.j) {
                    return Err(config_error(
                        "depth",
                        format!(
                            "step {} (from = {}): expected j in 1..=k = 1..={k}, got {}",
                            i + 1,
                            step.from,
                            step.j
                        ),
                    ));
                }
                if i > 0 && step.from <= steps[i - 1].from {
                    return Err(config_error(
                        "depth",
                        format!(
                            "step {} starts at n = {}, not after the step before (from = {}): expected increasing from",
                            i + 1,
                            step.from,
                            steps[i - 1].from
                        ),
                    ));
                }
            }
            Ok(())
        }
    }
}

/// The paper cutoff's threshold code for n: the smallest input code whose value is at least
/// cos(min(6/sqrt(n), pi)), so that `c < threshold` exactly when theta > 6/sqrt(n).
pub fn paper_threshold(n: u32, c_format: Format, one_raw: i64) -> i64 {
    let x = (PAPER_CUTOFF_CONSTANT / f64::from(n).sqrt())
        .min(std::f64::consts::PI)
        .cos();
    // x * 2^frac is exact (a power-of-two scaling); its ceiling is the first code >= x.
    let scaled = (x * one_raw as f64).ceil();
    (scaled as i64).clamp(c_format.min_raw(), c_format.max_raw())
}

/// The exact decimal value of `raw * 2^-frac_bits` (`frac_bits <= 62`): every digit, no
/// rounding through f64.
fn exact_decimal(raw: i128, frac_bits: u32) -> String {
    let sign = if raw < 0 { "-" } else { "" };
    let abs = raw.unsigned_abs();
    let mask = (1u128 << frac_bits) - 1;
    let mut text = format!("{sign}{}", abs >> frac_bits);
    let mut rest = abs & mask;
    if rest != 0 {
        text.push('.');
        while rest != 0 {
            rest *= 10;
            text.push(char::from(b'0' + (rest >> frac_bits) as u8));
            rest &= mask;
        }
    }
    text
}
