//! Datapath configuration: the TOML schema, the built-in `baseline`, and merging a file onto it.
//!
//! A configuration file only states what differs from `baseline`: every key it leaves out
//! takes the baseline's value. The result is a complete [`Config`], which
//! [`crate::pipeline::Datapath::new`] validates once.

use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::fixed::{Format, Overflow, Rounding};
use crate::nset::NSet;
use crate::reference::lobe::Cutoff;
use crate::reference::normalisation::{CoefSource, Form};

/// Which constants drive the base `slope * (c - 1) + offset`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Variant {
    /// slope n/m (a product with n and a shift by k), offset 1.
    Plain,
    /// slope A(n), offset A(n) + B(n) from the minimax table, each quantized to a format.
    Minimax,
}

impl Variant {
    /// Every variant.
    pub const ALL: [Variant; 2] = [Variant::Plain, Variant::Minimax];

    /// The name used in TOML and reports.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Plain => "plain",
            Variant::Minimax => "minimax",
        }
    }
}

crate::names::named_enum!(Variant, "variant", "plain or minimax");

/// A stage's output quantization: its format, rounding mode and overflow mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StageSpec {
    /// The stage's output format.
    pub format: Format,
    /// How dropped fraction bits are rounded.
    pub rounding: Rounding,
    /// What happens when the rounded value does not fit.
    pub overflow: Overflow,
}

/// A format alone, for the input and the exact subtraction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormatSpec {
    /// The format.
    pub format: Format,
}

/// The energy-conserving coefficient: which one, and the format it is stored in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoefSpec {
    /// The normalisation form.
    pub form: Form,
    /// Where the coefficient comes from.
    pub source: CoefSource,
    /// The format of the stored per-n constant.
    pub format: Format,
    /// How its f64 value is rounded into that format (it must fit: no overflow mode).
    pub rounding: Rounding,
}

/// The per-n constants of the minimax variant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MinimaxSpec {
    /// The format of the slope A(n).
    pub a_format: Format,
    /// The format of the offset A(n) + B(n) (the value of the base at c = 1).
    pub offset_format: Format,
    /// How both are rounded from their f64 values (they must fit).
    pub rounding: Rounding,
}

/// Width of the per-n depth field j(n) (1..=7) in the vectors, the ROM and the RTL's depth
/// port ([`PerN::Depth`](crate::pipeline::ports::PerN::Depth)).
pub const DEPTH_BITS: u32 = 3;

/// How many of the k squaring stages square at each n: `j(n)`, with `m(n) = 2^j(n)`; the
/// stages past `j(n)` pass their input through (a bypass multiplexer, then the stage's own
/// quantization). See `docs/arithmetic.md` section 2.
///
/// # Examples
/// ```
/// use specfx::pipeline::{Config, Depth, Variant};
/// let mut c = Config::baseline();
/// c.k = 7;
/// c.variant = Variant::Minimax;
/// c.depth = Depth::Best;
/// // The minimax table's smallest floor: m = 16 up to n = 21, then 32, 64 and 128.
/// assert_eq!([16, 21, 22, 42, 43, 85, 86, 1024].map(|n| c.depth_of(n)), [4, 4, 5, 5, 6, 6, 7, 7]);
/// let steps: Config = Config::from_toml("depth = [{ from = 1, j = 3 }, { from = 100, j = 4 }]").unwrap();
/// assert_eq!([16, 99, 100, 1024].map(|n| steps.depth_of(n)), [3, 3, 4, 4]);
/// ```
#[derive(Debug, Clone, PartialEq, Eq, Hash, Default)]
pub enum Depth {
    /// Every n uses all k squarings (`depth = "fixed"`, the default).
    #[default]
    Fixed,
    /// Each n uses the depth j in 1..=k whose lobe has the smallest f64 floor at n: the
    /// minimax table's `max_abs_err` (minimax variant) or `plain_max_abs_err` (plain), ties
    /// to the smaller j (`depth = "best"`).
    Best,
    /// A threshold list: each step's `j` holds from its `from` up to the next step's
    /// (`depth = [{ from = 16, j = 4 }, { from = 22, j = 5 }]`).
    Steps(Vec<DepthStep>),
}

