//! `specfx fit`: the cheapest datapath that renders a scene within an image-space budget,
//! using only the scene's exponents, input range and output depth; proved on every input the
//! scene produces, costed against the generic datapath (analytic and yosys), re-rendered.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;

use super::output::{print_json, write_atomic, write_provenance};
use super::Outcome;
use specfx::analysis::optimize::Candidate;
use specfx::cycle::Arch;
use specfx::hdl::cost::{analytic_cost, Target};
use specfx::hdl::rom::{constant_rom, rom_verilog};
use specfx::nset::NSet;
use specfx::pipeline::{Config, Datapath};
use specfx::provenance::{Inputs, Provenance};
use specfx::report::scene::{heatmap_png, path_png};
use specfx::report::table::{Align, TextTable};
use specfx::scene::fit::{
    fit_search, floors, objective, FitSearch, Floor, ImageBudget, SceneFigures, SceneJudge,
};
use specfx::scene::render::{difference_of, image_error, render_fragments, ImageError, Rendered};
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
    #[arg(long, default_value = "ice40")]
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

/// The cost of one datapath with its constant ROM.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct SideCost {
    /// The exponents it serves.
    pub n: String,
    /// Analytic LUTs of the datapath on the target (multipliers in DSPs where it has them).
    pub analytic_luts: u64,
    /// Analytic DSP blocks.
    pub analytic_dsps: u64,
    /// Analytic register bits.
    pub analytic_ffs: u64,
    /// ROM entries.
    pub rom_entries: u64,
    /// ROM bits stored.
    pub rom_bits: u64,
    /// Analytic LUTs of the ROM.
    pub rom_analytic_luts: u64,
    /// Analytic LUTs, datapath and ROM.
    pub analytic_total_luts: u64,
    /// The search's objective: generic analytic LUTs (multipliers as logic) plus the ROM's.
    pub objective: u64,
    /// yosys LUTs of the datapath.
    pub yosys_luts: Option<u64>,
    /// yosys DSP blocks.
    pub yosys_dsps: Option<u64>,
    /// yosys flip-flops.
    pub yosys_ffs: Option<u64>,
    /// yosys LUTs of the ROM.
    pub rom_yosys_luts: Option<u64>,
    /// yosys LUTs, datapath and ROM.
    pub yosys_total_luts: Option<u64>,
}

/// Costs a datapath and its ROM on a target.
fn side_cost(dp: &Datapath, target: Target, yosys: bool) -> Result<SideCost> {
    let a = analytic_cost(dp, Arch::Pipelined, target);
    let rom = constant_rom(dp, target);
    let (y, ry) = if yosys {
        let hdl = super::hdl_ref::hdl_ref_dir(None);
        let y = specfx::tools::yosys::synthesise(dp, Arch::Pipelined, target, &hdl)?.cost;
        let ry = specfx::tools::yosys::synthesise_rom(dp, target)?.cost;
        (Some(y), Some(ry))
    } else {
        (None, None)
    };
    Ok(SideCost {
        n: dp.config().n.to_string(),
        analytic_luts: a.luts,
        analytic_dsps: a.dsps,
        analytic_ffs: a.ffs,
        rom_entries: rom.entries,
        rom_bits: rom.bits,
        rom_analytic_luts: rom.luts,
        analytic_total_luts: a.luts + rom.luts,
        objective: objective(dp, target),
        yosys_luts: y.as_ref().map(|y| y.luts),
        yosys_dsps: y.as_ref().map(|y| y.dsps),
        yosys_ffs: y.as_ref().map(|y| y.ffs),
        rom_yosys_luts: ry.as_ref().map(|r| r.luts),
        yosys_total_luts: y.as_ref().zip(ry.as_ref()).map(|(y, r)| y.luts + r.luts),
    })
}

/// Per material: its figures through the generic and the fitted datapath.
#[derive(Debug, Clone, Serialize)]
pub struct FitRow {
    /// Material name, or "all".
    pub material: String,
    /// Its exponent (0 for "all").
    pub n: u32,
    /// The generic datapath's image against cos^n.
    pub generic: ImageError,
    /// The fitted datapath's image against cos^n.
    pub fitted: ImageError,
}

