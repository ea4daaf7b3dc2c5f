//! `specfx calibrate`: synthesises a seeded sample of configurations with yosys (resumably,
//! in parallel) into `data/calibration/<target>.jsonl`, then fits the analytic model's
//! coefficients to the records and prints them beside the committed ones with the fit error.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use rayon::prelude::*;
use serde::Serialize;

use super::cost::{hdl_ref_dir, run_yosys};
use super::output::{print_json, print_with};
use super::Outcome;
use specfx::hdl::calibrate::{calibration, fit, read_records, sample, Calibration, Record};
use specfx::hdl::cost::{Features, Target};
use specfx::pipeline::Datapath;
use specfx::report::table::{Align, TextTable};

/// Arguments of `specfx calibrate`.
#[derive(Debug, Args)]
pub struct CalibrateArgs {
    /// Targets to calibrate (comma-separated): ice40, xilinx, generic-fast.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "ice40,xilinx,generic-fast"
    )]
    targets: Vec<Target>,
    /// Number of sampled configurations per target (default: the committed sample's, 240
    /// for ice40 and 120 for the slower xilinx and generic-fast mappings); 1..=100000.
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
}

/// One target's refit beside the committed calibration.
#[derive(Debug, Serialize)]
pub struct TargetFit {
    /// The fit of the records now in the data directory.
    pub fitted: Calibration,
    /// The calibration the model uses (compiled in).
    pub committed: Calibration,
    /// Records yosys failed on (left out of the fit).
    pub failed: usize,
}

fn records_path(dir: &Path, target: Target) -> PathBuf {
    dir.join(format!("{}.jsonl", target.name()))
}

/// Reads a target's records (none when the file does not exist).
pub fn load_records(dir: &Path, target: Target) -> Result<Vec<Record>> {
    let path = records_path(dir, target);
    if !path.exists() {
        return Ok(Vec::new());
    }
    let text = std::fs::read_to_string(&path)
        .with_context(|| format!("cannot read {}", path.display()))?;
    Ok(read_records(&text, &path.display().to_string())?)
}

/// Synthesises the sample's missing records of a target and appends them, in index order.
fn collect(args: &CalibrateArgs, target: Target, hdl_ref: &Path) -> Result<()> {
    let path = records_path(&args.data, target);
    let mut records = load_records(&args.data, target)?;
    if records
        .iter()
        .any(|r| sample(args.seed, r.index).0 != r.config)
    {
        bail!(
            "{}: its records were drawn with another seed or sampler; use another --data directory",
            path.display()
        );
    }
    let have: std::collections::BTreeSet<u64> = records.iter().map(|r| r.index).collect();
    let count = args.count.unwrap_or(match target {
        Target::Ice40 => 240,
        _ => 120,
    });
    let todo: Vec<u64> = (0..count).filter(|i| !have.contains(i)).collect();
    if todo.is_empty() && records.windows(2).all(|w| w[0].index < w[1].index) {
        return Ok(());
    }
    std::fs::create_dir_all(&args.data)
        .with_context(|| format!("cannot create {}", args.data.display()))?;
    let bar = super::progress::Progress::new(
        &format!("calibrate {}", target.name()),
        "configurations",
        todo.len() as u64,
    );
    let file = std::sync::Mutex::new(
        std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&path)
            .with_context(|| format!("cannot write {}", path.display()))?,
    );
    let done: Result<Vec<Record>> = todo
        .par_iter()
        .map(|&index| {
            let (config, arch) = sample(args.seed, index);
            let dp = Datapath::new(config.clone())?;
            // A configuration yosys itself fails on is recorded as failed, not retried.
            let r = match run_yosys(&dp, arch, target, hdl_ref) {
                Ok((y, _, _)) => Record {
                    index,
                    arch,
                    config,
                    luts: y.luts,
                    carries: y.carries,
                    dsps: y.dsps,
                    ffs: y.ffs,
                    failed: None,
                },
                Err(e) => Record {
                    index,
                    arch,
                    config,
                    luts: 0,
                    carries: 0,
                    dsps: 0,
                    ffs: 0,
                    failed: Some(format!("{:#}", e).lines().next().unwrap_or("").to_string()),
                },
            };
            // One line per record as it finishes, so an interrupted run resumes.
            let line = serde_json::to_string(&r)? + "\n";
            file.lock()
                .expect("no writer panics")
                .write_all(line.as_bytes())?;
            log::debug!(
                "calibrate {}: configuration {index} synthesised",
                target.name()
            );
            bar.inc(1);
            Ok(r)
        })
        .collect();
    bar.finish();
    records.extend(done?);
    // Rewrite in index order: the committed file is the same whatever the finishing order.
    records.sort_by_key(|r| r.index);
    let text: String = records
        .iter()
        .map(|r| serde_json::to_string(r).map(|l| l + "\n"))
        .collect::<Result<_, _>>()?;
    super::output::write_atomic(&path, text.as_bytes())
}

