//! `specfx fit`: the cheapest datapath that renders a scene within an image-space budget,
//! using only the scene's exponents, input range and output depth; proved on every input the
//! scene produces, costed against the generic datapath (analytic and yosys), re-rendered.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;

use super::output::print_json;
use super::Outcome;
use specfx::cycle::Arch;
use specfx::hdl::cost::Target;
use specfx::nset::NSet;
use specfx::output::write_all_in;
use specfx::pipeline::Datapath;
use specfx::provenance::{Inputs, Provenance};
use specfx::report::fit::{fit_files, summary, write_no_fit};
use specfx::scene::fit::ImageBudget;
use specfx::scene::fitting::{FitOutcome, FitReport, FitRequest, SideCost};
use specfx::scene::Scene;

/// Arguments of `specfx fit`.
#[derive(Debug, Clone, Args)]
pub struct FitArgs {
    /// A scene TOML file (default: the built-in cells, vessel and bone scene).
    #[arg(long)]
    scene: Option<PathBuf>,
    /// The image-space budget against the f64 cos^n image, e.g. "max_lsb <= 8 and differing
    /// <= 5% and flip <= 0.02" (metrics max_lsb, mean_lsb, differing, flip). Default: no
    /// worse than the generic datapath renders the same scene.
    #[arg(long)]
    budget: Option<ImageBudget>,
    /// The generic datapath the fit starts from and is compared with (a TOML file or a
    /// built-in name); its n set is widened to hold the scene's exponents if needed.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Target of the reported cost (analytic and yosys): generic, ice40 or xilinx.
    #[arg(long, default_value = "ice40", value_parser = super::named_values(&Target::ALL, Target::name, super::no_help))]
    target: Target,
    /// Only the analytic cost: do not run yosys.
    #[arg(long)]
    analytic_only: bool,
    /// Fraction bits the internal stages start from (the search shrinks them).
    #[arg(long, default_value_t = 20, value_parser = clap::value_parser!(i32).range(1..=48))]
    start_frac: i32,
    /// Output directory.
    #[arg(long, default_value = "specfx-fit")]
    out: PathBuf,
    /// Replace an existing output directory that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    json: bool,
}

impl FitArgs {
    /// The defaults of `specfx fit` (the built-in scene, the default budget, baseline, iCE40),
    /// writing into `out`.
    pub fn defaults(out: PathBuf, analytic_only: bool) -> FitArgs {
        FitArgs {
            scene: None,
            budget: None,
            config: "baseline".into(),
            target: Target::Ice40,
            analytic_only,
            start_frac: 20,
            out,
            force: false,
            json: false,
        }
    }
}

/// Runs `specfx fit`.
pub fn run(args: &FitArgs) -> Result<Outcome> {
    let (scene, label) = super::render::load_scene(args.scene.as_deref())?;
    let out_dir = specfx::output::OutDir::begin(
        &args.out,
        "fit",
        args.force,
        &super::output::inputs(&args.config, args.scene.as_deref()),
    )?;
    let staged = FitArgs {
        out: out_dir.path().to_path_buf(),
        ..args.clone()
    };
    let fitted = fit_scene(&scene, &label, &staged)?;
    if fitted.is_some() {
        out_dir.commit()?;
    }
    match fitted {
        None => Ok(Outcome::CheckFailed),
        Some(report) => {
            if args.json {
                print_json(&report)?;
            } else {
                super::output::print_with(|w| {
                    use std::io::Write as _;
                    write!(w, "{}", summary(&report))
                })?;
                log::info!("fit: wrote {}", args.out.display());
            }
            Ok(Outcome::Ok)
        }
    }
}

/// The generic datapath: `config`, its n set widened to hold the scene's exponents.
fn generic_datapath(config: &str, scene: &Scene) -> Result<Datapath> {
    let dp = specfx::input::load_datapath(config, None)?;
    let ns = scene.exponents();
    if ns.iter().all(|n| dp.config().n.values().contains(n)) {
        return Ok(dp);
    }
    let lo = dp.config().n.min().min(ns[0]);
    let hi = dp
        .config()
        .n
        .max()
        .max(*ns.last().expect("a scene has materials"));
    Ok(specfx::input::load_datapath(
        config,
        Some(&NSet::range(lo, hi)?),
    )?)
}

/// Costs a datapath and its ROM on a target, with yosys unless `analytic_only`.
fn side_cost(
    dp: &Datapath,
    target: Target,
    analytic_only: bool,
) -> Result<SideCost, specfx::Error> {
    let yosys = if analytic_only {
        None
    } else {
        let hdl = super::hdl_ref::hdl_ref_dir(None);
        let y = specfx::tools::yosys::synthesise(dp, Arch::Pipelined, target, &hdl)?.cost;
        let ry = specfx::tools::yosys::synthesise_rom(dp, target)?.cost;
        Some((y, ry))
    };
    Ok(SideCost::new(dp, target, yosys))
}

/// Fits a datapath to `scene` and writes everything into `args.out`; `None` when nothing
/// meets the budget (the floors and the closest point are printed).
pub fn fit_scene(scene: &Scene, label: &str, args: &FitArgs) -> Result<Option<FitReport>> {
    if let Some(b) = &args.budget {
        b.check_materials(scene)?;
    }
    let generic = generic_datapath(&args.config, scene)?;
    log::info!(
        "fit: tracing {}x{} ({} materials, n = {:?})",
        scene.image.width,
        scene.image.height,
        scene.materials.len(),
        scene.exponents()
    );
    let frags = super::render::trace_with_progress(scene);
    let request = FitRequest {
        scene,
        label,
        frags: &frags,
        generic: &generic,
        budget: args.budget.as_ref(),
        start_frac: args.start_frac,
        target: args.target,
    };
    let progress = |line: &str| log::info!("fit: {line}");
    let cost = |dp: &Datapath| side_cost(dp, args.target, args.analytic_only);
    let fitted = match specfx::scene::fitting::fit_scene(&request, &progress, &cost)? {
        FitOutcome::NoFit(no) => {
            super::output::print_with(|w| write_no_fit(w, &no, super::terminal::table_width()))?;
            return Ok(None);
        }
        FitOutcome::Fitted(f) => f,
    };
    let mut inputs = Inputs::new("fit")
        .table("scene", scene.canonical())
        .config(generic.config())
        .option("target", args.target.name())
        .option("analytic_only", args.analytic_only)
        .option("start_frac", args.start_frac);
    if let Some(b) = &args.budget {
        inputs = inputs.option("budget", b.canonical());
    }
    let provenance = Provenance::new(&inputs);
    let mut files = fit_files(&fitted, &provenance)?;
    files.extend(provenance.files());
    write_all_in(&args.out, &files)?;
    Ok(Some(fitted.report))
}