/// One step of a [`Depth::Steps`] rule: from exponent `from` on, `j` squarings.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepthStep {
    /// The first exponent of the step.
    pub from: u32,
    /// The squarings done from there on (1..=k).
    pub j: u32,
}

impl Depth {
    /// Whether every n uses all k squarings (what configuration files leave out).
    pub fn is_fixed(&self) -> bool {
        *self == Depth::Fixed
    }

    /// The rule's name in reports: `fixed`, `best` or `steps`.
    pub fn name(&self) -> &'static str {
        match self {
            Depth::Fixed => "fixed",
            Depth::Best => "best",
            Depth::Steps(_) => "steps",
        }
    }
}

/// What a `depth` value may be, for its errors.
const DEPTH_EXPECTED: &str = "expected \"fixed\", \"best\" or a list of steps { from = N, j = J }";

/// What a step of a `depth` list is, for its errors.
const STEP_IS: &str = "a step is { from = N, j = J }: from exponent N on, J squarings";

impl Serialize for Depth {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Depth::Fixed => s.serialize_str("fixed"),
            Depth::Best => s.serialize_str("best"),
            Depth::Steps(steps) => steps.serialize(s),
        }
    }
}

impl<'de> Deserialize<'de> for Depth {
    /// Reads the value whole, then says what is wrong with it in the key's own terms: which
    /// step, which of its keys, and what a step is.
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let value = toml::Value::deserialize(d)?;
        depth_from_value(&value).map_err(serde::de::Error::custom)
    }
}

/// A `depth` value as TOML (or JSON, in a manifest) gives it.
fn depth_from_value(value: &toml::Value) -> Result<Depth, String> {
    match value {
        toml::Value::String(s) if s == "fixed" => Ok(Depth::Fixed),
        toml::Value::String(s) if s == "best" => Ok(Depth::Best),
        toml::Value::Array(items) => items
            .iter()
            .enumerate()
            .map(|(i, item)| step_from_value(i + 1, item))
            .collect::<Result<_, _>>()
            .map(Depth::Steps),
        other => Err(format!(
            "depth: {DEPTH_EXPECTED}, got {} {other}",
            other.type_str()
        )),
    }
}

/// Step `number` (from 1) of a `depth` list.
fn step_from_value(number: usize, item: &toml::Value) -> Result<DepthStep, String> {
    let fail = |what: String| format!("depth: step {number}: {what} ({STEP_IS})");
    let toml::Value::Table(table) = item else {
        return Err(fail(format!(
            "expected a table {{ from = N, j = J }}, got {} {item}",
            item.type_str()
        )));
    };
    if let Some(key) = table.keys().find(|k| *k != "from" && *k != "j") {
        return Err(fail(format!(
            "unknown key `{key}`, expected `from` and `j`"
        )));
    }
    let field = |key: &str, expected: &str| -> Result<u32, String> {
        let v = table
            .get(key)
            .ok_or_else(|| fail(format!("missing `{key}`")))?;
        v.as_integer()
            .and_then(|i| u32::try_from(i).ok())
            .ok_or_else(|| fail(format!("{key} = {v}: expected {expected}")))
    };
    Ok(DepthStep {
        from: field("from", "the step's first exponent, a whole number >= 0")?,
        j: field("j", "a number of squarings, a whole number in 1..=k")?,
    })
}

/// Register latencies of the operations in the cycle-level model (`docs/cycle.md`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LatencySpec {
    /// Registers after the clamp-and-subtract (pipelined only).
    pub sub: u32,
    /// Registers of each multiplier: the t product, each squaring, the output product.
    pub mul: u32,
    /// Registers after the add-and-cut (pipelined only).
    pub add: u32,
}

/// The two microarchitectures of the cycle model and the reference RTL (`docs/cycle.md`).
/// A configuration may record one (its `arch` key, [`Config::arch`]); every command that
/// costs, simulates or emits a datapath takes [`Config::resolve_arch`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Arch {
    /// One new input per cycle; every operation its own stage with its register latency.
    Pipelined,
    /// One shared multiplier for all k + 2 products, driven by an FSM.
    Folded,
}

