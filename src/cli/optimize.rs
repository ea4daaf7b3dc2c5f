//! `specfx optimize`: the cheapest configuration meeting an error budget.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use super::Outcome;
use specfx::analysis::budget_expr::{Budget, Metric};
use specfx::analysis::check::check;
use specfx::analysis::optimize::{
    algorithm_floors, optimize_all, Algorithm, Objective, SearchResult,
};
use specfx::cycle::Arch;
use specfx::hdl::cost::{analytic_cost, Target};
use specfx::nset::NSet;
use specfx::output::write_atomic;
use specfx::pipeline::{Datapath, Variant};
use specfx::report::optimize::write_no_answer;
use specfx::report::table::{Align, TextTable};

/// The first bytes of the configuration `specfx optimize` writes: a file that begins with
/// them is an earlier result, replaced without `--force`.
const OUT_HEADER: &str = "# specfx optimize:";
use specfx::provenance::{canonical_nset, Inputs, Provenance};

/// Arguments of `specfx optimize`.
#[derive(Debug, Args)]
pub struct OptimizeArgs {
    /// The budget, e.g. "shape_total <= 1 lsb8", "shape_quant <= 0.5 lsb8", "out <= 1 ulp",
    /// "correct >= 99%", several joined by commas.
    #[arg(long, default_value = "shape_total <= 1 lsb8")]
    budget: Budget,
    /// The base configuration (formats' integer bits, coefficient, cutoff ... are kept).
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Exponents, replacing the configuration's set.
    #[arg(long)]
    n: Option<NSet>,
    /// Cost to minimise: analytic (the calibrated model's logic cells on --target, instant) or
    /// yosys (yosys's count on --target, seconds per candidate).
    #[arg(long, default_value = "analytic")]
    objective: Objective,
    /// Target whose logic cells are minimised: ice40 (LUTs), xilinx (LUTs) or generic (gates).
    #[arg(long, default_value = "ice40")]
    target: Target,
    /// Numbers of squarings to try (each is searched only if its f64 floor can meet the
    /// budget).
    #[arg(long, default_value = "1..=7", value_parser = super::datapath::parse_k_set)]
    k: NSet,
    /// Variants to try: plain, minimax or both.
    #[arg(long, default_value = "plain,minimax", value_delimiter = ',',
          value_parser = |v: &str| v.trim().parse::<Variant>())]
    variants: Vec<Variant>,
    /// Fraction bits every searched stage starts from (must meet the budget).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(i32).range(1..=48))]
    start_frac: i32,
    /// Microarchitecture costed.
    #[arg(long, default_value = "pipelined")]
    arch: Arch,
    /// Where to write the configuration found (TOML).
    #[arg(long, default_value = "specfx-optimized.toml")]
    out: PathBuf,
    /// Replace an existing output file that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
}