/// A `--count`: a whole number in 1..=100000 (a negative one too gets the range, not a
/// parser's reason).
fn parse_count(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(n) if (1..=100_000).contains(&n) => Ok(n),
        _ => Err("expected a whole number of configurations in 1..=100000".to_string()),
    }
}

/// Runs `specfx calibrate`.
pub fn run(args: &CalibrateArgs) -> Result<Outcome> {
    let hdl_ref = hdl_ref_dir(args.hdl_ref.as_deref());
    let mut fits = Vec::new();
    for &target in &args.targets {
        if !args.fit_only {
            collect(args, target, &hdl_ref)?;
        }
        let records = load_records(&args.data, target)?;
        if records.is_empty() {
            bail!(
                "{}: no calibration records{}",
                records_path(&args.data, target).display(),
                if args.fit_only {
                    " (run without --fit-only to synthesise them)"
                } else {
                    ""
                }
            );
        }
        let (coefficients, error) = fit(&records, target)?;
        fits.push(TargetFit {
            fitted: Calibration {
                target,
                coefficients,
                error,
            },
            committed: calibration(target),
            failed: records.iter().filter(|r| r.failed.is_some()).count(),
        });
    }
    if args.json {
        print_json(&fits)?;
    } else {
        print_with(|w| write_fits(w, &fits, super::terminal::table_width()))?;
    }
    Ok(Outcome::Ok)
}

/// The fits as text: per target the fit error and the coefficient table, fitted into `width`
/// characters (`None`: as wide as its content).
fn write_fits(w: &mut impl Write, fits: &[TargetFit], width: Option<u16>) -> std::io::Result<()> {
    for f in fits {
        let (a, b) = (&f.fitted, &f.committed);
        writeln!(
            w,
            "{} ({} records{}): logic {} within {:.1}% of yosys (median), {:.1}% (90th percentile), {:.1}% (worst); flip-flops {:.1}% (median); DSP count exact on {:.0}%",
            a.target.name(),
            a.error.records,
            if f.failed > 0 {
                format!(", {} more that yosys failed on", f.failed)
            } else {
                String::new()
            },
            a.target.logic_unit(),
            100.0 * a.error.median_rel,
            100.0 * a.error.p90_rel,
            100.0 * a.error.max_rel,
            100.0 * a.error.ff_median_rel,
            100.0 * a.error.dsp_exact,
        )?;
        let mut table = TextTable::new(&[
            ("coefficient", Align::Left),
            ("fitted", Align::Right),
            ("committed", Align::Right),
        ])
        .indent(2);
        for (i, name) in Features::LOGIC_NAMES.iter().enumerate() {
            table.row([
                name.to_string(),
                format!("{:.6}", a.coefficients.logic[i]),
                format!("{:.6}", b.coefficients.logic[i]),
            ]);
        }
        table.row([
            "ffs_per_register_bit".to_string(),
            format!("{:.6}", a.coefficients.ff_per_register_bit),
            format!("{:.6}", b.coefficients.ff_per_register_bit),
        ]);
        table.write(w, width)?;
    }
    Ok(())
}
