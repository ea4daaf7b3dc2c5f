//! The optimiser: the cheapest configuration that meets an error budget, proved by an
//! exhaustive check.
//!
//! Search: start from a wide feasible point (every searched stage, t, b and the squarings, at
//! `start_frac` fraction bits; the other knobs, such as the coefficient's and output's formats
//! where the budget measures them, at the base's values), then per-knob bisection of the bits (each stage in turn, the others fixed,
//! repeated until nothing shrinks), from each combination of the discrete choices (k, the
//! variant, the rounding of every stage); keep the cheapest feasible result. Then a local
//! search from it: each stage's rounding and overflow mode changed alone (the output's too),
//! the rounding also with one fraction bit less, accepting any feasible cheaper move, until no
//! move improves. Every candidate is checked exhaustively, and the answer is shown locally
//! minimal: taking one fraction bit from any searched stage breaks the budget, and no single
//! mode change is feasible and cheaper. An overflow mode changes only on a stage the exhaustive
//! check proves never overflows (every mode then gives the same values).

use std::collections::BTreeMap;
use std::fmt;

use serde::Serialize;

use crate::analysis::budget_expr::{Bound, Budget, Metric, Synthesise, Verdict};
use crate::analysis::check::{
    check_outputs, check_outputs_cached, CheckReport, CosCache, OutputFigures,
};
use crate::cycle::Arch;
use crate::error::Error;
use crate::fixed::{Format, Overflow, Rounding};
use crate::hdl::cost::{analytic_cost, objective_value, CostFigures, Target};
use crate::hdl::pnr::{device_check, Device};
use crate::pipeline::walk::Stage;
use crate::pipeline::StageSpec;
use crate::pipeline::{Config, Datapath, Depth, Variant};

/// One dimension the search shrinks by bisection.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Knob {
    /// The fraction bits of a quantizing stage (`t`, `b`, a squaring, `out`).
    Frac(Stage),
    /// The fraction bits of the input c (and of d = c - 1, which stays exact).
    InputFrac,
    /// The fraction bits of the stored coefficient.
    CoefFrac,
    /// The integer bits of the stored coefficient (the largest coef(n) must fit).
    CoefInt,
    /// The integer bits of the output (fewer saturate the brightest outputs).
    OutInt,
    /// The fraction bits of the minimax slope A(n).
    MinimaxSlopeFrac,
    /// The fraction bits of the minimax offset A(n) + B(n).
    MinimaxOffsetFrac,
}

impl fmt::Display for Knob {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Knob::Frac(s) => write!(f, "{s} fraction bits"),
            Knob::InputFrac => f.write_str("c fraction bits"),
            Knob::CoefFrac => f.write_str("coef fraction bits"),
            Knob::CoefInt => f.write_str("coef integer bits"),
            Knob::OutInt => f.write_str("out integer bits"),
            Knob::MinimaxSlopeFrac => f.write_str("minimax slope fraction bits"),
            Knob::MinimaxOffsetFrac => f.write_str("minimax offset fraction bits"),
        }
    }
}

impl Knob {
    /// The knob's value in a configuration.
    pub fn get(self, cfg: &Config) -> i32 {
        match self {
            Knob::Frac(s) => spec_mut(&mut cfg.clone(), s).format.frac_bits(),
            Knob::InputFrac => cfg.c.format.frac_bits(),
            Knob::CoefFrac => cfg.coef.format.frac_bits(),
            Knob::CoefInt => cfg.coef.format.int_bits(),
            Knob::OutInt => cfg.out.format.int_bits(),
            Knob::MinimaxSlopeFrac => cfg.minimax.a_format.frac_bits(),
            Knob::MinimaxOffsetFrac => cfg.minimax.offset_format.frac_bits(),
        }
    }

    /// Sets the knob (an error when the format cannot exist).
    pub fn set(self, cfg: &mut Config, v: i32) -> Result<(), Error> {
        let with_frac = |f: Format| Format::new(f.is_signed(), f.int_bits(), v);
        match self {
            Knob::Frac(s) => set_frac(cfg, s, v)?,
            Knob::InputFrac => {
                cfg.c.format = with_frac(cfg.c.format)?;
                cfg.d.format = with_frac(cfg.d.format)?;
            }
            Knob::CoefFrac => cfg.coef.format = with_frac(cfg.coef.format)?,
            Knob::CoefInt => {
                let f = cfg.coef.format;
                cfg.coef.format = Format::new(f.is_signed(), v, f.frac_bits())?;
            }
            Knob::OutInt => {
                let f = cfg.out.format;
                cfg.out.format = Format::new(f.is_signed(), v, f.frac_bits())?;
            }
            Knob::MinimaxSlopeFrac => cfg.minimax.a_format = with_frac(cfg.minimax.a_format)?,
            Knob::MinimaxOffsetFrac => {
                cfg.minimax.offset_format = with_frac(cfg.minimax.offset_format)?
            }
        }
        Ok(())
    }

    /// Whether the search starts this knob at `start_frac` (the internal stages) rather than
    /// at the base configuration's value.
    fn starts_wide(self) -> bool {
        matches!(self, Knob::Frac(Stage::T | Stage::B | Stage::Square(_)))
    }
}

/// The searched stages: `t`, `b`, `sq1`..`sqk`. The output format is the interface the
/// design must deliver (and the unit of `out <= N ulp`), so `optimize` keeps it.
fn searched_stages(k: u32) -> Vec<Stage> {
    let mut v = vec![Stage::T, Stage::B];
    v.extend((0..k as usize).map(Stage::Square));
    v
}

/// The spec of a quantizing stage: t, b, a squaring or out (d and coef have none).
fn spec_mut(cfg: &mut Config, stage: Stage) -> &mut StageSpec {
    match stage {
        Stage::T => &mut cfg.t,
        Stage::B => &mut cfg.b,
        Stage::Square(i) => &mut cfg.square[i],
        Stage::Out => &mut cfg.out,
        Stage::D | Stage::Coef => unreachable!("the optimiser moves only quantizing stages"),
    }
}

/// Gives a stage `frac` fraction bits, keeping its integer bits.
fn set_frac(cfg: &mut Config, stage: Stage, frac: i32) -> Result<(), Error> {
    let spec = spec_mut(cfg, stage);
    spec.format = Format::new(spec.format.is_signed(), spec.format.int_bits(), frac)?;
    Ok(())
}

/// The stages the exhaustive check proves never overflow in a configuration (no wrap,
/// saturation or zeroing on any input): there every overflow mode gives the same values.
fn stages_never_overflowing(cfg: &Config) -> Result<Vec<Stage>, Error> {
    let events = crate::analysis::check::stage_events(&Datapath::new(cfg.clone())?)?;
    let k = cfg.k as usize;
    let mut stages = searched_stages(cfg.k);
    stages.push(Stage::Out);
    Ok(stages
        .into_iter()
        .filter(|stage| events[stage.index(k)] == [0, 0, 0])
        .collect())
}

/// What the optimiser minimises: the calibrated analytic model's logic cells (instant) or
/// yosys's count (seconds per candidate).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Objective {
    /// The analytic cost model.
    Analytic,
    /// yosys's synthesis.
    Yosys,
}