/// Everything `specfx fit` reports.
#[derive(Debug, Clone, Serialize)]
pub struct FitReport {
    /// The scene.
    pub scene: String,
    /// The budget (against f64 cos^n).
    pub budget: ImageBudget,
    /// Whether the budget was the default (no worse than the generic datapath).
    pub default_budget: bool,
    /// Target of the costs.
    pub target: Target,
    /// The generic datapath's name.
    pub generic_config: String,
    /// Inputs (pixel, light) the scene produces; every one is evaluated.
    pub inputs: u64,
    /// Covered pixels.
    pub pixels: u64,
    /// The f64 floor of each algorithm.
    pub floors: Vec<Floor>,
    /// Candidates judged.
    pub n_evaluations: u64,
    /// Why the answer is minimal within the search.
    pub minimality: Vec<String>,
    /// Per material and in all.
    pub rows: Vec<FitRow>,
    /// The generic datapath's cost.
    pub generic_cost: SideCost,
    /// The fitted datapath's cost.
    pub fitted_cost: SideCost,
    /// The fitted configuration (TOML).
    pub fitted_config: String,
}

/// The files `fit` writes in its output directory.
pub const FIT_FILES: [&str; 11] = [
    "fitted.toml",
    "fitted_rom.v",
    "fit.md",
    "fit.json",
    "inputs.csv",
    "f64_cos_n.png",
    "generic.png",
    "fitted.png",
    "diff_fitted_vs_cos_n.png",
    "diff_generic_vs_cos_n.png",
    "diff_fitted_vs_generic.png",
];

