//! The validated datapath and its bit-accurate evaluation: per-n constants, stages and probes.
//!
//! [`Datapath::new`] validates a [`Config`] once (every format can hold what it must, every
//! exact intermediate fits in `i128`, every per-n constant fits its format). After that,
//! [`Datapath::eval`] cannot fail: overflow is modelled by each stage's mode and reported as an
//! [`Event`] in the [`Probes`].

use crate::error::Error;
use crate::fixed::{quantize, Event, Exact, Format, Overflow, Quantized};
use crate::pipeline::config::{Config, Depth, Variant};
use crate::pipeline::fast::{
    constant_bits, count_event, magnitude_bits, quantize_to, BatchPlan, EventCounts, Kernel, Pre,
};
use crate::pipeline::walk::{walk, Arithmetic, Stage};
use crate::reference::lobe::{m_of_k, Cutoff, PAPER_CUTOFF_CONSTANT};
use crate::reference::minimax;
use crate::reference::normalisation::coefficient;

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

/// The probes of a batch of evaluations, one column per stage (structure of arrays).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ProbeColumns {
    /// `values[stage_idx][i]`: raw value of stage `stage_idx` for input `i`.
    pub values: Vec<Vec<i64>>,
    /// `event_counts[stage_idx]`: how many quantizations of the batch wrapped, saturated and
    /// overflowed to zero, in that order.
    pub event_counts: Vec<EventCounts>,
    /// Scratch space for the exact sums of the b stage.
    scratch: Vec<i64>,
    /// `cut[i]`: the cutoff forced the base to zero.
    pub cut: Vec<bool>,
    /// `input_clamped[i]`: the input was above 1.0.
    pub input_clamped: Vec<bool>,
    /// The b..out columns (all but coef) hold zeros written by
    /// [`Datapath::eval_batch_cut`] and nothing has written them since.
    zero_tail: bool,
}

impl ProbeColumns {
    /// Gives every column `len` rows and clears the event counts. The rows keep whatever they
    /// held: every evaluation writes every row of the columns it promises.
    fn reset(&mut self, n_stages: usize, len: usize) {
        let same = self.values.len() == n_stages && self.cut.len() == len;
        if !same {
            self.zero_tail = false;
            self.values.resize_with(n_stages, Vec::new);
            for col in &mut self.values {
                col.resize(len, 0);
            }
            self.cut.resize(len, false);
            self.input_clamped.resize(len, false);
        }
        self.event_counts.clear();
        self.event_counts.resize(n_stages, [0; 3]);
    }

    /// The number of evaluations held.
    pub fn len(&self) -> usize {
        self.cut.len()
    }

    /// Whether no evaluation is held.
    pub fn is_empty(&self) -> bool {
        self.cut.is_empty()
    }

