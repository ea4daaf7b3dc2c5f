//! `specfx optimize`: the cheapest configuration meeting an error budget.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::Outcome;
use specfx::analysis::budget_expr::Budget;
use specfx::analysis::optimize::{
    Algorithm, DepthSearch, DeviceLimit, Objective, Request, SearchResult,
};
use specfx::cycle::Arch;
use specfx::hdl::cost::Target;
use specfx::nset::NSet;
use specfx::output::write_atomic;
use specfx::pipeline::{Datapath, Variant};
use specfx::report::optimize::{answer_file, write_answer, write_no_answer, Answer};

/// The first bytes of the configuration `specfx optimize` writes: a file that begins with
/// them is an earlier result, replaced without `--force`.
const OUT_HEADER: &str = "# specfx optimize:";
use specfx::provenance::Provenance;

/// Arguments of `specfx optimize`.
#[derive(Debug, Args)]
pub struct OptimizeArgs {
    /// The budget, e.g. "shape_total <= 1 lsb8", "shape_quant <= 0.5 lsb8", "out <= 1 ulp",
    /// "correct >= 99%", several joined by commas. A metric with a unit needs it (lsbN, ulp):
    /// a bare number is refused (docs/budget.md).
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
    #[arg(long, default_value = "analytic", value_parser = super::named_values(&Objective::ALL, Objective::name, super::no_help))]
    objective: Objective,
    /// Target whose logic cells are minimised: ice40 (LUTs), xilinx (LUTs) or generic (gates).
    #[arg(long, default_value = "ice40", value_parser = super::named_values(&Target::ALL, Target::name, super::no_help))]
    target: Target,
    /// Numbers of squarings to try (each is searched only if its f64 floor can meet the
    /// budget).
    #[arg(long, default_value = specfx::reference::lobe::K_RANGE_TEXT, value_parser = super::datapath::parse_k_set)]
    k: NSet,
    /// Variants to try: plain, minimax or both.
    #[arg(long, default_value = "plain,minimax", value_delimiter = ',',
          value_parser = |v: &str| v.trim().parse::<Variant>())]
    variants: Vec<Variant>,
    /// Squaring depths to try: fixed (every n squares k times), best (each n squares to the
    /// depth j(n) <= k with the smallest f64 floor, the later stages bypassed), fixed,best
    /// (both, every algorithm) or auto (fixed first; the per-n depth only when no fixed-depth
    /// datapath meets the budget and fits).
    #[arg(long, default_value = "auto", value_parser = |v: &str| v.parse::<DepthSearch>())]
    depth: DepthSearch,
    /// Fraction bits every searched stage starts from (must meet the budget).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(i32).range(1..=48))]
    start_frac: i32,
    /// Microarchitecture costed: pipelined or folded. Left out: the base configuration's `arch`
    /// key; without one, pipelined, and folded for an algorithm whose pipelined answer does
    /// not fit the device. The answer's TOML records the one it was costed with (`arch`).
    #[arg(long, value_parser = super::named_values(&Arch::ALL, Arch::name, super::no_help))]
    arch: Option<Arch>,
    /// The device every answer must fit (its DSP blocks, LUTs and flip-flops, by the analytic
    /// model): up5k (iCE40), or none to lift the limit (hx8k, without DSP blocks, is refused:
    /// the model maps every multiplier to one). Left out: the iCE40 UP5K when the target is
    /// ice40, none otherwise.
    #[arg(long)]
    device: Option<DeviceLimit>,
    /// Where to write the configuration found (TOML).
    #[arg(long, default_value = "specfx-optimized.toml")]
    out: PathBuf,
    /// Replace an existing output file that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
}

/// Runs `specfx optimize`. Exit code 1 when no configuration meets the budget.
pub fn run(args: &OptimizeArgs) -> Result<Outcome> {
    let dp = specfx::input::load_datapath(&args.config, args.n.as_ref())?;
    specfx::output::check_file_output(
        &args.out,
        "--out",
        &super::output::inputs(&args.config, None),
        Some(OUT_HEADER),
        args.force,
    )?;
    let request = Request {
        base: dp.config().clone(),
        budget: args.budget.clone(),
        k: args.k.values().to_vec(),
        variants: args.variants.clone(),
        depth: args.depth,
        start_frac: args.start_frac,
        objective: args.objective,
        target: args.target,
        arch: args.arch,
        device: args.device.map(|DeviceLimit(d)| d),
    };
    request.device()?; // Its refusals come before any work.
    let unit = request.unit();
    let hdl = super::hdl_ref::hdl_ref_dir(None);
    let synth = |dp: &Datapath, arch: Arch, target: Target| {
        specfx::tools::yosys::synthesise(dp, arch, target, &hdl).map(|s| s.cost.figures(target))
    };
    log::info!(
        "optimize: f64 floor of {} algorithms (k in {}, {}; depth {})",
        request.algorithms().len(),
        args.k,
        args.variants
            .iter()
            .map(|v| v.name())
            .collect::<Vec<_>>()
            .join(", "),
        args.depth.name()
    );
    let bar = std::sync::OnceLock::new();
    let floors_found = |floors: &[specfx::analysis::optimize::AlgorithmFloor]| {
        let reachable = floors.iter().filter(|f| f.reachable).count() as u64;
        let _ = bar.set(super::progress::Progress::new(
            "optimize",
            "algorithms",
            reachable,
        ));
    };
    let done = |_: Algorithm, _: Arch, _: &SearchResult| {
        if let Some(bar) = bar.get() {
            bar.inc(1);
        }
    };
    let found = request.run(&synth, &floors_found, &done)?;
    if let Some(bar) = bar.into_inner() {
        bar.finish();
    }
    let r = &found.result;
    super::output::outln!(
        "optimize: budget '{}', {} exhaustive checks",
        r.budget,
        r.n_evaluations
    )?;
    let Some(answer) = Answer::of(&found, args.objective, &unit) else {
        super::output::print_with(|w| {
            write_no_answer(w, r, found.closest.as_ref(), super::terminal::table_width())
        })?;
        return Ok(Outcome::CheckFailed);
    };
    let provenance = Provenance::new(&request.inputs()?);
    let text = answer_file(OUT_HEADER, &answer, &provenance);
    write_atomic(&args.out, text.as_bytes())?;
    super::output::print_with(|w| {
        write_answer(w, &answer, &args.out, super::terminal::table_width())
    })?;
    Ok(Outcome::Ok)
}
