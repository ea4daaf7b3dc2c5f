//! `specfx sweep`: evaluate a design space (resumable, shardable) and `specfx sweep merge`.

use std::collections::BTreeMap;
use std::fs::{self, OpenOptions};
use std::io::Write;
use std::path::{Component, Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use serde::{Deserialize, Serialize};

use super::Outcome;
use specfx::analysis::cluster::{
    assign_dirs, parse_shard_spec, Emit, Plan, PointCost, SchedulerOptions, ShardSpec,
    MAX_SHARDS_PER_TASK, MAX_TASKS,
};
use specfx::analysis::sweep::{
    check_shard_complete, check_shards, mark_pareto, same_space, Evaluator, GivenShard, LogUse,
    PointResult, Space, SweepInfo, DEFAULT_SPACE,
};
use specfx::output::OutDir;
use specfx::provenance::{Inputs, Provenance};

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
    /// Output directory; an unfinished sweep of the same space and shard there is resumed.
    /// `{shard}` in it stands for the shard's index (zero-padded), and is required with
    /// `--shard auto` and with several shards per task: each shard writes its own directory.
    #[arg(long, default_value = "specfx-sweep")]
    out: PathBuf,
    /// Evaluate only the points whose index is I modulo N: `I/N`; `auto/N` takes I from the
    /// scheduler's array task (SLURM_ARRAY_TASK_ID, LSB_JOBINDEX, SGE_TASK_ID, PBS_ARRAYID or
    /// JOB_COMPLETION_INDEX); `auto` takes N from it too (docs/cluster.md).
    #[arg(long, value_parser = parse_shard_spec)]
    shard: Option<ShardSpec>,
    /// Shards per array task (with `--shard auto`): task t of T = ceil(N / S) evaluates shards
    /// t, t + T, t + 2T, ... in turn, so that a large N needs no more tasks than the
    /// scheduler's array allows.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    shards_per_task: u64,
    /// Also synthesise the Pareto points with yosys, on the space's target (`target` in the
    /// space file, ice40 by default); naming the target is allowed and must match it.
    #[arg(long, num_args = 0..=1, default_missing_value = "space")]
    yosys: Option<String>,
}

#[derive(Debug, Subcommand)]
enum SweepCommand {
    /// Writes the job scripts that run a sweep on a cluster: an array job whose tasks take
    /// their shards from the scheduler (`--shard auto/N`), a merge step after it, and
    /// `submit.sh` (docs/cluster.md).
    Plan(PlanArgs),
    /// Joins the shards of one sweep into a complete one.
    Merge {
        /// Output directory of the merged sweep (never one of the shards, nor inside one).
        #[arg(long)]
        out: PathBuf,
        /// Replace an existing directory that is not an earlier merge of the same sweep.
        #[arg(long)]
        force: bool,
        /// The shard directories: every shard of one sweep, each once.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
    },
}

/// Arguments of `specfx sweep plan`.
#[derive(Debug, Args)]
pub struct PlanArgs {
    /// The design space (as `specfx sweep --space`; without it, the built-in space).
    #[arg(long)]
    space: Option<PathBuf>,
    /// Number of array tasks.
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u64).range(1..=MAX_TASKS))]
    tasks: u64,
    /// Shards per task: the sweep has tasks x shards-per-task shards.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=MAX_SHARDS_PER_TASK))]
    shards_per_task: u64,
    /// The scheduler: slurm, lsf, sge, k8s or shell.
    #[arg(long, default_value = "slurm", value_parser = super::named_values(&Emit::ALL, Emit::name, super::no_help))]
    emit: Emit,
    /// Threads (CPUs) each task requests and uses.
    #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=256))]
    threads: u32,
    /// The command the scripts run specfx with (a path on the cluster's nodes).
    #[arg(long, default_value = "specfx")]
    specfx: String,
    /// The partition (Slurm) or queue (LSF, SGE) every job is submitted to.
    #[arg(long)]
    partition: Option<String>,
    /// The account (Slurm) or project (LSF, SGE) every job is charged to.
    #[arg(long)]
    account: Option<String>,
    /// The quality of service of every job (Slurm).
    #[arg(long)]
    qos: Option<String>,
    /// A line of your own for every job script, after the scheduler's prefix (`--directive
    /// --gres=gpu:1` writes `#SBATCH --gres=gpu:1`); repeat it for more.
    #[arg(long, allow_hyphen_values = true)]
    directive: Vec<String>,
    /// Seconds a point takes, instead of timing three points of the space here (the scripts
    /// are then the same bytes on every machine).
    #[arg(long, value_parser = parse_seconds)]
    seconds_per_point: Option<f64>,
    /// Output directory: the space, the scripts, `plan.json`; the tasks write `shards/` and
    /// the merge `merged/` beside them.
    #[arg(long, default_value = "specfx-sweep-plan")]
    out: PathBuf,
    /// Replace an existing directory that is not an earlier plan.
    #[arg(long)]
    force: bool,
}

fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 && v <= 86_400.0 => Ok(v),
        _ => Err(format!(
            "expected seconds per point in (0, 86400], got '{s}'"
        )),
    }
}

/// Runs `specfx sweep plan`.
fn plan(args: &PlanArgs) -> Result<Outcome> {
    // What the scripts ask the scheduler, refused before any work.
    let scheduler = SchedulerOptions {
        partition: args.partition.clone(),
        account: args.account.clone(),
        qos: args.qos.clone(),
        directives: args.directive.clone(),
    };
    scheduler.check(args.emit)?;
    let (space, text) = match &args.space {
        None => (Space::builtin(), DEFAULT_SPACE.to_string()),
        Some(path) => {
            let text = specfx::input::read_text(path, &format!("space {}", path.display()))?;
            let space =
                Space::from_toml(&text).with_context(|| format!("space {}", path.display()))?;
            (space, text)
        }
    };
    let n_points = space.n_points();
    let shards = specfx::analysis::cluster::split(n_points, args.tasks, args.shards_per_task)?;
    let sha = specfx::analysis::sweep::sweep_sha256(&space, shards);
    let inputs: Vec<(&str, PathBuf)> = args.space.iter().map(|p| ("--space", p.clone())).collect();
    // An earlier plan whose tasks ran is re-planned in place, its results kept; otherwise the
    // plan is staged and committed whole.
    let kept = earlier_plan_results(&args.out, &sha)?;
    let out_dir = match kept {
        Some(_) => {
            specfx::output::refuse_over_inputs(&args.out, "--out", &inputs)?;
            None
        }
        None => Some(OutDir::begin(&args.out, "sweep plan", args.force, &inputs)?),
    };
    let point_cost = match args.seconds_per_point {
        Some(seconds) => PointCost {
            seconds,
            peak_mib: 0,
            measured: false,
        },
        None => {
            log::info!("sweep plan: timing three points of the space ({n_points} points)");
            specfx::analysis::cluster::measure_point_cost(&space)
        }
    };
    let plan = Plan::new(
        args.emit,
        &sha,
        n_points,
        (args.tasks, args.shards_per_task),
        point_cost,
        args.threads,
        &args.specfx,
    )?
    .with_scheduler(scheduler.clone())?;
    let mut inputs = space
        .recorded(Inputs::new("sweep plan"))
        .option("emit", args.emit.name())
        .option("tasks", plan.tasks.to_string())
        .option("shards_per_task", plan.shards_per_task.to_string())
        .option("threads", i64::from(args.threads))
        .option("specfx", args.specfx.clone())
        .option("seconds_per_point", point_cost.seconds)
        .option("peak_mib", point_cost.peak_mib.to_string());
    // Recorded only when given: a plan without them keeps the provenance it had.
    for (key, value) in [
        ("partition", &scheduler.partition),
        ("account", &scheduler.account),
        ("qos", &scheduler.qos),
    ] {
        if let Some(v) = value {
            inputs = inputs.option(key, v.clone());
        }
    }
    if !scheduler.directives.is_empty() {
        inputs = inputs.option("directives", scheduler.directives.clone());
    }
    let mut files = specfx::report::cluster::plan_files(&plan, &text)?;
    files.extend(Provenance::new(&inputs).files());
    match out_dir {
        Some(out_dir) => {
            specfx::output::write_all_shown(out_dir.path(), &args.out, &files)?;
            out_dir.commit()?;
        }
        None => {
            specfx::output::write_all_shown(&args.out, &args.out, &files)?;
            // The earlier plan's scripts for another scheduler, gone from this plan.
            for entry in plan_entries(&args.out)? {
                if specfx::report::cluster::is_plan_file(&entry)
                    && !files.iter().any(|(name, _)| *name == entry)
                    && entry != specfx::output::MARKER
                {
                    let path = args.out.join(&entry);
                    fs::remove_file(&path)
                        .with_context(|| format!("cannot remove {}", path.display()))?;
                }
            }
        }
    }
    if let Some(results) = &kept {
        log::info!(
            "sweep plan: {} re-planned in place; kept what its tasks computed: {}",
            args.out.display(),
            summarise(results)
        );
    }
    let r = &plan.resources;
    super::output::outln!(
        "sweep plan: {} points in {} shards over {} {} tasks ({} threads, {} MiB, {} min each) in {}; run {}/submit.sh",
        n_points,
        plan.shards,
        plan.tasks,
        args.emit.name(),
        r.threads,
        r.memory_mib,
        r.time_s / 60,
        args.out.display(),
        args.out.display()
    )?;
    Ok(Outcome::Ok)
}

