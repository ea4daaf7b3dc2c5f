//! The optimiser's text: its answer (the proof, the comparison with the paper's datapath, why
//! it is minimal) or why nothing meets a budget (every algorithm's floor, the closest
//! algorithm and configuration searched).

use std::io::Write;

use crate::analysis::budget_expr::Bound;
use crate::analysis::check::{CheckReport, OutputFigures};
use crate::analysis::optimize::{Candidate, Closest, Objective, OptimizeAll, Outcome};
use crate::cycle::Arch;
use crate::hdl::cost::{analytic_cost, AnalyticCost, CostFigures, REPORTED_TARGETS};
use crate::pipeline::Datapath;
use crate::provenance::Provenance;
use crate::report::table::{Align, TextTable};

/// Why nothing meets the budget: every algorithm's f64 floor (a table fitted into `width`),
/// the closest algorithm and what would meet the budget, and the closest configuration
/// searched with its figures and cost ceilings.
pub fn write_no_answer(
    w: &mut impl Write,
    r: &OptimizeAll,
    closest: Option<&Closest>,
    width: Option<u16>,
) -> std::io::Result<()> {
    writeln!(w, "no configuration in the space meets the budget")?;
    writeln!(
        w,
        "the f64 floor of each algorithm (its own error against cos^n before any quantization):"
    )?;
    let normalised = r.budget.bounds.iter().any(|b| b.metric.is_normalised());
    let mut columns = vec![
        ("k", Align::Right),
        ("variant", Align::Left),
        ("depth", Align::Left),
        ("shape_total floor", Align::Right),
        ("lsb8", Align::Right),
    ];
    if normalised {
        columns.extend([
            ("out_rel floor", Align::Right),
            ("effective bits", Align::Right),
        ]);
    }
    columns.push(("", Align::Left));
    let mut table = TextTable::new(&columns).indent(2);
    for f in &r.floors {
        let a = f.algorithm;
        let mut row = vec![
            a.k.to_string(),
            a.variant.name().to_string(),
            a.depth().name().to_string(),
        ];
        match (f.shape_total, &f.reason) {
            (Some(x), _) => {
                row.push(format!("{x:.3e}"));
                row.push(format!("{:.2}", x / crate::analysis::LSB8));
                if normalised {
                    match f.norm_rel {
                        Some(r) => {
                            row.push(format!("{r:.3e}"));
                            row.push(format!("{:.1}", crate::analysis::check::effective_bits(r)));
                        }
                        None => row.extend(["-".to_string(), "-".to_string()]),
                    }
                }
                row.push(if f.reachable { "" } else { "beyond the budget" }.to_string());
            }
            (None, reason) => {
                row.extend(["-".to_string(), "-".to_string()]);
                if normalised {
                    row.extend(["-".to_string(), "-".to_string()]);
                }
                row.push(format!("not valid: {}", reason.as_deref().unwrap_or("")));
            }
        }
        table.row(row);
    }
    table.write(w, width)?;
    if let Some(f) = r
        .floors
        .iter()
        .filter(|f| f.shape_total.is_some())
        .min_by(|a, b| a.shape_total.unwrap().total_cmp(&b.shape_total.unwrap()))
    {
        writeln!(
            w,
            "closest algorithm: {}, whose f64 floor is {:.3e} ({:.2} lsb8); what would meet the budget: a shape_total limit above that floor (quantization adds to it), or fewer exponents (--n: the floors fall when every n is at least m = 2^k)",
            f.algorithm,
            f.shape_total.unwrap(),
            f.shape_total.unwrap() / crate::analysis::LSB8
        )?;
    }
    if let Some(c) = closest {
        writeln!(
            w,
            "closest: k = {}, {}: shape_total {:.3e}, shape_quant {:.3e}, out {:.2} ulp, {:.2}% correct ({:.2}x the budget)",
            c.candidate.config.k,
            c.candidate.config.variant.name(),
            c.shape_total,
            c.shape_quant,
            c.out_ulp,
            100.0 * c.correctly_rounded,
            c.candidate.excess
        )?;
        for (b, value) in &c.costs {
            let kind = if b.metric.is_yosys() { "" } else { "analytic " };
            writeln!(w, "  its {kind}{}: {value} (limit {})", b.metric, b.limit)?;
        }
    }
    Ok(())
}