/// Runs `specfx optimize`. Exit code 1 when no configuration meets the budget.
pub fn run(args: &OptimizeArgs) -> Result<Outcome> {
    let dp = super::datapath::load(&args.config, args.n.as_ref())?;
    specfx::output::check_file_output(
        &args.out,
        "--out",
        &super::output::inputs(&args.config, None),
        Some(OUT_HEADER),
        args.force,
    )?;
    let base = dp.config().clone();
    if let Some(&k) = args
        .k
        .values()
        .iter()
        .find(|&&k| !specfx::reference::lobe::K_RANGE.contains(&k))
    {
        bail!("--k: expected numbers of squarings in 1..=7, got {k}");
    }
    let yosys = args.objective == Objective::Yosys;
    let hdl = super::hdl_ref::hdl_ref_dir(None);
    let arch = args.arch;
    let target = args.target;
    let unit = format!("{} on {}", target.logic_unit(), target.name());
    let cost = |dp: &Datapath| -> Result<f64, specfx::Error> {
        if yosys {
            specfx::tools::yosys::synthesise(dp, arch, target, &hdl).map(|s| s.cost.luts as f64)
        } else {
            Ok(analytic_cost(dp, arch, target).luts as f64)
        }
    };
    let variants = &args.variants;
    log::info!(
        "optimize: f64 floor of {} algorithms (k in {}, {})",
        args.k.len() * variants.len(),
        args.k,
        variants
            .iter()
            .map(|v| v.name())
            .collect::<Vec<_>>()
            .join(", ")
    );
    let mut budget = args.budget.clone();
    budget.arch = arch;
    let floors = algorithm_floors(&base, &budget, args.k.values(), variants, args.start_frac);
    let reachable = floors.iter().filter(|f| f.reachable).count();
    let bar = super::progress::Progress::new("optimize", "algorithms", reachable as u64);
    let done = |a: Algorithm, r: &SearchResult| {
        let line = format!(
            "optimize: k = {}, {}: {}",
            a.k,
            a.variant.name(),
            r.best
                .as_ref()
                .map_or("nothing meets the budget".to_string(), |b| format!(
                    "{:.0} {unit} ({})",
                    b.cost, args.objective
                ))
        );
        log::info!("{line}");
        bar.inc(1);
    };
    let synth = |dp: &Datapath,
                 arch: Arch,
                 target: Target|
     -> Result<specfx::hdl::cost::CostFigures, specfx::Error> {
        specfx::tools::yosys::synthesise(dp, arch, target, &hdl).map(|s| {
            specfx::hdl::cost::CostFigures {
                target,
                luts: s.cost.luts,
                dsps: s.cost.dsps,
                ffs: s.cost.ffs,
            }
        })
    };
    let r = optimize_all(
        &base,
        &budget,
        floors,
        args.start_frac,
        &cost,
        Some(&synth),
        &done,
    )?;
    bar.finish();
    super::output::outln!(
        "optimize: budget '{}', {} exhaustive checks",
        r.budget,
        r.n_evaluations
    )?;
    let Some(best) = &r.best else {
        let closest = specfx::analysis::optimize::closest(&r, Some(&synth))?;
        super::output::print_with(|w| {
            write_no_answer(w, &r, closest.as_ref(), super::terminal::table_width())
        })?;
        return Ok(Outcome::CheckFailed);
    };
    // The proof: the exhaustive check of the answer, against the budget.
    let mut config = best.config.clone();
    config.name = "optimized".into();
    let dp = Datapath::new(config.clone())?;
    let proof = check(&dp)?;
    if !r.budget.met_by(&proof.output_figures(), &dp)
        || !r.budget.cost_verdict(&dp, Some(&synth))?.feasible
    {
        bail!("the configuration found does not meet the budget on re-check: this is a bug");
    }
    for b in r.budget.bounds.iter().filter(|b| b.metric.is_yosys()) {
        let (Metric::YosysLuts(t) | Metric::YosysDsps(t) | Metric::YosysFfs(t)) = b.metric else {
            continue;
        };
        let f = synth(&dp, arch, t)?;
        super::output::outln!(
            "yosys on {}: {} {}, {} DSPs, {} flip-flops (the budget's {} <= {})",
            t.name(),
            f.luts,
            t.logic_unit(),
            f.dsps,
            f.ffs,
            b.metric,
            b.limit
        )?;
    }
    let header = format!(
        "{OUT_HEADER} cheapest configuration found for the budget '{}'\n# cost {:.0} {unit} ({}), {} exhaustive checks; proved by `specfx check`:\n# shape_total {:.4e}, shape_quant {:.4e}, out {:.3} ulp, {:.3}% correctly rounded\n",
        r.budget,
        best.cost,
        args.objective,
        r.n_evaluations,
        proof.shape_total_max_abs,
        proof.shape_quant_max_abs,
        proof.out_max_ulp,
        100.0 * proof.stages[dp.stage_out()].correctly_rounded
    );
    let mut variant_names: Vec<&str> = variants.iter().map(|v| v.name()).collect();
    variant_names.sort_unstable();
    variant_names.dedup();
    let provenance = Provenance::new(
        &Inputs::new("optimize")
            .config(&base)
            .option("budget", args.budget.canonical())
            .option("objective", args.objective.name())
            .option("target", target.name())
            .option("k", canonical_nset(&args.k))
            .option("variants", variant_names)
            .option("start_frac", args.start_frac)
            .option("arch", arch.to_string()),
    );
    write_atomic(
        &args.out,
        format!(
            "{header}{}{}",
            provenance_comment(&provenance),
            config.to_toml()
        )
        .as_bytes(),
    )?;
    super::output::outln!(
        "best: k = {}, {}, t {} b {} squares {} out {}: {:.0} {unit} ({})",
        config.k,
        config.variant.name(),
        config.t.format,
        config.b.format,
        config
            .square
            .iter()
            .map(|s| s.format.to_string())
            .collect::<Vec<_>>()
            .join("/"),
        config.out.format,
        best.cost,
        args.objective
    )?;
    super::output::outln!(
        "proved by an exhaustive check: shape_total {:.4e}, shape_quant {:.4e}, out {:.3} ulp, {:.3}% correctly rounded",
        proof.shape_total_max_abs,
        proof.shape_quant_max_abs,
        proof.out_max_ulp,
        100.0 * proof.stages[dp.stage_out()].correctly_rounded
    )?;
    // Overflow: a stage left to wrap must never overflow on any input (the exhaustive check
    // counts every event).
    let wrapping: Vec<String> = proof
        .stages
        .iter()
        .filter(|s| s.wrapped > 0)
        .map(|s| format!("{} ({} times)", s.stage, s.wrapped))
        .collect();
    if wrapping.is_empty() {
        super::output::outln!("overflow: no stage wraps on any input (exhaustive)")?;
    } else {
        super::output::outln!(
            "overflow: WARNING, these stages wrap on some inputs although the budget holds: {}",
            wrapping.join(", ")
        )?;
    }
    // The answer's cost on every target, beside the paper's datapath (baseline: plain, k = 4)
    // serving the same exponents.
    let mut paper_cfg = specfx::pipeline::Config::baseline();
    paper_cfg.n = config.n.clone();
    let paper = Datapath::new(paper_cfg)?;
    let paper_check = specfx::analysis::check::check_outputs(&paper)?;
    super::output::outln!(
        "against the paper's datapath (baseline: plain, k = 4, same n): shape_total {:.3e} ({:.2} lsb8) against {:.3e} ({:.2} lsb8)",
        proof.shape_total_max_abs,
        proof.shape_total_max_abs / specfx::analysis::LSB8,
        paper_check.shape_total_max_abs,
        paper_check.shape_total_max_abs / specfx::analysis::LSB8
    )?;
    super::output::outln!(
        "  analytic cost, {arch} (the model `specfx cost --analytic-only` prints):"
    )?;
    let mut table = TextTable::new(&[
        ("target", Align::Left),
        ("this", Align::Right),
        ("paper's", Align::Right),
    ])
    .indent(4);
    for target in specfx::hdl::cost::REPORTED_TARGETS {
        let a = analytic_cost(&dp, arch, target);
        let p = analytic_cost(&paper, arch, target);
        let show = |c: &specfx::hdl::cost::AnalyticCost| {
            format!("{} {} {} DSPs {} FFs", c.luts, c.logic_unit, c.dsps, c.ffs)
        };
        table.row([target.name().to_string(), show(&a), show(&p)]);
    }
    super::output::print_with(|w| table.write(w, super::terminal::table_width()))?;
    super::output::outln!("why minimal (within this search, not over every possible datapath):")?;
    for m in &r.minimality {
        super::output::outln!("  {m}")?;
    }
    super::output::outln!("written to {}", args.out.display())?;
    Ok(Outcome::Ok)
}

/// The provenance of a configuration file as TOML comments: the line documents end with, then
/// the canonical inputs, each line behind `#| ` (the hash is of those lines without the
/// prefix, each ending in a newline: `grep '^#|' FILE | cut -c4- | sha256sum`).
fn provenance_comment(p: &Provenance) -> String {
    let mut s = format!(
        "# specfx {} · specfx {} · inputs sha256 {}: the canonical inputs, on the lines starting with '#|'\n",
        p.specfx_version, p.command, p.inputs_sha256
    );
    for line in p.canonical.lines() {
        s.push_str(if line.is_empty() { "#|" } else { "#| " });
        s.push_str(line);
        s.push('\n');
    }
    s
}
