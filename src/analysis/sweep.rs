//! Design-space sweeps: a space of configurations (axes of values over a base configuration),
//! every point checked exhaustively and costed analytically, and the error/cost Pareto front.
//!
//! Points are numbered in a fixed order (the cartesian product of the axes, axes sorted by
//! key, last axis fastest), so a sweep can be split into shards by index and merged back, or
//! resumed, with identical results.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::analysis::check::{check_outputs_cached, CosCache};
use crate::analysis::optimize::COS_CACHE_VALUES;
use crate::cycle::Arch;
use crate::error::Error;
use crate::fixed::Format;
use crate::hdl::cost::{analytic_cost, Target};
use crate::nset::NSet;
use crate::pipeline::{Config, Datapath};

/// A design space: a base configuration and the values each axis takes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Space {
    /// The base configuration every point starts from.
    pub base: Config,
    /// Axes by key (see [`AXIS_KEYS`]), each with its values as TOML values.
    pub axes: BTreeMap<String, Vec<toml::Value>>,
    /// The target the points are priced on (analytic model) and the Pareto front drawn for.
    #[serde(default = "default_target")]
    pub target: Target,
}

fn default_target() -> Target {
    Target::Ice40
}

/// The keys an axis may have. `<stage>.frac` and `<stage>.int` change the fraction or integer
/// bits of a stage's format (for `square`, of every squaring stage), keeping the other.
pub const AXIS_KEYS: &[&str] = &[
    "k",
    "cutoff",
    "variant",
    "arch",
    "coef.form",
    "coef.source",
    "coef.frac",
    "coef.rounding",
    "t.frac",
    "t.int",
    "t.rounding",
    "t.overflow",
    "b.frac",
    "b.int",
    "b.rounding",
    "b.overflow",
    "square.frac",
    "square.int",
    "square.rounding",
    "square.overflow",
    "out.frac",
    "out.int",
    "out.rounding",
    "out.overflow",
    "latency.mul",
];

/// What a space file says (`base` and `n` optional, `[vary]` the axes).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpaceFile {
    base: Option<crate::pipeline::config::ConfigFile>,
    n: Option<NSet>,
    target: Option<String>,
    vary: toml::Table,
}

fn space_error(key: &str, problem: String) -> Error {
    Error::Config {
        key: key.to_string(),
        problem,
    }
}

/// Expands `"10..=16"` (or `"10..16"`, both ends included) into integers; other values stay.
/// The most values one axis may take.
pub const MAX_AXIS_VALUES: usize = 257;

/// The most points a space may hold (every point is checked exhaustively).
pub const MAX_POINTS: u64 = 1 << 20;

fn expand(key: &str, v: &toml::Value) -> Result<Vec<toml::Value>, Error> {
    match v {
        toml::Value::Array(items) => {
            if items.is_empty() || items.len() > MAX_AXIS_VALUES {
                return Err(space_error(
                    &format!("vary.{key}"),
                    format!("expected 1..={MAX_AXIS_VALUES} values, got {}", items.len()),
                ));
            }
            // A value twice would be the same point twice, costed and charted twice.
            if let Some((i, v)) = items
                .iter()
                .enumerate()
                .find(|(i, v)| items[..*i].contains(v))
            {
                return Err(space_error(
                    &format!("vary.{key}"),
                    format!("expected distinct values, got {v} again (value {})", i + 1),
                ));
            }
            Ok(items.clone())
        }
        toml::Value::String(s) if s.contains("..") => {
            let (lo, hi) = s.split_once("..").expect("checked");
            let hi = hi.strip_prefix('=').unwrap_or(hi);
            let parse = |x: &str| {
                x.trim().parse::<i64>().map_err(|_| {
                    space_error(
                        &format!("vary.{key}"),
                        format!("expected a range like \"10..=16\", got \"{s}\""),
                    )
                })
            };
            let (lo, hi) = (parse(lo)?, parse(hi)?);
            if hi
                .checked_sub(lo)
                .is_none_or(|d| !(0..MAX_AXIS_VALUES as i64).contains(&d))
            {
                return Err(space_error(
                    &format!("vary.{key}"),
                    format!(
                        "expected an ascending range of at most {MAX_AXIS_VALUES} values, got \"{s}\""
                    ),
                ));
            }
            Ok((lo..=hi).map(toml::Value::Integer).collect())
        }
        other => Ok(vec![other.clone()]),
    }
}

