//! `specfx budget`: the error-budget report of a configuration (Markdown, HTML, JSON, charts),
//! with gappa's formal bounds when gappa is installed.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, Context, Result};
use clap::Args;

use super::output::print_json;
use super::Outcome;
use specfx::analysis::budget::{analyse, BudgetReport};
use specfx::analysis::budget_expr::Budget;
use specfx::analysis::gappa;
use specfx::nset::NSet;
use specfx::output::write_all_in;
use specfx::pipeline::Datapath;
use specfx::provenance::{Inputs, Provenance};
use specfx::report::budget::budget_files;
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
    /// The budget to judge against, e.g. "shape_total <= 1 lsb8, out <= 1 ulp" (a metric with
    /// a unit needs it: a bare number is refused). Cost ceilings are counted on the
    /// configuration's `arch` key (pipelined without one).
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
            let bar = super::progress::Progress::new("gappa", "exponents", ns.len() as u64);
            gappa::add_formal_bounds(dp, &mut report, ns, &specfx::tools::gappa::run, &|| {
                bar.inc(1)
            })?;
            bar.finish();
        }
        None => report.formal_note = Some("gappa was not run (--no-gappa).".into()),
    }
    let provenance = Provenance::new(&inputs(dp, budget, gappa_n));
    write_all_in(dir, &budget_files(&report, &provenance)?)?;
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
    let dp = specfx::input::load_datapath(&args.config, args.n.as_ref())?;
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
        None => Some(gappa::spread(&ns)),
    };
    let out_dir = specfx::output::OutDir::begin(
        &args.out,
        "budget",
        args.force,
        &super::output::inputs(&args.config, None),
    )?;
    // Cost ceilings are counted on the configuration's own architecture (its `arch` key).
    let judged = args.budget.clone().map(|mut b| {
        b.arch = dp.config().resolve_arch(None);
        b
    });
    let report = budget(&dp, judged.as_ref(), gappa_n.as_deref(), out_dir.path())?;
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
