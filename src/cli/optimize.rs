//! `specfx optimize`: the cheapest configuration meeting an error budget.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use super::Outcome;
use specfx::analysis::budget_expr::{Budget, Metric};
use specfx::analysis::check::check;
use specfx::analysis::optimize::{
    algorithm_floors, optimize_all, Algorithm, DepthSearch, DeviceFit, Objective, SearchResult,
};
use specfx::cycle::Arch;
use specfx::hdl::cost::{analytic_cost, dsp_weight, objective_value, Target};
use specfx::hdl::pnr::Device;
use specfx::nset::NSet;
use specfx::output::write_atomic;
use specfx::pipeline::{Datapath, Variant};
use specfx::report::optimize::{answer_header, write_answer, write_no_answer, Answer};

/// The first bytes of the configuration `specfx optimize` writes: a file that begins with
/// them is an earlier result, replaced without `--force`.
const OUT_HEADER: &str = "# specfx optimize:";
use specfx::provenance::{canonical_nset, Inputs, Provenance};

/// How many syntheses with yosys `optimize` runs between two lines of progress.
const SYNTHESES_PER_LINE: u64 = 10;

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
    #[arg(long, default_value = "analytic")]
    objective: Objective,
    /// Target whose logic cells are minimised: ice40 (LUTs), xilinx (LUTs) or generic (gates).
    #[arg(long, default_value = "ice40")]
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
    #[arg(long)]
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

/// The value of `--device`: a device every answer must fit, or `none` (no limit). A type of
/// its own, because clap reads `Option<Option<T>>` as a flag whose value may be left out.
#[derive(Debug, Clone, Copy)]
struct DeviceLimit(Option<Device>);