impl Objective {
    /// Every objective.
    pub const ALL: [Objective; 2] = [Objective::Analytic, Objective::Yosys];

    /// The name used on the command line and in provenance.
    pub fn name(self) -> &'static str {
        match self {
            Objective::Analytic => "analytic",
            Objective::Yosys => "yosys",
        }
    }
}

crate::names::named_enum!(Objective, "objective", "analytic or yosys");

/// What the search may change beyond the internal stages' fraction bits.
#[derive(Debug, Clone, PartialEq)]
pub struct Space {
    /// The discrete choices.
    pub choices: Choices,
    /// Fraction bits the internal stages (t, b, the squarings) start from.
    pub start_frac: i32,
    /// Knobs searched after the internal stages', starting at the base's values.
    pub extra_knobs: Vec<Knob>,
    /// The rounding modes the local search tries on each stage.
    pub local_roundings: Vec<Rounding>,
    /// Whether the local search may change overflow modes.
    pub overflow_moves: bool,
    /// The microarchitecture the candidates are costed in.
    pub arch: Arch,
}

/// What a search found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SearchResult {
    /// The cheapest feasible configuration, if any.
    pub best: Option<Candidate>,
    /// The closest configuration (least excess) when none is feasible.
    pub closest: Option<Candidate>,
    /// Candidates judged.
    pub n_evaluations: u64,
    /// Why the answer is minimal within the search.
    pub minimality: Vec<String>,
}

/// The discrete choices the local search tries.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Choices {
    /// Numbers of squarings.
    pub k: Vec<u32>,
    /// Variants.
    pub variants: Vec<Variant>,
    /// Squaring depths: all k at every n (`false`, [`Depth::Fixed`]) or the best j(n) per
    /// n (`true`, [`Depth::Best`]).
    pub per_n: Vec<bool>,
    /// Rounding modes (applied to every searched stage at once).
    pub roundings: Vec<Rounding>,
}

/// One evaluated candidate.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Candidate {
    /// Its configuration.
    pub config: Config,
    /// The cost (LUTs, analytic or yosys).
    pub cost: f64,
    /// Whether it meets the budget.
    pub feasible: bool,
    /// How far from the budget (<= 1 when met).
    pub excess: f64,
    /// The microarchitecture it was costed in.
    pub arch: Arch,
}

/// What the optimiser found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OptimizeResult {
    /// The budget.
    pub budget: Budget,
    /// The cheapest feasible configuration, if any.
    pub best: Option<Candidate>,
    /// The closest configuration (least excess) when none is feasible.
    pub closest: Option<Candidate>,
    /// Exhaustive checks run.
    pub n_evaluations: u64,
    /// Why the answer is minimal within the search.
    pub minimality: Vec<String>,
}

/// Searches for the cheapest configuration meeting `budget`, starting from `base`; every
/// candidate is checked exhaustively ([`check_outputs`]).
///
/// `cost` prices a validated datapath (analytic LUTs, or yosys); `progress` receives a line
/// per step.
pub fn optimize(
    base: &Config,
    budget: &Budget,
    choices: &Choices,
    start_frac: i32,
    cost: &mut dyn FnMut(&Datapath) -> Result<f64, Error>,
    progress: &mut dyn FnMut(&str),
) -> Result<OptimizeResult, Error> {
    let space = Space {
        choices: choices.clone(),
        start_frac,
        extra_knobs: Vec::new(),
        local_roundings: Rounding::ALL.to_vec(),
        overflow_moves: true,
        arch: budget.arch,
    };
    let cos = CosCache::new(COS_CACHE_VALUES);
    let mut judge =
        |dp: &Datapath| -> Result<Verdict, Error> { exhaustive_judge(dp, budget, Some(&cos)) };
    let r = search(base, &space, &mut judge, cost, progress)?;
    Ok(OptimizeResult {
        budget: budget.clone(),
        best: r.best,
        closest: r.closest,
        n_evaluations: r.n_evaluations,
        minimality: r.minimality,
    })
}

/// The search behind [`optimize`], with any judge: from each combination of the discrete
/// choices, every internal stage at `start_frac` fraction bits and the extra knobs at the
/// base's values; per-knob bisection until nothing shrinks; the cheapest feasible point, then
/// a local search over rounding (and, if allowed, overflow) modes.
pub fn search(
    base: &Config,
    space: &Space,
    judge: &mut dyn FnMut(&Datapath) -> Result<Verdict, Error>,
    cost: &mut dyn FnMut(&Datapath) -> Result<f64, Error>,
    progress: &mut dyn FnMut(&str),
) -> Result<SearchResult, Error> {
    let choices = &space.choices;
    let mut eval = Evaluator {
        arch: space.arch,
        judge,
        cost,
        memo: BTreeMap::new(),
        costs: BTreeMap::new(),
        n_eval: 0,
    };
    let mut best: Option<Candidate> = None;
    let mut closest: Option<Candidate> = None;
    let algorithms = choices.k.iter().flat_map(|&k| {
        choices.variants.iter().flat_map(move |&variant| {
            choices
                .per_n
                .iter()
                .map(move |&per_n| Algorithm { k, variant, per_n })
        })
    });
    for algorithm in algorithms {
        {
            for &rounding in &choices.roundings {
                let cfg = start_config(base, space, algorithm, rounding)?;
                progress(&format!(
                    "{algorithm}, {rounding}: start at {} fraction bits",
                    space.start_frac
                ));
                let Some(start) = eval.evaluate(&cfg)? else {
                    continue;
                };
                if !start.feasible {
                    if closest.as_ref().is_none_or(|c| start.excess < c.excess) {
                        closest = Some(start);
                    }
                    continue;
                }
                let current = bisect(&mut eval, &space.knobs(algorithm.k), start)?;
                progress(&format!("  -> {:.0} LUTs", current.cost));
                if best.as_ref().is_none_or(|b| current.cost < b.cost) {
                    best = Some(current);
                }
            }
        }
    }
    let mut n_moves = 0u64;
    if let Some(start) = best.take() {
        let (current, moves) = local_search(&mut eval, space, start, progress)?;
        best = Some(current);
        n_moves = moves;
    }
    let minimality = match &best {
        Some(b) => minimality(&mut eval, space, b, n_moves)?,
        None => Vec::new(),
    };
    Ok(SearchResult {
        best,
        closest,
        n_evaluations: eval.n_eval,
        minimality,
    })
}

impl Space {
    /// The knobs searched for k squarings: every searched stage's fraction bits, then the
    /// extra knobs.
    fn knobs(&self, k: u32) -> Vec<Knob> {
        searched_stages(k)
            .into_iter()
            .map(Knob::Frac)
            .chain(self.extra_knobs.iter().copied())
            .collect()
    }
}

/// The search's judge and cost with memos: each configuration is judged once, and counted,
/// and priced once.
struct Evaluator<'a> {
    arch: Arch,
    judge: &'a mut dyn FnMut(&Datapath) -> Result<Verdict, Error>,
    cost: &'a mut dyn FnMut(&Datapath) -> Result<f64, Error>,
    memo: BTreeMap<String, Option<Candidate>>,
    costs: BTreeMap<String, Option<f64>>,
    n_eval: u64,
}

