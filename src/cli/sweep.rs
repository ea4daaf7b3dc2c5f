//! `specfx sweep`: evaluate a design space (resumable, shardable) and `specfx sweep merge`.

use std::collections::BTreeMap;
use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use serde::{Deserialize, Serialize};

use super::output::write_atomic;
use super::Outcome;
use specfx::analysis::sweep::{evaluate, mark_pareto, parse_shard, PointResult, Space};

/// Arguments of `specfx sweep`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct SweepArgs {
    #[command(subcommand)]
    command: Option<SweepCommand>,
    /// The design space (TOML: `base`, `n`, `[vary]`; see docs/sweep.md). Without it, the
    /// built-in space: baseline with k = 3..5, squarings of 10..=18 fraction bits, TRN or RND.
    #[arg(long)]
    space: Option<PathBuf>,
    /// Output directory; an unfinished sweep there is resumed.
    #[arg(long, default_value = "specfx-sweep")]
    out: PathBuf,
    /// Evaluate only the points whose index is I modulo N (written I/N).
    #[arg(long, value_parser = parse_shard)]
    shard: Option<(u64, u64)>,
    /// Also synthesise the Pareto points with yosys, on the space's target (`target` in the
    /// space file, ice40 by default); naming the target is allowed and must match it.
    #[arg(long, num_args = 0..=1, default_missing_value = "space")]
    yosys: Option<String>,
}

#[derive(Debug, Subcommand)]
enum SweepCommand {
    /// Joins the shards of one sweep into a complete one.
    Merge {
        /// Output directory of the merged sweep.
        #[arg(long)]
        out: PathBuf,
        /// The shard directories.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
    },
}

/// `space.json`: what a sweep directory holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct SweepInfo {
    specfx_version: String,
    space: Space,
    shard_index: u64,
    shard_count: u64,
    n_points: u64,
}

/// Runs `specfx sweep ...`.
pub fn run(args: &SweepArgs) -> Result<Outcome> {
    if let Some(SweepCommand::Merge { out, shards }) = &args.command {
        return merge(out, shards);
    }
    let space = match &args.space {
        None => Space::builtin(),
        Some(space_path) => {
            let text =
                super::input::read_text(space_path, &format!("space {}", space_path.display()))?;
            Space::from_toml(&text).with_context(|| format!("space {}", space_path.display()))?
        }
    };
    let (shard_index, shard_count) = args.shard.unwrap_or((0, 1));
    let info = SweepInfo {
        specfx_version: env!("CARGO_PKG_VERSION").to_string(),
        n_points: space.n_points(),
        space,
        shard_index,
        shard_count,
    };
    let dir = &args.out;
    let info_path = dir.join("space.json");
    if info_path.exists() {
        let old: SweepInfo = serde_json::from_str(&fs::read_to_string(&info_path)?)
            .with_context(|| format!("{}: not a sweep directory", dir.display()))?;
        if old.space != info.space
            || (old.shard_index, old.shard_count) != (shard_index, shard_count)
        {
            bail!(
                "{} holds another sweep (a different space or shard): choose another --out",
                dir.display()
            );
        }
    } else {
        fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        let mut json = serde_json::to_vec_pretty(&info)?;
        json.push(b'\n');
        write_atomic(&info_path, &json)?;
    }
    let mut done = read_points(&dir.join("points.jsonl"))?;
    let todo: Vec<u64> = (0..info.n_points)
        .filter(|i| i % shard_count == shard_index && !done.contains_key(i))
        .collect();
    let total = (0..info.n_points)
        .filter(|i| i % shard_count == shard_index)
        .count();
    log::info!(
        "sweep: {} points in the space, {total} in this shard, {} already done",
        info.n_points,
        total - todo.len()
    );
    let bar = super::progress::Progress::new("sweep", "points", total as u64)
        .resumed_at((total - todo.len()) as u64);
    let mut log = OpenOptions::new()
        .create(true)
        .append(true)
        .open(dir.join("points.jsonl"))
        .with_context(|| format!("cannot open {}", dir.join("points.jsonl").display()))?;
    for &index in &todo {
        let p = evaluate(&info.space, index);
        let mut line = serde_json::to_string(&p)?;
        line.push('\n');
        log.write_all(line.as_bytes())?;
        log.flush()?;
        log::debug!("sweep: point {index} done: {}", p.values);
        bar.inc(1);
        done.insert(index, p);
    }
    bar.finish();
    let mut points: Vec<PointResult> = done.into_values().collect();
    specfx::analysis::sweep::mark_pareto(&mut points);
    if let Some(named) = &args.yosys {
        let target = info.space.target;
        if named != "space" && named.parse::<specfx::hdl::cost::Target>()? != target {
            bail!(
                "--yosys {named}: the space is priced on {target}; set target = \"{named}\" in the space file to synthesise on {named}"
            );
        }
        synthesise_front(&info.space, &mut points, target, dir)?;
    }
    write_results(dir, &mut points, info.space.target)?;
    super::output::outln!(
        "sweep: {} points in {} ({} on the Pareto front)",
        points.len(),
        dir.display(),
        points.iter().filter(|p| p.pareto).count()
    )?;
    Ok(Outcome::Ok)
}