impl Arch {
    /// Both architectures.
    pub const ALL: [Arch; 2] = [Arch::Pipelined, Arch::Folded];

    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Arch::Pipelined => "pipelined",
            Arch::Folded => "folded",
        }
    }

    /// Cycles from an input's transfer to its output's transfer when nothing stalls.
    ///
    /// # Examples
    /// ```
    /// use specfx::cycle::Arch;
    /// use specfx::pipeline::Config;
    /// let cfg = Config::baseline();
    /// assert_eq!(Arch::Pipelined.latency(&cfg), 8);
    /// assert_eq!(Arch::Folded.latency(&cfg), 7);
    /// ```
    pub fn latency(self, cfg: &Config) -> u64 {
        let l = &cfg.latency;
        let k = u64::from(cfg.k);
        match self {
            Arch::Pipelined => u64::from(l.sub + l.add) + (k + 2) * u64::from(l.mul),
            Arch::Folded => (k + 2) * u64::from(l.mul) + 1,
        }
    }

    /// Cycles between the starts of two inputs when nothing stalls.
    pub fn initiation_interval(self, cfg: &Config) -> u64 {
        match self {
            Arch::Pipelined => 1,
            Arch::Folded => (u64::from(cfg.k) + 2) * u64::from(cfg.latency.mul),
        }
    }
}

crate::names::named_enum!(Arch, "architecture", "pipelined or folded");

/// A complete datapath configuration. See `docs/arithmetic.md` for the arithmetic it implies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// A name for reports and manifests.
    pub name: String,
    /// Plain (n/m, 1) or minimax (A(n), A(n) + B(n)) constants.
    pub variant: Variant,
    /// Number of squaring stages; m = 2^k (at every n unless `depth` says otherwise).
    pub k: u32,
    /// How many of the k stages square at each n (`fixed`: all of them).
    #[serde(default, skip_serializing_if = "Depth::is_fixed")]
    pub depth: Depth,
    /// How the base is cut: `clamp`, `paper` or `none`.
    pub cutoff: Cutoff,
    /// The exponents the datapath serves.
    pub n: NSet,
    /// The input cosine c (values above 1.0 are clamped to 1.0).
    pub c: FormatSpec,
    /// d = c - 1, exact.
    pub d: FormatSpec,
    /// t = d * slope.
    pub t: StageSpec,
    /// b = t + offset, then the cutoff.
    pub b: StageSpec,
    /// One entry per squaring stage, k in all.
    pub square: Vec<StageSpec>,
    /// The coefficient coef(n).
    pub coef: CoefSpec,
    /// out = square_k * coef.
    pub out: StageSpec,
    /// The minimax constants' formats (used by the minimax variant only).
    pub minimax: MinimaxSpec,
    /// Register latencies for the cycle-level model and the RTL.
    pub latency: LatencySpec,
    /// The microarchitecture the configuration was made for (`optimize` records the one its
    /// answer was costed with): the default of every command that reads the configuration,
    /// which a command's `--arch` overrides ([`Config::resolve_arch`]). Left out: none
    /// recorded, pipelined.
    #[serde(
        default,
        skip_serializing_if = "Option::is_none",
        deserialize_with = "arch_key"
    )]
    pub arch: Option<Arch>,
}

fn fmt(s: &str) -> Format {
    s.parse().expect("built-in format notation is valid")
}

/// The longest configuration name.
pub const MAX_NAME_LEN: usize = 64;

/// Checks a configuration name. Names end up in file names, Verilog comments, CSV, HTML,
/// Markdown, TOML and VCD, so they are 1..=64 ASCII letters, digits and `_ - . +`, not
/// starting with `.` or `-`: nothing that could change a generated file's meaning or escape
/// a directory.
///
/// # Errors
/// A description of what was expected, which the callers put into their error (a
/// configuration's `name`, a scene's material, a sweep's base).
pub(crate) fn check_name(name: &str) -> Result<(), String> {
    let ok_char = |c: char| c.is_ascii_alphanumeric() || "_-.+".contains(c);
    let bad = name.chars().find(|&c| !ok_char(c));
    if name.is_empty()
        || name.len() > MAX_NAME_LEN
        || bad.is_some()
        || name.starts_with('.')
        || name.starts_with('-')
    {
        let why = match bad {
            Some(c) => format!("{:?} is not allowed", c),
            None if name.is_empty() => "it is empty".to_string(),
            None if name.len() > MAX_NAME_LEN => format!("it has {} characters", name.len()),
            None => "it starts with '.' or '-'".to_string(),
        };
        return Err(format!(
            "expected 1..={MAX_NAME_LEN} ASCII letters, digits and _ - . + (not starting with . or -), got {name:?}: {why}"
        ));
    }
    Ok(())
}

