//! The trade-off's CSV files and terminal table, and its charts: error against each target's
//! hardware cost (the hardware question), accuracy against software speed, and the error
//! against n.

use std::io::{self, Write};

use crate::analysis::tradeoff::MethodFigures;
use crate::analysis::LSB8;
use crate::csv_dialect::CsvWriter;
use crate::error::Error;
use crate::hdl::cost::{CostFigures, Target};
use crate::provenance::Provenance;
use crate::report::chart::{front_2d, Chart, Dash, Marker, RefLine, Series};
use crate::report::table::{Align, TextTable};
use crate::report::{chart_files, in_memory, json_file, File};

/// A method's analytic cost on a target, if it has one.
fn cost_on(f: &MethodFigures, t: Target) -> Option<CostFigures> {
    f.costs.iter().find(|c| c.target == t).copied()
}

/// Writes `tradeoff.csv`: one row per method, its errors (also in lsb8), multipliers, the
/// analytic cost on each target, the latency and yosys's figures (empty cells where a method
/// has none). Nothing measured: the same bytes on every run.
pub fn write_csv(w: &mut impl Write, figures: &[MethodFigures]) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record([
        "method",
        "kind",
        "max_abs_err",
        "max_err_lsb8",
        "mean_abs_err",
        "multipliers",
        "ice40_luts",
        "ice40_dsps",
        "ice40_ffs",
        "xilinx_luts",
        "xilinx_dsps",
        "xilinx_ffs",
        "generic_gates",
        "generic_ffs",
        "latency",
        "yosys_target",
        "yosys_luts",
        "yosys_dsps",
        "yosys_ffs",
    ])?;
    let opt = |x: Option<u64>| x.map_or(String::new(), |v| v.to_string());
    for f in figures {
        csv.record([
            f.method.clone(),
            f.kind.to_string(),
            format!("{:e}", f.max_abs_err),
            format!("{:e}", f.max_abs_err / LSB8),
            format!("{:e}", f.mean_abs_err),
            opt(f.multipliers.map(u64::from)),
            opt(cost_on(f, Target::Ice40).map(|c| c.luts)),
            opt(cost_on(f, Target::Ice40).map(|c| c.dsps)),
            opt(cost_on(f, Target::Ice40).map(|c| c.ffs)),
            opt(cost_on(f, Target::Xilinx).map(|c| c.luts)),
            opt(cost_on(f, Target::Xilinx).map(|c| c.dsps)),
            opt(cost_on(f, Target::Xilinx).map(|c| c.ffs)),
            opt(cost_on(f, Target::Generic).map(|c| c.luts)),
            opt(cost_on(f, Target::Generic).map(|c| c.ffs)),
            opt(f.latency),
            f.yosys.as_ref().map_or(String::new(), |y| y.target.clone()),
            opt(f.yosys.as_ref().map(|y| y.luts)),
            opt(f.yosys.as_ref().map(|y| y.dsps)),
            opt(f.yosys.as_ref().map(|y| y.ffs)),
        ])?;
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
    pub const CHARTS: [(CostAxis, &'static str); 6] = [
        (CostAxis::Logic(Target::Ice40), "error_vs_luts_ice40"),
        (CostAxis::Dsps(Target::Ice40), "error_vs_dsps_ice40"),
        (CostAxis::Logic(Target::Xilinx), "error_vs_luts_xilinx"),
        (CostAxis::Logic(Target::Generic), "error_vs_gates_generic"),
        (CostAxis::Ffs(Target::Ice40), "error_vs_ffs_ice40"),
        (CostAxis::Latency, "error_vs_latency"),
    ];

    fn of(self, f: &MethodFigures) -> Option<f64> {
        let on =
            |t: Target| -> Option<CostFigures> { f.costs.iter().find(|c| c.target == t).copied() };
        match self {
            CostAxis::Logic(t) => on(t).map(|c| c.luts as f64),
            CostAxis::Dsps(t) => on(t).map(|c| c.dsps as f64),
            CostAxis::Ffs(t) => on(t).map(|c| c.ffs as f64),
            CostAxis::Latency => f.latency.map(|l| l as f64),
        }
    }

    fn label(self) -> String {
        match self {
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

/// Chart of error (lsb8, log) against one hardware cost: one labelled point per fixed-point
/// datapath, the Pareto front (no datapath both cheaper and more accurate) as a line, and the
/// 1 lsb8 line.
pub fn cost_chart(figures: &[MethodFigures], axis: CostAxis) -> Chart {
    let pts: Vec<(&str, f64, f64)> = figures
        .iter()
        .filter_map(|f| {
            axis.of(f)
                .map(|x| (f.method.as_str(), x, f.max_abs_err / LSB8))
        })
        .collect();
    let front = front_2d(&pts.iter().map(|&(_, x, y)| (x, y)).collect::<Vec<_>>());
    let mut series: Vec<Series> = pts
        .iter()
        .enumerate()
        .map(|(i, &(name, x, y))| Series::styled(name, vec![(x, y)], false, i + 1))
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
        title: format!("Error against {}", axis.label()),
        x_label: axis.label(),
        y_label: "max |fixed lobe - cos^n| over n = 16..1024 (lsb8 = 2^-8, log scale)".into(),
        log_y: true,
        x_integer: true,
        direct_labels: true,
        ref_lines: vec![RefLine {
            at: 1.0,
            label: "1 lsb8".into(),
        }],
        x_ref_lines: match axis {
            CostAxis::Dsps(Target::Ice40) => vec![RefLine {
                at: 8.0,
                label: "iCE40 UP5K has 8".into(),
            }],
            _ => Vec::new(),
        },
        series,
        ..Chart::default()
    }
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
/// (CSV, JSON), the cost charts, and apart the wall-clock measurements of this run (every
/// other file is the same on every run).
pub fn tradeoff_files(
    figures: &[MethodFigures],
    ns: &[u32],
    provenance: &Provenance,
) -> Result<Vec<File>, Error> {
    let mut files: Vec<File> = vec![
        ("tradeoff.csv".into(), in_memory(|w| write_csv(w, figures))),
        json_file("tradeoff.json", &figures)?,
    ];
    for (axis, stem) in CostAxis::CHARTS {
        files.extend(chart_files(stem, &cost_chart(figures, axis))?.1);
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