    /// The probes of evaluation `i`, as one [`Probes`] (without the events, which a batch only
    /// counts).
    pub fn row(&self, i: usize) -> Probes {
        let mut p = Probes::default();
        for (stage_idx, col) in self.values.iter().enumerate() {
            p.values[stage_idx] = col[i];
        }
        p.cut = self.cut[i];
        p.input_clamped = self.input_clamped[i];
        p
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

/// The first code of `codes` from which a monotone predicate holds (false on a prefix, true
/// after it), by bisection; `codes.end` when it never holds.
///
/// # Examples
/// ```
/// use specfx::pipeline::first_code_where;
/// assert_eq!(first_code_where(0..100, |c| c * c >= 50), 8);
/// assert_eq!(first_code_where(0..5, |_| false), 5);
/// assert_eq!(first_code_where(i64::MIN..i64::MAX, |c| c >= -3), -3);
/// ```
pub fn first_code_where(codes: std::ops::Range<i64>, holds: impl Fn(i64) -> bool) -> i64 {
    let (mut lo, mut hi) = (codes.start, codes.end);
    while lo < hi {
        // The midpoint in i128: a 64-bit code range would overflow `hi - lo`.
        let mid = ((i128::from(lo) + i128::from(hi)) >> 1) as i64;
        if holds(mid) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    lo
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

    /// Chooses each stage's batch kernel from a bound on its exact input: the magnitude bits
    /// of the formats and constants feeding it (a product adds its factors' bits, a sum takes
    /// the larger aligned term's bits plus one).
    fn batch_plan(config: &Config, constants: &[NConstants]) -> BatchPlan {
        // The slope's and offset's fraction bits are the same for every n.
        let (slope_frac, offset_frac) = constants
            .first()
            .map_or((0, 0), |c| (c.slope_frac, c.offset_frac));
        let slope_bits = constant_bits(constants.iter().map(|c| c.slope_raw));
        let offset_bits = constant_bits(constants.iter().map(|c| c.offset_raw));
        let coef_bits = constant_bits(constants.iter().map(|c| c.coef_raw));
        let ft = config.t.format.frac_bits();
        let fb = ft.max(offset_frac);
        let t_align = (fb - ft) as u32;
        let offset_align = (fb - offset_frac) as u32;
        let sum_bits = (magnitude_bits(config.t.format).saturating_add(t_align))
            .max(offset_bits.saturating_add(offset_align))
            .saturating_add(1);
        let mut squares = Vec::with_capacity(config.square.len());
        let mut passes = Vec::with_capacity(config.square.len());
        let mut prev = config.b.format;
        for spec in &config.square {
            squares.push(Kernel::for_stage(
                2 * prev.frac_bits(),
                2 * magnitude_bits(prev),
                spec,
            ));
            passes.push(Kernel::for_stage(
                prev.frac_bits(),
                magnitude_bits(prev),
                spec,
            ));
            prev = spec.format;
        }
        BatchPlan {
            t: Kernel::for_stage(
                config.d.format.frac_bits() + slope_frac,
                magnitude_bits(config.d.format) + slope_bits,
                &config.t,
            ),
            t_align,
            offset_align,
            b: Kernel::for_stage(fb, sum_bits, &config.b),
            squares,
            passes,
            out: Kernel::for_stage(
                prev.frac_bits() + config.coef.format.frac_bits(),
                magnitude_bits(prev) + coef_bits,
                &config.out,
            ),
        }
    }

    /// The batch plan: which stages run the `i64` kernels and which the exact fallback.
    pub fn batch_plan_of(&self) -> &BatchPlan {
        &self.plan
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

    /// Evaluates the datapath on one raw input code for one n, bit for bit.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(64).unwrap();
    /// // c = 1.0: the lobe is 1 and the output is the coefficient itself.
    /// let p = dp.eval(dp.one_code(), nc);
    /// assert_eq!(p.values[dp.stage_out()], nc.coef_raw);
    /// ```
    ///
    /// This is the plain transcription of the arithmetic (exact intermediates in `i128`,
    /// quantized by [`quantize`]); [`Datapath::eval_batch`] is its fast twin.
    pub fn eval(&self, c_raw: i64, nc: &NConstants) -> Probes {
        let mut p = Probes::default();
        let mut fixed = FixedWalk {
            dp: self,
            nc,
            c_raw,
            c: c_raw,
            probes: &mut p,
        };
        p.cut = walk(
            &mut fixed,
            self.config.cutoff,
            self.config.k as usize,
            nc.depth as usize,
        )
        .cut;
        p
    }

    /// The output code of one pair, the pair checked first: `c_raw` a code of the input
    /// format, `n` in the configuration's exponent set. What a testbench compares with
    /// `out_data`, and what the C and Python faces return for one pair.
    ///
    /// # Errors
    /// [`Error::Domain`] for a code outside the input format or an n outside the set.
    ///
    /// # Examples
    /// ```
    /// let dp = specfx::load_datapath("baseline", None).unwrap();
    /// // c = 0 at n = 16: (16/16)(0 - 1) + 1 = 0, so the output is 0.
    /// assert_eq!(dp.eval_out(0, 16).unwrap(), 0);
    /// // c = 1.0: the lobe is 1 and the output is the coefficient itself.
    /// assert_eq!(dp.eval_out(dp.one_code(), 64).unwrap(), dp.constants_for(64).unwrap().coef_raw);
    /// assert!(dp.eval_out(0, 7).is_err());
    /// ```
    pub fn eval_out(&self, c_raw: i64, n: u32) -> Result<i64, Error> {
        let nc = self.constants_checked(n, "n")?;
        self.check_code(c_raw, "c")?;
        Ok(self.eval(c_raw, nc).values[self.stage_out()])
    }

    /// The exact sum `t + offset` on the larger of their fraction bits (`b_frac`).
    #[inline]
    fn exact_sum(&self, t: i64, nc: &NConstants) -> i128 {
        let ft = self.config.t.format.frac_bits();
        let fb = self.b_frac(nc);
        (i128::from(t) << (fb - ft) as u32)
            + (i128::from(nc.offset_raw) << (fb - nc.offset_frac) as u32)
    }

    /// Fraction bits of the exact sum `t + offset`.
    #[inline]
    fn b_frac(&self, nc: &NConstants) -> i32 {
        self.config.t.format.frac_bits().max(nc.offset_frac)
    }

    /// Operation `sub`: clamps the input code to 1.0 and returns it with d = c - 1, exact in
    /// d's format.
    #[inline]
    pub fn op_sub(&self, c_raw: i64) -> (i64, i64) {
        let c = c_raw.min(self.one_raw);
        (c, (c - self.one_raw) << self.d_shift)
    }

    /// Operation `mul_t`: t = d * slope, exact (`d.frac + slope_frac` fraction bits), then
    /// quantized by t's stage.
    #[inline]
    pub fn op_mul_t(&self, d: i64, nc: &NConstants) -> Quantized {
        quantize_to(
            i128::from(d) * i128::from(nc.slope_raw),
            self.config.d.format.frac_bits() + nc.slope_frac,
            &self.config.t,
        )
    }

    /// Operation `add_b`: b = t + offset, exact on the larger fraction, then the cutoff (which
    /// needs the clamped input code `c`), then b's stage. Returns b and whether it was cut.
    #[inline]
    pub fn op_add_b(&self, t: i64, c: i64, nc: &NConstants) -> (Quantized, bool) {
        let sum = self.exact_sum(t, nc);
        let cut = self.config.cutoff.cuts(sum < 0, nc.below_threshold(c));
        let base = if cut { 0 } else { sum };
        (quantize_to(base, self.b_frac(nc), &self.config.b), cut)
    }

    /// Operation `square` number `i` (0-based): the exact square of the previous stage's raw
    /// value (doubled fraction bits), quantized by squaring stage `i`.
    #[inline]
    pub fn op_square(&self, i: usize, x: i64) -> Quantized {
        let cfg = &self.config;
        let f_in = if i == 0 {
            cfg.b.format.frac_bits()
        } else {
            cfg.square[i - 1].format.frac_bits()
        };
        quantize_to(i128::from(x) * i128::from(x), 2 * f_in, &cfg.square[i])
    }

    /// Operation `pass` number `i` (0-based): squaring stage `i` bypassed, the previous stage's
    /// raw value quantized by stage `i` (what the stage gives at an n whose depth is at most
    /// `i`).
    #[inline]
    pub fn op_pass(&self, i: usize, x: i64) -> Quantized {
        let cfg = &self.config;
        let f_in = if i == 0 {
            cfg.b.format.frac_bits()
        } else {
            cfg.square[i - 1].format.frac_bits()
        };
        quantize_to(i128::from(x), f_in, &cfg.square[i])
    }

    /// Squaring stage `i` at an n of depth `depth`: [`Datapath::op_square`] below the depth,
    /// [`Datapath::op_pass`] from it on.
    #[inline]
    pub fn op_stage(&self, i: usize, depth: u32, x: i64) -> Quantized {
        if i < depth as usize {
            self.op_square(i, x)
        } else {
            self.op_pass(i, x)
        }
    }

    /// Operation `mul_out`: out = sq_k * coef, exact, then quantized by the output stage.
    #[inline]
    pub fn op_mul_out(&self, s: i64, nc: &NConstants) -> Quantized {
        let cfg = &self.config;
        let fs = cfg.square[cfg.square.len() - 1].format.frac_bits();
        quantize_to(
            i128::from(s) * i128::from(nc.coef_raw),
            fs + cfg.coef.format.frac_bits(),
            &cfg.out,
        )
    }

    /// Evaluates a batch of raw input codes for one n into columns, stage by stage: the same
    /// results as [`Datapath::eval`] on each code, several times faster.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath, ProbeColumns};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(100).unwrap();
    /// let codes: Vec<i64> = (0..=40_000).collect();
    /// let mut cols = ProbeColumns::default();
    /// dp.eval_batch(nc, &codes, &mut cols);
    /// assert_eq!(cols.row(31_000), dp.eval(31_000, nc));
    /// ```
    pub fn eval_batch(&self, nc: &NConstants, codes: &[i64], cols: &mut ProbeColumns) {
        let n_stages = self.stages.len();
        cols.reset(n_stages, codes.len());
        cols.zero_tail = false;
        let plan = &self.plan;
        self.d_column(codes, &mut cols.values[STAGE_D], &mut cols.input_clamped);
        let stage = |cols: &mut ProbeColumns, kernel: &Kernel, pre: Pre, from: usize, to: usize| {
            let (head, tail) = cols.values.split_at_mut(to);
            kernel.run(pre, &head[from], &mut tail[0], &mut cols.event_counts[to]);
        };
        stage(cols, &plan.t, Pre::Mul(nc.slope_raw), STAGE_D, STAGE_T);
        // The exact sum and the cutoff, then the b stage.
        let (head, tail) = cols.values.split_at_mut(STAGE_B);
        self.b_column(
            nc,
            codes,
            &head[STAGE_T],
            &mut tail[0],
            &mut cols.cut,
            &mut cols.scratch,
            &mut cols.event_counts[STAGE_B],
        );
        for i in 0..plan.squares.len() {
            let (kernel, pre) = plan.square_stage(i, nc.depth);
            stage(cols, kernel, pre, STAGE_SQ0 + i - 1, STAGE_SQ0 + i);
        }
        let coef_idx = STAGE_SQ0 + plan.squares.len();
        cols.values[coef_idx].fill(nc.coef_raw);
        stage(
            cols,
            &plan.out,
            Pre::Mul(nc.coef_raw),
            coef_idx - 1,
            coef_idx + 1,
        );
    }

    /// The d stage over columns: each code clamped to 1.0, then `d = c - 1`, exact.
    fn d_column(&self, codes: &[i64], d: &mut [i64], clamped: &mut [bool]) {
        let one = self.one_raw;
        let d_shift = self.d_shift;
        for ((d, clamped), &code) in d.iter_mut().zip(clamped.iter_mut()).zip(codes) {
            *clamped = code > one;
            *d = (code.min(one) - one) << d_shift;
        }
    }

    /// The b stage over columns: the exact sum `t + offset`, the cutoff, then b's kernel (the
    /// `i64` loop when the sums are proven to fit, [`Datapath::op_add_b`] per element
    /// otherwise).
    #[allow(clippy::too_many_arguments)]
    fn b_column(
        &self,
        nc: &NConstants,
        codes: &[i64],
        t: &[i64],
        b: &mut [i64],
        cut: &mut [bool],
        sums: &mut Vec<i64>,
        counts: &mut EventCounts,
    ) {
        let one = self.one_raw;
        if !self.plan.b.is_fast() {
            for (i, &code) in codes.iter().enumerate() {
                let (q, was_cut) = self.op_add_b(t[i], code.min(one), nc);
                b[i] = q.raw;
                cut[i] = was_cut;
                count_event(counts, q.event);
            }
            return;
        }
        let offset = nc.offset_raw << self.plan.offset_align;
        let t_align = self.plan.t_align;
        let threshold = nc.threshold.unwrap_or(i64::MIN);
        let cutoff = self.config.cutoff;
        sums.clear();
        sums.extend(
            t.iter()
                .zip(codes)
                .zip(cut.iter_mut())
                .map(|((&t, &code), cut)| {
                    let sum = (t << t_align) + offset;
                    *cut = cutoff.cuts(sum < 0, code.min(one) < threshold);
                    if *cut {
                        0
                    } else {
                        sum
                    }
                }),
        );
        self.plan.b.run(Pre::Identity, sums, b, counts);
    }

    /// The last squaring's raw value as a function of b's raw value, tabulated once per
    /// datapath and depth when b has at most [`MAX_CHAIN_TABLE`] codes (the squaring chain
    /// depends on n only through its depth).
    fn chain_table(&self, depth: u32) -> Option<&ChainTable> {
        self.chain[depth as usize]
            .get_or_init(|| {
                let b = self.config.b.format;
                let (lo, hi) = (b.min_raw(), b.max_raw());
                let codes = u64::try_from(i128::from(hi) - i128::from(lo) + 1).ok()?;
                if codes > MAX_CHAIN_TABLE {
                    return None;
                }
                // Every b code through the squaring stages' batch kernels (the same values as
                // `op_stage`, the property tests say so), one column at a time.
                let mut last: Vec<i64> = (lo..=hi).collect();
                let mut next = vec![0; last.len()];
                let mut counts = [0; 3];
                for i in 0..self.plan.squares.len() {
                    let (kernel, pre) = self.plan.square_stage(i, depth);
                    kernel.run(pre, &last, &mut next, &mut counts);
                    std::mem::swap(&mut last, &mut next);
                }
                Some(ChainTable { b_min: lo, last })
            })
            .as_ref()
    }

    /// Evaluates the output code of each input code for one n: the same `out` as
    /// [`Datapath::eval`], without the other probes and the event counts, and faster (the
    /// squaring chain is looked up from b where it is tabulated).
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath, OutputScratch};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(100).unwrap();
    /// let codes: Vec<i64> = (32_000..=32_768).collect();
    /// let mut out = vec![0; codes.len()];
    /// dp.eval_outputs(nc, &codes, &mut out, &mut OutputScratch::default());
    /// assert_eq!(out[700], dp.eval(32_700, nc).values[dp.stage_out()]);
    /// ```
    pub fn eval_outputs(
        &self,
        nc: &NConstants,
        codes: &[i64],
        out: &mut [i64],
        scratch: &mut OutputScratch,
    ) {
        self.outputs(nc, codes, out, scratch, true);
    }

    /// [`Datapath::eval_outputs`] with the squaring chain run stage by stage, never tabulated:
    /// for a datapath evaluated once over fewer live codes than b has codes (the output-only
    /// check of a datapath with few exponents or a wide b), where building the table would
    /// cost more than it saves. The lobes are left in the scratch ([`OutputScratch::lobes`]).
    pub fn eval_outputs_untabulated(
        &self,
        nc: &NConstants,
        codes: &[i64],
        out: &mut [i64],
        scratch: &mut OutputScratch,
    ) {
        self.outputs(nc, codes, out, scratch, false);
    }

    fn outputs(
        &self,
        nc: &NConstants,
        codes: &[i64],
        out: &mut [i64],
        scratch: &mut OutputScratch,
        tabulate: bool,
    ) {
        let len = codes.len();
        let s = scratch;
        for col in [&mut s.a, &mut s.b] {
            col.clear();
            col.resize(len, 0);
        }
        s.cut.clear();
        s.cut.resize(len, false);
        let one = self.one_raw;
        let d_shift = self.d_shift;
        for (d, &code) in s.a.iter_mut().zip(codes) {
            *d = (code.min(one) - one) << d_shift;
        }
        let mut counts = [0; 3];
        self.plan
            .t
            .run(Pre::Mul(nc.slope_raw), &s.a, &mut s.b, &mut counts);
        // t is in b; the base goes to a.
        self.b_column(
            nc,
            codes,
            &s.b,
            &mut s.a,
            &mut s.cut,
            &mut s.sums,
            &mut counts,
        );
        // Only where tabulating is asked for: building the table costs a pass over every b
        // code and squaring stage, which an untabulated evaluation exists to avoid.
        if let Some(table) = tabulate.then(|| self.chain_table(nc.depth)).flatten() {
            for (sq, &b) in s.b.iter_mut().zip(&s.a) {
                *sq = table.last[(b - table.b_min) as usize];
            }
        } else {
            for i in 0..self.plan.squares.len() {
                let (kernel, pre) = self.plan.square_stage(i, nc.depth);
                kernel.run(pre, &s.a, &mut s.b, &mut counts);
                std::mem::swap(&mut s.a, &mut s.b);
            }
            std::mem::swap(&mut s.a, &mut s.b);
        }
        self.plan
            .out
            .run(Pre::Mul(nc.coef_raw), &s.b, out, &mut counts);
    }
}

impl Datapath {
    /// Where the cutoff can cut, as proven from the configuration.
    pub fn cut_structure(&self) -> CutStructure {
        match (self.config.cutoff, self.cut_is_prefix) {
            (Cutoff::None, _) => CutStructure::Never,
            (_, true) => CutStructure::Prefix,
            (_, false) => CutStructure::Scan,
        }
    }

    /// Whether the cutoff forces the base of input `c_raw` to zero for this n.
    pub fn is_cut(&self, c_raw: i64, nc: &NConstants) -> bool {
        let (c, d) = self.op_sub(c_raw);
        let t = self.op_mul_t(d, nc);
        self.op_add_b(t.raw, c, nc).1
    }

    /// The first code of `codes` whose base is not cut, found by bisection where the cut
    /// codes are proven to be a prefix (the paper cutoff; the clamp with a saturating,
    /// non-negative t); `codes.start` otherwise.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(1024).unwrap();
    /// // The base (1024/16)(c - 1) + 1 is negative, and cut, below c = 1 - 1/64 (code 32256).
    /// assert_eq!(dp.first_live_code(nc, 0..32769), 32256);
    /// ```
    pub fn first_live_code(&self, nc: &NConstants, codes: std::ops::Range<i64>) -> i64 {
        if !self.cut_is_prefix {
            return codes.start;
        }
        first_code_where(codes, |code| !self.is_cut(code, nc))
    }

    /// Whether the last squaring (the lobe) is proven non-decreasing in the input code up to
    /// 1.0. t saturates and every slope is non-negative, so t is non-decreasing and at most 0
    /// (c <= 1), and the exact sum at most the largest offset. From b on every stage must be
    /// monotone on the values it can receive: every rounding mode is monotone, and so are the
    /// squares of non-negative values and the bypassed stages' requantization; a stage's
    /// overflow is monotone when it saturates, or when the quantization of the largest value
    /// it can receive fits the format (then no value overflows: wrapping and zeroing never
    /// act). Negative bases are cut by the clamp, or reach an unsigned b that saturates them
    /// to 0. Then the codes whose lobe is 0 are a prefix ([`Datapath::first_nonzero_lobe`]).
    pub fn lobe_is_monotone(&self) -> bool {
        self.lobe_monotone
    }

    fn prove_lobe_monotone(&self) -> bool {
        let cfg = &self.config;
        let sat = |o: Overflow| matches!(o, Overflow::Sat | Overflow::SatSym);
        if !sat(cfg.t.overflow) || self.constants.iter().any(|c| c.slope_raw < 0) {
            return false;
        }
        if cfg.cutoff != Cutoff::Clamp && !(cfg.b.format.is_signed() || sat(cfg.b.overflow)) {
            return false;
        }
        if cfg.cutoff != Cutoff::Clamp && cfg.b.format.is_signed() {
            return false;
        }
        // The largest exact sum (the largest offset) on the sum's fraction bits, then the
        // largest value each stage can hold, or None once a stage could overflow without
        // saturating.
        let Some(first) = self.constants.first() else {
            return true;
        };
        let fb = self.b_frac(first);
        let top = self
            .constants
            .iter()
            .map(|c| i128::from(c.offset_raw) << (fb - c.offset_frac) as u32)
            .max()
            .unwrap_or(0)
            .max(0);
        let bound = |exact: i128, frac: i32, spec: &crate::pipeline::StageSpec| {
            let q = quantize_to(exact, frac, spec);
            (q.event == Event::None || sat(spec.overflow)).then_some(q.raw.max(0))
        };
        let Some(mut upper) = bound(top, fb, &cfg.b) else {
            return false;
        };
        let mut frac = cfg.b.format.frac_bits();
        for spec in &cfg.square {
            let u = i128::from(upper);
            let (Some(squared), Some(passed)) =
                (bound(u * u, 2 * frac, spec), bound(u, frac, spec))
            else {
                return false;
            };
            upper = squared.max(passed);
            frac = spec.format.frac_bits();
        }
        true
    }

    /// The first code of `codes` whose lobe (the last squaring) is not 0, by bisection where
    /// [`Datapath::lobe_is_monotone`] proves the zero lobes a prefix; `codes.start` otherwise.
    /// Below it every output is 0 too (the quantization of 0 is 0).
    pub fn first_nonzero_lobe(&self, nc: &NConstants, codes: std::ops::Range<i64>) -> i64 {
        if !self.lobe_is_monotone() {
            return codes.start;
        }
        let last = self.stage_last_square();
        first_code_where(codes, |code| self.eval(code, nc).values[last] != 0)
    }

    /// [`Datapath::eval_batch`] for a batch of codes that are all cut (every code below
    /// [`Datapath::first_live_code`]): d and t are evaluated, and every later stage holds
    /// what a cut base gives, 0 (the quantization of 0 is 0 in every format and mode, with no
    /// overflow event). The caller guarantees the codes are cut.
    pub fn eval_batch_cut(&self, nc: &NConstants, codes: &[i64], cols: &mut ProbeColumns) {
        let n_stages = self.stages.len();
        cols.reset(n_stages, codes.len());
        self.d_column(codes, &mut cols.values[STAGE_D], &mut cols.input_clamped);
        let (head, tail) = cols.values.split_at_mut(STAGE_T);
        self.plan.t.run(
            Pre::Mul(nc.slope_raw),
            &head[STAGE_D],
            &mut tail[0],
            &mut cols.event_counts[STAGE_T],
        );
        cols.cut.fill(true);
        let coef_idx = self.stage_coef();
        cols.values[coef_idx].fill(nc.coef_raw);
        if !cols.zero_tail {
            for (stage_idx, col) in cols.values.iter_mut().enumerate().skip(STAGE_B) {
                if stage_idx != coef_idx {
                    col.fill(0);
                }
            }
            cols.zero_tail = true;
        }
    }

    /// [`Datapath::eval_outputs`] over a range of codes, `out[i]` for code `codes.start + i`:
    /// the cut prefix (see [`Datapath::first_live_code`]) is filled with its output, 0, the
    /// rest is evaluated. Returns the length of the cut prefix.
    pub fn eval_outputs_range(
        &self,
        nc: &NConstants,
        codes: std::ops::Range<i64>,
        out: &mut [i64],
        scratch: &mut OutputScratch,
    ) -> usize {
        let live = self.first_live_code(nc, codes.clone());
        self.eval_outputs_from(nc, codes, live, out, scratch)
    }

    /// [`Datapath::eval_outputs_range`] given `live`, [`Datapath::first_live_code`] of a range
    /// that holds `codes` (found once for many batches of it): the codes of `codes` below it
    /// are cut (their output is 0), the others are evaluated. Returns the length of the cut
    /// prefix.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Config, Datapath, OutputScratch};
    /// let dp = Datapath::new(Config::baseline()).unwrap();
    /// let nc = dp.constants_for(1024).unwrap();
    /// let live = dp.first_live_code(nc, 0..32769);
    /// let mut out = vec![0; 2048];
    /// let cut = dp.eval_outputs_from(nc, 30720..32768, live, &mut out, &mut OutputScratch::default());
    /// assert_eq!(cut, (live - 30720) as usize);
    /// assert_eq!(out[2047], dp.eval(32767, nc).values[dp.stage_out()]);
    /// ```
    pub fn eval_outputs_from(
        &self,
        nc: &NConstants,
        codes: std::ops::Range<i64>,
        live: i64,
        out: &mut [i64],
        scratch: &mut OutputScratch,
    ) -> usize {
        let live = live.clamp(codes.start, codes.end);
        let n_dead = (live - codes.start) as usize;
        // A cut base is 0, and 0 is every stage's exact value from b on (every rounding mode
        // keeps 0, and every format holds it): the cut output is 0, written at the memory's
        // pace (the check's dead prefix rests on the same fact).
        out[..n_dead].fill(0);
        let mut live_codes = std::mem::take(&mut scratch.codes);
        live_codes.clear();
        live_codes.extend(live..codes.end);
        self.eval_outputs(nc, &live_codes, &mut out[n_dead..], scratch);
        scratch.codes = live_codes;
        n_dead
    }
}

/// The bit-accurate interpreter of the walk: raw values (exact sums in `i128`), every stage's
/// probe and overflow event recorded as the walk goes.
struct FixedWalk<'a> {
    dp: &'a Datapath,
    nc: &'a NConstants,
    c_raw: i64,
    /// The input clamped to 1.0 (set by `sub`).
    c: i64,
    probes: &'a mut Probes,
}

impl FixedWalk<'_> {
    #[inline]
    fn record(&mut self, stage_idx: usize, q: Quantized) -> i128 {
        self.probes.values[stage_idx] = q.raw;
        self.probes.events[stage_idx] = q.event;
        i128::from(q.raw)
    }
}

impl Arithmetic for FixedWalk<'_> {
    type Value = i128;