impl Evaluator<'_> {
    /// The candidate `cfg` is, or None when it is not a valid datapath.
    fn evaluate(&mut self, cfg: &Config) -> Result<Option<Candidate>, Error> {
        let key = cfg.to_toml();
        if let Some(c) = self.memo.get(&key) {
            return Ok(c.clone());
        }
        let c = match Datapath::new(cfg.clone()) {
            Err(_) => None,
            Ok(dp) => {
                self.n_eval += 1;
                let v = (self.judge)(&dp)?;
                Some(Candidate {
                    config: cfg.clone(),
                    cost: self.price(&key, &dp)?,
                    feasible: v.feasible,
                    excess: v.excess,
                    arch: self.arch,
                })
            }
        };
        self.memo.insert(key, c.clone());
        Ok(c)
    }

    /// The cost of `cfg` alone, without judging it (None when it is not a valid datapath):
    /// the same figure [`Evaluator::evaluate`] gives it.
    fn cost_of(&mut self, cfg: &Config) -> Result<Option<f64>, Error> {
        let key = cfg.to_toml();
        if let Some(c) = self.memo.get(&key) {
            return Ok(c.as_ref().map(|c| c.cost));
        }
        if let Some(&c) = self.costs.get(&key) {
            return Ok(c);
        }
        match Datapath::new(cfg.clone()) {
            Err(_) => {
                self.costs.insert(key, None);
                Ok(None)
            }
            Ok(dp) => self.price(&key, &dp).map(Some),
        }
    }

    fn price(&mut self, key: &str, dp: &Datapath) -> Result<f64, Error> {
        if let Some(&Some(c)) = self.costs.get(key) {
            return Ok(c);
        }
        let c = (self.cost)(dp)?;
        self.costs.insert(key.to_string(), Some(c));
        Ok(c)
    }
}

/// The starting point of one combination of the discrete choices: every knob that starts
/// wide at `start_frac` fraction bits, every rounding stage at `rounding`.
fn start_config(
    base: &Config,
    space: &Space,
    algorithm: Algorithm,
    rounding: Rounding,
) -> Result<Config, Error> {
    let k = algorithm.k;
    let mut cfg = base.clone();
    algorithm.apply(&mut cfg);
    for knob in space.knobs(k).into_iter().filter(|k| k.starts_wide()) {
        knob.set(&mut cfg, space.start_frac)?;
    }
    cfg.t.rounding = rounding;
    cfg.b.rounding = rounding;
    cfg.out.rounding = rounding;
    for sq in &mut cfg.square {
        sq.rounding = rounding;
    }
    Ok(cfg)
}

/// Per-knob bisection from a feasible `start` until no knob shrinks.
fn bisect(eval: &mut Evaluator, knobs: &[Knob], start: Candidate) -> Result<Candidate, Error> {
    let mut current = start;
    loop {
        let mut changed = false;
        for &knob in knobs {
            let (mut lo, mut hi) = (-1, knob.get(&current.config));
            // Invariant: hi feasible; find the smallest feasible in (lo, hi], down to 0 bits.
            while hi - lo > 1 {
                let mid = (lo + hi) / 2;
                let mut trial = current.config.clone();
                if knob.set(&mut trial, mid).is_err() {
                    lo = mid;
                    continue;
                }
                match eval.evaluate(&trial)? {
                    Some(c) if c.feasible => {
                        hi = mid;
                        current = c;
                        changed = true;
                    }
                    _ => lo = mid,
                }
            }
        }
        if !changed {
            return Ok(current);
        }
    }
}

/// Local search over each stage's rounding and overflow modes (the output's too: its format
/// is the interface, its modes are not), alone or with one fraction bit less, until no single
/// move is both feasible and cheaper. Returns the point and the number of moves tried.
///
/// A move is priced before it is judged: one that is not cheaper cannot be taken, so only
/// the cheaper ones are checked exhaustively (the moves taken are those judging every move
/// would take, in the same order). Overflow moves need a proof that the stage never
/// overflows (an exhaustive check of the current point, made once per point and only when
/// one of them is cheaper).
fn local_search(
    eval: &mut Evaluator,
    space: &Space,
    start: Candidate,
    progress: &mut dyn FnMut(&str),
) -> Result<(Candidate, u64), Error> {
    let mut n_moves = 0u64;
    let mut current = start;
    let mut stages = searched_stages(current.config.k);
    stages.push(Stage::Out);
    loop {
        let mut improved = false;
        let mut overflows: Option<Vec<Stage>> = None;
        for &s in &stages {
            let (rounding, overflow) = local_moves(space, &current.config, s)?;
            n_moves += (rounding.len() + overflow.len()) as u64;
            let mut cheaper = cheaper_than(eval, rounding, current.cost)?;
            let cheaper_overflow = cheaper_than(eval, overflow, current.cost)?;
            if !cheaper_overflow.is_empty() {
                if overflows.is_none() {
                    overflows = Some(stages_never_overflowing(&current.config)?);
                }
                if overflows.as_ref().is_some_and(|o| o.contains(&s)) {
                    cheaper.extend(cheaper_overflow);
                }
            }
            for trial in cheaper {
                if let Some(c) = eval.evaluate(&trial)? {
                    if c.feasible && c.cost < current.cost {
                        let now = *spec_mut(&mut c.config.clone(), s);
                        progress(&format!(
                            "  local search: {s} {} {} {}: {:.0} LUTs",
                            now.format, now.rounding, now.overflow, c.cost
                        ));
                        current = c;
                        improved = true;
                        overflows = None;
                        // The other trials of this stage were built from the old point.
                        break;
                    }
                }
            }
        }
        if !improved {
            return Ok((current, n_moves));
        }
    }
}

/// The valid trials whose cost is below `bound`, in their order (priced, not judged).
fn cheaper_than(
    eval: &mut Evaluator,
    trials: Vec<Config>,
    bound: f64,
) -> Result<Vec<Config>, Error> {
    let mut cheaper = Vec::new();
    for trial in trials {
        if eval.cost_of(&trial)?.is_some_and(|cost| cost < bound) {
            cheaper.push(trial);
        }
    }
    Ok(cheaper)
}

/// The local search's moves on stage `s` of `config`: every other rounding mode, alone and
/// (internal stages) with one fraction bit less; then every other overflow mode, when the
/// space allows overflow moves (valid only where the stage never overflows: see
/// [`stages_never_overflowing`]).
fn local_moves(
    space: &Space,
    config: &Config,
    s: Stage,
) -> Result<(Vec<Config>, Vec<Config>), Error> {
    let spec = *spec_mut(&mut config.clone(), s);
    let mut trials = Vec::new();
    for &r in space
        .local_roundings
        .iter()
        .filter(|&&r| r != spec.rounding)
    {
        let mut trial = config.clone();
        spec_mut(&mut trial, s).rounding = r;
        if s != Stage::Out {
            let mut fewer = trial.clone();
            if set_frac(&mut fewer, s, spec.format.frac_bits() - 1).is_ok() {
                trials.push(fewer);
            }
        }
        trials.push(trial);
    }
    let mut overflow = Vec::new();
    if space.overflow_moves {
        for o in Overflow::ALL.into_iter().filter(|&o| o != spec.overflow) {
            let mut trial = config.clone();
            spec_mut(&mut trial, s).overflow = o;
            overflow.push(trial);
        }
    }
    Ok((trials, overflow))
}

