//! `specfx budget`: the error-budget report of a configuration (Markdown, HTML, JSON, charts),
//! with gappa's formal bounds when gappa is installed.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context, Result};
use clap::Args;
use rayon::prelude::*;

use super::output::{print_json, write_atomic, write_chart, write_provenance};
use super::Outcome;
use specfx::analysis::budget::{analyse, BudgetReport, FormalBound};
use specfx::analysis::gappa;
use specfx::analysis::optimize::Budget;
use specfx::nset::NSet;
use specfx::pipeline::Datapath;
use specfx::provenance::{Inputs, Provenance};
use specfx::report::budget::{charts, document};
use specfx::report::doc::{write_html, write_markdown, Block};
use specfx::report::table::{Align, TextTable};

/// Arguments of `specfx budget`.
#[derive(Debug, Args)]
pub struct BudgetArgs {
    /// A TOML configuration file, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Exponents, replacing the configuration's set.
    #[arg(long)]
    n: Option<NSet>,
    /// The budget to judge against, e.g. "shape_total <= 1 lsb8, out <= 1 ulp".
    #[arg(long)]
    budget: Option<Budget>,
    /// Output directory.
    #[arg(long, default_value = "specfx-budget")]
    out: PathBuf,
    /// Replace an existing output directory that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
    /// Exponents to prove a bound for with gappa (default: up to 8 spread over the set).
    #[arg(long)]
    gappa_n: Option<NSet>,
    /// Skip gappa even when it is installed.
    #[arg(long)]
    no_gappa: bool,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Up to 8 exponents of a set, spread evenly on a log scale, always with its ends.
pub fn spread(ns: &[u32]) -> Vec<u32> {
    if ns.len() <= 8 {
        return ns.to_vec();
    }
    let (lo, hi) = (f64::from(ns[0]), f64::from(ns[ns.len() - 1]));
    let mut picked: Vec<u32> = (0..8)
        .map(|j| {
            let target = lo * (hi / lo).powf(f64::from(j) / 7.0);
            *ns.iter()
                .min_by(|a, b| {
                    (f64::from(**a) - target)
                        .abs()
                        .total_cmp(&(f64::from(**b) - target).abs())
                })
                .expect("a non-empty set")
        })
        .collect();
    picked.dedup();
    picked
}

/// Proves bounds with gappa for the chosen exponents and adds them to the report.
fn add_formal_bounds(dp: &Datapath, report: &mut BudgetReport, ns: &[u32]) -> Result<()> {
    let jobs: Vec<(u32, Result<gappa::Job, specfx::Error>)> = ns
        .iter()
        .filter_map(|&n| dp.constants_for(n).map(|nc| (n, gappa::job(dp, nc))))
        .collect();
    let bar = super::progress::Progress::new("gappa", "exponents", jobs.len() as u64);
    let results: Vec<Result<Option<(u32, f64, String)>>> = jobs
        .par_iter()
        .map(|(n, job)| {
            let job = match job {
                Ok(j) => j,
                Err(why) => return Ok(Some((*n, f64::NAN, why.to_string()))),
            };
            let output = if job.upper_from.is_some() {
                match specfx::tools::gappa::run(&job.script)? {
                    Some(text) => text,
                    None => return Ok(None),
                }
            } else {
                String::new()
            };
            Ok(Some(match gappa::bound(job, &output) {
                Ok(b) => {
                    let how = match job.upper_from {
                        Some(0) => "gappa on every code".to_string(),
                        Some(k) => format!(
                            "gappa from code {k}; below it, where a model cuts the base, monotonicity bounds the error by {:.3e}",
                            job.lower_bound
                        ),
                        None => "every code is cut: monotonicity alone".to_string(),
                    };
                    (*n, b, how)
                }
                Err(why) => (*n, f64::NAN, why.to_string()),
            }))
        })
        .inspect(|_| bar.inc(1))
        .collect();
    bar.finish();
    let out_lsb = report.out_lsb;
    let mut failures = Vec::new();
    for r in results {
        let Some((n, bound, how)) = r? else {
            report.formal_note = Some(
                "gappa is not installed (Debian package `gappa`): no formal bound, only the exhaustive figures."
                    .into(),
            );
            report.formal.clear();
            return Ok(());
        };
        if bound.is_nan() {
            failures.push(format!("n = {n}: {how}"));
            continue;
        }
        let exhaustive = report
            .per_n
            .iter()
            .find(|p| p.n == n)
            .map_or(f64::NAN, |p| p.out_quant_max_ulp);
        report.formal.push(FormalBound {
            n,
            bound,
            bound_ulp: bound / out_lsb,
            exhaustive_ulp: exhaustive,
            how,
        });
    }
    if !failures.is_empty() {
        report.formal_note = Some(format!("No bound proved for {}", failures.join("; ")));
    }
    Ok(())
}

/// Analyses a datapath and writes the budget report into `dir`: `budget.md`, `budget.html`,
/// `budget.json` and the charts (SVG and PNG).
pub fn budget(
    dp: &Datapath,
    budget: Option<&Budget>,
    gappa_n: Option<&[u32]>,
    dir: &Path,
) -> Result<BudgetReport> {
    fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    log::info!(
        "budget: {}: attributing the error of every input to each source",
        dp.config().name
    );
    let mut report =
        analyse(dp, budget).map_err(|e| anyhow!("config {}: {e}", dp.config().name))?;
    match gappa_n {
        Some(ns) => {
            log::info!("budget: proving bounds with gappa for n = {ns:?}");
            add_formal_bounds(dp, &mut report, ns)?;
        }
        None => report.formal_note = Some("gappa was not run (--no-gappa).".into()),
    }
    let mut svgs = Vec::new();
    for (stem, chart) in charts(&report) {
        let svg = write_chart(dir, &stem, &chart)?;
        svgs.push((stem, svg));
    }
    let provenance = Provenance::new(&inputs(dp, budget, gappa_n));
    let mut doc = document(&report);
    doc.push(Block::Paragraph(provenance.line()));
    let mut md = Vec::new();
    write_markdown(&mut md, &doc)?;
    let mut html = Vec::new();
    write_html(
        &mut html,
        &format!("Error budget: {}", report.config),
        &doc,
        |stem| {
            svgs.iter()
                .find(|(s, _)| s == stem)
                .map(|(_, svg)| svg.clone())
        },
    )?;
    let mut json = serde_json::to_vec_pretty(&report)?;
    json.push(b'\n');
    write_atomic(&dir.join("budget.md"), &md)?;
    write_atomic(&dir.join("budget.html"), &html)?;
    write_atomic(&dir.join("budget.json"), &json)?;
    write_provenance(dir, &provenance)?;
    Ok(report)
}

/// What determines a budget report: the configuration, the budget and gappa's exponents.
fn inputs(dp: &Datapath, budget: Option<&Budget>, gappa_n: Option<&[u32]>) -> Inputs {
    let mut inputs = Inputs::new("budget").config(dp.config());
    if let Some(b) = budget {
        inputs = inputs.option("budget", b.canonical());
    }
    match gappa_n {
        Some(ns) => inputs.option("gappa_n", ns.to_vec()),
        None => inputs.option("no_gappa", true),
    }
}

/// Runs `specfx budget`. Exit code 1 when the budget is not met.
pub fn run(args: &BudgetArgs) -> Result<Outcome> {
    if let Some(b) = args
        .budget
        .as_ref()
        .and_then(|b| b.bounds.iter().find(|b| b.metric.is_yosys()))
    {
        return Err(anyhow!(
            "--budget: {} is a yosys ceiling, judged by `specfx optimize` (use `specfx cost` for yosys's figures of one configuration)",
            b.metric
        ));
    }
    let dp = super::datapath::load(&args.config, args.n.as_ref())?;
    let ns: Vec<u32> = dp.constants().iter().map(|c| c.n).collect();
    let gappa_n = match &args.gappa_n {
        _ if args.no_gappa => None,
        Some(set) => {
            let wanted = set.values().to_vec();
            if let Some(n) = wanted.iter().find(|n| !ns.contains(n)) {
                return Err(anyhow!(
                    "--gappa-n: n = {n} is not in the configuration's set {}",
                    dp.config().n
                ));
            }
            Some(wanted)
        }
        None => Some(spread(&ns)),
    };
    let out_dir = super::output::OutDir::begin(
        &args.out,
        "budget",
        args.force,
        &super::output::inputs(&args.config, None),
    )?;
    let report = budget(
        &dp,
        args.budget.as_ref(),
        gappa_n.as_deref(),
        out_dir.path(),
    )?;
    out_dir.commit()?;
    if args.json {
        print_json(&report)?;
    } else {
        let a = &report.attribution;
        let mut table = TextTable::new(&[
            ("source", Align::Left),
            ("format", Align::Left),
            ("max |err|", Align::Right),
            ("max LSB", Align::Right),
            ("RMS", Align::Right),
        ]);
        for s in a.sources.iter().chain(std::iter::once(&a.total)) {
            table.row([
                s.source.to_string(),
                s.format.to_string(),
                format!("{:.3e}", s.max_abs),
                format!("{:.3}", s.max_ulp),
                format!("{:.3e}", s.rms),
            ]);
        }
        let mut out = super::output::stdout();
        table.write(&mut out, super::terminal::table_width())?;
        writeln!(
            out,
            "sum of parts {:.3e}, residual {:.3e}",
            a.sum_of_max_abs, a.residual_max_abs
        )?;
        for f in &report.formal {
            writeln!(
                out,
                "gappa n = {}: |err| <= {:.3} LSB (exhaustive {:.3})",
                f.n, f.bound_ulp, f.exhaustive_ulp
            )?;
        }
        if let Some(note) = &report.formal_note {
            writeln!(out, "{note}")?;
        }
        if let (Some(text), Some(pass)) = (&report.budget, report.pass) {
            writeln!(out, "budget {text}: {}", if pass { "PASS" } else { "FAIL" })?;
        }
        writeln!(out, "written to {}", args.out.display())?;
    }
    Ok(if report.pass == Some(false) {
        Outcome::CheckFailed
    } else {
        Outcome::Ok
    })
}