/// Runs `specfx fit`.
pub fn run(args: &FitArgs) -> Result<Outcome> {
    let (scene, label) = super::render::load_scene(args.scene.as_deref())?;
    let out_dir = super::output::OutDir::begin(
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
    let dp = super::datapath::load(config, None)?;
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
    super::datapath::load(config, Some(&NSet::range(lo, hi)?))
}

/// Fits a datapath to `scene` and writes everything into `args.out`; `None` when nothing
/// meets the budget (the floors and the closest point are printed).
pub fn fit_scene(scene: &Scene, label: &str, args: &FitArgs) -> Result<Option<FitReport>> {
    if let Some(b) = &args.budget {
        b.check_materials(scene)?;
    }
    let generic = generic_datapath(&args.config, scene)?;
    let form = generic.config().coef.form;
    log::info!(
        "fit: tracing {}x{} ({} materials, n = {:?})",
        scene.image.width,
        scene.image.height,
        scene.materials.len(),
        scene.exponents()
    );
    let frags = super::render::trace_with_progress(scene);
    let judge = SceneJudge::new(scene, &frags, form);
    let generic_image = judge.datapath_image(&generic);
    let generic_figures = judge.figures(&generic_image, true);
    let generic_all = generic_figures.all;
    let (budget, default_budget) = match &args.budget {
        Some(b) => (b.clone(), false),
        None => (ImageBudget::no_worse_than(scene, &generic_figures), true),
    };
    log::info!(
        "fit: generic datapath {} on the scene: max {} LSB, {:.2}% differing, FLIP {:.5}; budget '{}'",
        generic.config().name,
        generic_all.max_lsb,
        100.0 * generic_all.differing,
        generic_all.flip_mean,
        budget
    );
    let mut base: Config = generic.config().clone();
    base.n = NSet::from_values(&scene.exponents())?;
    let floors = floors(&judge, &base, &budget, args.start_frac);
    let progress = |line: &str| log::info!("fit: {line}");
    let found = fit_search(
        &judge,
        &base,
        &budget,
        &floors,
        args.start_frac,
        args.target,
        &progress,
    )?;
    let FitSearch {
        best,
        closest,
        n_evaluations,
        minimality,
    } = found;
    let Some(best) = best else {
        print_no_fit(&floors, closest.as_ref(), &judge, scene, &budget)?;
        return Ok(None);
    };
    let mut fitted_cfg = best.config.clone();
    fitted_cfg.name = "fitted".into();
    let fitted = Datapath::new(fitted_cfg.clone())?;
    // The proof: re-render through the renderer and judge every input again.
    let fitted_r = render_fragments(scene, &frags, &fitted);
    let generic_r = render_fragments(scene, &frags, &generic);
    let flip_fitted = specfx::scene::render::flip_errors(&fitted_r, 2, 0);
    let flip_generic = specfx::scene::render::flip_errors(&generic_r, 2, 0);
    let mut rows: Vec<FitRow> = scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| FitRow {
            material: m.name.clone(),
            n: m.n,
            generic: image_error(&generic_r, 2, 0, Some(i as u16), &flip_generic),
            fitted: image_error(&fitted_r, 2, 0, Some(i as u16), &flip_fitted),
        })
        .collect();
    let fitted_all = image_error(&fitted_r, 2, 0, None, &flip_fitted);
    let proof = SceneFigures {
        all: fitted_all,
        materials: rows.iter().map(|r| r.fitted).collect(),
    };
    if !budget.met_by(scene, &proof) || fitted_r.codes[2] != judge.datapath_image(&fitted) {
        bail!("the fitted datapath does not meet the budget on re-render: this is a bug");
    }
    rows.push(FitRow {
        material: "all".into(),
        n: 0,
        generic: image_error(&generic_r, 2, 0, None, &flip_generic),
        fitted: fitted_all,
    });
    log::info!("fit: costing the generic and the fitted datapath");
    let yosys = !args.analytic_only;
    let report = FitReport {
        scene: label.to_string(),
        budget: budget.clone(),
        default_budget,
        target: args.target,
        generic_config: generic.config().name.clone(),
        inputs: frags.terms.len() as u64,
        pixels: fitted_all.pixels,
        floors,
        n_evaluations,
        minimality,
        rows,
        generic_cost: side_cost(&generic, args.target, yosys)?,
        fitted_cost: side_cost(&fitted, args.target, yosys)?,
        fitted_config: fitted_cfg.to_toml(),
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
    write_fit(
        &args.out,
        &report,
        &fitted,
        &fitted_r,
        &generic_r,
        &provenance,
    )?;
    Ok(Some(report))
}

/// Writes the fit's files.
fn write_fit(
    out: &Path,
    r: &FitReport,
    fitted: &Datapath,
    fitted_r: &Rendered,
    generic_r: &Rendered,
    provenance: &Provenance,
) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let header = format!(
        "# specfx fit: the cheapest datapath found that renders {} within '{}' (against f64 cos^n),\n# proved on all {} inputs the scene produces; see fit.md.\n",
        r.scene.escape_debug(),
        r.budget,
        r.inputs
    );
    write_atomic(
        &out.join("fitted.toml"),
        format!("{header}{}", r.fitted_config).as_bytes(),
    )?;
    write_atomic(&out.join("fitted_rom.v"), rom_verilog(fitted).as_bytes())?;
    let md = format!("{}\n{}\n", fit_markdown(r), provenance.line());
    write_atomic(&out.join("fit.md"), md.as_bytes())?;
    write_atomic(&out.join("fit.json"), &serde_json::to_vec_pretty(r)?)?;
    write_atomic(
        &out.join("inputs.csv"),
        super::render::inputs_csv(&fitted_r.inputs, fitted.config().c.format.lsb()).as_bytes(),
    )?;
    write_atomic(&out.join("f64_cos_n.png"), &path_png(fitted_r, 0)?)?;
    write_atomic(&out.join("generic.png"), &path_png(generic_r, 2)?)?;
    write_atomic(&out.join("fitted.png"), &path_png(fitted_r, 2)?)?;
    let maps = [
        (
            "diff_fitted_vs_cos_n.png",
            &fitted_r.codes[2],
            &fitted_r.codes[0],
            "fitted vs cos^n",
        ),
        (
            "diff_generic_vs_cos_n.png",
            &generic_r.codes[2],
            &fitted_r.codes[0],
            "generic vs cos^n",
        ),
        (
            "diff_fitted_vs_generic.png",
            &fitted_r.codes[2],
            &generic_r.codes[2],
            "fitted vs generic",
        ),
    ];
    for (file, a, b, title) in maps {
        write_atomic(
            &out.join(file),
            &heatmap_png(fitted_r, &difference_of(a, b), title)?,
        )?;
    }
    write_provenance(out, provenance)
}