/// The names of the entries of the directory `dir`, sorted.
fn plan_entries(dir: &Path) -> Result<Vec<String>> {
    let mut names = Vec::new();
    for entry in fs::read_dir(dir).with_context(|| format!("cannot read {}", dir.display()))? {
        let entry = entry.with_context(|| format!("cannot read {}", dir.display()))?;
        names.push(entry.file_name().to_string_lossy().into_owned());
    }
    names.sort();
    Ok(names)
}

/// A few of `names`, for a message: `shards/, merged/, slurm-1_0.out and 3 more`.
fn summarise(names: &[String]) -> String {
    let shown: Vec<String> = names.iter().take(3).cloned().collect();
    match names.len() - shown.len() {
        0 => shown.join(", "),
        more => format!("{} and {more} more", shown.join(", ")),
    }
}

/// What re-planning into `out` must keep. `None` where `out` holds no plan's results: it is
/// absent, empty, not a plan (left to [`OutDir`]'s rules), or a plan that nothing ran from.
/// `Some(entries)` where it is an earlier plan of the same sweep (`sweep_sha256`) whose tasks,
/// merge or scheduler wrote `entries` (`shards/`, `merged/`, logs): they are kept in place.
/// Refused, even with `--force`, where they belong to another sweep: replacing the plan would
/// delete what a cluster computed.
fn earlier_plan_results(out: &Path, sweep_sha256: &str) -> Result<Option<Vec<String>>> {
    if !out.is_dir() || specfx::output::result_of(out).as_deref() != Some("sweep plan") {
        return Ok(None);
    }
    let results: Vec<String> = plan_entries(out)?
        .into_iter()
        .filter(|name| !specfx::report::cluster::is_plan_file(name))
        .collect();
    if results.is_empty() {
        return Ok(None);
    }
    let earlier = fs::read_to_string(out.join("plan.json"))
        .ok()
        .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
        .and_then(|v| v["sweep_sha256"].as_str().map(str::to_string));
    match earlier {
        Some(earlier) if earlier == sweep_sha256 => Ok(Some(results)),
        earlier => bail!(
            "{} holds what an earlier plan's tasks computed ({}) for {}: re-planning there would lose it, with or without --force; choose another --out, or move those results away first",
            out.display(),
            summarise(&results),
            match earlier {
                Some(e) => format!(
                    "another sweep ({} there, {} now)",
                    &e[..e.len().min(12)],
                    &sweep_sha256[..12]
                ),
                None => "a sweep whose plan.json is unreadable".to_string(),
            }
        ),
    }
}

/// Reads and checks a sweep directory's `space.json` ([`SweepInfo::from_json`]).
fn read_info(dir: &Path) -> Result<SweepInfo> {
    let path = dir.join("space.json");
    if !path.exists() && !path.is_symlink() {
        bail!("{}: not a sweep directory (no space.json)", dir.display());
    }
    let text = specfx::input::read_text(&path, &path.display().to_string())?;
    Ok(SweepInfo::from_json(
        &text,
        &path.display().to_string(),
        &dir.display().to_string(),
    )?)
}