/// The built-in design space `specfx sweep` evaluates without `--space`: around `baseline`,
/// the number of squarings and the squaring stages' fraction bits and rounding (54 points).
pub const DEFAULT_SPACE: &str = r#"# specfx's built-in design space: baseline with k, and the squarings' width and rounding.
n = "16..=1024"

[vary]
k = [3, 4, 5]
"square.frac" = "10..=18"
"square.rounding" = ["TRN", "RND"]
"#;

impl Space {
    /// Records the space in a result's inputs: `[space]`, its base configuration in
    /// canonical form ([`crate::provenance::canonical_config`]), its axes and target.
    pub fn recorded(&self, inputs: crate::provenance::Inputs) -> crate::provenance::Inputs {
        let mut s = self.clone();
        s.base = crate::provenance::canonical_config(&self.base);
        inputs.value("space", &s)
    }

    /// The built-in space ([`DEFAULT_SPACE`]).
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::sweep::Space;
    /// assert_eq!(Space::builtin().n_points(), 3 * 9 * 2);
    /// ```
    pub fn builtin() -> Space {
        Space::from_toml(DEFAULT_SPACE).expect("the built-in space is valid")
    }

    /// Reads a space file. `base` is a table of configuration keys over `baseline` (as in a
    /// configuration file), `n` replaces the exponents, and `[vary]` gives each axis its values
    /// (an array, or a range string like `"10..=16"`).
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::sweep::Space;
    /// let s = Space::from_toml("n = \"64\"\n[vary]\nk = [3, 4]\n\"square.frac\" = \"12..=14\"\n").unwrap();
    /// assert_eq!(s.n_points(), 6);
    /// ```
    pub fn from_toml(text: &str) -> Result<Space, Error> {
        let file: SpaceFile = crate::error::parse_toml(text)?;
        let mut base = match file.base {
            Some(b) => b.onto(Config::baseline()).map_err(|e| match e {
                Error::Config { key, problem } => space_error(&format!("base.{key}"), problem),
                e => e,
            })?,
            None => Config::baseline(),
        };
        // Each point is named after the base (the name reaches reports and file headers).
        crate::pipeline::config::check_name(&base.name)
            .map_err(|problem| space_error("base.name", problem))?;
        if let Some(n) = file.n {
            base.n = n;
        }
        let mut axes = BTreeMap::new();
        for (key, v) in &file.vary {
            if !AXIS_KEYS.contains(&key.as_str()) {
                return Err(space_error(
                    &format!("vary.{key}"),
                    format!("unknown axis; expected one of {}", AXIS_KEYS.join(", ")),
                ));
            }
            axes.insert(key.clone(), expand(key, v)?);
        }
        let target = match file.target {
            Some(t) => t
                .parse()
                .map_err(|e: Error| space_error("target", e.to_string()))?,
            None => default_target(),
        };
        let points = axes
            .values()
            .try_fold(1u64, |acc, v| acc.checked_mul(v.len() as u64))
            .filter(|&p| p <= MAX_POINTS);
        if points.is_none() {
            let sizes: Vec<String> = axes
                .iter()
                .map(|(k, v)| format!("{k} {}", v.len()))
                .collect();
            return Err(space_error(
                "vary",
                format!(
                    "expected at most {MAX_POINTS} points (the product of the axes' lengths), got {} ({})",
                    axes.values()
                        .fold(1u128, |acc, v| acc.saturating_mul(v.len() as u128)),
                    sizes.join(" x ")
                ),
            ));
        }
        let space = Space { base, axes, target };
        // Every value must at least be of the right kind for its axis.
        for (key, values) in &space.axes {
            for v in values {
                let mut cfg = space.base.clone();
                let mut arch = Arch::Pipelined;
                apply(&mut cfg, &mut arch, key, v).map_err(|e| match e {
                    Error::Config { problem, .. } => space_error(&format!("vary.{key}"), problem),
                    e => e,
                })?;
            }
        }
        Ok(space)
    }

    /// The number of points (the product of the axes' lengths).
    pub fn n_points(&self) -> u64 {
        self.axes.values().map(|v| v.len() as u64).product()
    }

