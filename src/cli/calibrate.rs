//! `specfx calibrate`: synthesises a seeded sample of configurations with yosys (resumably,
//! in parallel) into `data/calibration/<target>.jsonl`, then fits the analytic model's
//! coefficients to the records and prints them beside the committed ones with the fit error.
//! A configuration yosys fails on is not a record (never stored, tried again by the next run);
//! a fit over no record is an error; everything that can be refused is refused before the
//! first synthesis.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};
use rayon::prelude::*;

use super::output::{print_json, print_with};
use super::Outcome;
use specfx::analysis::cluster::{assign_dirs, parse_shard_spec, ShardSpec};
use specfx::hdl::calibrate::{
    calibration, fit, merge_records, read_records, sample, Calibration, Coefficients, Record,
    TargetFit,
};
use specfx::hdl::cost::Target;
use specfx::pipeline::Datapath;
use specfx::report::calibrate::write_fits;

/// Arguments of `specfx calibrate`.
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true)]
pub struct CalibrateArgs {
    #[command(subcommand)]
    command: Option<CalibrateCommand>,
    /// Targets to calibrate (comma-separated): ice40, xilinx, generic-fast.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "ice40,xilinx,generic-fast",
        value_parser = super::named_values(&Target::ALL, Target::name, super::no_help)
    )]
    targets: Vec<Target>,
    /// Number of sampled configurations per target (default: the committed sample's, 320
    /// for ice40 and 240 for the slower xilinx and generic-fast mappings); 1..=100000.
    #[arg(long, value_parser = parse_count)]
    count: Option<u64>,
    /// Seed of the sample.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Directory of the records (one `<target>.jsonl` each).
    #[arg(long, default_value = "data/calibration")]
    data: PathBuf,
    /// Only fit the records already there: do not run yosys.
    #[arg(long)]
    fit_only: bool,
    /// The reference Verilog directory (default: as `specfx cost`).
    #[arg(long)]
    hdl_ref: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
    /// Synthesise only the sample's indexes I modulo N (`I/N`; `auto/N` or `auto` from the
    /// scheduler's array task, as `specfx sweep`), into `--data` (which may hold `{shard}`),
    /// without fitting: `specfx calibrate merge` joins the shards (docs/cluster.md).
    #[arg(long, value_parser = parse_shard_spec)]
    shard: Option<ShardSpec>,
    /// Shards per array task (with `--shard auto`), as `specfx sweep`.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..))]
    shards_per_task: u64,
}

#[derive(Debug, Subcommand)]
enum CalibrateCommand {
    /// Joins the records of calibration shards (and those already in `--data`) into
    /// `--data`, in index order: the file one machine's run writes.
    Merge {
        /// The records directory to write (its records are kept and merged with the shards').
        #[arg(long, default_value = "data/calibration")]
        data: PathBuf,
        /// The seed the shards were drawn with.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The shards' records directories.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
    },
}

fn records_path(dir: &Path, target: Target) -> PathBuf {
    dir.join(format!("{}.jsonl", target.name()))
}

/// Reads a target's records (none when the file does not exist): a regular file only.
pub fn load_records(path: &Path) -> Result<Vec<Record>> {
    if !path.exists() && !path.is_symlink() {
        return Ok(Vec::new());
    }
    let shown = path.display().to_string();
    // A record is about a kilobyte: --count's largest sample is about 110 MB.
    let bytes = specfx::input::read_bytes(path, &shown, specfx::input::MAX_BINARY_BYTES)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        anyhow::anyhow!(
            "{shown}: expected UTF-8 text, got an invalid byte at offset {}",
            e.utf8_error().valid_up_to()
        )
    })?;
    Ok(read_records(&text, &shown)?)
}

/// The records as their file holds them: in index order, one JSON line each.
fn records_text(records: &[Record]) -> Result<String> {
    Ok(records
        .iter()
        .map(|r| serde_json::to_string(r).map(|l| l + "\n"))
        .collect::<Result<_, _>>()?)
}