/// The largest points log read (about 600 bytes a point, at most 2^20 points).
const MAX_LOG_BYTES: u64 = 1 << 30;

/// The points of a sweep directory's `points.jsonl`, each checked to belong to the sweep and
/// shard of `info` (its index in the shard, its axis values those of the space).
fn read_log(dir: &Path, info: &SweepInfo, how: LogUse) -> Result<BTreeMap<u64, PointResult>> {
    let path = dir.join("points.jsonl");
    if !path.exists() && !path.is_symlink() {
        return Ok(BTreeMap::new());
    }
    let bytes = specfx::input::read_bytes(&path, &path.display().to_string(), MAX_LOG_BYTES)?;
    let text = String::from_utf8_lossy(&bytes);
    let (map, good) = info.read_points(&text, &path.display().to_string(), how)?;
    if how == LogUse::Resume && good.len() != text.len() {
        specfx::output::write_all_shown(
            dir,
            dir,
            &[("points.jsonl".to_string(), good.into_bytes())],
        )?;
    }
    Ok(map)
}

/// Runs `specfx sweep ...`.
pub fn run(args: &SweepArgs) -> Result<Outcome> {
    match &args.command {
        Some(SweepCommand::Merge { out, force, shards }) => return merge(out, shards, *force),
        Some(SweepCommand::Plan(plan_args)) => return plan(plan_args),
        None => {}
    }
    let space = match &args.space {
        None => Space::builtin(),
        Some(space_path) => {
            let text =
                specfx::input::read_text(space_path, &format!("space {}", space_path.display()))?;
            Space::from_toml(&text).with_context(|| format!("space {}", space_path.display()))?
        }
    };
    let spec = args
        .shard
        .unwrap_or(ShardSpec::Given { index: 0, count: 1 });
    let env = |var: &str| std::env::var(var).ok();
    let (assignment, dirs) = assign_dirs(spec, args.shards_per_task, &env, &args.out, "--out")?;
    if assignment.several_or_scheduled() {
        log::info!("sweep: {}", assignment.describe());
    }
    let target = space.target;
    if let Some(named) = &args.yosys {
        if named != "space" && named.parse::<specfx::hdl::cost::Target>()? != target {
            bail!(
                "--yosys {named}: the space is priced on {target}; set target = \"{named}\" in the space file to synthesise on {named}"
            );
        }
    }
    for (&shard_index, dir) in assignment.shards.iter().zip(&dirs) {
        sweep_shard(args, space.clone(), shard_index, assignment.count, dir)?;
    }
    Ok(Outcome::Ok)
}