    /// The axis values of point `index`: the last axis varies fastest.
    pub fn point_values(&self, index: u64) -> Vec<(String, toml::Value)> {
        let mut rest = index;
        let mut out: Vec<(String, toml::Value)> = Vec::new();
        for (key, values) in self.axes.iter().rev() {
            let len = values.len() as u64;
            out.push((key.clone(), values[(rest % len) as usize].clone()));
            rest /= len;
        }
        out.reverse();
        out
    }

    /// The axis values of point `index` as one label, `key=value` joined by `;` (the
    /// `values` of its [`PointResult`]).
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::sweep::Space;
    /// let s = Space::from_toml("[vary]\nk = [3, 4]\n\"square.rounding\" = [\"TRN\", \"RND\"]\n").unwrap();
    /// assert_eq!(s.point_label(3), "k=4;square.rounding=RND");
    /// ```
    pub fn point_label(&self, index: u64) -> String {
        self.point_values(index)
            .iter()
            .map(|(k, v)| format!("{k}={}", v.to_string().trim_matches('"')))
            .collect::<Vec<_>>()
            .join(";")
    }

    /// The configuration and architecture of point `index`: the `arch` axis's value, else the
    /// base's `arch` key, else pipelined (a base that records an architecture records the
    /// point's).
    pub fn point(&self, index: u64) -> Result<(Config, Arch), Error> {
        let mut cfg = self.base.clone();
        let mut arch = self.base.resolve_arch(None);
        for (key, v) in self.point_values(index) {
            apply(&mut cfg, &mut arch, &key, &v)?;
        }
        if cfg.arch.is_some() {
            cfg.arch = Some(arch);
        }
        cfg.name = format!("point{index}");
        Ok((cfg, arch))
    }
}

fn with_frac(key: &str, f: Format, frac: i64) -> Result<Format, Error> {
    let frac = i32::try_from(frac)
        .map_err(|_| space_error(key, format!("fraction bits out of range: {frac}")))?;
    Format::new(f.is_signed(), f.int_bits(), frac).map_err(|e| space_error(key, e.to_string()))
}

fn with_int(key: &str, f: Format, int: i64) -> Result<Format, Error> {
    let int = i32::try_from(int)
        .map_err(|_| space_error(key, format!("integer bits out of range: {int}")))?;
    Format::new(f.is_signed(), int, f.frac_bits()).map_err(|e| space_error(key, e.to_string()))
}

fn as_str<'a>(key: &str, v: &'a toml::Value) -> Result<&'a str, Error> {
    v.as_str()
        .ok_or_else(|| space_error(key, format!("expected a string, got {v}")))
}

fn as_int(key: &str, v: &toml::Value) -> Result<i64, Error> {
    v.as_integer()
        .ok_or_else(|| space_error(key, format!("expected an integer, got {v}")))
}

fn parse<T: std::str::FromStr>(key: &str, v: &toml::Value) -> Result<T, Error>
where
    T::Err: std::fmt::Display,
{
    as_str(key, v)?
        .parse::<T>()
        .map_err(|e| space_error(key, e.to_string()))
}

