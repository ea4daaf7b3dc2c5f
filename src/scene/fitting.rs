//! A datapath fitted to a scene end to end, as `specfx fit` and `specfx report` run it: the
//! floors and the search of [`super::fit`], the proof by re-rendering the answer through the
//! renderer, and the costs of the generic and the fitted datapath side by side
//! ([`FitReport`]); or, when nothing meets the budget, what came closest ([`NoFit`]).

use serde::Serialize;

use super::fit::{
    fit_search, floors, objective, FitSearch, Floor, ImageBudget, SceneFigures, SceneJudge,
};
use super::render::{flip_errors, image_error, render_fragments, Fragments, ImageError, Rendered};
use super::Scene;
use crate::analysis::optimize::Candidate;
use crate::cycle::Arch;
use crate::error::Error;
use crate::hdl::cost::{analytic_cost, Target, YosysCost};
use crate::hdl::rom::constant_rom;
use crate::nset::NSet;
use crate::pipeline::{Config, Datapath};

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

impl SideCost {
    /// The pipelined datapath `dp` and its ROM on `target`: the analytic figures, beside
    /// yosys's for the datapath and the ROM when given.
    pub fn new(dp: &Datapath, target: Target, yosys: Option<(YosysCost, YosysCost)>) -> SideCost {
        let a = analytic_cost(dp, Arch::Pipelined, target);
        let rom = constant_rom(dp, target);
        let (y, ry) = yosys.unzip();
        SideCost {
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
        }
    }
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

/// A fit that met its budget: the report, the fitted datapath, and the scene rendered
/// through it and through the generic one.
pub struct Fitted {
    /// What `fit` reports.
    pub report: FitReport,
    /// The fitted datapath (named `fitted`).
    pub datapath: Datapath,
    /// The scene through the fitted datapath (paths: f64 cos^n, its f64 model, itself).
    pub fitted_render: Rendered,
    /// The scene through the generic datapath.
    pub generic_render: Rendered,
}

/// Why nothing met the budget.
pub struct NoFit {
    /// The budget.
    pub budget: ImageBudget,
    /// The f64 floor of each algorithm.
    pub floors: Vec<Floor>,
    /// The floor closest to the budget and how far its figures are from it (times the
    /// budget), if any algorithm is valid.
    pub closest_floor: Option<(Floor, f64)>,
    /// The closest datapath searched and its image's figures against cos^n, if any.
    pub closest: Option<(Candidate, ImageError)>,
}

/// What a fit comes to.
pub enum FitOutcome {
    /// A datapath meets the budget.
    Fitted(Box<Fitted>),
    /// None does.
    NoFit(Box<NoFit>),
}

/// What a fit is asked.
pub struct FitRequest<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// How documents name it (its path, or "the built-in scene").
    pub label: &'a str,
    /// Its fragments, traced once.
    pub frags: &'a Fragments,
    /// The generic datapath, whose n set holds the scene's exponents.
    pub generic: &'a Datapath,
    /// The budget; `None`: no worse than the generic datapath renders the scene.
    pub budget: Option<&'a ImageBudget>,
    /// The fraction bits the search starts from.
    pub start_frac: i32,
    /// The target of the costs.
    pub target: Target,
}

/// Fits a datapath to the scene: the floors, the search, the proof on every input the scene
/// produces (re-rendered through the renderer; a failure is a bug), and the costs of the
/// generic and the fitted datapath by `cost`. `progress` receives the search's lines.
pub fn fit_scene(
    req: &FitRequest<'_>,
    progress: &(dyn Fn(&str) + Sync),
    cost: &dyn Fn(&Datapath) -> Result<SideCost, Error>,
) -> Result<FitOutcome, Error> {
    let FitRequest {
        scene,
        label,
        frags,
        generic,
        start_frac,
        target,
        ..
    } = *req;
    let form = generic.config().coef.form;
    let judge = SceneJudge::new(scene, frags, form);
    let generic_image = judge.datapath_image(generic);
    let generic_figures = judge.figures(&generic_image, true);
    let generic_all = generic_figures.all;
    let (budget, default_budget) = match req.budget {
        Some(b) => (b.clone(), false),
        None => (ImageBudget::no_worse_than(scene, &generic_figures), true),
    };
    progress(&format!(
        "generic datapath {} on the scene: max {} LSB, {:.2}% differing, FLIP {:.5}; budget '{}'",
        generic.config().name,
        generic_all.max_lsb,
        100.0 * generic_all.differing,
        generic_all.flip_mean,
        budget
    ));
    let mut base: Config = generic.config().clone();
    base.n = NSet::from_values(&scene.exponents())?;
    let floors = floors(&judge, &base, &budget, start_frac);
    let found = fit_search(
        &judge, &base, &budget, &floors, start_frac, target, progress,
    )?;
    let FitSearch {
        best,
        closest,
        n_evaluations,
        minimality,
    } = found;
    let Some(best) = best else {
        let closest_floor = floors
            .iter()
            .filter_map(|f| f.figures.as_ref().map(|e| (f, budget.excess(scene, e))))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(f, excess)| (f.clone(), excess));
        let closest = match closest {
            Some(c) => {
                let dp = Datapath::new(c.config.clone())?;
                let e = judge.figures(&judge.datapath_image(&dp), true).all;
                Some((c, e))
            }
            None => None,
        };
        return Ok(FitOutcome::NoFit(Box::new(NoFit {
            budget,
            floors,
            closest_floor,
            closest,
        })));
    };
    let mut fitted_cfg = best.config.clone();
    fitted_cfg.name = "fitted".into();
    let fitted = Datapath::new(fitted_cfg.clone())?;
    // The proof: re-render through the renderer and judge every input again.
    let fitted_r = render_fragments(scene, frags, &fitted);
    let generic_r = render_fragments(scene, frags, generic);
    let flip_fitted = flip_errors(&fitted_r, 2, 0);
    let flip_generic = flip_errors(&generic_r, 2, 0);
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
    assert!(
        budget.met_by(scene, &proof) && fitted_r.codes[2] == judge.datapath_image(&fitted),
        "the fitted datapath does not meet the budget on re-render: this is a bug"
    );
    rows.push(FitRow {
        material: "all".into(),
        n: 0,
        generic: image_error(&generic_r, 2, 0, None, &flip_generic),
        fitted: fitted_all,
    });
    progress("costing the generic and the fitted datapath");
    let report = FitReport {
        scene: label.to_string(),
        budget,
        default_budget,
        target,
        generic_config: generic.config().name.clone(),
        inputs: frags.terms.len() as u64,
        pixels: fitted_all.pixels,
        floors,
        n_evaluations,
        minimality,
        rows,
        generic_cost: cost(generic)?,
        fitted_cost: cost(&fitted)?,
        fitted_config: fitted_cfg.to_toml(),
    };
    Ok(FitOutcome::Fitted(Box::new(Fitted {
        report,
        datapath: fitted,
        fitted_render: fitted_r,
        generic_render: generic_r,
    })))
}
