//! `specfx tradeoff`: speed against accuracy for every method, with charts.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::output::print_json;
use super::Outcome;
use specfx::analysis::frontier::{self as fr, Frontier};
use specfx::analysis::tradeoff::{inputs, method_count, MethodFigures, YosysFigures};
use specfx::cycle::Arch;
use specfx::nset::NSet;
use specfx::output::write_all_in;
use specfx::pipeline::Datapath;
use specfx::provenance::Provenance;
use specfx::report::tradeoff::{tradeoff_files, write_table};
use specfx::tools::yosys::synthesise;

/// Arguments of `specfx tradeoff`.
#[derive(Debug, Args)]
pub struct TradeoffArgs {
    /// Output directory.
    #[arg(long, default_value = "specfx-tradeoff")]
    out: PathBuf,
    /// Replace an existing output directory that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
    /// Exponents.
    #[arg(long, default_value = "16..=1024")]
    n: NSet,
    /// Also synthesise the fixed-point datapaths with yosys for this target (ice40, xilinx,
    /// generic, generic-fast): a few seconds each.
    #[arg(long, value_parser = super::named_values(&specfx::hdl::cost::Target::ALL, specfx::hdl::cost::Target::name, super::no_help))]
    yosys: Option<specfx::hdl::cost::Target>,
    /// The error budgets of the frontier (shape_total, in lsb8): at each, every algorithm's
    /// cheapest datapath found by the optimiser (pipelined, no device limit), charted against
    /// its cost; none skips the frontier and its charts (minutes on 2 cores for the default
    /// over n = 16..1024).
    #[arg(long, default_value = "8,4,2,1,0.75,0.5", value_parser = parse_ladder)]
    ladder: Ladder,
    /// Print the figures as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// The budgets of `--ladder`, in lsb8 (empty: no frontier).
#[derive(Debug, Clone)]
pub struct Ladder(pub Vec<f64>);

/// Parses `--ladder`: budgets in lsb8 joined by commas, each positive, or `none`.
pub fn parse_ladder(s: &str) -> std::result::Result<Ladder, String> {
    if s.trim() == "none" {
        return Ok(Ladder(Vec::new()));
    }
    s.split(',')
        .map(|b| match b.trim().parse::<f64>() {
            Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
            _ => Err(format!(
                "expected budgets in lsb8 joined by commas, each a positive number (e.g. 8,4,2,1), or none; got '{}'",
                b.trim()
            )),
        })
        .collect::<std::result::Result<Vec<f64>, String>>()
        .map(Ladder)
}

/// The frontier of the optimiser's cheapest datapaths over `ladder` (none when it is empty),
/// with a progress bar.
pub fn frontier(ns: &NSet, ladder: &[f64]) -> Result<Option<Frontier>> {
    if ladder.is_empty() {
        return Ok(None);
    }
    let base = fr::tradeoff_base(ns);
    let floors = fr::frontier_floors(&base, ladder)?;
    let bar = super::progress::Progress::new(
        "tradeoff frontier",
        "searches",
        fr::rung_count(&floors, ladder) as u64,
    );
    let f = fr::frontier(&base, floors, ladder, Arch::Pipelined, &|a, b| {
        log::debug!("tradeoff frontier: {a} at {b} lsb8 searched");
        bar.inc(1);
    })?;
    bar.finish();
    Ok(Some(f))
}

/// Computes every method's figures (with yosys figures of the datapaths for `yosys`) and the
/// frontier over `ladder` (none when it is empty), and writes CSV, JSON and charts into
/// `dir`.
pub fn tradeoff(
    dir: &std::path::Path,
    ns: &NSet,
    yosys: Option<specfx::hdl::cost::Target>,
    ladder: &[f64],
) -> Result<Vec<MethodFigures>> {
    let frontier = frontier(ns, ladder)?;
    // The wall clock the library leaves to its callers.
    let mut time_it = |work: &mut dyn FnMut()| {
        let start = std::time::Instant::now();
        work();
        start.elapsed().as_secs_f64()
    };
    let bar = super::progress::Progress::new("tradeoff", "methods", method_count() as u64);
    let synthesise = |dp: &Datapath| {
        let target = yosys.expect("synthesised only with a target");
        log::info!(
            "tradeoff: synthesising {} with yosys ({target})",
            dp.config().name
        );
        let hdl = super::hdl_ref::hdl_ref_dir(None);
        let cost = synthesise(dp, Arch::Pipelined, target, &hdl)?.cost;
        Ok(YosysFigures {
            target: target.to_string(),
            luts: cost.luts,
            dsps: cost.dsps,
            ffs: cost.ffs,
        })
    };
    let figures = specfx::analysis::tradeoff::tradeoff(
        ns,
        &mut time_it,
        yosys.is_some().then_some(&synthesise as _),
        &|name, done| {
            log::debug!("tradeoff: {name}");
            bar.set_position(done as u64);
            bar.set_message(name.to_string());
        },
    )?;
    bar.finish();
    let provenance = Provenance::new(&inputs(ns, yosys, ladder));
    write_all_in(
        dir,
        &tradeoff_files(&figures, frontier.as_ref(), ns.values(), &provenance)?,
    )?;
    Ok(figures)
}

/// Runs `specfx tradeoff`.
pub fn run(args: &TradeoffArgs) -> Result<Outcome> {
    let out_dir = specfx::output::OutDir::begin(&args.out, "tradeoff", args.force, &[])?;
    let figures = tradeoff(out_dir.path(), &args.n, args.yosys, &args.ladder.0)?;
    out_dir.commit()?;
    if args.json {
        print_json(&figures)?;
    } else {
        let mut out = super::output::stdout();
        write_table(&mut out, &figures, super::terminal::table_width())?;
        writeln!(out, "written to {}", args.out.display())?;
    }
    Ok(Outcome::Ok)
}
