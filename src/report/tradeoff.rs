//! The trade-off's CSV files and terminal table, and its charts: error against each target's
//! hardware cost (the hardware question), accuracy against software speed, and the error
//! against n.

use std::io::{self, Write};

use crate::analysis::frontier::{algorithm_name, Frontier, FrontierPoint};
use crate::analysis::tradeoff::MethodFigures;
use crate::analysis::LSB8;
use crate::csv_dialect::CsvWriter;
use crate::error::Error;
use crate::hdl::cost::{CostFigures, Target};
use crate::hdl::pnr::Device;
use crate::provenance::Provenance;
use crate::report::chart::{front_2d, Chart, Dash, Marker, RefLine, Series};
use crate::report::table::{Align, TextTable};
use crate::report::{chart_files, in_memory, json_file, File};

/// A method's analytic cost on a target, if it has one.
fn cost_on(f: &MethodFigures, t: Target) -> Option<CostFigures> {
    f.costs.iter().find(|c| c.target == t).copied()
}

/// The analytic cost columns of the trade-off's CSV files, [`cost_cells`]'s order.
const COST_COLUMNS: [&str; 8] = [
    "ice40_luts",
    "ice40_dsps",
    "ice40_ffs",
    "xilinx_luts",
    "xilinx_dsps",
    "xilinx_ffs",
    "generic_gates",
    "generic_ffs",
];

/// The cells of [`COST_COLUMNS`] for analytic figures on the targets (empty where a target has
/// none).
fn cost_cells(costs: &[CostFigures]) -> [String; 8] {
    let on = |t: Target| costs.iter().find(|c| c.target == t);
    let cell =
        |t: Target, v: fn(&CostFigures) -> u64| on(t).map_or(String::new(), |c| v(c).to_string());
    [
        cell(Target::Ice40, |c| c.luts),
        cell(Target::Ice40, |c| c.dsps),
        cell(Target::Ice40, |c| c.ffs),
        cell(Target::Xilinx, |c| c.luts),
        cell(Target::Xilinx, |c| c.dsps),
        cell(Target::Xilinx, |c| c.ffs),
        cell(Target::Generic, |c| c.luts),
        cell(Target::Generic, |c| c.ffs),
    ]
}

/// Writes `tradeoff.csv`: one row per method, its errors (also in lsb8), multipliers, the
/// analytic cost on each target, the latency and yosys's figures (empty cells where a method
/// has none). Nothing measured: the same bytes on every run.
pub fn write_csv(w: &mut impl Write, figures: &[MethodFigures]) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    let head = [
        "method",
        "kind",
        "max_abs_err",
        "max_err_lsb8",
        "mean_abs_err",
        "multipliers",
    ];
    let tail = [
        "latency",
        "yosys_target",
        "yosys_luts",
        "yosys_dsps",
        "yosys_ffs",
    ];
    csv.record(head.into_iter().chain(COST_COLUMNS).chain(tail))?;
    let opt = |x: Option<u64>| x.map_or(String::new(), |v| v.to_string());
    for f in figures {
        let head = [
            f.method.clone(),
            f.kind.to_string(),
            format!("{:e}", f.max_abs_err),
            format!("{:e}", f.max_abs_err / LSB8),
            format!("{:e}", f.mean_abs_err),
            opt(f.multipliers.map(u64::from)),
        ];
        let tail = [
            opt(f.latency),
            f.yosys.as_ref().map_or(String::new(), |y| y.target.clone()),
            opt(f.yosys.as_ref().map(|y| y.luts)),
            opt(f.yosys.as_ref().map(|y| y.dsps)),
            opt(f.yosys.as_ref().map(|y| y.ffs)),
        ];
        csv.record(head.into_iter().chain(cost_cells(&f.costs)).chain(tail))?;
    }
    csv.finish().map(drop)
}

/// Writes `measured_speed.csv`: each method's evaluations per second measured in the run,
/// beside its max error (the only trade-off file that changes from run to run).
pub fn write_speed_csv(w: &mut impl Write, figures: &[MethodFigures]) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record(["method", "kind", "evals_per_s", "max_abs_err"])?;
    for f in figures {
        csv.record([
            f.method.clone(),
            f.kind.to_string(),
            format!("{:e}", f.evals_per_s),
            format!("{:e}", f.max_abs_err),
        ])?;
    }
    csv.finish().map(drop)
}