/// Applies one axis value to a configuration; an error names `key`.
fn apply(cfg: &mut Config, arch: &mut Arch, key: &str, v: &toml::Value) -> Result<(), Error> {
    let fail = |problem: String| space_error(key, problem);
    match key {
        "k" => {
            let k = u32::try_from(as_int(key, v)?).map_err(|_| fail(format!("bad k: {v}")))?;
            if !crate::reference::lobe::K_RANGE.contains(&k) {
                return Err(fail(format!(
                    "expected k in {}, got {k}",
                    crate::reference::lobe::K_RANGE_TEXT
                )));
            }
            let first = cfg.square[0];
            cfg.square = vec![first; k as usize];
            cfg.k = k;
        }
        "cutoff" => cfg.cutoff = parse(key, v)?,
        "variant" => {
            cfg.variant = match as_str(key, v)? {
                "plain" => crate::pipeline::Variant::Plain,
                "minimax" => crate::pipeline::Variant::Minimax,
                s => return Err(fail(format!("expected plain or minimax, got '{s}'"))),
            }
        }
        "arch" => *arch = parse(key, v)?,
        "coef.form" => cfg.coef.form = parse(key, v)?,
        "coef.source" => cfg.coef.source = parse(key, v)?,
        "coef.frac" => cfg.coef.format = with_frac(key, cfg.coef.format, as_int(key, v)?)?,
        "coef.rounding" => cfg.coef.rounding = parse(key, v)?,
        "latency.mul" => {
            cfg.latency.mul =
                u32::try_from(as_int(key, v)?).map_err(|_| fail(format!("bad latency: {v}")))?
        }
        _ => {
            let unknown = || fail("unknown axis".into());
            let (stage, field) = key.split_once('.').ok_or_else(unknown)?;
            let specs: Vec<&mut crate::pipeline::StageSpec> = match stage {
                "t" => vec![&mut cfg.t],
                "b" => vec![&mut cfg.b],
                "out" => vec![&mut cfg.out],
                "square" => cfg.square.iter_mut().collect(),
                _ => return Err(unknown()),
            };
            for spec in specs {
                match field {
                    "frac" => spec.format = with_frac(key, spec.format, as_int(key, v)?)?,
                    "int" => spec.format = with_int(key, spec.format, as_int(key, v)?)?,
                    "rounding" => spec.rounding = parse(key, v)?,
                    "overflow" => spec.overflow = parse(key, v)?,
                    _ => return Err(unknown()),
                }
            }
        }
    }
    Ok(())
}

/// The figures of one evaluated point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointResult {
    /// The point's index in the space.
    pub index: u64,
    /// Its axis values, `key=value` joined by `;`.
    pub values: String,
    /// Why the configuration is invalid, if it is (then the figures are absent).
    pub invalid: Option<String>,
    /// max |fixed lobe - cos^n|.
    pub shape_total_max_abs: Option<f64>,
    /// max |fixed lobe - f64 lobe|.
    pub shape_quant_max_abs: Option<f64>,
    /// max output error in output LSBs.
    pub out_max_ulp: Option<f64>,
    /// Share of outputs correctly rounded.
    pub out_correctly_rounded: Option<f64>,
    /// Output non-decreasing in c for every n.
    pub monotonic: Option<bool>,
    /// Analytic logic cells on the space's target (LUTs; gates for generic).
    pub luts: Option<u64>,
    /// Analytic DSP blocks on the space's target.
    #[serde(default)]
    pub dsps: Option<u64>,
    /// Analytic flip-flops on the space's target.
    #[serde(default)]
    pub ffs: Option<u64>,
    /// Analytic register bits.
    pub register_bits: Option<u64>,
    /// Partial-product bits of the multipliers.
    pub multiplier_bits: Option<u64>,
    /// Latency in cycles.
    pub latency: Option<u64>,
    /// Initiation interval in cycles.
    pub initiation_interval: Option<u64>,
    /// On the error/cost Pareto front (set when the sweep is assembled).
    #[serde(default)]
    pub pareto: bool,
    /// yosys LUTs (Pareto points, with `--yosys`).
    #[serde(default)]
    pub yosys_luts: Option<u64>,
    /// yosys flip-flops (Pareto points, with `--yosys`).
    #[serde(default)]
    pub yosys_ffs: Option<u64>,
    /// yosys DSP blocks (Pareto points, with `--yosys`).
    #[serde(default)]
    pub yosys_dsps: Option<u64>,
}

/// Evaluates point `index` of a space: exhaustive check and analytic cost. A sweep of many
/// points evaluates them through one [`Evaluator`], which shares work between them.
pub fn evaluate(space: &Space, index: u64) -> PointResult {
    Evaluator::new(space).evaluate(index)
}

/// Evaluates the points of one space, sharing between them what does not depend on their
/// stages: the `cos^n` of the input codes and the f64 floors of each algorithm
/// ([`CosCache`], 128 MiB at most). Every point's figures are those of [`evaluate`], bit for
/// bit.
pub struct Evaluator<'a> {
    space: &'a Space,
    cos: CosCache,
}