/// One target's work, planned (and everything about it checked) before any synthesis.
struct Plan {
    target: Target,
    /// Its records file.
    path: PathBuf,
    /// The records already there.
    records: Vec<Record>,
    /// The sample's indexes still to synthesise (none with `--fit-only`).
    todo: Vec<u64>,
}

/// The records file of a collecting run, appended one line per record as it finishes (so that
/// an interrupted run resumes); created, with its directory, at the first record.
struct RecordLog {
    path: PathBuf,
    dir: PathBuf,
    file: Option<std::fs::File>,
}

impl RecordLog {
    /// Appends one line; a failed write is taken back (the file keeps its complete lines only)
    /// and named.
    fn append(&mut self, line: &str) -> Result<()> {
        let cannot = || format!("cannot write {}", self.path.display());
        if self.file.is_none() {
            std::fs::create_dir_all(&self.dir)
                .with_context(|| format!("cannot create {}", self.dir.display()))?;
            let file = std::fs::OpenOptions::new()
                .create(true)
                .append(true)
                .open(&self.path)
                .with_context(cannot)?;
            self.file = Some(file);
        }
        let file = self.file.as_mut().expect("opened above");
        let before = file.metadata().with_context(cannot)?.len();
        if let Err(e) = file.write_all(line.as_bytes()).and_then(|()| file.flush()) {
            let _ = file.set_len(before);
            return Err(e).with_context(cannot);
        }
        Ok(())
    }
}

/// Synthesises a target's missing records, appending each to its file as it finishes and to
/// the plan's records. Returns the configurations yosys failed on (index and first error
/// line): not records, never stored, so a later run tries them again.
fn collect(args: &CalibrateArgs, plan: &mut Plan, hdl_ref: &Path) -> Result<Vec<(u64, String)>> {
    let target = plan.target;
    let bar = super::progress::Progress::new(
        &format!("calibrate {}", target.name()),
        "configurations",
        plan.todo.len() as u64,
    );
    let log = std::sync::Mutex::new(RecordLog {
        path: plan.path.clone(),
        dir: plan
            .path
            .parent()
            .expect("a records file is in --data")
            .to_path_buf(),
        file: None,
    });
    let done: Result<Vec<std::result::Result<Record, (u64, String)>>> = plan
        .todo
        .par_iter()
        .map(|&index| {
            let (config, arch) = sample(args.seed, index);
            let dp = Datapath::new(config.clone())?;
            let r = match specfx::tools::yosys::synthesise(&dp, arch, target, hdl_ref) {
                Ok(s) => Record {
                    index,
                    arch,
                    config,
                    luts: s.cost.luts,
                    carries: s.cost.carries,
                    dsps: s.cost.dsps,
                    ffs: s.cost.ffs,
                },
                Err(e) => {
                    let first = format!("{e:#}").lines().next().unwrap_or("").to_string();
                    log::debug!(
                        "calibrate {}: configuration {index}: {first}",
                        target.name()
                    );
                    bar.inc(1);
                    return Ok(Err((index, first)));
                }
            };
            let line = serde_json::to_string(&r)? + "\n";
            log.lock().expect("no writer panics").append(&line)?;
            log::debug!(
                "calibrate {}: configuration {index} synthesised",
                target.name()
            );
            bar.inc(1);
            Ok(Ok(r))
        })
        .collect();
    bar.finish();
    let mut failed = Vec::new();
    for r in done? {
        match r {
            Ok(r) => plan.records.push(r),
            Err(f) => failed.push(f),
        }
    }
    failed.sort_by_key(|f| f.0);
    Ok(failed)
}

/// A `--count`: a whole number in 1..=100000 (a negative one too gets the range, not a
/// parser's reason).
fn parse_count(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(n) if (1..=100_000).contains(&n) => Ok(n),
        _ => Err("expected a whole number of configurations in 1..=100000".to_string()),
    }
}