/// Why `best` is minimal within the search: how it was found, and each knob's verdict one
/// bit narrower.
fn minimality(
    eval: &mut Evaluator,
    space: &Space,
    best: &Candidate,
    n_moves: u64,
) -> Result<Vec<String>, Error> {
    let choices = &space.choices;
    let mut lines = vec![
        format!(
            "cheapest of {} starting points (k in {:?}, variants {:?}, depths {:?}, roundings {:?}), each shrunk by per-stage bisection until no stage could lose a fraction bit",
            choices.k.len() * choices.variants.len() * choices.per_n.len() * choices.roundings.len(),
            choices.k,
            choices
                .variants
                .iter()
                .map(|v| v.name())
                .collect::<Vec<_>>(),
            choices
                .per_n
                .iter()
                .map(|&p| depth_of_choice(p).name())
                .collect::<Vec<_>>(),
            choices
                .roundings
                .iter()
                .map(|r| r.name())
                .collect::<Vec<_>>()
        ),
        format!(
            "then a local search over every stage's rounding{} modes (the output's included), each alone or with one fraction bit less: {n_moves} moves tried (each priced, the cheaper ones checked exhaustively), none of the final ones both feasible and cheaper",
            if space.overflow_moves {
                " and overflow"
            } else {
                ""
            }
        ),
    ];
    if space.overflow_moves {
        lines.push("overflow modes were changed only on stages an exhaustive check proves never overflow, where every mode gives the same values".to_string());
    }
    let knobs = space.knobs(best.config.k);
    lines.push(format!(
        "the knobs searched: {}",
        knobs
            .iter()
            .map(|k| k.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ));
    for knob in knobs {
        let mut trial = best.config.clone();
        let bits = knob.get(&trial);
        let verdict = if knob.set(&mut trial, bits - 1).is_err() {
            "cannot lose a bit (format limit)".to_string()
        } else {
            match eval.evaluate(&trial)? {
                Some(c) if c.feasible => {
                    format!("ALSO FEASIBLE with {} bits (cost {:.0})", bits - 1, c.cost)
                }
                Some(_) => format!("{bits}: one fewer breaks the budget"),
                None => "one fewer bit is not a valid configuration".to_string(),
            }
        };
        lines.push(format!("{knob}: {verdict}"));
    }
    Ok(lines)
}

/// One algorithm the optimiser may choose: k squaring stages, a variant, and whether each n
/// squares only to its best depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Algorithm {
    /// Squaring stages.
    pub k: u32,
    /// Variant.
    pub variant: Variant,
    /// Each n squares to the depth j(n) <= k with the smallest f64 floor ([`Depth::Best`]),
    /// the later stages bypassed; otherwise every n squares k times.
    pub per_n: bool,
}

/// Which squaring depths the optimiser searches (`specfx optimize --depth`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DepthSearch {
    /// Every n squares k times.
    Fixed,
    /// Each n squares to its best depth ([`Depth::Best`]).
    Best,
    /// Both, every algorithm in each.
    Both,
    /// The fixed depth first; the per-n depth only when no fixed-depth answer exists (the
    /// bypass multiplexers are paid for only where they are what reaches the budget).
    Auto,
}

impl DepthSearch {
    /// The per-n flags of the algorithms searched ([`Algorithm::all`]).
    pub fn per_n(self) -> &'static [bool] {
        match self {
            DepthSearch::Fixed => &[false],
            DepthSearch::Best => &[true],
            DepthSearch::Both | DepthSearch::Auto => &[false, true],
        }
    }

    /// The name `--depth` takes: `fixed`, `best`, `fixed,best` or `auto`.
    pub fn name(self) -> &'static str {
        match self {
            DepthSearch::Fixed => "fixed",
            DepthSearch::Best => "best",
            DepthSearch::Both => "fixed,best",
            DepthSearch::Auto => "auto",
        }
    }
}

impl std::str::FromStr for DepthSearch {
    type Err = String;

    /// `fixed`, `best`, `fixed,best` (either order) or `auto`.
    fn from_str(s: &str) -> Result<DepthSearch, String> {
        let mut items: Vec<&str> = s.split(',').map(str::trim).collect();
        items.sort_unstable();
        items.dedup();
        match items[..] {
            ["fixed"] => Ok(DepthSearch::Fixed),
            ["best"] => Ok(DepthSearch::Best),
            ["best", "fixed"] => Ok(DepthSearch::Both),
            ["auto"] => Ok(DepthSearch::Auto),
            _ => Err(format!(
                "expected fixed, best, fixed,best or auto, got '{}'",
                s.trim()
            )),
        }
    }
}

/// The depth rule of a choice: [`Depth::Best`] per n, [`Depth::Fixed`] otherwise.
fn depth_of_choice(per_n: bool) -> Depth {
    if per_n {
        Depth::Best
    } else {
        Depth::Fixed
    }
}

impl Algorithm {
    /// The depth rule the algorithm gives a configuration.
    pub fn depth(self) -> Depth {
        depth_of_choice(self.per_n)
    }

    /// Gives `cfg` the algorithm: k stages (each like its first), the variant and the depth
    /// rule.
    pub fn apply(self, cfg: &mut Config) {
        cfg.k = self.k;
        cfg.square = vec![cfg.square[0]; self.k as usize];
        cfg.variant = self.variant;
        cfg.depth = self.depth();
    }

    /// Every algorithm of `ks` x `variants` x `per_n`, in that order, less the per-n ones
    /// that would be their fixed twin (every exponent of `n` already at its best depth k).
    pub fn all(base: &Config, ks: &[u32], variants: &[Variant], per_n: &[bool]) -> Vec<Algorithm> {
        let mut v = Vec::new();
        for &k in ks {
            for &variant in variants {
                for &p in per_n {
                    let a = Algorithm {
                        k,
                        variant,
                        per_n: p,
                    };
                    let mut cfg = base.clone();
                    a.apply(&mut cfg);
                    if !p || cfg.has_bypass() {
                        v.push(a);
                    }
                }
            }
        }
        v
    }
}

impl Algorithm {
    /// Every algorithm of the library: plain and minimax, k = 1..7, fixed and per-n depth
    /// ([`Algorithm::all`], per-n ones left out where they would be their fixed twin).
    pub fn every(base: &Config) -> Vec<Algorithm> {
        let ks: Vec<u32> = crate::reference::lobe::K_RANGE.collect();
        Algorithm::all(
            base,
            &ks,
            &[Variant::Plain, Variant::Minimax],
            &[false, true],
        )
    }
}

impl fmt::Display for Algorithm {
    /// `k = 6 minimax`, or `k = 6 minimax, per-n depth`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "k = {} {}", self.k, self.variant.name())?;
        if self.per_n {
            f.write_str(", per-n depth")?;
        }
        Ok(())
    }
}

