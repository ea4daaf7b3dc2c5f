//! Speed against accuracy: every method of computing the specular lobe, its error against
//! cos^n, its software speed measured in the same run, and its hardware cost.

use serde::Serialize;

use crate::cycle::Arch;
use crate::engine::{fold_n, Codes};
use crate::error::Error;
use crate::hdl::cost::{analytic_cost, figures_on_targets, CostFigures, Target};
use crate::nset::NSet;
use crate::pipeline::{Config, Datapath, ProbeColumns};
use crate::reference::lobe::{cos_pow, Cutoff};
use crate::reference::method::Method;
use crate::reference::minimax::sup_abs_error;

/// Measures how long a piece of work takes, in seconds: the caller's clock (the library has
/// none, so that everything it computes is deterministic).
pub type Timer<'a> = &'a mut dyn FnMut(&mut dyn FnMut()) -> f64;

/// A datapath's yosys figures, from the caller (the library runs no tool itself).
pub type Synthesise<'a> = &'a dyn Fn(&Datapath) -> Result<YosysFigures, Error>;

/// One method's figures.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MethodFigures {
    /// The method's name.
    pub method: String,
    /// `f64` (software reference models) or `fixed` (a bit-accurate datapath).
    pub kind: &'static str,
    /// max over n and c of |method - cos^n|.
    pub max_abs_err: f64,
    /// Mean over n and over the c grid of |method - cos^n|.
    pub mean_abs_err: f64,
    /// Software evaluations per second, single thread, measured in this run. A measurement of
    /// this machine, not a property of the method: it is kept out of the JSON (and of every file
    /// but `measured_speed.csv` and the `measured_speed_accuracy` chart), so that the other
    /// outputs are byte-identical from run to run.
    #[serde(skip)]
    pub evals_per_s: f64,
    /// Multipliers of a hardware implementation (None: needs a divider, exp or log unit).
    pub multipliers: Option<u32>,
    /// Analytic cost of the pipelined datapath on every reported target (fixed-point methods
    /// only): the same figures `specfx cost --analytic-only` prints.
    pub costs: Vec<CostFigures>,
    /// yosys figures of the pipelined datapath (fixed-point methods, with `--yosys`): the
    /// target, LUTs (logic gates for generic), DSP blocks and flip-flops.
    pub yosys: Option<YosysFigures>,
    /// Latency in cycles at initiation interval 1 (pipelined, one register per operation).
    pub latency: Option<u64>,
    /// max over c of the error, for each n of the set.
    pub per_n_max_abs_err: Vec<f64>,
}

/// yosys figures of one datapath.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct YosysFigures {
    /// The synthesis target (`ice40`, `xilinx`, `generic`, `generic-fast`).
    pub target: String,
    /// LUTs (logic gates for the generic targets).
    pub luts: u64,
    /// DSP blocks.
    pub dsps: u64,
    /// Flip-flops.
    pub ffs: u64,
}

/// The f64 methods compared: powf, repeated-squaring powi, Schlick, exp(-n(1-c)), cs_m with
/// every cutoff for k = 2..7, minimax for k = 2..7, and minimax with a per-n depth (each n at
/// its best m(n) <= 2^k) for k = 5..7.
pub fn f64_methods() -> Vec<(String, Method)> {
    let mut v = vec![
        ("powf".to_string(), Method::CosPow),
        ("schlick".to_string(), Method::Schlick),
        ("exp_limit".to_string(), Method::ExpLimit),
    ];
    for k in 2..=crate::reference::lobe::K_MAX {
        for cutoff in Cutoff::ALL {
            let m = Method::CsM { k, cutoff };
            v.push((m.name(), m));
        }
        let m = Method::Minimax { k };
        v.push((m.name(), m));
    }
    for k in 5..=crate::reference::lobe::K_MAX {
        let m = Method::MinimaxPerN { k };
        v.push((m.name(), m));
    }
    v
}

/// The c grid of the mean error and of the speed measurement: 4097 points on [0, 1].
fn grid() -> Vec<f64> {
    (0..=4096).map(|i| f64::from(i) / 4096.0).collect()
}

/// cos^n of `c`, 0 at and below 0: the one rule ([`cos_pow`]).
fn cos_n(c: f64, n: u32) -> f64 {
    cos_pow(c, f64::from(n))
}