/// Evaluates shard `shard_index` of `shard_count` into `dir` (resuming what is there), writes
/// its results and prints its summary line.
fn sweep_shard(
    args: &SweepArgs,
    space: Space,
    shard_index: u64,
    shard_count: u64,
    dir: &Path,
) -> Result<()> {
    let target = space.target;
    let info = SweepInfo::new(space, shard_index, shard_count);
    if dir.join("space.json").exists() || dir.join("space.json").is_symlink() {
        let old = read_info(dir)?;
        if old.sweep_sha256 != info.sweep_sha256 || old.shard_index != shard_index {
            let what = if !same_space(&old.space, &info.space) {
                "another design space".to_string()
            } else {
                format!("shard {}, not {}", old.shard(), info.shard())
            };
            bail!(
                "{} holds another sweep ({what}): choose another --out",
                dir.display()
            );
        }
    } else {
        // A new sweep directory is staged and renamed: it appears with its space.json, or not.
        let non_empty = fs::read_dir(dir).is_ok_and(|mut d| d.next().is_some());
        if non_empty {
            bail!(
                "{} exists and is not a sweep directory (no space.json): choose another --out",
                dir.display()
            );
        }
        if dir.exists() && !dir.is_dir() {
            bail!(
                "{}: exists and is not a directory (pass another --out)",
                dir.display()
            );
        }
        let staged = OutDir::begin(dir, "sweep", false, &[])?;
        specfx::output::write_all_shown(
            staged.path(),
            dir,
            &[("space.json".to_string(), info.json())],
        )?;
        staged.commit()?;
    }
    let log_path = dir.join("points.jsonl");
    let mut done = read_log(dir, &info, LogUse::Resume)?;
    let todo: Vec<u64> = (0..info.n_points)
        .filter(|&i| info.holds(i) && !done.contains_key(&i))
        .collect();
    let total = info.shard_points() as usize;
    log::info!(
        "sweep: {} points in the space, {total} in this shard, {} already done",
        info.n_points,
        total - todo.len()
    );
    let bar = super::progress::Progress::new("sweep", "points", total as u64)
        .resumed_at((total - todo.len()) as u64);
    let cannot_write = || format!("cannot write {}", log_path.display());
    let mut log = OpenOptions::new()
        .create(true)
        .append(true)
        .open(&log_path)
        .with_context(cannot_write)?;
    let evaluator = Evaluator::new(&info.space);
    for &index in &todo {
        let p = evaluator.evaluate(index);
        let mut line = serde_json::to_string(&p)?;
        line.push('\n');
        log.write_all(line.as_bytes())
            .and_then(|()| log.flush())
            .with_context(cannot_write)?;
        log::debug!("sweep: point {index} done: {}", p.values);
        bar.inc(1);
        done.insert(index, p);
    }
    bar.finish();
    log.sync_all().with_context(cannot_write)?;
    let mut points: Vec<PointResult> = done.into_values().collect();
    specfx::analysis::sweep::mark_pareto(&mut points);
    let mut inputs = info
        .space
        .recorded(Inputs::new("sweep"))
        .option("shard", info.shard());
    if args.yosys.is_some() {
        synthesise_front(&info.space, &mut points, target, dir)?;
        inputs = inputs.option("yosys", target.name());
    }
    write_results(dir, dir, &mut points, target, &Provenance::new(&inputs))?;
    super::output::outln!(
        "sweep: {} points in {} ({} on the Pareto front)",
        points.len(),
        dir.display(),
        points.iter().filter(|p| p.pareto).count()
    )?;
    Ok(())
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
    let text = if path.exists() || path.is_symlink() {
        specfx::input::read_text(&path, &path.display().to_string())?
    } else {
        String::new()
    };
    let mut known: BTreeMap<u64, Synth> = text
        .lines()
        .filter_map(|l| serde_json::from_str::<Synth>(l).ok())
        .map(|s| (s.index, s))
        .collect();
    let hdl = super::hdl_ref::hdl_ref_dir(None);
    for p in points.iter_mut().filter(|p| p.pareto) {
        if let std::collections::btree_map::Entry::Vacant(slot) = known.entry(p.index) {
            let (cfg, arch) = space.point(p.index)?;
            let dp = specfx::pipeline::Datapath::new(cfg)?;
            log::info!(
                "sweep: synthesising Pareto point {} with yosys ({target})",
                p.index
            );
            let cost = specfx::tools::yosys::synthesise(&dp, arch, target, &hdl)?.cost;
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
                .open(&path)
                .and_then(|mut f| f.write_all(line.as_bytes()))
                .with_context(|| format!("cannot write {}", path.display()))?;
            slot.insert(s);
        }
        let s = &known[&p.index];
        p.yosys_luts = Some(s.luts);
        p.yosys_ffs = Some(s.ffs);
        p.yosys_dsps = Some(s.dsps);
    }
    Ok(())
}

/// Writes the sweep's results into `dir` (named `shown` in errors) all or nothing: CSV,
/// JSON, the chart, and what determined them (`inputs.toml`, `provenance.json`).
fn write_results(
    dir: &Path,
    shown: &Path,
    points: &mut [PointResult],
    target: specfx::hdl::cost::Target,
    provenance: &Provenance,
) -> Result<()> {
    mark_pareto(points);
    let files = specfx::report::sweep::sweep_files(points, target, provenance)?;
    Ok(specfx::output::write_all_shown(dir, shown, &files)?)
}

