//! `specfx tradeoff`: speed against accuracy for every method, with charts.

use std::fs;
use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use super::output::{print_json, write_atomic, write_chart, write_provenance};
use super::Outcome;
use specfx::analysis::tradeoff::{
    f64_figures, f64_methods, fixed_config, fixed_figures, fixed_minimax_config, powi_figures,
    MethodFigures, YosysFigures,
};
use specfx::nset::NSet;
use specfx::pipeline::Datapath;
use specfx::provenance::{canonical_nset, Inputs, Provenance};
use specfx::report::tradeoff::{
    cost_chart, per_n_chart, speed_chart, write_csv, write_speed_csv, write_table, CostAxis,
};

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
    fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let ns_v = ns.values();
    // The wall clock the library leaves to its callers.
    let mut time_it = |work: &mut dyn FnMut()| {
        let start = std::time::Instant::now();
        work();
        start.elapsed().as_secs_f64()
    };
    let mut figures = Vec::new();
    let methods = f64_methods();
    let configs: Vec<_> = [8, 12, 16]
        .into_iter()
        .map(fixed_config)
        .chain((3..=6).map(fixed_minimax_config))
        .collect();
    let bar = super::progress::Progress::new(
        "tradeoff",
        "methods",
        (methods.len() + 1 + configs.len()) as u64,
    );
    let method_start = |name: &str| {
        log::debug!("tradeoff: {name}");
        bar.set_message(name.to_string());
    };
    for (name, method) in methods {
        method_start(&name);
        figures.push(f64_figures(&name, method, ns_v, &mut time_it));
        bar.inc(1);
    }
    method_start("powi");
    figures.insert(1, powi_figures(ns_v, &mut time_it));
    bar.inc(1);
    for mut cfg in configs {
        cfg.n = ns.clone();
        let dp = Datapath::new(cfg)?;
        method_start(&dp.config().name);
        let mut f = fixed_figures(&dp, &mut time_it);
        if let Some(target) = yosys {
            log::info!(
                "tradeoff: synthesising {} with yosys ({target})",
                dp.config().name
            );
            let hdl = super::hdl_ref::hdl_ref_dir(None);
            let cost = specfx::tools::yosys::synthesise(
                &dp,
                specfx::cycle::Arch::Pipelined,
                target,
                &hdl,
            )?
            .cost;
            f.yosys = Some(YosysFigures {
                target: target.to_string(),
                luts: cost.luts,
                dsps: cost.dsps,
                ffs: cost.ffs,
            });
        }
        figures.push(f);
        bar.inc(1);
    }
    bar.finish();
    let mut csv = Vec::new();
    write_csv(&mut csv, &figures)?;
    write_atomic(&dir.join("tradeoff.csv"), &csv)?;
    let mut json = serde_json::to_vec_pretty(&figures)?;
    json.push(b'\n');
    write_atomic(&dir.join("tradeoff.json"), &json)?;
    for (axis, stem) in CostAxis::CHARTS {
        write_chart(dir, stem, &cost_chart(&figures, axis))?;
    }
    // Wall-clock measurements of this run, apart: every other file is the same on every run.
    let mut speed = Vec::new();
    write_speed_csv(&mut speed, &figures)?;
    write_atomic(&dir.join("measured_speed.csv"), &speed)?;
    write_chart(dir, "measured_speed_accuracy", &speed_chart(&figures))?;
    write_chart(
        dir,
        "error_vs_n",
        &per_n_chart(
            &figures,
            ns_v,
            &[
                "cs16_clamp",
                "minimax16",
                "schlick",
                "exp_limit",
                "fixed_sq12",
                "cs128_clamp",
            ],
        ),
    )?;
    let mut inputs = Inputs::new("tradeoff").option("n", canonical_nset(ns));
    if let Some(target) = yosys {
        inputs = inputs.option("yosys", target.name());
    }
    write_provenance(dir, &Provenance::new(&inputs))?;
    Ok(figures)
}

/// Runs `specfx tradeoff`.
pub fn run(args: &TradeoffArgs) -> Result<Outcome> {
    let out_dir = super::output::OutDir::begin(&args.out, "tradeoff", args.force, &[])?;
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