/// A valid name made from any text (a file stem): every other character becomes `_`, a
/// leading `.` or `-` is dropped, at most [`MAX_NAME_LEN`] characters; `config` if nothing
/// is left.
///
/// # Examples
/// ```
/// use specfx::pipeline::config::name_from;
/// assert_eq!(name_from("my design (v2)"), "my_design__v2_");
/// assert_eq!(name_from(".."), "config");
/// ```
pub fn name_from(text: &str) -> String {
    let s: String = text
        .trim_start_matches(['.', '-'])
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "_-.+".contains(c) {
                c
            } else {
                '_'
            }
        })
        .take(MAX_NAME_LEN)
        .collect();
    if s.is_empty() {
        "config".to_string()
    } else {
        s
    }
}

impl Config {
    /// The formats of the per-n constants the datapath reads from its ROM: (slope, offset).
    /// Plain datapaths take n with k fraction bits (the value n/m) and the constant 1;
    /// minimax ones take A(n) and A(n) + B(n) in their configured formats. The vector ports,
    /// the ROM, the RTL's parameters and the cost model all use these.
    pub fn constant_formats(&self) -> (Format, Format) {
        match self.variant {
            Variant::Plain => {
                // n / 2^j(n) with k fraction bits: the raw n << (k - j(n)) needs
                // bits(n) + k - j(n) bits, the widest over the set.
                let k = self.k as i32;
                let bits = self
                    .n
                    .values()
                    .iter()
                    .map(|&n| (32 - n.leading_zeros()) as i32 + k - self.depth_of(n) as i32)
                    .max()
                    .unwrap_or(k + 1);
                (
                    Format::unsigned(bits - k, k).expect("1..=17 bits"),
                    Format::unsigned(1, 0).expect("one bit"),
                )
            }
            Variant::Minimax => (self.minimax.a_format, self.minimax.offset_format),
        }
    }

    /// The squarings done at exponent `n`, `j(n)` in 1..=k (k for the fixed rule). Total: an n
    /// the rule does not cover takes k (best, beyond the minimax table) or the first step's j;
    /// [`crate::pipeline::Datapath::new`] refuses such rules.
    pub fn depth_of(&self, n: u32) -> u32 {
        match &self.depth {
            Depth::Fixed => self.k,
            Depth::Best => {
                crate::reference::minimax::best_depth(n, self.k, self.variant == Variant::Plain)
                    .unwrap_or(self.k)
            }
            Depth::Steps(steps) => steps
                .iter()
                .take_while(|s| s.from <= n)
                .last()
                .or(steps.first())
                .map_or(self.k, |s| s.j),
        }
    }

    /// Whether some n uses fewer than k squarings (the datapath then needs its bypass
    /// multiplexers and the per-n depth field).
    pub fn has_bypass(&self) -> bool {
        !self.depth.is_fixed() && self.n.values().iter().any(|&n| self.depth_of(n) < self.k)
    }

    /// The microarchitecture a command uses: its `--arch` flag when given, else the one the
    /// configuration records (its `arch` key), else pipelined. Every command that reads a
    /// configuration and costs, simulates or emits it resolves its architecture here.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::{Arch, Config};
    /// let folded = Config::from_toml("arch = \"folded\"").unwrap();
    /// assert_eq!(folded.resolve_arch(None), Arch::Folded);
    /// assert_eq!(folded.resolve_arch(Some(Arch::Pipelined)), Arch::Pipelined);
    /// assert_eq!(Config::baseline().resolve_arch(None), Arch::Pipelined);
    /// ```
    pub fn resolve_arch(&self, flag: Option<Arch>) -> Arch {
        flag.or(self.arch).unwrap_or(Arch::Pipelined)
    }