/// Figures of an f64 method over the exponents `ns`; `time` measures its speed.
pub fn f64_figures(name: &str, method: Method, ns: &[u32], time: Timer) -> MethodFigures {
    let cs = grid();
    let mut sum = 0.0;
    let mut per_n = Vec::with_capacity(ns.len());
    for &n in ns {
        for &c in &cs {
            sum += (method.eval(c, n) - cos_n(c, n)).abs();
        }
        per_n.push(sup_abs_error(n, 0.0, |c| method.eval(c, n)).0);
    }
    // Speed: one pass over the grid for every n, timed; "powi" is measured as repeated
    // squaring on integer n.
    let secs = time(&mut || {
        let mut sink = 0.0;
        for &n in ns {
            for &c in &cs {
                sink += method.eval(std::hint::black_box(c), n);
            }
        }
        std::hint::black_box(sink);
    })
    .max(1e-9);
    let (multipliers, latency) = match method {
        Method::CsM { k, .. } | Method::Minimax { k } | Method::MinimaxPerN { k } => {
            (Some(k + 2), Some(u64::from(k) + 4))
        }
        _ => (None, None),
    };
    MethodFigures {
        method: name.to_string(),
        kind: "f64",
        max_abs_err: per_n.iter().copied().fold(0.0, f64::max),
        mean_abs_err: sum / (ns.len() * cs.len()) as f64,
        evals_per_s: (ns.len() * cs.len()) as f64 / secs,
        multipliers,
        costs: Vec::new(),
        yosys: None,
        latency,
        per_n_max_abs_err: per_n,
    }
}

/// Figures of `c.powi(n)` (repeated squaring in f64), which [`Method`] does not name; `time`
/// measures its speed.
pub fn powi_figures(ns: &[u32], time: Timer) -> MethodFigures {
    let cs = grid();
    let eval = |c: f64, n: u32| c.powi(n as i32);
    let mut sum = 0.0;
    let mut per_n = Vec::new();
    for &n in ns {
        for &c in &cs {
            sum += (eval(c, n) - cos_n(c, n)).abs();
        }
        per_n.push(sup_abs_error(n, 0.0, |c| eval(c, n)).0);
    }
    let secs = time(&mut || {
        let mut sink = 0.0;
        for &n in ns {
            for &c in &cs {
                sink += eval(std::hint::black_box(c), n);
            }
        }
        std::hint::black_box(sink);
    })
    .max(1e-9);
    MethodFigures {
        method: "powi".into(),
        kind: "f64",
        max_abs_err: per_n.iter().copied().fold(0.0, f64::max),
        mean_abs_err: sum / (ns.len() * cs.len()) as f64,
        evals_per_s: (ns.len() * cs.len()) as f64 / secs,
        multipliers: None,
        costs: Vec::new(),
        yosys: None,
        latency: None,
        per_n_max_abs_err: per_n,
    }
}

/// Baseline with every squaring (and b) at `frac` fraction bits: the fixed-point points.
pub fn fixed_config(frac: i32) -> Config {
    let mut cfg = Config::baseline();
    cfg.name = format!("fixed_sq{frac}");
    let fmt = crate::fixed::Format::unsigned(1, frac).expect("u1.F");
    cfg.b.format = fmt;
    for s in &mut cfg.square {
        s.format = fmt;
    }
    cfg
}

/// The minimax datapath with `k` squarings in the trade-off: baseline's widths, u1.16 squares.
pub fn fixed_minimax_config(k: u32) -> Config {
    let mut cfg = Config::baseline();
    cfg.name = format!("fixed_mm{k}");
    cfg.variant = crate::pipeline::Variant::Minimax;
    cfg.k = k;
    cfg.square = vec![cfg.square[0]; k as usize];
    cfg
}