/// What `optimize` found and proved, for [`write_answer`] and [`answer_file`].
pub struct Answer<'a> {
    /// The search.
    pub result: &'a OptimizeAll,
    /// Its cheapest feasible point.
    pub best: &'a Candidate,
    /// The answer's datapath (its configuration named `optimized`).
    pub dp: &'a Datapath,
    /// The answer's exhaustive check.
    pub proof: &'a CheckReport,
    /// What was minimised, and in which unit (`LUTs on ice40`).
    pub objective: Objective,
    /// The cost's unit (`LUTs on ice40`).
    pub unit: &'a str,
    /// The microarchitecture costed.
    pub arch: Arch,
    /// The paper's datapath serving the same exponents, and its output figures.
    pub paper: (&'a Datapath, &'a OutputFigures),
    /// Each yosys ceiling of the budget with the answer's yosys figures on its target.
    pub yosys: &'a [(Bound, CostFigures)],
}

impl<'a> Answer<'a> {
    /// The answer of a search, when it found one (and proved it): `None` when nothing met
    /// the budget. `unit` is the cost's ([`Request::unit`](crate::analysis::optimize::Request::unit)).
    pub fn of(found: &'a Outcome, objective: Objective, unit: &'a str) -> Option<Answer<'a>> {
        let (best, proven) = (found.result.best.as_ref()?, found.proven.as_ref()?);
        Some(Answer {
            result: &found.result,
            best,
            dp: &proven.dp,
            proof: &proven.proof,
            objective,
            unit,
            arch: proven.arch,
            paper: (&proven.paper.0, &proven.paper.1),
            yosys: &proven.yosys,
        })
    }
}

/// The configuration file `optimize` writes: [`answer_header`] after `first` (the file's own
/// header, `# specfx optimize:`), the provenance as comments, then the answer's TOML.
pub fn answer_file(first: &str, a: &Answer<'_>, provenance: &Provenance) -> String {
    format!(
        "{}{}{}",
        answer_header(first, a),
        provenance.comment(),
        a.dp.config().to_toml()
    )
}