impl<'a> Evaluator<'a> {
    /// An evaluator of `space`'s points, with nothing shared yet.
    pub fn new(space: &'a Space) -> Evaluator<'a> {
        Evaluator {
            space,
            cos: CosCache::new(COS_CACHE_VALUES),
        }
    }

    /// Evaluates point `index`: exhaustive check and analytic cost.
    pub fn evaluate(&self, index: u64) -> PointResult {
        let space = self.space;
        let values = space.point_label(index);
        let empty = |invalid: String| PointResult {
            index,
            values: values.clone(),
            invalid: Some(invalid),
            shape_total_max_abs: None,
            shape_quant_max_abs: None,
            out_max_ulp: None,
            out_correctly_rounded: None,
            monotonic: None,
            luts: None,
            dsps: None,
            ffs: None,
            register_bits: None,
            multiplier_bits: None,
            latency: None,
            initiation_interval: None,
            pareto: false,
            yosys_luts: None,
            yosys_ffs: None,
            yosys_dsps: None,
        };
        let (cfg, arch) = match space.point(index) {
            Ok(p) => p,
            Err(e) => return empty(e.to_string()),
        };
        let dp = match Datapath::new(cfg) {
            Ok(dp) => dp,
            Err(e) => return empty(e.to_string()),
        };
        let r = match check_outputs_cached(&dp, Some(&self.cos)) {
            Ok(r) => r,
            Err(e) => return empty(e.to_string()),
        };
        let cost = analytic_cost(&dp, arch, space.target);
        PointResult {
            index,
            values,
            invalid: None,
            shape_total_max_abs: Some(r.shape_total_max_abs),
            shape_quant_max_abs: Some(r.shape_quant_max_abs),
            out_max_ulp: Some(r.out_max_ulp),
            out_correctly_rounded: Some(r.out_correctly_rounded),
            monotonic: Some(r.monotonic),
            luts: Some(cost.luts),
            dsps: Some(cost.dsps),
            ffs: Some(cost.ffs),
            register_bits: Some(cost.features.register_bits),
            multiplier_bits: Some(cost.features.multiplier_bits),
            latency: Some(cost.latency),
            initiation_interval: Some(cost.initiation_interval),
            pareto: false,
            yosys_luts: None,
            yosys_ffs: None,
            yosys_dsps: None,
        }
    }
}

/// Marks the Pareto front: the valid points no other point beats in logic cells, DSP blocks
/// and error (`shape_total_max_abs`) at once, ties broken by index. Sorts by index.
pub fn mark_pareto(points: &mut [PointResult]) {
    points.sort_by_key(|p| p.index);
    let key = |p: &PointResult| {
        p.luts
            .zip(p.shape_total_max_abs)
            .map(|(c, e)| (c, p.dsps.unwrap_or(0), e))
    };
    for i in 0..points.len() {
        let Some((ci, di, ei)) = key(&points[i]) else {
            points[i].pareto = false;
            continue;
        };
        let dominated = points.iter().enumerate().any(|(j, q)| {
            key(q).is_some_and(|(cj, dj, ej)| {
                let le = cj <= ci && dj <= di && ej <= ei;
                let same = cj == ci && dj == di && ej == ei;
                j != i && le && (!same || j < i)
            })
        });
        points[i].pareto = !dominated;
    }
}

/// Parses `I/N` (0 <= I < N).
///
/// # Examples
/// ```
/// use specfx::analysis::sweep::parse_shard;
/// assert_eq!(parse_shard("1/4").unwrap(), (1, 4));
/// assert!(parse_shard("4/4").is_err());
/// ```
pub fn parse_shard(s: &str) -> Result<(u64, u64), Error> {
    let bad = || Error::Shard { got: s.to_string() };
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n) = (
        i.trim().parse::<u64>().map_err(|_| bad())?,
        n.trim().parse::<u64>().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// `space.json`: what a sweep directory holds, the identity of its sweep and its shard.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepInfo {
    /// The specfx version that wrote it.
    pub specfx_version: String,
    /// The sweep's identity, shared by all its shards: the sha256 of the canonical space and
    /// the number of shards ([`sweep_sha256`]).
    pub sweep_sha256: String,
    /// The design space.
    pub space: Space,
    /// This shard's index, `I` of `I/N`.
    pub shard_index: u64,
    /// The number of shards, `N` of `I/N`.
    pub shard_count: u64,
    /// Points of the whole space.
    pub n_points: u64,
}

/// The identity of a sweep: the sha256 of the canonical text of its space and shard count, so
/// the same space written differently is the same sweep, and a shard of another space or of
/// another sharding is not.
pub fn sweep_sha256(space: &Space, shard_count: u64) -> String {
    let inputs = space
        .recorded(crate::provenance::Inputs::new("sweep"))
        .option("shard_count", shard_count.to_string());
    crate::provenance::sha256_hex(inputs.canonical().as_bytes())
}

/// A shard given to a merge: its directory as given, the same with links resolved, and its
/// identity.
#[derive(Debug, Clone)]
pub struct GivenShard {
    /// The directory as given, for messages.
    pub dir: std::path::PathBuf,
    /// The directory with links resolved: two names of one directory are one shard.
    pub real: std::path::PathBuf,
    /// The shard's identity.
    pub info: SweepInfo,
}

/// Checks that `shards` form one complete sweep: each directory once, one design space, one
/// shard count, each shard once, none missing ([`Error::Merge`] naming what is wrong).
pub fn check_shards(shards: &[GivenShard]) -> Result<(), Error> {
    let refuse = |problem: String| Err(Error::Merge { problem });
    for (k, given) in shards.iter().enumerate() {
        let (dir, info) = (given.dir.display(), &given.info);
        for other in &shards[..k] {
            let (other_dir, other_info) = (other.dir.display(), &other.info);
            if other.real == given.real {
                return refuse(format!(
                    "{other_dir} and {dir} are the same directory: pass each shard once"
                ));
            }
            if !same_space(&other_info.space, &info.space) {
                return refuse(format!(
                    "{dir}: a shard of another sweep (its design space differs from {other_dir}'s)"
                ));
            }
            if other_info.sweep_sha256 != info.sweep_sha256 {
                return refuse(format!(
                    "{dir}: shard {} of a sweep in {} shards, but {other_dir} is shard {}: shards of one sweep share their count",
                    info.shard(),
                    info.shard_count,
                    other_info.shard()
                ));
            }
            if other_info.shard_index == info.shard_index {
                return refuse(format!(
                    "{other_dir} and {dir} are both shard {}: pass each shard once",
                    info.shard()
                ));
            }
        }
    }
    let Some(first) = shards.first() else {
        return refuse("no shard to merge".to_string());
    };
    let count = first.info.shard_count;
    let missing: Vec<String> = (0..count)
        .filter(|i| !shards.iter().any(|s| s.info.shard_index == *i))
        .take(8)
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return refuse(format!(
            "the shards given are {} of {count}: shard{} {} missing (pass every shard's directory)",
            shards.len(),
            if missing.len() > 1 { "s" } else { "" },
            missing.join(", ")
        ));
    }
    Ok(())
}