/// The terminal summary.
fn summary(r: &FitReport) -> String {
    let all = r.rows.last().expect("the all row");
    let (g, f) = (&r.generic_cost, &r.fitted_cost);
    let opt = |x: Option<u64>| x.map_or("-".to_string(), |v| v.to_string());
    let cfg: Config = Config::from_toml(&r.fitted_config).expect("written by to_toml");
    format!(
        "fit: budget '{}' against f64 cos^n, proved on all {} inputs ({} pixels)\n  fitted: k = {}, {}, n = {}, c {}, t {}, b {}, squares {}, coef {}, out {}\n  image: max {} LSB (generic {}), {:.2}% differing (generic {:.2}%), FLIP {:.5} (generic {:.5})\n  cost on {} (datapath + constant ROM): analytic {} + {} = {} LUTs (generic {} + {} = {}), yosys {} + {} = {} LUTs (generic {} + {} = {}); DSPs {} (generic {})\n  {} candidates judged\n",
        r.budget,
        r.inputs,
        r.pixels,
        cfg.k,
        cfg.variant.name(),
        cfg.n,
        cfg.c.format,
        cfg.t.format,
        cfg.b.format,
        cfg.square
            .iter()
            .map(|s| s.format.to_string())
            .collect::<Vec<_>>()
            .join("/"),
        cfg.coef.format,
        cfg.out.format,
        all.fitted.max_lsb,
        all.generic.max_lsb,
        100.0 * all.fitted.differing,
        100.0 * all.generic.differing,
        all.fitted.flip_mean,
        all.generic.flip_mean,
        r.target,
        f.analytic_luts,
        f.rom_analytic_luts,
        f.analytic_total_luts,
        g.analytic_luts,
        g.rom_analytic_luts,
        g.analytic_total_luts,
        opt(f.yosys_luts),
        opt(f.rom_yosys_luts),
        opt(f.yosys_total_luts),
        opt(g.yosys_luts),
        opt(g.rom_yosys_luts),
        opt(g.yosys_total_luts),
        opt(f.yosys_dsps).replace('-', &f.analytic_dsps.to_string()),
        opt(g.yosys_dsps).replace('-', &g.analytic_dsps.to_string()),
        r.n_evaluations
    )
}

/// The floors table (Markdown).
fn floors_markdown(floors: &[Floor]) -> String {
    let mut s = "| k | variant | f64 floor: max LSB | mean LSB | differing | FLIP | meets the budget |\n|---:|---|---:|---:|---:|---:|---|\n".to_string();
    for f in floors {
        match (f.figures.as_ref().map(|e| &e.all), &f.reason) {
            (Some(e), _) => s.push_str(&format!(
                "| {} | {} | {} | {:.4} | {:.2}% | {:.5} | {} |\n",
                f.k,
                f.variant.name(),
                e.max_lsb,
                e.mean_lsb,
                100.0 * e.differing,
                e.flip_mean,
                if f.meets { "yes" } else { "no" }
            )),
            (None, reason) => s.push_str(&format!(
                "| {} | {} | - | - | - | - | not valid: {} |\n",
                f.k,
                f.variant.name(),
                reason.as_deref().unwrap_or("").replace('|', "/")
            )),
        }
    }
    s
}

