//! `specfx tradeoff`: speed against accuracy for every method, with charts.

use std::fs;
use std::io::Write;
use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use super::output::{print_json, write_atomic, write_chart};
use super::Outcome;
use specfx::analysis::tradeoff::{
    f64_figures, f64_methods, fixed_config, fixed_figures, fixed_minimax_config, powi_figures,
    MethodFigures, YosysFigures,
};
use specfx::hdl::cost::Target;
use specfx::nset::NSet;
use specfx::pipeline::Datapath;
use specfx::report::tradeoff::{cost_chart, per_n_chart, speed_chart, CostAxis};

/// Arguments of `specfx tradeoff`.
#[derive(Debug, Args)]
pub struct TradeoffArgs {
    /// Output directory.
    #[arg(long, default_value = "specfx-tradeoff")]
    out: PathBuf,
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
            let hdl = super::cost::hdl_ref_dir(None);
            let (cost, _, _) =
                super::cost::run_yosys(&dp, specfx::cycle::Arch::Pipelined, target, &hdl)?;
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
    writeln!(
        csv,
        "method,kind,max_abs_err,max_err_lsb8,mean_abs_err,multipliers,ice40_luts,ice40_dsps,ice40_ffs,xilinx_luts,xilinx_dsps,xilinx_ffs,generic_gates,generic_ffs,latency,yosys_target,yosys_luts,yosys_dsps,yosys_ffs"
    )?;
    let opt = |x: Option<u64>| x.map_or(String::new(), |v| v.to_string());
    let cost = |f: &MethodFigures, t: Target| f.costs.iter().find(|c| c.target == t).copied();
    for f in &figures {
        writeln!(
            csv,
            "{},{},{:e},{:e},{:e},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            f.method,
            f.kind,
            f.max_abs_err,
            f.max_abs_err / specfx::analysis::LSB8,
            f.mean_abs_err,
            opt(f.multipliers.map(u64::from)),
            opt(cost(f, Target::Ice40).map(|c| c.luts)),
            opt(cost(f, Target::Ice40).map(|c| c.dsps)),
            opt(cost(f, Target::Ice40).map(|c| c.ffs)),
            opt(cost(f, Target::Xilinx).map(|c| c.luts)),
            opt(cost(f, Target::Xilinx).map(|c| c.dsps)),
            opt(cost(f, Target::Xilinx).map(|c| c.ffs)),
            opt(cost(f, Target::Generic).map(|c| c.luts)),
            opt(cost(f, Target::Generic).map(|c| c.ffs)),
            opt(f.latency),
            f.yosys.as_ref().map_or("", |y| y.target.as_str()),
            opt(f.yosys.as_ref().map(|y| y.luts)),
            opt(f.yosys.as_ref().map(|y| y.dsps)),
            opt(f.yosys.as_ref().map(|y| y.ffs))
        )?;
    }
    write_atomic(&dir.join("tradeoff.csv"), &csv)?;
    let mut json = serde_json::to_vec_pretty(&figures)?;
    json.push(b'\n');
    write_atomic(&dir.join("tradeoff.json"), &json)?;
    for (axis, stem) in CostAxis::CHARTS {
        write_chart(dir, stem, &cost_chart(&figures, axis))?;
    }
    // Wall-clock measurements of this run, apart: every other file is the same on every run.
    let mut speed = Vec::new();
    writeln!(speed, "method,kind,evals_per_s,max_abs_err")?;
    for f in &figures {
        writeln!(
            speed,
            "{},{},{:e},{:e}",
            f.method, f.kind, f.evals_per_s, f.max_abs_err
        )?;
    }
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
    Ok(figures)
}

/// Runs `specfx tradeoff`.
pub fn run(args: &TradeoffArgs) -> Result<Outcome> {
    let figures = tradeoff(&args.out, &args.n, args.yosys)?;
    if args.json {
        print_json(&figures)?;
    } else {
        let mut out = super::output::stdout();
        writeln!(
            out,
            "{:<16} {:>6} {:>11} {:>11} {:>12} {:>5} {:>22} {:>7}",
            "method",
            "kind",
            "max |err|",
            "mean |err|",
            "Meval/s",
            "mult",
            "ice40 LUTs+DSPs (an.)",
            "latency"
        )?;
        for f in &figures {
            writeln!(
                out,
                "{:<16} {:>6} {:>11.3e} {:>11.3e} {:>12.1} {:>5} {:>22} {:>7}",
                f.method,
                f.kind,
                f.max_abs_err,
                f.mean_abs_err,
                f.evals_per_s / 1e6,
                f.multipliers.map_or("-".into(), |m| m.to_string()),
                f.costs
                    .iter()
                    .find(|c| c.target == Target::Ice40)
                    .map_or("-".into(), |c| format!("{} + {}", c.luts, c.dsps)),
                f.latency.map_or("-".into(), |m| m.to_string())
            )?;
        }
        writeln!(out, "written to {}", args.out.display())?;
    }
    Ok(Outcome::Ok)
}