/// The depths of a per-n datapath as ranges of n: `m = 16 for n = 16..=21, m = 32 for ...`.
pub fn depth_text(dp: &Datapath) -> String {
    let mut runs: Vec<(u32, u32, u32)> = Vec::new();
    for nc in dp.constants() {
        match runs.last_mut() {
            Some((j, _, last)) if *j == nc.depth => *last = nc.n,
            _ => runs.push((nc.depth, nc.n, nc.n)),
        }
    }
    runs.iter()
        .map(|(j, first, last)| {
            let ns = if first == last {
                first.to_string()
            } else {
                format!("{first}..={last}")
            };
            format!("m = {} for n = {ns}", 1u32 << j)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The comment lines the configuration file `optimize` writes begins with: the budget, the
/// cost and the proof, each line after `first` (the file's own header, `# specfx optimize:`).
pub fn answer_header(first: &str, a: &Answer<'_>) -> String {
    let (r, proof) = (a.result, a.proof);
    format!(
        "{first} cheapest configuration found for the budget '{}'\n# cost {:.0} {} ({}), {} exhaustive checks; proved by `specfx check`:\n# shape_total {:.4e}, shape_quant {:.4e}, out {:.3} ulp, {:.3}% correctly rounded\n",
        r.budget,
        a.best.cost,
        a.unit,
        a.objective,
        r.n_evaluations,
        proof.shape_total_max_abs,
        proof.shape_quant_max_abs,
        proof.out_max_ulp,
        100.0 * proof.stages[a.dp.stage_out()].correctly_rounded
    )
}

/// The answer on the terminal: its yosys figures, the configuration and its cost, the proof,
/// overflow, the comparison with the paper's datapath (the analytic cost on every target, a
/// table fitted into `width`), why it is minimal and where it was written (`out`).
pub fn write_answer(
    w: &mut impl Write,
    a: &Answer<'_>,
    out: &std::path::Path,
    width: Option<u16>,
) -> std::io::Result<()> {
    let (proof, dp) = (a.proof, a.dp);
    for (b, f) in a.yosys {
        let t = f.target;
        writeln!(
            w,
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
    let config = dp.config();
    let depth = if config.has_bypass() {
        format!(", per-n depth ({})", depth_text(dp))
    } else {
        String::new()
    };
    writeln!(
        w,
        "best: k = {}, {}{depth}, {}, t {} b {} squares {} out {}: {:.0} {} ({})",
        config.k,
        config.variant.name(),
        a.arch,
        config.t.format,
        config.b.format,
        config
            .square
            .iter()
            .map(|s| s.format.to_string())
            .collect::<Vec<_>>()
            .join("/"),
        config.out.format,
        a.best.cost,
        a.unit,
        a.objective
    )?;
    if let Some(device) = a.result.device {
        let f = analytic_cost(dp, a.arch, crate::hdl::cost::Target::Ice40);
        let l = device.limits();
        writeln!(
            w,
            "fits the {} ({}, analytic): {} of {} DSPs, {} of {} LUTs, {} of {} flip-flops; --device none lifts the limit",
            device.full_name(),
            a.arch,
            f.dsps,
            l.dsps,
            f.luts,
            l.luts,
            f.ffs,
            l.ffs
        )?;
    }
    writeln!(
        w,
        "proved by an exhaustive check: shape_total {:.4e}, shape_quant {:.4e}, out {}, {:.3}% correctly rounded",
        proof.shape_total_max_abs,
        proof.shape_quant_max_abs,
        super::check::out_ulp_brief(&proof.stages[dp.stage_out()], 3),
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
        writeln!(w, "overflow: no stage wraps on any input (exhaustive)")?;
    } else {
        writeln!(
            w,
            "overflow: WARNING, these stages wrap on some inputs although the budget holds: {}",
            wrapping.join(", ")
        )?;
    }
    let (paper, paper_check) = a.paper;
    let lsb8 = crate::analysis::LSB8;
    writeln!(
        w,
        "against the paper's datapath (baseline: plain, k = 4, same n): shape_total {:.3e} ({:.2} lsb8) against {:.3e} ({:.2} lsb8)",
        proof.shape_total_max_abs,
        proof.shape_total_max_abs / lsb8,
        paper_check.shape_total_max_abs,
        paper_check.shape_total_max_abs / lsb8
    )?;
    writeln!(
        w,
        "  analytic cost, {} (the model `specfx cost --analytic-only` prints):",
        a.arch
    )?;
    let mut table = TextTable::new(&[
        ("target", Align::Left),
        ("this", Align::Right),
        ("paper's", Align::Right),
    ])
    .indent(4);
    for target in REPORTED_TARGETS {
        let show =
            |c: &AnalyticCost| format!("{} {} {} DSPs {} FFs", c.luts, c.logic_unit, c.dsps, c.ffs);
        table.row([
            target.name().to_string(),
            show(&analytic_cost(dp, a.arch, target)),
            show(&analytic_cost(paper, a.arch, target)),
        ]);
    }
    table.write(w, width)?;
    writeln!(
        w,
        "why minimal (within this search, not over every possible datapath):"
    )?;
    for m in &a.result.minimality {
        writeln!(w, "  {m}")?;
    }
    writeln!(w, "written to {}", out.display())
}