    /// The built-in `baseline` configuration (see `docs/arithmetic.md`).
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::Config;
    /// let b = Config::baseline();
    /// assert_eq!(b.t.format.to_string(), "s2.16");
    /// assert_eq!(b.square.len(), 4);
    /// ```
    pub fn baseline() -> Config {
        let rnd_sat = |f: &str| StageSpec {
            format: fmt(f),
            rounding: Rounding::Rnd,
            overflow: Overflow::Sat,
        };
        Config {
            name: "baseline".to_string(),
            variant: Variant::Plain,
            k: 4,
            depth: Depth::Fixed,
            cutoff: Cutoff::Clamp,
            n: NSet::range(16, 1024).expect("valid range"),
            c: FormatSpec {
                format: fmt("u1.15"),
            },
            d: FormatSpec {
                format: fmt("s1.15"),
            },
            t: rnd_sat("s2.16"),
            // b = t + 1 is exact in u1.16 for t in s2.16 and c <= 1: the rounding never acts.
            b: rnd_sat("u1.16"),
            square: vec![rnd_sat("u1.16"); 4],
            coef: CoefSpec {
                form: Form::Phong,
                source: CoefSource::Exact,
                format: fmt("u8.16"),
                rounding: Rounding::Rnd,
            },
            out: rnd_sat("u8.16"),
            minimax: MinimaxSpec {
                a_format: fmt("u8.16"),
                offset_format: fmt("u1.16"),
                rounding: Rounding::Rnd,
            },
            latency: LatencySpec {
                sub: 1,
                mul: 1,
                add: 1,
            },
            arch: None,
        }
    }

    /// A built-in configuration by name (`baseline`), if there is one.
    pub fn builtin(name: &str) -> Option<Config> {
        (name == "baseline").then(Config::baseline)
    }

    /// Reads a TOML text onto `baseline`: every key it gives replaces the baseline's value.
    ///
    /// # Examples
    /// ```
    /// use specfx::pipeline::Config;
    /// let c = Config::from_toml("k = 5\n[t]\nformat = \"s3.20\"\n").unwrap();
    /// assert_eq!(c.k, 5);
    /// assert_eq!(c.square.len(), 5); // the baseline's one squaring spec, five times
    /// assert_eq!(c.t.format.to_string(), "s3.20");
    /// assert_eq!(c.t.rounding, Config::baseline().t.rounding);
    /// let err = Config::from_toml("[t]\nformt = \"s3.20\"\n").unwrap_err();
    /// assert!(err.to_string().starts_with("line 2: unknown field `formt`"));
    /// ```
    pub fn from_toml(text: &str) -> Result<Config, Error> {
        let file: ConfigFile = crate::error::parse_toml(text)?;
        file.onto(Config::baseline())
    }

    /// The configuration as TOML text (complete: every key).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a Config always serialises")
    }
}

/// A stage section of a file: any key may be left out.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct StagePatch {
    format: Option<Format>,
    rounding: Option<Rounding>,
    overflow: Option<Overflow>,
}