/// The floors as a terminal table (the same columns as [`floors_markdown`]).
fn floors_table(floors: &[Floor]) -> TextTable {
    let mut t = TextTable::new(&[
        ("k", Align::Right),
        ("variant", Align::Left),
        ("f64 floor: max LSB", Align::Right),
        ("mean LSB", Align::Right),
        ("differing", Align::Right),
        ("FLIP", Align::Right),
        ("meets the budget", Align::Left),
    ]);
    for f in floors {
        let (k, variant) = (f.k.to_string(), f.variant.name().to_string());
        match (f.figures.as_ref().map(|e| &e.all), &f.reason) {
            (Some(e), _) => t.row([
                k,
                variant,
                e.max_lsb.to_string(),
                format!("{:.4}", e.mean_lsb),
                format!("{:.2}%", 100.0 * e.differing),
                format!("{:.5}", e.flip_mean),
                if f.meets { "yes" } else { "no" }.to_string(),
            ]),
            (None, reason) => t.row([
                k,
                variant,
                "-".into(),
                "-".into(),
                "-".into(),
                "-".into(),
                format!("not valid: {}", reason.as_deref().unwrap_or("")),
            ]),
        }
    }
    t
}

/// Prints why nothing fits: the floors, the closest point and what would meet.
fn print_no_fit(
    floors: &[Floor],
    closest: Option<&Candidate>,
    judge: &SceneJudge<'_>,
    scene: &Scene,
    budget: &ImageBudget,
) -> Result<()> {
    super::output::outln!("fit: no datapath meets '{budget}' on this scene")?;
    super::output::outln!(
        "the f64 floor of each algorithm (its image without quantization, against cos^n):"
    )?;
    super::output::print_with(|w| floors_table(floors).write(w, super::terminal::table_width()))?;
    let best_floor = floors
        .iter()
        .filter_map(|f| f.figures.as_ref().map(|e| (f, budget.excess(scene, e))))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    if let Some((f, excess)) = best_floor {
        super::output::outln!(
            "the closest algorithm is k = {}, {}, whose f64 floor alone is {excess:.2}x the budget: no quantization can do better; loosen the budget to its floor's figures (see the table) or lower the scene's exponents",
            f.k,
            f.variant.name(),
        )?;
    }
    if let Some(c) = closest {
        let dp = Datapath::new(c.config.clone())?;
        let e = judge.figures(&judge.datapath_image(&dp), true).all;
        super::output::outln!(
            "closest datapath searched: k = {}, {}: max {} LSB, {:.2}% differing, FLIP {:.5} ({:.2}x the budget)",
            c.config.k,
            c.config.variant.name(),
            e.max_lsb,
            100.0 * e.differing,
            e.flip_mean,
            c.excess
        )?;
    }
    Ok(())
}