    #[inline]
    fn sub(&mut self) -> i128 {
        let (c, d) = self.dp.op_sub(self.c_raw);
        self.c = c;
        self.probes.input_clamped = c != self.c_raw;
        self.probes.values[STAGE_D] = d;
        i128::from(d)
    }

    #[inline]
    fn below_threshold(&self) -> bool {
        self.nc.below_threshold(self.c)
    }

    #[inline]
    fn mul_t(&mut self, d: i128) -> i128 {
        let q = self.dp.op_mul_t(d as i64, self.nc);
        self.record(STAGE_T, q)
    }

    #[inline]
    fn add_offset(&mut self, t: i128) -> i128 {
        self.dp.exact_sum(t as i64, self.nc)
    }

    #[inline]
    fn is_negative(&self, sum: i128) -> bool {
        sum < 0
    }

    #[inline]
    fn zero(&self) -> i128 {
        0
    }

    #[inline]
    fn quant_b(&mut self, base: i128) -> i128 {
        let q = quantize_to(base, self.dp.b_frac(self.nc), &self.dp.config.b);
        self.record(STAGE_B, q)
    }

    #[inline]
    fn square(&mut self, i: usize, x: i128) -> i128 {
        let q = self.dp.op_square(i, x as i64);
        self.record(STAGE_SQ0 + i, q)
    }