/// Plans every target and checks everything that can be refused (the targets, the reference
/// Verilog, the data directory and its files, the tools) before the first synthesis.
fn plan(
    args: &CalibrateArgs,
    data: &Path,
    shard: Option<(u64, u64)>,
) -> Result<(Vec<Plan>, Option<PathBuf>)> {
    for (i, t) in args.targets.iter().enumerate() {
        if args.targets[..i].contains(t) {
            bail!(
                "--targets: expected each target once, got {} twice",
                t.name()
            );
        }
    }
    let hdl_ref = if args.fit_only {
        None
    } else {
        let dir = super::hdl_ref::hdl_ref(args.hdl_ref.as_deref())?;
        specfx::output::check_can_create(data, "--data")?;
        Some(dir)
    };
    let mut plans = Vec::new();
    for &target in &args.targets {
        let path = records_path(data, target);
        let records = load_records(&path)?;
        if let Some((i, n)) = shard {
            if let Some(r) = records.iter().find(|r| r.index % n != i) {
                bail!(
                    "{}: record {} is of shard {}/{n}, not {i}/{n}: expected a directory of this shard (another --data)",
                    path.display(),
                    r.index,
                    r.index % n
                );
            }
        }
        let mut todo = Vec::new();
        if args.fit_only {
            if records.is_empty() {
                bail!(
                    "{}: no calibration records (run without --fit-only to synthesise them)",
                    path.display()
                );
            }
        } else {
            if let Some(r) = records
                .iter()
                .find(|r| sample(args.seed, r.index).0 != r.config)
            {
                bail!(
                    "{}: record {} was drawn with another seed than --seed {} or another sampler; use another --data directory",
                    path.display(),
                    r.index,
                    args.seed
                );
            }
            let have: std::collections::BTreeSet<u64> = records.iter().map(|r| r.index).collect();
            let count = args.count.unwrap_or(match target {
                Target::Ice40 => 320,
                _ => 240,
            });
            todo = (0..count)
                .filter(|i| !have.contains(i) && shard.is_none_or(|(s, n)| i % n == s))
                .collect();
            // The file takes new lines: checked now, not after the first synthesis.
            if !todo.is_empty() && path.exists() {
                std::fs::OpenOptions::new()
                    .append(true)
                    .open(&path)
                    .with_context(|| format!("cannot write {}", path.display()))?;
            }
        }
        plans.push(Plan {
            target,
            path,
            records,
            todo,
        });
    }
    if plans.iter().any(|p| !p.todo.is_empty()) {
        specfx::tools::yosys::check()?;
    }
    Ok((plans, hdl_ref))
}

/// Runs `specfx calibrate`.
pub fn run(args: &CalibrateArgs) -> Result<Outcome> {
    if let Some(CalibrateCommand::Merge { data, seed, shards }) = &args.command {
        return merge(args, data, *seed, shards);
    }
    let Some(spec) = args.shard else {
        return calibrate(args, &args.data, None);
    };
    if args.fit_only {
        bail!("--shard: a shard synthesises its part of the sample; --fit-only fits whole records (after `specfx calibrate merge`)");
    }
    let env = |var: &str| std::env::var(var).ok();
    let (assignment, dirs) = assign_dirs(spec, args.shards_per_task, &env, &args.data, "--data")?;
    if assignment.several_or_scheduled() {
        log::info!("calibrate: {}", assignment.describe());
    }
    for (&i, dir) in assignment.shards.iter().zip(&dirs) {
        calibrate(args, dir, Some((i, assignment.count)))?;
    }
    Ok(Outcome::Ok)
}