/// Writes the terminal table of the trade-off, fitted into `width` characters (`None`: as wide
/// as its content; see [`TextTable::write`]).
pub fn write_table(
    w: &mut impl Write,
    figures: &[MethodFigures],
    width: Option<u16>,
) -> io::Result<()> {
    let mut table = TextTable::new(&[
        ("method", Align::Left),
        ("kind", Align::Left),
        ("max |err|", Align::Right),
        ("mean |err|", Align::Right),
        ("Meval/s", Align::Right),
        ("mult", Align::Right),
        ("ice40 LUTs+DSPs (an.)", Align::Right),
        ("latency", Align::Right),
    ]);
    let dash = |x: Option<String>| x.unwrap_or_else(|| "-".into());
    for f in figures {
        table.row([
            f.method.clone(),
            f.kind.to_string(),
            format!("{:.3e}", f.max_abs_err),
            format!("{:.3e}", f.mean_abs_err),
            format!("{:.1}", f.evals_per_s / 1e6),
            dash(f.multipliers.map(|m| m.to_string())),
            dash(cost_on(f, Target::Ice40).map(|c| format!("{} + {}", c.luts, c.dsps))),
            dash(f.latency.map(|l| l.to_string())),
        ]);
    }
    table.write(w, width)
}

/// A hardware cost axis of the trade-off.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CostAxis {
    /// What the optimiser minimises on iCE40: LUTs plus each DSP block weighed as the logic
    /// its product would take ([`crate::hdl::cost::objective_value`]).
    Objective,
    /// Logic cells on a target (LUTs; gates for generic).
    Logic(Target),
    /// DSP blocks on a target.
    Dsps(Target),
    /// Flip-flops on a target.
    Ffs(Target),
    /// Latency in cycles (pipelined).
    Latency,
}

