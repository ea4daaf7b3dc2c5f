//! The reachable frontier: for each algorithm, the optimiser's cheapest datapath at each rung
//! of a ladder of error budgets, so that an error-against-cost chart reads "the least
//! hardware that reaches this accuracy" rather than a few hand-picked widths.

use serde::Serialize;

use crate::analysis::budget_expr::Budget;
use crate::analysis::check::{check_outputs_cached, CosCache};
use crate::analysis::optimize::{
    algorithm_floors, exhaustive_judge, optimize_space, search, Algorithm, AlgorithmFloor,
    COS_CACHE_VALUES,
};
use crate::analysis::LSB8;
use crate::cycle::Arch;
use crate::error::Error;
use crate::hdl::cost::{analytic_cost, figures_on_targets, objective_value, CostFigures, Target};
use crate::nset::NSet;
use crate::pipeline::{Config, Datapath};

/// The budgets of the frontier, in lsb8 of `shape_total` (the lobe against cos^n): from
/// eight display steps down to half of one.
pub const LADDER_LSB8: [f64; 6] = [8.0, 4.0, 2.0, 1.0, 0.75, 0.5];

/// The fraction bits every search of the frontier starts from (the optimiser's default).
pub const START_FRAC: i32 = 20;

/// One point of the frontier: an algorithm's cheapest datapath within one budget.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrontierPoint {
    /// The algorithm.
    pub algorithm: Algorithm,
    /// The budget, `shape_total` in lsb8.
    pub budget_lsb8: f64,
    /// The budget whose search found the datapath: this one, or a tighter one whose answer
    /// was cheaper (an answer within a tighter budget is within this one too, and the
    /// searches are local: they need not find it from their own start).
    pub found_at_lsb8: f64,
    /// The datapath found (named after its algorithm and budget).
    #[serde(skip)]
    pub config: Config,
    /// Its configuration as TOML (what `specfx check --config` reads).
    pub config_toml: String,
    /// Its exhaustively checked `shape_total` (max |fixed lobe - cos^n|), absolute.
    pub shape_total: f64,
    /// What the optimiser minimised: analytic iCE40 LUTs plus each DSP block weighed as the
    /// logic its product would take ([`objective_value`]).
    pub objective: f64,
    /// Its analytic cost on every reported target, in the frontier's architecture.
    pub costs: Vec<CostFigures>,
    /// Its latency in cycles.
    pub latency: u64,
}

impl FrontierPoint {
    /// The datapath's cost on `target`.
    pub fn cost_on(&self, target: Target) -> Option<CostFigures> {
        self.costs.iter().find(|c| c.target == target).copied()
    }
}

/// The frontier of every algorithm.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Frontier {
    /// The architecture every datapath is costed in.
    pub arch: Arch,
    /// The budgets, in lsb8, loosest first.
    pub ladder_lsb8: Vec<f64>,
    /// Every algorithm's f64 floor (an algorithm is searched at the budgets its floor leaves
    /// reachable).
    pub floors: Vec<AlgorithmFloor>,
    /// The points, in the floors' order of algorithms, loosest budget first; an algorithm
    /// has none at the budgets below its floor or where no datapath was found.
    pub points: Vec<FrontierPoint>,
    /// Candidates judged, over every search.
    pub n_evaluations: u64,
}

/// The budget `shape_total <= b lsb8`, costed in `arch`.
pub fn rung_budget(b: f64, arch: Arch) -> Result<Budget, Error> {
    let mut budget: Budget = format!("shape_total <= {b} lsb8").parse()?;
    budget.arch = arch;
    Ok(budget)
}

/// The searches the frontier of `algorithms` runs at most (for a progress bar): each
/// algorithm at every budget its floor leaves reachable.
pub fn rung_count(floors: &[AlgorithmFloor], ladder_lsb8: &[f64]) -> usize {
    floors
        .iter()
        .map(|f| match f.shape_total {
            Some(x) => ladder_lsb8.iter().filter(|&&b| x <= b * LSB8).count(),
            None => 0,
        })
        .sum()
}

/// The base of the trade-off's frontier: the baseline (the paper's formats) serving `ns`.
pub fn tradeoff_base(ns: &NSet) -> Config {
    let mut base = Config::baseline();
    base.n = ns.clone();
    base
}