impl std::str::FromStr for DeviceLimit {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<DeviceLimit, String> {
        match s.trim() {
            "none" => Ok(DeviceLimit(None)),
            other => other
                .parse::<Device>()
                .map(|d| DeviceLimit(Some(d)))
                .map_err(|e| format!("{e}, or none to lift the limit")),
        }
    }
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
    let base = dp.config().clone();
    // --arch, else the base configuration's own (an earlier answer's); neither: auto.
    let chosen_arch = args.arch.or(base.arch);
    if let Some(&k) = args
        .k
        .values()
        .iter()
        .find(|&&k| !specfx::reference::lobe::K_RANGE.contains(&k))
    {
        bail!(
            "--k: expected numbers of squarings in {}, got {k}",
            specfx::reference::lobe::K_RANGE_TEXT
        );
    }
    let yosys = args.objective == Objective::Yosys;
    let hdl = super::hdl_ref::hdl_ref_dir(None);
    let arch = base.resolve_arch(args.arch);
    let target = args.target;
    let device = match args.device {
        Some(DeviceLimit(d)) => d,
        None => (target == Target::Ice40).then_some(Device::Up5k),
    };
    if device.is_some() && target != Target::Ice40 {
        bail!(
            "--device: the devices are iCE40s, costed on --target ice40 (got --target {}); give --device none to cost on {} without a device",
            target.name(),
            target.name()
        );
    }
    if let Some(d) = device.filter(|d| d.limits().dsps == 0) {
        bail!(
            "--device {}: the {} has no DSP blocks, and the analytic iCE40 model maps every multiplier to one, so no datapath can fit it; give --device up5k, or none to lift the limit",
            d.name(),
            d.full_name()
        );
    }
    let fit = device.map(|device| DeviceFit {
        device,
        fold_when_needed: chosen_arch.is_none(),
    });
    let unit = match dsp_weight(target) {
        w if w > 0.0 => format!(
            "{}-equivalents on {} ({} + {w:.0} per DSP block)",
            target.logic_unit().trim_end_matches('s'),
            target.name(),
            target.logic_unit()
        ),
        _ => format!("{} on {}", target.logic_unit(), target.name()),
    };
    // Each synthesis takes seconds to minutes and a search runs many: a line at the first and
    // at every tenth, since nothing else would show for minutes off a terminal.
    let syntheses = std::sync::atomic::AtomicU64::new(0);
    let synthesising = |target: Target| {
        let done = syntheses.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        if done == 0 {
            log::info!(
                "optimize: synthesising with yosys on {} (seconds to minutes each, cached ones at once; a line every {SYNTHESES_PER_LINE})",
                target.name()
            );
        } else if done.is_multiple_of(SYNTHESES_PER_LINE) {
            log::info!("optimize: {done} syntheses with yosys so far");
        }
    };
    let cost = |dp: &Datapath, arch: Arch| -> Result<f64, specfx::Error> {
        if yosys {
            synthesising(target);
            specfx::tools::yosys::synthesise(dp, arch, target, &hdl).map(|s| {
                objective_value(&specfx::hdl::cost::CostFigures {
                    target,
                    luts: s.cost.luts,
                    dsps: s.cost.dsps,
                    ffs: s.cost.ffs,
                })
            })
        } else {
            Ok(objective_value(&analytic_cost(dp, arch, target).figures()))
        }
    };
    let variants = &args.variants;
    let algorithms = Algorithm::all(&base, args.k.values(), variants, args.depth.per_n());
    log::info!(
        "optimize: f64 floor of {} algorithms (k in {}, {}; depth {})",
        algorithms.len(),
        args.k,
        variants
            .iter()
            .map(|v| v.name())
            .collect::<Vec<_>>()
            .join(", "),
        args.depth.name()
    );
    let mut budget = args.budget.clone();
    budget.arch = arch;
    let floors = algorithm_floors(&base, &budget, &algorithms, args.start_frac);
    let reachable = floors.iter().filter(|f| f.reachable).count();
    let bar = super::progress::Progress::new("optimize", "algorithms", reachable as u64);
    let no_answer = match device {
        Some(d) => format!("nothing meets the budget and fits the {}", d.full_name()),
        None => "nothing meets the budget".to_string(),
    };
    let done = |a: Algorithm, r: &SearchResult| {
        let line = format!(
            "optimize: {a}: {}",
            r.best.as_ref().map_or(no_answer.to_string(), |b| format!(
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
        synthesising(target);
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
        fit,
        args.depth,
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
    // The proof: the exhaustive check of the answer, against the budget, in the answer's
    // architecture.
    let arch = best.arch;
    let mut budget = r.budget.clone();
    budget.arch = arch;
    let mut config = best.config.clone();
    config.name = "optimized".into();
    // The answer records the microarchitecture it was costed with: cost, timing, sim, hdl,
    // vectors and cosim read it as their default.
    config.arch = Some(arch);
    let dp = Datapath::new(config.clone())?;
    let proof = check(&dp)?;
    if !budget.met_by(&proof.output_figures(), &dp)
        || !budget.cost_verdict(&dp, Some(&synth))?.feasible
        || fit.is_some_and(|f| !f.overflows(&dp, arch).is_empty())
    {
        bail!("the configuration found does not meet the budget on re-check: this is a bug");
    }
    let mut yosys = Vec::new();
    for b in r.budget.bounds.iter().filter(|b| b.metric.is_yosys()) {
        let (Metric::YosysLuts(t) | Metric::YosysDsps(t) | Metric::YosysFfs(t)) = b.metric else {
            continue;
        };
        yosys.push((b, synth(&dp, arch, t)?));
    }
    // The answer's cost on every target, beside the paper's datapath (baseline: plain, k = 4)
    // serving the same exponents.
    let mut paper_cfg = specfx::pipeline::Config::baseline();
    paper_cfg.n = config.n.clone();
    let paper = Datapath::new(paper_cfg)?;
    let paper_check = specfx::analysis::check::check_outputs(&paper)?;
    let answer = Answer {
        result: &r,
        best,
        dp: &dp,
        proof: &proof,
        objective: args.objective,
        unit: &unit,
        arch,
        paper: (&paper, &paper_check),
        yosys: &yosys,
    };
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
            .option("depth", args.depth.name())
            .option(
                "arch",
                chosen_arch.map_or("auto".to_string(), |a| a.to_string()),
            )
            .option("device", device.map_or("none", |d| d.name())),
    );
    let text = format!(
        "{}{}{}",
        answer_header(OUT_HEADER, &answer),
        provenance.comment(),
        config.to_toml()
    );
    write_atomic(&args.out, text.as_bytes())?;
    super::output::print_with(|w| {
        write_answer(w, &answer, &args.out, super::terminal::table_width())
    })?;
    Ok(Outcome::Ok)
}