impl CostAxis {
    /// The cost charts the trade-off draws, and their file stems.
    pub const CHARTS: [(CostAxis, &'static str); 7] = [
        (CostAxis::Objective, "error_vs_cost_ice40"),
        (CostAxis::Logic(Target::Ice40), "error_vs_luts_ice40"),
        (CostAxis::Dsps(Target::Ice40), "error_vs_dsps_ice40"),
        (CostAxis::Logic(Target::Xilinx), "error_vs_luts_xilinx"),
        (CostAxis::Logic(Target::Generic), "error_vs_gates_generic"),
        (CostAxis::Ffs(Target::Ice40), "error_vs_ffs_ice40"),
        (CostAxis::Latency, "error_vs_latency"),
    ];

    fn of(self, p: &FrontierPoint) -> Option<f64> {
        match self {
            CostAxis::Objective => Some(p.objective),
            CostAxis::Logic(t) => p.cost_on(t).map(|c| c.luts as f64),
            CostAxis::Dsps(t) => p.cost_on(t).map(|c| c.dsps as f64),
            CostAxis::Ffs(t) => p.cost_on(t).map(|c| c.ffs as f64),
            CostAxis::Latency => Some(p.latency as f64),
        }
    }

    /// The axis in a few words, for a title.
    fn short(self) -> String {
        match self {
            CostAxis::Objective => "iCE40 LUT-equivalents".into(),
            CostAxis::Logic(t) => format!("{} {}", t.name(), t.logic_unit()),
            CostAxis::Dsps(t) => format!("{} DSP blocks", t.name()),
            CostAxis::Ffs(t) => format!("{} flip-flops", t.name()),
            CostAxis::Latency => "latency".into(),
        }
    }

    /// The device limit drawn on the axis: the iCE40 UP5K's resources on the iCE40 axes.
    fn device_limit(self) -> Option<RefLine> {
        let l = Device::Up5k.limits();
        let (at, what) = match self {
            CostAxis::Logic(Target::Ice40) => (l.luts, "LUTs"),
            CostAxis::Dsps(Target::Ice40) => (l.dsps, "DSPs"),
            CostAxis::Ffs(Target::Ice40) => (l.ffs, "flip-flops"),
            _ => return None,
        };
        Some(RefLine {
            at: at as f64,
            label: format!("{}: {at} {what}", Device::Up5k.full_name()),
        })
    }

    fn label(self) -> String {
        match self {
            CostAxis::Objective => format!(
                "analytic LUT-equivalents on ice40 (LUTs + {:.0} per DSP block: what the optimiser minimises)",
                crate::hdl::cost::dsp_weight(Target::Ice40)
            ),
            CostAxis::Logic(t) => format!(
                "analytic {} on {} (calibrated against yosys)",
                t.logic_unit(),
                t.name()
            ),
            CostAxis::Dsps(t) => format!("DSP blocks on {}", t.name()),
            CostAxis::Ffs(t) => format!("analytic flip-flops on {}", t.name()),
            CostAxis::Latency => "latency (cycles, pipelined)".into(),
        }
    }
}

/// Chart of the reachable frontier against one hardware cost: for each algorithm, a line
/// through the optimiser's cheapest datapath at each budget of the ladder (its achieved error,
/// lsb8, log scale), the Pareto front across every algorithm (no point both cheaper and more
/// accurate), the 1 lsb8 line and, on the iCE40 axes, the UP5K's limit.
pub fn cost_chart(frontier: &Frontier, axis: CostAxis) -> Chart {
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    for p in &frontier.points {
        let Some(x) = axis.of(p) else { continue };
        let name = algorithm_name(p.algorithm);
        let y = p.shape_total / LSB8;
        match curves.last_mut() {
            Some((n, pts)) if *n == name => pts.push((x, y)),
            _ => curves.push((name, vec![(x, y)])),
        }
    }
    let all: Vec<(f64, f64)> = curves.iter().flat_map(|(_, p)| p.iter().copied()).collect();
    let front = front_2d(&all);
    // The device's limit as a line where it is within reach of the points; said in the
    // axis's label where it would squeeze them against the left edge.
    let widest = all.iter().map(|p| p.0).fold(0.0, f64::max);
    let mut x_label = axis.label();
    let mut x_ref_lines = Vec::new();
    if let Some(limit) = axis.device_limit() {
        if limit.at <= 2.0 * widest {
            x_ref_lines.push(limit);
        } else {
            x_label = format!("{x_label}; {}, far right", limit.label);
        }
    }
    let mut series: Vec<Series> = curves
        .into_iter()
        .enumerate()
        .map(|(i, (name, mut points))| {
            points.dedup();
            Series::styled(&name, points, true, i + 1)
        })
        .collect();
    series.push(Series {
        label: "Pareto front".into(),
        points: front,
        line: true,
        color: (0, 0, 0),
        dash: Dash::Dashed,
        marker: Marker::None,
        ..Series::default()
    });
    Chart {
        title: match axis {
            CostAxis::Objective => format!(
                "Least hardware reaching each accuracy, {} ({})",
                axis.short(),
                frontier.arch
            ),
            // The points minimise the LUT-equivalents: on another axis a curve may turn back.
            _ => format!(
                "The same cheapest datapaths (by LUT-equivalents) against {} ({})",
                axis.short(),
                frontier.arch
            ),
        },
        x_label,
        y_label: format!(
            "max |fixed lobe - cos^n| (lsb8 = 2^-8, log); budgets {} lsb8",
            frontier
                .ladder_lsb8
                .iter()
                .map(|b| b.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        log_y: true,
        x_integer: true,
        direct_labels: false,
        ref_lines: vec![RefLine {
            at: 1.0,
            label: "1 lsb8".into(),
        }],
        x_ref_lines,
        series,
        ..Chart::default()
    }
}

/// Writes `frontier.csv`: one row per point of the frontier (algorithm, budget, the budget
/// whose search found it, its error, the optimiser's objective, its analytic cost on every
/// target and its latency).
pub fn write_frontier_csv(w: &mut impl Write, frontier: &Frontier) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record(
        [
            "algorithm",
            "k",
            "variant",
            "depth",
            "arch",
            "budget_lsb8",
            "found_at_lsb8",
            "shape_total",
            "shape_total_lsb8",
            "objective_ice40",
        ]
        .into_iter()
        .chain(COST_COLUMNS)
        .chain(["latency"]),
    )?;
    for p in &frontier.points {
        let a = p.algorithm;
        csv.record(
            [
                algorithm_name(a),
                a.k.to_string(),
                a.variant.name().to_string(),
                a.depth().name().to_string(),
                frontier.arch.to_string(),
                p.budget_lsb8.to_string(),
                p.found_at_lsb8.to_string(),
                format!("{:e}", p.shape_total),
                format!("{:.4}", p.shape_total / LSB8),
                format!("{:.0}", p.objective),
            ]
            .into_iter()
            .chain(cost_cells(&p.costs))
            .chain([p.latency.to_string()]),
        )?;
    }
    csv.finish().map(drop)
}

/// Chart of accuracy against speed: one point per method.
pub fn speed_chart(figures: &[MethodFigures]) -> Chart {
    let shown: Vec<&MethodFigures> = figures
        .iter()
        .filter(|f| !f.method.ends_with("_none") && !f.method.ends_with("_paper"))
        .collect();
    Chart {
        title: "Speed against accuracy, n = 16..1024".into(),
        x_label: "software speed (million evaluations per second, one core)".into(),
        y_label: "max |method - cos^n| (absolute, log scale)".into(),
        log_x: false,
        log_y: true,
        series: shown
            .iter()
            .enumerate()
            .map(|(i, f)| Series {
                label: f.method.clone(),
                points: vec![(f.evals_per_s / 1e6, f.max_abs_err)],
                line: false,
                color: crate::report::chart::color(i),
                ..Series::default()
            })
            .collect(),
        direct_labels: true,
        ..Chart::default()
    }
}

/// Chart of the error against n for a few methods.
pub fn per_n_chart(figures: &[MethodFigures], ns: &[u32], names: &[&str]) -> Chart {
    let colors = [
        (31, 119, 180),
        (214, 39, 40),
        (44, 160, 44),
        (255, 127, 14),
        (148, 103, 189),
        (0, 0, 0),
    ];
    Chart {
        title: "Error against n".into(),
        x_label: "specular exponent n".into(),
        y_label: "max over c of |method - cos^n| (absolute, log scale)".into(),
        log_x: false,
        log_y: true,
        series: names
            .iter()
            .filter_map(|name| figures.iter().find(|f| f.method == *name))
            .enumerate()
            .map(|(i, f)| Series {
                label: f.method.clone(),
                points: ns
                    .iter()
                    .zip(&f.per_n_max_abs_err)
                    .map(|(&n, &e)| (f64::from(n), e.max(1e-17)))
                    .collect(),
                line: true,
                color: colors[i % colors.len()],
                ..Series::default()
            })
            .collect(),
        ..Chart::default()
    }
}

/// Every file of a trade-off's directory, provenance included, rendered in memory: the table
/// (CSV, JSON), the frontier (CSV, JSON) and its cost charts when it was computed, and apart
/// the wall-clock measurements of this run (every other file is the same on every run).
pub fn tradeoff_files(
    figures: &[MethodFigures],
    frontier: Option<&Frontier>,
    ns: &[u32],
    provenance: &Provenance,
) -> Result<Vec<File>, Error> {
    let mut files: Vec<File> = vec![
        ("tradeoff.csv".into(), in_memory(|w| write_csv(w, figures))),
        json_file("tradeoff.json", &figures)?,
    ];
    if let Some(frontier) = frontier {
        files.push((
            "frontier.csv".into(),
            in_memory(|w| write_frontier_csv(w, frontier)),
        ));
        files.push(json_file("frontier.json", frontier)?);
        for (axis, stem) in CostAxis::CHARTS {
            files.extend(chart_files(stem, &cost_chart(frontier, axis))?.1);
        }
    }
    files.push((
        "measured_speed.csv".into(),
        in_memory(|w| write_speed_csv(w, figures)),
    ));
    files.extend(chart_files("measured_speed_accuracy", &speed_chart(figures))?.1);
    let per_n = per_n_chart(
        figures,
        ns,
        &[
            "cs16_clamp",
            "minimax16",
            "schlick",
            "exp_limit",
            "fixed_sq12",
            "cs128_clamp",
            "minimax64_per_n",
        ],
    );
    files.extend(chart_files("error_vs_n", &per_n)?.1);
    files.extend(provenance.files());
    Ok(files)
}