/// A path made absolute with every symbolic link resolved, also when its last components do
/// not exist yet (they are appended to the canonical form of the longest existing prefix).
fn resolved(path: &Path) -> Result<PathBuf> {
    let abs = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir()
            .context("cannot read the current directory")?
            .join(path)
    };
    let mut existing = abs.as_path();
    let mut rest: Vec<Component<'_>> = Vec::new();
    loop {
        if let Ok(c) = existing.canonicalize() {
            let mut out = c;
            for comp in rest.iter().rev() {
                match comp {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::CurDir => {}
                    other => out.push(other.as_os_str()),
                }
            }
            return Ok(out);
        }
        match (existing.parent(), existing.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last);
                existing = parent;
            }
            _ => return Ok(abs),
        }
    }
}

/// Whether `out` is an earlier merge of the sweep `sweep` (which a merge may replace).
fn earlier_merge_of(out: &Path, sweep: &str) -> bool {
    specfx::output::result_of(out).as_deref() == Some(MERGE_MARKER)
        && read_info(out).is_ok_and(|i| i.sweep_sha256 == sweep)
}

/// The marker of a merged sweep directory.
const MERGE_MARKER: &str = "sweep-merge";

fn merge(out: &Path, shards: &[PathBuf], force: bool) -> Result<Outcome> {
    // Every shard's identity first, then every point, then the output: nothing is written
    // until the inputs are known to form one complete sweep.
    let mut given = Vec::new();
    for dir in shards {
        let info = read_info(dir)?;
        given.push(GivenShard {
            dir: dir.clone(),
            real: resolved(dir)?,
            info,
        });
    }
    check_shards(&given)?;
    let first = given[0].info.clone();
    // The output is none of the inputs, inside none, and holds none.
    let out_real = resolved(out)?;
    for GivenShard { real, dir, .. } in &given {
        if out_real == *real || out_real.starts_with(real) || real.starts_with(&out_real) {
            let how = if out_real == *real {
                "is"
            } else if out_real.starts_with(real) {
                "is inside"
            } else {
                "contains"
            };
            bail!(
                "--out {} {how} the shard {}: merge never writes over its inputs (choose another --out)",
                out.display(),
                dir.display()
            );
        }
    }
    let mut points = BTreeMap::new();
    for GivenShard { dir, info, .. } in &given {
        let mine = read_log(dir, info, LogUse::Merge)?;
        check_shard_complete(dir, info, mine.len() as u64)?;
        points.extend(mine);
    }
    let merged = SweepInfo::new(first.space.clone(), 0, 1);
    let occupied = fs::read_dir(out).is_ok_and(|mut d| d.next().is_some());
    if occupied && !force && !earlier_merge_of(out, &merged.sweep_sha256) {
        // A result there (another sweep's merge, any command's) is never offered to --force.
        match specfx::output::result_of(out) {
            Some(holder) => bail!(
                "{} holds {}, not an earlier merge of this sweep: choose another --out, or move it away first",
                out.display(),
                if holder == MERGE_MARKER {
                    "the merge of another sweep".to_string()
                } else {
                    format!("a `specfx {holder}` result")
                }
            ),
            None => bail!(
                "{} already exists and is not an earlier merge of this sweep: pass --force to replace it",
                out.display()
            ),
        }
    }
    let staged = OutDir::begin(out, MERGE_MARKER, true, &[])?;
    let target = merged.space.target;
    let mut lines = String::new();
    for p in points.values() {
        lines.push_str(&serde_json::to_string(p)?);
        lines.push('\n');
    }
    specfx::output::write_all_shown(
        staged.path(),
        out,
        &[
            ("space.json".to_string(), merged.json()),
            ("points.jsonl".to_string(), lines.into_bytes()),
        ],
    )?;
    let mut points: Vec<PointResult> = points.into_values().collect();
    let inputs = merged
        .space
        .recorded(Inputs::new("sweep"))
        .option("shard", merged.shard());
    write_results(
        staged.path(),
        out,
        &mut points,
        target,
        &Provenance::new(&inputs),
    )?;
    staged.commit()?;
    super::output::outln!(
        "sweep merge: {} points from {} shards into {}",
        points.len(),
        shards.len(),
        out.display()
    )?;
    Ok(Outcome::Ok)
}