/// The f64 floor of an algorithm: max |f64 lobe - cos^n| over the input codes and the n set
/// (`shape_approx` of an exhaustive check of a wide configuration), which no fraction bits
/// remove.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AlgorithmFloor {
    /// The algorithm.
    pub algorithm: Algorithm,
    /// The floor, if the algorithm is valid for the base (else `reason`).
    pub shape_total: Option<f64>,
    /// The floor of `out_rel` (the algorithm's f64 lobe times its f64 coefficient against
    /// exact normalised cos^n, relative to coef(n)).
    pub norm_rel: Option<f64>,
    /// Why the algorithm is not valid for the base.
    pub reason: Option<String>,
    /// Whether the floors leave the budget reachable (`shape_total`, `out_rel` and
    /// `effective_bits` have floors; other metrics are always reachable).
    pub reachable: bool,
}

/// The floors of every algorithm ([`Algorithm::all`]), from `base` with the internal stages
/// at `start_frac` fraction bits.
pub fn algorithm_floors(
    base: &Config,
    budget: &Budget,
    algorithms: &[Algorithm],
    start_frac: i32,
) -> Vec<AlgorithmFloor> {
    use rayon::prelude::*;
    algorithms
        .par_iter()
        .map(|&algorithm| {
            let dp = start_of(base, algorithm, start_frac).and_then(Datapath::new);
            let figures = dp.and_then(|dp| check_outputs(&dp));
            match figures {
                Err(e) => AlgorithmFloor {
                    algorithm,
                    shape_total: None,
                    norm_rel: None,
                    reason: Some(e.to_string()),
                    reachable: false,
                },
                Ok(f) => AlgorithmFloor {
                    algorithm,
                    shape_total: Some(f.shape_approx_max_abs),
                    reason: None,
                    norm_rel: Some(f.norm_approx_rel),
                    reachable: budget.bounds.iter().all(|b| match b.metric {
                        Metric::ShapeTotal => f.shape_approx_max_abs <= b.limit,
                        Metric::OutRel => f.norm_approx_rel <= b.limit,
                        Metric::EffectiveBits => {
                            crate::analysis::check::effective_bits(f.norm_approx_rel) >= b.limit
                        }
                        _ => true,
                    }),
                },
            }
        })
        .collect()
}

/// The starting point of an algorithm: the base with the algorithm ([`Algorithm::apply`]),
/// every internal stage at `start_frac` fraction bits.
pub fn start_of(base: &Config, a: Algorithm, start_frac: i32) -> Result<Config, Error> {
    let mut cfg = base.clone();
    a.apply(&mut cfg);
    for s in searched_stages(a.k) {
        set_frac(&mut cfg, s, start_frac)?;
    }
    Ok(cfg)
}

/// The optimiser's search space for one algorithm: the internal stages; the coefficient's
/// fraction bits when the budget measures the output (`out`, `correct`: the shape metrics
/// measure the lobe before the coefficient, so they cannot constrain it); the output's
/// fraction bits when it measures correct rounding but not output LSBs (whose unit the output
/// format is); for minimax, the stored constants' fraction bits. TRN or RND everywhere as
/// starting points; every rounding and overflow mode in the local search.
pub fn optimize_space(a: Algorithm, budget: &Budget, start_frac: i32) -> Space {
    let has = |m: Metric| budget.bounds.iter().any(|b| b.metric == m);
    let mut extra_knobs = Vec::new();
    let out_lsbs = has(Metric::Out) || has(Metric::OutTotal);
    let output_side = out_lsbs || has(Metric::Correct) || has(Metric::OutRel);
    if output_side || has(Metric::EffectiveBits) {
        extra_knobs.push(Knob::CoefFrac);
    }
    if (has(Metric::Correct) || has(Metric::OutRel) || has(Metric::EffectiveBits)) && !out_lsbs {
        extra_knobs.push(Knob::Frac(Stage::Out));
    }
    if a.variant == Variant::Minimax {
        extra_knobs.extend([Knob::MinimaxSlopeFrac, Knob::MinimaxOffsetFrac]);
    }
    Space {
        choices: Choices {
            k: vec![a.k],
            variants: vec![a.variant],
            per_n: vec![a.per_n],
            roundings: vec![Rounding::Trn, Rounding::Rnd],
        },
        start_frac,
        extra_knobs,
        local_roundings: Rounding::ALL.to_vec(),
        overflow_moves: true,
        arch: budget.arch,
    }
}

/// The `cos^n` values a search keeps across its candidates ([`CosCache`]): 128 MiB at most
/// (the baseline's input format over n = 16..1024 needs about 18 MiB).
pub const COS_CACHE_VALUES: usize = 1 << 24;

/// The exhaustive judge of a budget, with a quick rejection: for budgets of maxima only, a
/// candidate is first checked on every 8th exponent (and the last); a subset's maximum never
/// exceeds the whole set's, so failing there is failing. `cos` keeps `cos^n` across the
/// candidates of a search (the same figures with or without it).
pub fn exhaustive_judge(
    dp: &Datapath,
    budget: &Budget,
    cos: Option<&CosCache>,
) -> Result<Verdict, Error> {
    // Cost ceilings are not judged here: the search minimises cost, so its answer is the
    // point most likely to meet them, and [`optimize_all`] checks them on it.
    let budget = &budget.without_costs();
    let maxima_only = budget.bounds.iter().all(|b| b.metric != Metric::Correct);
    let ns = dp.config().n.values();
    if maxima_only && ns.len() > 64 {
        let mut subset: Vec<u32> = ns.iter().step_by(8).copied().collect();
        if subset.last() != ns.last() {
            subset.push(*ns.last().expect("not empty"));
        }
        let mut cfg = dp.config().clone();
        cfg.n = crate::nset::NSet::from_values(&subset)?;
        let quick = check_outputs_cached(&Datapath::new(cfg)?, cos)?;
        if !budget.met_by(&quick, dp) {
            return Ok(Verdict {
                feasible: false,
                excess: budget.excess(&quick, dp),
            });
        }
    }
    let r = check_outputs_cached(dp, cos)?;
    Ok(Verdict {
        feasible: budget.met_by(&r, dp),
        excess: budget.excess(&r, dp),
    })
}

/// The searches of several algorithms as one: the cheapest answer (with its minimality), or
/// the closest point when none has one; every evaluation counted. Ties keep the earlier.
pub fn combine(results: Vec<SearchResult>) -> SearchResult {
    let mut out = SearchResult {
        best: None,
        closest: None,
        n_evaluations: 0,
        minimality: Vec::new(),
    };
    for r in results {
        out.n_evaluations += r.n_evaluations;
        if let Some(b) = r.best {
            if out.best.as_ref().is_none_or(|x| b.cost < x.cost) {
                out.best = Some(b);
                out.minimality = r.minimality;
            }
        } else if let Some(c) = r.closest {
            if out.closest.as_ref().is_none_or(|x| c.excess < x.excess) {
                out.closest = Some(c);
            }
        }
    }
    out
}