impl StagePatch {
    fn onto(&self, base: StageSpec) -> StageSpec {
        StageSpec {
            format: self.format.unwrap_or(base.format),
            rounding: self.rounding.unwrap_or(base.rounding),
            overflow: self.overflow.unwrap_or(base.overflow),
        }
    }
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct FormatPatch {
    format: Option<Format>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct CoefPatch {
    form: Option<Form>,
    source: Option<CoefSource>,
    format: Option<Format>,
    rounding: Option<Rounding>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct MinimaxPatch {
    a_format: Option<Format>,
    offset_format: Option<Format>,
    rounding: Option<Rounding>,
}

#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct LatencyPatch {
    sub: Option<u32>,
    mul: Option<u32>,
    add: Option<u32>,
}

/// `[square]` (one spec for every stage) or `[[square]]` (one table per stage).
#[derive(Debug, Clone)]
enum SquarePatch {
    All(StagePatch),
    Each(Vec<StagePatch>),
}

impl<'de> Deserialize<'de> for SquarePatch {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error as _;
        // Read the raw value first, then each table, so that a mistake inside one names it.
        let value = toml::Value::deserialize(d)?;
        let table = |v: toml::Value, key: &str| {
            StagePatch::deserialize(v)
                .map_err(|e| D::Error::custom(format!("{key}: {}", e.message())))
        };
        match value {
            toml::Value::Table(_) => Ok(SquarePatch::All(table(value, "[square]")?)),
            toml::Value::Array(items) => items
                .into_iter()
                .enumerate()
                .map(|(i, v)| table(v, &format!("[[square]] number {}", i + 1)))
                .collect::<Result<_, _>>()
                .map(SquarePatch::Each),
            other => Err(D::Error::custom(format!(
                "square: expected a [square] table or [[square]] tables, got {}",
                other.type_str()
            ))),
        }
    }
}

/// What a configuration file may say (also a design space's `[base]`).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct ConfigFile {
    name: Option<String>,
    variant: Option<Variant>,
    k: Option<u32>,
    depth: Option<Depth>,
    cutoff: Option<Cutoff>,
    n: Option<NSet>,
    c: Option<FormatPatch>,
    d: Option<FormatPatch>,
    t: Option<StagePatch>,
    b: Option<StagePatch>,
    square: Option<SquarePatch>,
    coef: Option<CoefPatch>,
    out: Option<StagePatch>,
    minimax: Option<MinimaxPatch>,
    latency: Option<LatencyPatch>,
    #[serde(default, deserialize_with = "arch_key")]
    arch: Option<Arch>,
}

/// The `arch` key: `"pipelined"` or `"folded"` (any case), refused with both names otherwise.
fn arch_key<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<Arch>, D::Error> {
    let value = toml::Value::deserialize(d)?;
    match value.as_str().map(str::parse::<Arch>) {
        Some(Ok(arch)) => Ok(Some(arch)),
        _ => Err(serde::de::Error::custom(format!(
            "arch: expected \"pipelined\" or \"folded\" (the microarchitecture), got {value}"
        ))),
    }
}

