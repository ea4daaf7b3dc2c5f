//! `specfx tradeoff`: speed against accuracy for every method, with charts.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::output::print_json;
use super::Outcome;
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
    #[arg(long)]
    yosys: Option<specfx::hdl::cost::Target>,
    /// Print the figures as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Computes every method's figures (with yosys figures of the datapaths for `yosys`) and
/// writes CSV, JSON and charts into `dir`.
pub fn tradeoff(
    dir: &std::path::Path,
    ns: &NSet,
    yosys: Option<specfx::hdl::cost::Target>,
) -> Result<Vec<MethodFigures>> {
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
    let provenance = Provenance::new(&inputs(ns, yosys));
    write_all_in(dir, &tradeoff_files(&figures, ns.values(), &provenance)?)?;
    Ok(figures)
}

/// Runs `specfx tradeoff`.
pub fn run(args: &TradeoffArgs) -> Result<Outcome> {
    let out_dir = specfx::output::OutDir::begin(&args.out, "tradeoff", args.force, &[])?;
    let figures = tradeoff(out_dir.path(), &args.n, args.yosys)?;
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