/// What [`optimize_all`] found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OptimizeAll {
    /// The budget.
    pub budget: Budget,
    /// Every algorithm's floor (searched only where reachable).
    pub floors: Vec<AlgorithmFloor>,
    /// The cheapest feasible configuration, if any.
    pub best: Option<Candidate>,
    /// The closest configuration (least excess) when none is feasible.
    pub closest: Option<Candidate>,
    /// Candidates judged (each exhaustively, or rejected on a subset of n).
    pub n_evaluations: u64,
    /// Why the answer is minimal within the search.
    pub minimality: Vec<String>,
    /// The device every answer had to fit, if any.
    pub device: Option<Device>,
}

/// The device an answer must fit, checked on the analytic figures of the datapath alone
/// (without its constant ROM) on the device's family ([`Target::Ice40`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct DeviceFit {
    /// The device.
    pub device: Device,
    /// Whether an algorithm whose pipelined answer does not fit is searched again in the
    /// folded architecture (one shared multiplier).
    pub fold_when_needed: bool,
}

impl DeviceFit {
    /// The resources a datapath in `arch` needs beyond the device's, one line each (empty
    /// when it fits).
    pub fn overflows(&self, dp: &Datapath, arch: Arch) -> Vec<String> {
        let f = analytic_cost(dp, arch, Target::Ice40);
        device_check(f.dsps, f.luts, f.ffs, self.device)
    }

    /// How far a datapath is from fitting: the largest ratio of a resource used to the
    /// device's (above 1 when it does not fit).
    fn excess(&self, dp: &Datapath, arch: Arch) -> f64 {
        let f = analytic_cost(dp, arch, Target::Ice40);
        let l = self.device.limits();
        [(f.dsps, l.dsps), (f.luts, l.luts), (f.ffs, l.ffs)]
            .into_iter()
            .map(|(used, available)| match (used, available) {
                (0, _) => 0.0,
                (_, 0) => f64::INFINITY,
                _ => used as f64 / available as f64,
            })
            .fold(0.0, f64::max)
    }
}

/// Searches every reachable algorithm (in parallel, results combined in the floors' order) for
/// the cheapest configuration meeting `budget`, costed by `cost` in the budget's architecture;
/// `done(algorithm, arch)` is called as each finishes, with the architecture of its pass. With
/// a device (`fit`), an answer that does not fit it is no answer (it becomes the closest point, and a line of the minimality); when
/// no algorithm's answer fits and `fit` allows it, the algorithms are searched again in the
/// folded architecture (one shared multiplier, an initiation interval of k + 2 cycles), whose
/// answers then compete. With [`DepthSearch::Auto`], the per-n algorithms among the floors are
/// searched (in the same way) only when no fixed-depth one has an answer.
#[allow(clippy::too_many_arguments)]
pub fn optimize_all(
    base: &Config,
    budget: &Budget,
    floors: Vec<AlgorithmFloor>,
    start_frac: i32,
    cost: &(dyn Fn(&Datapath, Arch) -> Result<f64, Error> + Sync),
    synth: Option<Synthesise>,
    fit: Option<DeviceFit>,
    depth: DepthSearch,
    done: &(dyn Fn(Algorithm, Arch, &SearchResult) + Sync),
) -> Result<OptimizeAll, Error> {
    use rayon::prelude::*;
    // Every algorithm's candidates share the input format: one cache of cos^n for all.
    let cos = CosCache::new(COS_CACHE_VALUES);
    // A candidate's error verdict does not depend on the architecture it is costed in: a
    // folded search after a pipelined one judges again only what the first did not.
    let verdicts = std::sync::Mutex::new(std::collections::HashMap::<String, Verdict>::new());
    let search_in = |a: Algorithm, arch: Arch| -> Result<SearchResult, Error> {
        let mut budget = budget.clone();
        budget.arch = arch;
        let space = optimize_space(a, &budget, start_frac);
        let mut judge = |dp: &Datapath| -> Result<Verdict, Error> {
            let key = dp.config().to_toml();
            if let Some(v) = verdicts.lock().expect("not poisoned").get(&key) {
                return Ok(*v);
            }
            let v = exhaustive_judge(dp, &budget, Some(&cos))?;
            verdicts.lock().expect("not poisoned").insert(key, v);
            Ok(v)
        };
        let mut cost = |dp: &Datapath| cost(dp, arch);
        let mut r = search(base, &space, &mut judge, &mut cost, &mut |_| {})?;
        // The cheapest point meeting the error bounds must meet the cost ceilings too.
        if let Some(b) = r.best.take() {
            let v = budget.cost_verdict(&Datapath::new(b.config.clone())?, synth)?;
            if v.feasible {
                r.best = Some(b);
            } else {
                r.closest = Some(Candidate {
                    feasible: false,
                    excess: v.excess,
                    ..b
                });
            }
        }
        Ok(r)
    };
    // Every reachable algorithm in the budget's architecture; with a device, an answer that
    // does not fit becomes the closest point.
    let phase = |algorithms: &[Algorithm],
                 arch: Arch|
     -> Result<Vec<(SearchResult, Option<String>)>, Error> {
        algorithms
            .par_iter()
            .map(|&a| {
                let mut r = search_in(a, arch)?;
                let mut note = None;
                if let (Some(fit), Some(b)) = (fit, r.best.clone()) {
                    let dp = Datapath::new(b.config.clone())?;
                    let over = fit.overflows(&dp, b.arch);
                    if !over.is_empty() {
                        note = Some(format!("{a}, {}: {}", b.arch, over.join(", ")));
                        r.closest = Some(Candidate {
                            feasible: false,
                            excess: fit.excess(&dp, b.arch),
                            ..b
                        });
                        r.best = None;
                    }
                }
                done(a, arch, &r);
                Ok((r, note))
            })
            .collect()
    };
    // One group of algorithms in the budget's architecture; when no answer fits, the folded
    // architecture (one shared multiplier) for the algorithms whose answers did not.
    let group = |reachable: &[Algorithm]| -> Result<Vec<(SearchResult, Option<String>)>, Error> {
        let mut results = phase(reachable, budget.arch)?;
        if fit.is_some_and(|f| f.fold_when_needed) && budget.arch == Arch::Pipelined {
            let unfit: Vec<Algorithm> = reachable
                .iter()
                .zip(&results)
                .filter(|(_, (_, note))| note.is_some())
                .map(|(&a, _)| a)
                .collect();
            if results.iter().all(|(r, _)| r.best.is_none()) && !unfit.is_empty() {
                results.extend(phase(&unfit, Arch::Folded)?);
            }
        }
        Ok(results)
    };
    let reachable = |per_n: &[bool]| -> Vec<Algorithm> {
        floors
            .iter()
            .filter(|f| f.reachable && per_n.contains(&f.algorithm.per_n))
            .map(|f| f.algorithm)
            .collect()
    };
    let mut results = if depth == DepthSearch::Auto {
        group(&reachable(&[false]))?
    } else {
        group(&reachable(&[false, true]))?
    };
    if depth == DepthSearch::Auto && results.iter().all(|(r, _)| r.best.is_none()) {
        results.extend(group(&reachable(&[true]))?);
    }
    let notes: Vec<String> = results.iter().filter_map(|(_, n)| n.clone()).collect();
    let results: Vec<SearchResult> = results.into_iter().map(|(r, _)| r).collect();
    let mut out = OptimizeAll {
        budget: budget.clone(),
        floors: Vec::new(),
        best: None,
        closest: None,
        n_evaluations: 0,
        minimality: Vec::new(),
        device: None,
    };
    let combined = combine(results);
    out.best = combined.best;
    out.closest = combined.closest;
    out.n_evaluations = combined.n_evaluations;
    out.minimality = combined.minimality;
    let skipped: Vec<String> = floors
        .iter()
        .filter(|f| !f.reachable)
        .map(|f| f.algorithm.to_string())
        .collect();
    if out.best.is_some() && !skipped.is_empty() {
        out.minimality.insert(
            0,
            format!(
                "not searched, their f64 floor (the algorithm's own error against cos^n, before any quantization) already breaks the budget or they are not valid: {}",
                skipped.join(", ")
            ),
        );
    }
    if let Some(fit) = fit {
        let mut lines = vec![format!(
            "device: every answer must fit the {} (analytic figures of the datapath, its constant ROM aside)",
            fit.device.full_name()
        )];
        lines.extend(notes.into_iter().map(|n| format!("  does not fit: {n}")));
        for (i, l) in lines.into_iter().enumerate() {
            out.minimality.insert(i, l);
        }
    }
    out.floors = floors;
    out.device = fit.map(|f| f.device);
    Ok(out)
}