/// The floors of every algorithm (plain and minimax, k = 1..7, fixed and per-n depth) from
/// `base`: the first step of [`frontier`], apart so that a caller can size its progress bar
/// ([`rung_count`]).
pub fn frontier_floors(base: &Config, ladder_lsb8: &[f64]) -> Result<Vec<AlgorithmFloor>, Error> {
    let loosest = ladder_lsb8.iter().copied().fold(0.0, f64::max);
    let algorithms = Algorithm::every(base);
    Ok(algorithm_floors(
        base,
        &rung_budget(loosest, Arch::Pipelined)?,
        &algorithms,
        START_FRAC,
    ))
}

/// The frontier: each algorithm of `floors` searched ([`search`], the optimiser's search,
/// minimising [`objective_value`] on iCE40 in `arch`, with no device limit) at each budget
/// of `ladder_lsb8` from the loosest down, until its floor or a failed search stops it; the
/// algorithms in parallel, every candidate's figures shared across the budgets (a
/// candidate met again is not checked again). `done(algorithm, budget_lsb8)` is called as
/// each search ends.
pub fn frontier(
    base: &Config,
    floors: Vec<AlgorithmFloor>,
    ladder_lsb8: &[f64],
    arch: Arch,
    done: &(dyn Fn(Algorithm, f64) + Sync),
) -> Result<Frontier, Error> {
    use rayon::prelude::*;
    let mut ladder: Vec<f64> = ladder_lsb8.to_vec();
    ladder.sort_by(|a, b| b.total_cmp(a));
    ladder.dedup();
    let cos = CosCache::new(COS_CACHE_VALUES);
    let curves: Vec<(Vec<FrontierPoint>, u64)> = floors
        .par_iter()
        .filter(|f| f.reachable)
        .map(|f| -> Result<(Vec<FrontierPoint>, u64), Error> {
            let a = f.algorithm;
            let floor = f.shape_total.unwrap_or(f64::INFINITY);
            let mut points = Vec::new();
            let mut n_evaluations = 0;
            for &b in ladder.iter().filter(|&&b| floor <= b * LSB8) {
                let budget = rung_budget(b, arch)?;
                let space = optimize_space(a, &budget, START_FRAC);
                let mut judge = |dp: &Datapath| exhaustive_judge(dp, &budget, Some(&cos));
                let mut cost = |dp: &Datapath| {
                    Ok(objective_value(
                        &analytic_cost(dp, arch, Target::Ice40).figures(),
                    ))
                };
                let r = search(base, &space, &mut judge, &mut cost, &mut |_| {})?;
                n_evaluations += r.n_evaluations;
                done(a, b);
                let Some(best) = r.best else {
                    // A tighter budget cannot be met where this one was not.
                    break;
                };
                let mut config = best.config;
                config.name = format!("{}_{b}lsb8", algorithm_name(a));
                let dp = Datapath::new(config.clone())?;
                let figures = check_outputs_cached(&dp, Some(&cos))?;
                points.push(FrontierPoint {
                    config_toml: config.to_toml(),
                    algorithm: a,
                    budget_lsb8: b,
                    found_at_lsb8: b,
                    config,
                    shape_total: figures.shape_total_max_abs,
                    objective: best.cost,
                    costs: figures_on_targets(&dp, arch),
                    latency: analytic_cost(&dp, arch, Target::Ice40).latency,
                });
            }
            Ok((cheapest_within(points), n_evaluations))
        })
        .collect::<Result<_, Error>>()?;
    let n_evaluations = curves.iter().map(|(_, n)| n).sum();
    Ok(Frontier {
        arch,
        ladder_lsb8: ladder,
        floors,
        points: curves.into_iter().flat_map(|(p, _)| p).collect(),
        n_evaluations,
    })
}

/// One algorithm's points (loosest budget first), each replaced by the answer of a tighter
/// budget where that one is cheaper: the curve then never costs more for a looser budget.
fn cheapest_within(mut points: Vec<FrontierPoint>) -> Vec<FrontierPoint> {
    for i in (0..points.len().saturating_sub(1)).rev() {
        if points[i + 1].objective < points[i].objective {
            let budget = points[i].budget_lsb8;
            points[i] = FrontierPoint {
                budget_lsb8: budget,
                ..points[i + 1].clone()
            };
        }
    }
    points
}

/// An algorithm's short name: `minimax5`, `plain4`, `minimax6_per_n`.
pub fn algorithm_name(a: Algorithm) -> String {
    format!(
        "{}{}{}",
        a.variant.name(),
        a.k,
        if a.per_n { "_per_n" } else { "" }
    )
}