/// Figures of a fixed-point datapath: its lobe (before the coefficient) against cos^n on the
/// input codes of the grid, the batch evaluation speed (measured by `time`), and its analytic
/// cost.
pub fn fixed_figures(dp: &Datapath, time: Timer) -> MethodFigures {
    let one = dp.one_code();
    let step = (one / 4096).max(1);
    let codes: Vec<i64> = (0..=one).step_by(step as usize).collect();
    let lsb_c = dp.config().c.format.lsb();
    let last = dp.stage_last_square();
    let lsb_s = dp.stages()[last].format.lsb();
    // One pass of the engine's stream over every code: the maximum error of each n, and the
    // errors on the grid's codes (every step-th), summed afterwards in n and code order.
    let all_codes = Codes::new(dp, (0..=one).collect());
    let per_n_figures = fold_n(
        dp,
        &all_codes,
        |_| (0.0f64, Vec::with_capacity(codes.len())),
        |(max, grid), chunk| {
            for (i, &k) in chunk.codes.iter().enumerate() {
                let lobe = chunk.probes.values[last][i] as f64 * lsb_s;
                let err = (lobe - cos_n(k as f64 * lsb_c, chunk.nc.n)).abs();
                *max = max.max(err);
                if k % step == 0 {
                    grid.push(err);
                }
            }
        },
        &|| {},
    );
    let sum = per_n_figures.iter().flat_map(|(_, grid)| grid).sum::<f64>();
    let per_n: Vec<f64> = per_n_figures.iter().map(|&(max, _)| max).collect();
    let mut cols = ProbeColumns::default();
    let secs = time(&mut || {
        for nc in dp.constants() {
            dp.eval_batch(nc, std::hint::black_box(&codes), &mut cols);
        }
    })
    .max(1e-9);
    let cost = analytic_cost(dp, Arch::Pipelined, Target::Ice40);
    MethodFigures {
        method: dp.config().name.clone(),
        kind: "fixed",
        max_abs_err: per_n.iter().copied().fold(0.0, f64::max),
        mean_abs_err: sum / (dp.constants().len() * codes.len()) as f64,
        evals_per_s: (dp.constants().len() * codes.len()) as f64 / secs,
        multipliers: Some(dp.config().k + 2),
        costs: figures_on_targets(dp, Arch::Pipelined),
        yosys: None,
        latency: Some(cost.latency),
        per_n_max_abs_err: per_n,
    }
}
/// The fixed-point datapaths compared: cs16 with 8, 12 and 16 fraction bits, and minimax for
/// k = 3..=6.
pub fn fixed_configs() -> Vec<Config> {
    [8, 12, 16]
        .into_iter()
        .map(fixed_config)
        .chain((3..=6).map(fixed_minimax_config))
        .collect()
}

/// How many methods [`tradeoff`] measures: its progress runs to this.
pub fn method_count() -> usize {
    f64_methods().len() + 1 + fixed_configs().len()
}

/// Every method's figures over `ns`, in the table's order (powf, powi, the other f64
/// methods, the fixed-point datapaths), timed on `time`. `synthesise` gives a datapath's yosys
/// figures (none without it); `progress` is told each method's name and how many are done
/// as it starts.
pub fn tradeoff(
    ns: &NSet,
    time: Timer,
    synthesise: Option<Synthesise>,
    progress: &dyn Fn(&str, usize),
) -> Result<Vec<MethodFigures>, Error> {
    let ns_v = ns.values();
    let mut figures = Vec::new();
    for (name, method) in f64_methods() {
        progress(&name, figures.len());
        figures.push(f64_figures(&name, method, ns_v, time));
    }
    progress("powi", figures.len());
    figures.insert(1, powi_figures(ns_v, time));
    for mut cfg in fixed_configs() {
        cfg.n = ns.clone();
        let dp = Datapath::new(cfg)?;
        progress(&dp.config().name, figures.len());
        let mut f = fixed_figures(&dp, time);
        if let Some(synthesise) = synthesise {
            f.yosys = Some(synthesise(&dp)?);
        }
        figures.push(f);
    }
    Ok(figures)
}

/// What determines a trade-off, for its provenance: the exponents, the frontier's budgets
/// (lsb8; empty: no frontier) and the yosys target.
pub fn inputs(ns: &NSet, yosys: Option<Target>, ladder_lsb8: &[f64]) -> crate::provenance::Inputs {
    let inputs = crate::provenance::Inputs::new("tradeoff")
        .option("n", crate::provenance::canonical_nset(ns))
        .option("ladder", ladder_lsb8.to_vec());
    match yosys {
        Some(target) => inputs.option("yosys", target.name()),
        None => inputs,
    }
}