/// The closest configuration searched when none meets the budget, with its check's figures
/// and the value of each of the budget's cost ceilings.
#[derive(Debug, Clone)]
pub struct Closest {
    /// The configuration and how far it is from the budget.
    pub candidate: Candidate,
    /// Its lobe error against cos^n.
    pub shape_total: f64,
    /// Its quantization error.
    pub shape_quant: f64,
    /// Its output error in ulp.
    pub out_ulp: f64,
    /// The fraction of its outputs correctly rounded.
    pub correctly_rounded: f64,
    /// Each cost ceiling of the budget with its value ([`Budget::cost_values`]).
    pub costs: Vec<(Bound, f64)>,
}

/// [`Closest`] for the result's closest configuration, if it has one: checked exhaustively,
/// its cost ceilings valued (yosys's through `synth`).
pub fn closest(r: &OptimizeAll, synth: Option<Synthesise>) -> Result<Option<Closest>, Error> {
    let Some(c) = &r.closest else {
        return Ok(None);
    };
    let dp = Datapath::new(c.config.clone())?;
    let chk = crate::analysis::check::check(&dp)?;
    Ok(Some(Closest {
        candidate: c.clone(),
        shape_total: chk.shape_total_max_abs,
        shape_quant: chk.shape_quant_max_abs,
        out_ulp: chk.out_max_ulp,
        correctly_rounded: chk.stages[dp.stage_out()].correctly_rounded,
        costs: r.budget.cost_values(&dp, synth)?,
    }))
}

/// How many syntheses with yosys [`Request::run`] runs between two lines of progress.
const SYNTHESES_PER_LINE: u64 = 10;

/// A device limit as `--device` takes it: a device every answer must fit, or `none` (no
/// limit). A type of its own, because clap reads `Option<Option<T>>` as a flag whose value may
/// be left out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DeviceLimit(pub Option<Device>);

impl std::str::FromStr for DeviceLimit {
    type Err = String;

    fn from_str(s: &str) -> Result<DeviceLimit, String> {
        match s.trim() {
            "none" => Ok(DeviceLimit(None)),
            other => other
                .parse::<Device>()
                .map(|d| DeviceLimit(Some(d)))
                .map_err(|e| format!("{e}, or none to lift the limit")),
        }
    }
}

/// What `specfx optimize` is asked, end to end: the search's settings as a face hands them
/// over. [`Request::run`] resolves the device and the architecture, searches every algorithm
/// whose floor can meet the budget, and proves the answer.
#[derive(Debug, Clone)]
pub struct Request {
    /// The base configuration (its exponents already the ones to serve).
    pub base: Config,
    /// The budget.
    pub budget: Budget,
    /// The numbers of squarings to try.
    pub k: Vec<u32>,
    /// The variants to try.
    pub variants: Vec<Variant>,
    /// The squaring depths to try.
    pub depth: DepthSearch,
    /// Fraction bits every searched stage starts from.
    pub start_frac: i32,
    /// The cost minimised.
    pub objective: Objective,
    /// The target whose logic cells are minimised.
    pub target: Target,
    /// The microarchitecture asked for, if any (else the base's `arch`, else chosen).
    pub arch: Option<Arch>,
    /// The device every answer must fit: `Some(None)` for none, `None` for the target's own
    /// (the iCE40 UP5K on ice40, none elsewhere).
    pub device: Option<Option<Device>>,
}

/// An answer, proven: the exhaustive check of the cheapest configuration against the budget,
/// in the architecture it was costed in, and what a summary sets beside it.
#[derive(Debug)]
pub struct Proven {
    /// The answer's configuration, named `optimized`, recording its architecture (`arch`).
    pub config: Config,
    /// Its datapath.
    pub dp: Datapath,
    /// Its exhaustive check.
    pub proof: CheckReport,
    /// The microarchitecture it was costed in.
    pub arch: Arch,
    /// Each yosys ceiling of the budget with the answer's yosys figures on its target.
    pub yosys: Vec<(Bound, CostFigures)>,
    /// The paper's datapath (baseline: plain, k = 4) serving the same exponents, and its
    /// output figures.
    pub paper: (Datapath, OutputFigures),
}

/// What a [`Request`] found.
#[derive(Debug)]
pub struct Outcome {
    /// The search.
    pub result: OptimizeAll,
    /// The proven answer, when a configuration meets the budget (and fits).
    pub proven: Option<Proven>,
    /// Otherwise the closest configuration, when the search found one.
    pub closest: Option<Closest>,
}

impl Request {
    /// The microarchitecture asked for: the request's, else the base configuration's own (an
    /// earlier answer's); `None` lets the search fold where pipelined does not fit.
    pub fn chosen_arch(&self) -> Option<Arch> {
        self.arch.or(self.base.arch)
    }

    /// The device every answer must fit. Refused: a device on another target than ice40 (the
    /// devices are iCE40s), and a device without DSP blocks (the analytic iCE40 model maps
    /// every multiplier to one, so nothing could fit it).
    pub fn device(&self) -> Result<Option<Device>, Error> {
        let target = self.target;
        let device = match self.device {
            Some(d) => d,
            None => (target == Target::Ice40).then_some(Device::Up5k),
        };
        let refused = |problem: String| Error::Config {
            key: "--device".into(),
            problem,
        };
        if device.is_some() && target != Target::Ice40 {
            return Err(refused(format!(
                "the devices are iCE40s, costed on --target ice40 (got --target {}); give --device none to cost on {} without a device",
                target.name(),
                target.name()
            )));
        }
        if let Some(d) = device.filter(|d| d.limits().dsps == 0) {
            return Err(Error::Config {
                key: format!("--device {}", d.name()),
                problem: format!(
                    "the {} has no DSP blocks, and the analytic iCE40 model maps every multiplier to one, so no datapath can fit it; give --device up5k, or none to lift the limit",
                    d.full_name()
                ),
            });
        }
        Ok(device)
    }