    #[inline]
    fn pass(&mut self, i: usize, x: i128) -> i128 {
        let q = self.dp.op_pass(i, x as i64);
        self.record(STAGE_SQ0 + i, q)
    }

    #[inline]
    fn mul_out(&mut self, s: i128) -> i128 {
        self.probes.values[self.dp.stage_coef()] = self.nc.coef_raw;
        let q = self.dp.op_mul_out(s as i64, self.nc);
        self.record(self.dp.stage_out(), q)
    }
}

/// The most b codes for which the squaring chain is tabulated (8 MiB of `i64`).
pub const MAX_CHAIN_TABLE: u64 = 1 << 20;

/// The last squaring as a function of b's raw value: `last[b - b_min]`.
#[derive(Debug, Clone)]
struct ChainTable {
    b_min: i64,
    last: Vec<i64>,
}

/// Reusable columns for [`Datapath::eval_outputs`].
#[derive(Debug, Clone, Default)]
pub struct OutputScratch {
    codes: Vec<i64>,
    a: Vec<i64>,
    b: Vec<i64>,
    sums: Vec<i64>,
    cut: Vec<bool>,
}

impl OutputScratch {
    /// The lobes (the last squaring's raw values) of the latest [`Datapath::eval_outputs`],
    /// one per code it evaluated.
    pub fn lobes(&self) -> &[i64] {
        &self.b
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