/// Collects the missing records of `data` (those of shard `shard` only, when given) and fits
/// them (not a shard's: it is a part of the sample).
fn calibrate(args: &CalibrateArgs, data: &Path, shard: Option<(u64, u64)>) -> Result<Outcome> {
    let (plans, hdl_ref) = plan(args, data, shard)?;
    let mut fits = Vec::new();
    for mut plan in plans {
        let target = plan.target;
        let mut failed = Vec::new();
        if let Some(hdl_ref) = &hdl_ref {
            if !plan.todo.is_empty() {
                failed = collect(args, &mut plan, hdl_ref)?;
            }
            // In index order: the file is the same whatever the finishing order, and holds
            // records only (an earlier specfx's stored failures and a torn line are dropped).
            plan.records.sort_by_key(|r| r.index);
            let text = records_text(&plan.records)?;
            let on_disk = std::fs::read(&plan.path).ok();
            if !plan.records.is_empty() && on_disk.as_deref() != Some(text.as_bytes()) {
                specfx::output::write_atomic(&plan.path, text.as_bytes())?;
            }
        }
        if let Some((index, first)) = failed.first() {
            if plan.records.is_empty() {
                bail!(
                    "{}: no calibration records to fit: yosys failed on all {} configurations it was given (configuration {index}: {first})",
                    plan.path.display(),
                    failed.len()
                );
            }
            log::warn!(
                "calibrate {}: yosys failed on {} of {} configurations (configuration {index}: {first}); they are left out and tried again by the next run",
                target.name(),
                failed.len(),
                plan.todo.len()
            );
        }
        if let Some((i, n)) = shard {
            super::output::outln!(
                "calibrate {}: shard {i}/{n}: {} records in {}{}",
                target.name(),
                plan.records.len(),
                plan.path.display(),
                if failed.is_empty() {
                    String::new()
                } else {
                    format!(" ({} failed, tried again by the next run)", failed.len())
                }
            )?;
            continue;
        }
        if plan.records.len() < Coefficients::COUNT {
            log::warn!(
                "calibrate {}: {} records for {} coefficients: the fit is underdetermined, and its error says nothing (synthesise at least {} with --count)",
                target.name(),
                plan.records.len(),
                Coefficients::COUNT,
                Coefficients::COUNT
            );
        }
        let (coefficients, error) = fit(&plan.records, target)?;
        fits.push(TargetFit {
            fitted: Calibration {
                target,
                coefficients,
                error,
            },
            committed: calibration(target),
            failed: failed.len(),
        });
    }
    if shard.is_some() {
        return Ok(Outcome::Ok);
    }
    if args.json {
        print_json(&fits)?;
    } else {
        print_with(|w| write_fits(w, &fits, super::terminal::table_width()))?;
    }
    Ok(Outcome::Ok)
}

/// `specfx calibrate merge`: every target's records of `shards` and of `data` joined into
/// `data`, in index order; refused before writing anything when a record was drawn with
/// another seed or one index has two different records.
fn merge(args: &CalibrateArgs, data: &Path, seed: u64, shards: &[PathBuf]) -> Result<Outcome> {
    // A shard is a records directory `specfx calibrate --shard` wrote: a missing one, or a
    // file, is a mistake in the command (a shard not run, a typo), never "no records".
    for dir in shards {
        if !dir.is_dir() {
            bail!(
                "calibrate merge: shard {}: {}, expected a records directory of `specfx calibrate --shard`",
                dir.display(),
                if dir.exists() || dir.is_symlink() {
                    "is not a directory"
                } else {
                    "does not exist"
                }
            );
        }
    }
    let mut merged = Vec::new();
    for &target in &args.targets {
        let mut sets = Vec::new();
        let mut sources = 0;
        for dir in std::iter::once(&data.to_path_buf()).chain(shards) {
            let path = records_path(dir, target);
            let records = load_records(&path)?;
            sources += usize::from(!records.is_empty() && dir != data);
            sets.push((path.display().to_string(), records));
        }
        let records = merge_records(seed, sets)?;
        if sources > 0 {
            merged.push((target, records));
        }
    }
    if merged.is_empty() {
        bail!(
            "calibrate merge: no records of {} in the shards given",
            args.targets
                .iter()
                .map(|t| t.name())
                .collect::<Vec<_>>()
                .join(", ")
        );
    }
    specfx::output::check_can_create(data, "--data")?;
    std::fs::create_dir_all(data).with_context(|| format!("cannot create {}", data.display()))?;
    for (target, records) in &merged {
        let path = records_path(data, *target);
        specfx::output::write_atomic(&path, records_text(records)?.as_bytes())?;
        let last = records.last().map_or(0, |r| r.index);
        super::output::outln!(
            "calibrate merge {}: {} records into {} (indexes 0..={last}; {} missing: failed or not run, synthesised by `specfx calibrate --data {}`)",
            target.name(),
            records.len(),
            path.display(),
            last + 1 - records.len() as u64,
            data.display()
        )?;
    }
    Ok(Outcome::Ok)
}