/// The fit's document.
fn fit_markdown(r: &FitReport) -> String {
    let (g, f) = (&r.generic_cost, &r.fitted_cost);
    let opt = |x: Option<u64>| x.map_or("-".to_string(), |v| v.to_string());
    let saving = |a: u64, b: u64| {
        if b == 0 {
            "-".to_string()
        } else {
            format!("{:.0}%", 100.0 * (1.0 - a as f64 / b as f64))
        }
    };
    let saving_opt = |a: Option<u64>, b: Option<u64>| match (a, b) {
        (Some(a), Some(b)) => saving(a, b),
        _ => "-".to_string(),
    };
    let mut s = format!(
        "# specfx fit: {}\n\nBudget against the f64 cos^n image: `{}`{}.\n\nProved on every input the scene produces: {} (pixel, light) inputs over {} covered pixels, each evaluated bit-accurately by the fitted datapath and the image re-rendered through the renderer.\n\n",
        specfx::report::doc::md_escape(&r.scene),
        r.budget,
        if r.default_budget {
            " (the default: no worse than the generic datapath renders this scene)"
        } else {
            ""
        },
        r.inputs,
        r.pixels
    );
    s.push_str("## Fitted configuration\n\n```toml\n");
    s.push_str(&r.fitted_config);
    s.push_str("```\n\n## Cost\n\n");
    s.push_str(&format!(
        "Target {}; the pipelined datapath plus its per-n constant ROM (`fitted_rom.v`; the generic one is addressed by n).\n\n| | generic ({}) | fitted | saving |\n|---|---:|---:|---:|\n",
        r.target, r.generic_config
    ));
    let rows: [(&str, u64, u64); 5] = [
        ("exponents served", g.rom_entries, f.rom_entries),
        ("ROM bits", g.rom_bits, f.rom_bits),
        ("analytic LUTs, datapath", g.analytic_luts, f.analytic_luts),
        (
            "analytic LUTs, ROM",
            g.rom_analytic_luts,
            f.rom_analytic_luts,
        ),
        (
            "analytic LUTs, total",
            g.analytic_total_luts,
            f.analytic_total_luts,
        ),
    ];
    for (name, a, b) in rows {
        s.push_str(&format!("| {name} | {a} | {b} | {} |\n", saving(b, a)));
    }
    s.push_str(&format!(
        "| analytic DSPs | {} | {} | {} |\n| analytic flip-flops | {} | {} | {} |\n",
        g.analytic_dsps,
        f.analytic_dsps,
        saving(f.analytic_dsps, g.analytic_dsps),
        g.analytic_ffs,
        f.analytic_ffs,
        saving(f.analytic_ffs, g.analytic_ffs)
    ));
    let yrows: [(&str, Option<u64>, Option<u64>); 5] = [
        ("yosys LUTs, datapath", g.yosys_luts, f.yosys_luts),
        ("yosys LUTs, ROM", g.rom_yosys_luts, f.rom_yosys_luts),
        ("yosys LUTs, total", g.yosys_total_luts, f.yosys_total_luts),
        ("yosys DSPs", g.yosys_dsps, f.yosys_dsps),
        ("yosys flip-flops", g.yosys_ffs, f.yosys_ffs),
    ];
    for (name, a, b) in yrows {
        s.push_str(&format!(
            "| {name} | {} | {} | {} |\n",
            opt(a),
            opt(b),
            saving_opt(b, a)
        ));
    }
    s.push_str(&format!(
        "\nThe search minimised the analytic LUTs on the target, datapath plus ROM: {} for the generic datapath, {} fitted (DSPs are not in the objective).\n\n## The image\n\n`f64_cos_n.png`, `generic.png`, `fitted.png`; differences in display LSBs `diff_fitted_vs_cos_n.png`, `diff_generic_vs_cos_n.png`, `diff_fitted_vs_generic.png`.\n\n| material | n | pixels | max LSB generic | max LSB fitted | mean LSB generic | mean LSB fitted | differing generic | differing fitted | FLIP generic | FLIP fitted |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        g.objective, f.objective
    ));
    for row in &r.rows {
        let n = if row.n == 0 {
            "-".to_string()
        } else {
            row.n.to_string()
        };
        s.push_str(&format!(
            "| {} | {n} | {} | {} | {} | {:.4} | {:.4} | {:.2}% | {:.2}% | {:.5} | {:.5} |\n",
            row.material,
            row.fitted.pixels,
            row.generic.max_lsb,
            row.fitted.max_lsb,
            row.generic.mean_lsb,
            row.fitted.mean_lsb,
            100.0 * row.generic.differing,
            100.0 * row.fitted.differing,
            row.generic.flip_mean,
            row.fitted.flip_mean
        ));
    }
    s.push_str("\nErrors are in display LSBs against the f64 cos^n image (the largest channel difference of a pixel); they include the approximation of cos^n by the algorithm, which no number of bits removes.\n\n## The search\n\nThe f64 floor of each algorithm is its image with no quantization; only algorithms whose floor meets the budget are searched.\n\n");
    s.push_str(&floors_markdown(&r.floors));
    s.push_str(&format!(
        "\n{} candidates judged, each on every input of the scene. Why the answer is minimal within the search:\n\n",
        r.n_evaluations
    ));
    for m in &r.minimality {
        s.push_str(&format!("- {m}\n"));
    }
    s
}