/// Runs yosys on every Pareto point, keeping results in `yosys-<target>.jsonl` so that a
/// resumed sweep does not synthesise a point twice.
fn synthesise_front(
    space: &Space,
    points: &mut [PointResult],
    target: specfx::hdl::cost::Target,
    dir: &Path,
) -> Result<()> {
    #[derive(Serialize, Deserialize)]
    struct Synth {
        index: u64,
        luts: u64,
        ffs: u64,
        dsps: u64,
    }
    let path = dir.join(format!("yosys-{target}.jsonl"));
    let mut known: BTreeMap<u64, Synth> = fs::read_to_string(&path)
        .unwrap_or_default()
        .lines()
        .filter_map(|l| serde_json::from_str::<Synth>(l).ok())
        .map(|s| (s.index, s))
        .collect();
    let hdl = super::cost::hdl_ref_dir(None);
    for p in points.iter_mut().filter(|p| p.pareto) {
        if let std::collections::btree_map::Entry::Vacant(slot) = known.entry(p.index) {
            let (cfg, arch) = space.point(p.index).map_err(anyhow::Error::msg)?;
            let dp = specfx::pipeline::Datapath::new(cfg)?;
            log::info!(
                "sweep: synthesising Pareto point {} with yosys ({target})",
                p.index
            );
            let (cost, _, _) = super::cost::run_yosys(&dp, arch, target, &hdl)?;
            let s = Synth {
                index: p.index,
                luts: cost.luts,
                ffs: cost.ffs,
                dsps: cost.dsps,
            };
            let mut line = serde_json::to_string(&s)?;
            line.push('\n');
            OpenOptions::new()
                .create(true)
                .append(true)
                .open(&path)?
                .write_all(line.as_bytes())?;
            slot.insert(s);
        }
        let s = &known[&p.index];
        p.yosys_luts = Some(s.luts);
        p.yosys_ffs = Some(s.ffs);
        p.yosys_dsps = Some(s.dsps);
    }
    Ok(())
}

/// The points recorded so far; a torn last line (an interrupted write) is dropped and will be
/// computed again.
fn read_points(path: &Path) -> Result<BTreeMap<u64, PointResult>> {
    let mut map = BTreeMap::new();
    let Ok(text) = fs::read_to_string(path) else {
        return Ok(map);
    };
    let mut good = String::new();
    for line in text.lines() {
        if let Ok(p) = serde_json::from_str::<PointResult>(line) {
            good.push_str(line);
            good.push('\n');
            map.insert(p.index, p);
        }
    }
    if good.len() != text.len() {
        write_atomic(path, good.as_bytes())?;
    }
    Ok(map)
}

fn write_results(
    dir: &Path,
    points: &mut [PointResult],
    target: specfx::hdl::cost::Target,
) -> Result<()> {
    mark_pareto(points);
    let mut csv = Vec::new();
    specfx::report::sweep::write_csv(&mut csv, points, target)?;
    write_atomic(&dir.join("sweep.csv"), &csv)?;
    let mut json = serde_json::to_vec_pretty(&points)?;
    json.push(b'\n');
    write_atomic(&dir.join("sweep.json"), &json)?;
    let chart = specfx::report::sweep::chart(points, target);
    let svg = specfx::report::chart::render_svg(&chart).map_err(anyhow::Error::msg)?;
    write_atomic(&dir.join("sweep.svg"), svg.as_bytes())?;
    let png = specfx::report::chart::render_png(&chart).map_err(anyhow::Error::msg)?;
    write_atomic(&dir.join("sweep.png"), &png)?;
    Ok(())
}

fn merge(out: &Path, shards: &[PathBuf]) -> Result<Outcome> {
    let mut info: Option<SweepInfo> = None;
    let mut points = BTreeMap::new();
    for dir in shards {
        let path = dir.join("space.json");
        let this: SweepInfo = serde_json::from_str(
            &fs::read_to_string(&path)
                .with_context(|| format!("cannot read {}", path.display()))?,
        )
        .with_context(|| format!("{}: not a sweep directory", dir.display()))?;
        if let Some(first) = &info {
            if first.space != this.space {
                bail!(
                    "{}: a shard of another sweep (its space differs)",
                    dir.display()
                );
            }
        } else {
            info = Some(this.clone());
        }
        points.extend(read_points(&dir.join("points.jsonl"))?);
    }
    let info = info.expect("at least one shard");
    let missing = (0..info.n_points)
        .filter(|i| !points.contains_key(i))
        .count();
    if missing > 0 {
        bail!(
            "the shards hold {} of {} points: {missing} are missing (run or resume the other shards)",
            points.len(),
            info.n_points
        );
    }
    fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let target = info.space.target;
    let merged = SweepInfo {
        shard_index: 0,
        shard_count: 1,
        ..info
    };
    let mut json = serde_json::to_vec_pretty(&merged)?;
    json.push(b'\n');
    write_atomic(&out.join("space.json"), &json)?;
    let mut lines = String::new();
    for p in points.values() {
        lines.push_str(&serde_json::to_string(p)?);
        lines.push('\n');
    }
    write_atomic(&out.join("points.jsonl"), lines.as_bytes())?;
    let mut points: Vec<PointResult> = points.into_values().collect();
    write_results(out, &mut points, target)?;
    super::output::outln!(
        "sweep merge: {} points from {} shards into {}",
        points.len(),
        shards.len(),
        out.display()
    )?;
    Ok(Outcome::Ok)
}