/// Checks that the shard in `dir` holds all of its points (`held` of them).
pub fn check_shard_complete(
    dir: &std::path::Path,
    info: &SweepInfo,
    held: u64,
) -> Result<(), Error> {
    let expected = info.shard_points();
    if held < expected {
        return Err(Error::Merge {
            problem: format!(
                "{} (shard {}) holds {held} of its {expected} points, {} missing: resume it (specfx sweep --shard {} --out {}, with its space)",
                dir.display(),
                info.shard(),
                expected - held,
                info.shard(),
                dir.display()
            ),
        });
    }
    Ok(())
}

/// Whether two spaces are the same, however they were written.
pub fn same_space(a: &Space, b: &Space) -> bool {
    sweep_sha256(a, 1) == sweep_sha256(b, 1)
}

/// How a points log is read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogUse {
    /// By the sweep that writes it: unreadable lines (a torn last line, an interrupted
    /// write) are dropped and computed again, and the log rewritten without them.
    Resume,
    /// By `sweep merge`, which never writes to its inputs: an unreadable line is an error,
    /// except a torn last line, which only makes the shard incomplete.
    Merge,
}

impl SweepInfo {
    /// The shard `shard_index/shard_count` of a sweep of `space`, by this specfx version.
    pub fn new(space: Space, shard_index: u64, shard_count: u64) -> SweepInfo {
        SweepInfo {
            specfx_version: crate::provenance::VERSION.to_string(),
            sweep_sha256: sweep_sha256(&space, shard_count),
            n_points: space.n_points(),
            space,
            shard_index,
            shard_count,
        }
    }