impl ConfigFile {
    /// The configuration `base` with every key the file sets replaced, checked.
    pub(crate) fn onto(self, base: Config) -> Result<Config, Error> {
        let k = self.k.unwrap_or(base.k);
        if !crate::reference::lobe::K_RANGE.contains(&k) {
            return Err(Error::Config {
                key: "k".to_string(),
                problem: format!(
                    "expected a number of squarings in {}, got {k}",
                    crate::reference::lobe::K_RANGE_TEXT
                ),
            });
        }
        let base_square = base.square[0];
        let square = match &self.square {
            None => vec![base_square; k as usize],
            Some(SquarePatch::All(p)) => vec![p.onto(base_square); k as usize],
            Some(SquarePatch::Each(list)) => {
                if list.len() != k as usize {
                    return Err(Error::Config {
                        key: "square".to_string(),
                        problem: format!(
                            "expected one [square] table for all stages or k = {k} [[square]] tables, got {}",
                            list.len()
                        ),
                    });
                }
                list.iter().map(|p| p.onto(base_square)).collect()
            }
        };
        let latency = self.latency.unwrap_or_default();
        let latency = LatencySpec {
            sub: latency.sub.unwrap_or(base.latency.sub),
            mul: latency.mul.unwrap_or(base.latency.mul),
            add: latency.add.unwrap_or(base.latency.add),
        };
        for (key, value) in [
            ("latency.sub", latency.sub),
            ("latency.mul", latency.mul),
            ("latency.add", latency.add),
        ] {
            if !(1..=8).contains(&value) {
                return Err(Error::Config {
                    key: key.to_string(),
                    problem: format!("expected a register latency in 1..=8, got {value}"),
                });
            }
        }
        let coef = self.coef.unwrap_or_default();
        let mm = self.minimax.unwrap_or_default();
        Ok(Config {
            name: self.name.unwrap_or(base.name),
            variant: self.variant.unwrap_or(base.variant),
            k,
            depth: self.depth.unwrap_or(base.depth),
            cutoff: self.cutoff.unwrap_or(base.cutoff),
            n: self.n.unwrap_or(base.n),
            c: FormatSpec {
                format: self.c.and_then(|p| p.format).unwrap_or(base.c.format),
            },
            d: FormatSpec {
                format: self.d.and_then(|p| p.format).unwrap_or(base.d.format),
            },
            t: self.t.unwrap_or_default().onto(base.t),
            b: self.b.unwrap_or_default().onto(base.b),
            square,
            coef: CoefSpec {
                form: coef.form.unwrap_or(base.coef.form),
                source: coef.source.unwrap_or(base.coef.source),
                format: coef.format.unwrap_or(base.coef.format),
                rounding: coef.rounding.unwrap_or(base.coef.rounding),
            },
            out: self.out.unwrap_or_default().onto(base.out),
            minimax: MinimaxSpec {
                a_format: mm.a_format.unwrap_or(base.minimax.a_format),
                offset_format: mm.offset_format.unwrap_or(base.minimax.offset_format),
                rounding: mm.rounding.unwrap_or(base.minimax.rounding),
            },
            latency,
            arch: self.arch.or(base.arch),
        })
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn names_that_could_change_a_file_are_refused() {
        assert!(super::check_name("k5_minimax-2.1").is_ok());
        assert!(super::check_name("a\n`define X").is_err());
        assert!(super::check_name("../escaped").is_err());
    }

    use super::*;

    #[test]
    fn empty_file_is_baseline() {
        let mut c = Config::from_toml("").unwrap();
        assert_eq!(c, Config::baseline());
        c.name = "x".into();
        assert_ne!(c, Config::baseline());
    }

    #[test]
    fn full_toml_round_trips() {
        let mut c = Config::baseline();
        c.k = 2;
        c.square = vec![
            StageSpec {
                format: fmt("u1.12"),
                rounding: Rounding::Trn,
                overflow: Overflow::Wrap,
            },
            StageSpec {
                format: fmt("u1.10"),
                rounding: Rounding::RndConv,
                overflow: Overflow::SatSym,
            },
        ];
        c.variant = Variant::Minimax;
        c.cutoff = Cutoff::Paper;
        let text = c.to_toml();
        assert_eq!(Config::from_toml(&text).unwrap(), c);
    }

    #[test]
    fn per_stage_squares_must_number_k() {
        let text = "k = 3\n[[square]]\nformat = \"u1.10\"\n[[square]]\nformat = \"u1.9\"\n";
        let e = Config::from_toml(text).unwrap_err().to_string();
        assert_eq!(
            e,
            "square: expected one [square] table for all stages or k = 3 [[square]] tables, got 2"
        );
    }

    #[test]
    fn arch_is_recorded_read_back_and_checked() {
        let mut c = Config::baseline();
        assert!(!c.to_toml().contains("arch"), "no arch recorded, no key");
        c.arch = Some(Arch::Folded);
        let text = c.to_toml();
        assert!(text.contains("arch = \"folded\""), "{text}");
        assert_eq!(Config::from_toml(&text).unwrap(), c);
        let c = Config::from_toml("arch = \"Pipelined\"").unwrap();
        assert_eq!(c.arch, Some(Arch::Pipelined));
        for (text, got) in [("arch = \"fold\"", "\"fold\""), ("arch = 1", "1")] {
            let e = Config::from_toml(text).unwrap_err().to_string();
            assert_eq!(
                e,
                format!(
                    "line 1: arch: expected \"pipelined\" or \"folded\" (the microarchitecture), got {got}"
                )
            );
        }
        // The flag wins, then the key, then pipelined.
        let folded = Config::from_toml("arch = \"folded\"").unwrap();
        assert_eq!(folded.resolve_arch(Some(Arch::Pipelined)), Arch::Pipelined);
        assert_eq!(folded.resolve_arch(None), Arch::Folded);
        assert_eq!(
            Config::baseline().resolve_arch(Some(Arch::Folded)),
            Arch::Folded
        );
        assert_eq!(Config::baseline().resolve_arch(None), Arch::Pipelined);
    }

    #[test]
    fn bad_values_name_their_line() {
        let e = Config::from_toml("k = 4\n[t]\nrounding = \"ROUND\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("line 3: rounding mode must be one of"), "{e}");
        let e = Config::from_toml("[b]\nformat = \"q1.2\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("line 2: format must look like"), "{e}");
        let e = Config::from_toml("k = 9\n").unwrap_err().to_string();
        assert_eq!(e, "k: expected a number of squarings in 1..=7, got 9");
    }
}