    /// The unit the objective is counted in: `LUT-equivalents on ice40 (LUTs + 260 per DSP
    /// block)`, `gates on generic`.
    pub fn unit(&self) -> String {
        let target = self.target;
        match crate::hdl::cost::dsp_weight(target) {
            w if w > 0.0 => format!(
                "{}-equivalents on {} ({} + {w:.0} per DSP block)",
                target.logic_unit().trim_end_matches('s'),
                target.name(),
                target.logic_unit()
            ),
            _ => format!("{} on {}", target.logic_unit(), target.name()),
        }
    }

    /// What an answer records of the request: its canonical inputs (`inputs.toml`, the
    /// comment of the configuration `specfx optimize` writes).
    pub fn inputs(&self) -> Result<crate::provenance::Inputs, Error> {
        let mut variants: Vec<&str> = self.variants.iter().map(|v| v.name()).collect();
        variants.sort_unstable();
        variants.dedup();
        let k = crate::nset::NSet::from_values(&self.k).map_err(|e| Error::Config {
            key: "--k".into(),
            problem: e.to_string(),
        })?;
        Ok(crate::provenance::Inputs::new("optimize")
            .config(&self.base)
            .option("budget", self.budget.canonical())
            .option("objective", self.objective.name())
            .option("target", self.target.name())
            .option("k", k.to_string())
            .option("variants", variants)
            .option("start_frac", self.start_frac)
            .option("depth", self.depth.name())
            .option(
                "arch",
                self.chosen_arch()
                    .map_or("auto".to_string(), |a| a.to_string()),
            )
            .option("device", self.device()?.map_or("none", |d| d.name())))
    }

    /// The algorithms searched: every k, variant and depth asked for.
    pub fn algorithms(&self) -> Vec<Algorithm> {
        Algorithm::all(&self.base, &self.k, &self.variants, self.depth.per_n())
    }

    /// Searches and proves: the f64 floor of every algorithm (`floors` hears them before the
    /// search), the search of those that can meet the budget (`done` hears each algorithm's
    /// result, from the worker threads, after its line of progress in the log), then the answer's exhaustive check in its
    /// architecture, its yosys figures for the budget's yosys ceilings, and the paper's
    /// datapath beside it. `synth` runs yosys (the library starts no process): the objective
    /// `yosys` and the yosys ceilings call it.
    ///
    /// # Errors
    /// The device's refusals ([`Request::device`]), a synthesis that fails, and an answer that
    /// does not meet the budget on its re-check (a bug).
    pub fn run(
        &self,
        synth: Synthesise,
        floors_found: &dyn Fn(&[AlgorithmFloor]),
        done: &(dyn Fn(Algorithm, Arch, &SearchResult) + Sync),
    ) -> Result<Outcome, Error> {
        let device = self.device()?;
        let fit = device.map(|device| DeviceFit {
            device,
            fold_when_needed: self.chosen_arch().is_none(),
        });
        // Each synthesis takes seconds to minutes and a search runs many: a line at the first
        // and at every tenth, since nothing else would show for minutes off a terminal.
        let syntheses = std::sync::atomic::AtomicU64::new(0);
        let counted = |dp: &Datapath, arch: Arch, target: Target| {
            let so_far = syntheses.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            if so_far == 0 {
                log::info!(
                    "optimize: synthesising with yosys on {} (seconds to minutes each, cached ones at once; a line every {SYNTHESES_PER_LINE})",
                    target.name()
                );
            } else if so_far.is_multiple_of(SYNTHESES_PER_LINE) {
                log::info!("optimize: {so_far} syntheses with yosys so far");
            }
            synth(dp, arch, target)
        };
        let synth: Synthesise = &counted;
        // A line per algorithm searched: its cheapest cost, or that nothing met the budget.
        let unit = self.unit();
        let no_answer = match device {
            Some(d) => format!("nothing meets the budget and fits the {}", d.full_name()),
            None => "nothing meets the budget".to_string(),
        };
        let done = |a: Algorithm, arch: Arch, r: &SearchResult| {
            let found = r.best.as_ref().map_or(no_answer.clone(), |b| {
                format!("{:.0} {unit} ({})", b.cost, self.objective)
            });
            log::info!("optimize: {a}, {arch}: {found}");
            done(a, arch, r);
        };
        let target = self.target;
        let objective = self.objective;
        let cost = |dp: &Datapath, arch: Arch| -> Result<f64, Error> {
            match objective {
                Objective::Yosys => synth(dp, arch, target).map(|f| objective_value(&f)),
                Objective::Analytic => Ok(objective_value(
                    &crate::hdl::cost::analytic_cost(dp, arch, target).figures(),
                )),
            }
        };
        let mut budget = self.budget.clone();
        budget.arch = self.base.resolve_arch(self.arch);
        let floors = algorithm_floors(&self.base, &budget, &self.algorithms(), self.start_frac);
        floors_found(&floors);
        let result = optimize_all(
            &self.base,
            &budget,
            floors,
            self.start_frac,
            &cost,
            Some(synth),
            fit,
            self.depth,
            &done,
        )?;
        let Some(best) = &result.best else {
            let closest = closest(&result, Some(synth))?;
            return Ok(Outcome {
                result,
                proven: None,
                closest,
            });
        };
        // The proof: the exhaustive check of the answer, against the budget, in the answer's
        // architecture.
        let arch = best.arch;
        let mut budget = result.budget.clone();
        budget.arch = arch;
        let mut config = best.config.clone();
        config.name = "optimized".into();
        // The answer records the microarchitecture it was costed with: cost, timing, sim,
        // hdl, vectors and cosim read it as their default.
        config.arch = Some(arch);
        let dp = Datapath::new(config.clone())?;
        let proof = crate::analysis::check::check(&dp)?;
        if !budget.met_by(&proof.output_figures(), &dp)
            || !budget.cost_verdict(&dp, Some(synth))?.feasible
            || fit.is_some_and(|f| !f.overflows(&dp, arch).is_empty())
        {
            return Err(Error::Output {
                message:
                    "the configuration found does not meet the budget on re-check: this is a bug"
                        .into(),
            });
        }
        let mut yosys = Vec::new();
        for b in result.budget.bounds.iter().filter(|b| b.metric.is_yosys()) {
            let (Metric::YosysLuts(t) | Metric::YosysDsps(t) | Metric::YosysFfs(t)) = b.metric
            else {
                continue;
            };
            yosys.push((*b, synth(&dp, arch, t)?));
        }
        // The answer's cost on every target, beside the paper's datapath serving the same
        // exponents.
        let mut paper_cfg = Config::baseline();
        paper_cfg.n = config.n.clone();
        let paper = Datapath::new(paper_cfg)?;
        let paper_check = crate::analysis::check::check_outputs(&paper)?;
        Ok(Outcome {
            result,
            proven: Some(Proven {
                config,
                dp,
                proof,
                arch,
                yosys,
                paper: (paper, paper_check),
            }),
            closest: None,
        })
    }
}