    /// Reads and checks `space.json`'s text (`name` names it in errors, `dir` its sweep
    /// directory): written by this specfx version, its identity matching its space, its shard
    /// within its count.
    pub fn from_json(text: &str, name: &str, dir: &str) -> Result<SweepInfo, Error> {
        let refuse = |problem: String| Error::Manifest { problem };
        let version = crate::provenance::VERSION;
        let info: SweepInfo = serde_json::from_str(text).map_err(|e| {
            refuse(format!(
                "{dir}: not a sweep directory of specfx {version} (space.json): {}",
                crate::error::one_line(&e.to_string())
            ))
        })?;
        if info.specfx_version != version {
            return Err(refuse(format!(
                "{dir}: written by specfx {}, this is {version}: finish and merge it with specfx {}, or sweep again",
                info.specfx_version, info.specfx_version
            )));
        }
        if info.shard_count == 0
            || info.shard_index >= info.shard_count
            || info.n_points != info.space.n_points()
            || info.sweep_sha256 != sweep_sha256(&info.space, info.shard_count)
        {
            return Err(refuse(format!(
                "{name}: space.json does not match itself (its sweep_sha256, shard or number of points was changed)"
            )));
        }
        Ok(info)
    }

    /// `I/N`.
    pub fn shard(&self) -> String {
        format!("{}/{}", self.shard_index, self.shard_count)
    }

    /// Whether point `index` belongs to this shard.
    pub fn holds(&self, index: u64) -> bool {
        index < self.n_points && index % self.shard_count == self.shard_index
    }

    /// The number of points of this shard.
    pub fn shard_points(&self) -> u64 {
        let (n, i, c) = (self.n_points, self.shard_index, self.shard_count);
        if i >= n {
            0
        } else {
            (n - 1 - i) / c + 1
        }
    }

    /// `space.json`'s bytes (pretty JSON and a newline).
    pub fn json(&self) -> Vec<u8> {
        let mut json = serde_json::to_vec_pretty(self).expect("a sweep's identity serialises");
        json.push(b'\n');
        json
    }

    /// The points of a points log's `text` (`name` names it in errors), each checked to
    /// belong to this sweep and shard (its index in the shard, its axis values those of the
    /// space), and the log's good lines (to rewrite it without the others when resuming).
    pub fn read_points(
        &self,
        text: &str,
        name: &str,
        how: LogUse,
    ) -> Result<(BTreeMap<u64, PointResult>, String), Error> {
        let refuse = |problem: String| Error::Manifest { problem };
        let mut map = BTreeMap::new();
        let mut good = String::new();
        let lines: Vec<&str> = text.split_inclusive('\n').collect();
        for (i, raw) in lines.iter().enumerate() {
            let line = raw.trim_end_matches('\n');
            let at = || format!("{name} line {}", i + 1);
            let Ok(p) = serde_json::from_str::<PointResult>(line) else {
                let torn = i + 1 == lines.len() && !raw.ends_with('\n');
                if how == LogUse::Merge && !torn {
                    return Err(refuse(format!(
                        "{}: not a point record (expected one JSON object a line)",
                        at()
                    )));
                }
                continue;
            };
            if p.index >= self.n_points {
                return Err(refuse(format!(
                    "{}: point {} is outside the space ({} points): not a point of this sweep",
                    at(),
                    p.index,
                    self.n_points
                )));
            }
            if !self.holds(p.index) {
                return Err(refuse(format!(
                    "{}: point {} belongs to shard {}/{}, not to this directory's shard {}",
                    at(),
                    p.index,
                    p.index % self.shard_count,
                    self.shard_count,
                    self.shard()
                )));
            }
            let label = self.space.point_label(p.index);
            if p.values != label {
                return Err(refuse(format!(
                    "{}: point {} is '{}' there but '{label}' in the space: not a point of this sweep",
                    at(),
                    p.index,
                    p.values
                )));
            }
            match map.get(&p.index) {
                Some(q) if *q != p => {
                    return Err(refuse(format!(
                        "{}: point {} is recorded twice with different figures",
                        at(),
                        p.index
                    )));
                }
                Some(_) => continue,
                None => {}
            }
            good.push_str(line);
            good.push('\n');
            map.insert(p.index, p);
        }
        Ok((map, good))
    }
}
