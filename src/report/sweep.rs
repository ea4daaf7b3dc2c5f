//! The sweep's chart: lobe error in lsb8 against the analytic cost on the space's target,
//! points grouped by k and variant, the Pareto front and the 1 lsb8 line.

use std::collections::BTreeMap;

use crate::analysis::sweep::PointResult;
use crate::analysis::LSB8;
use crate::hdl::cost::Target;
use crate::report::chart::{front_2d, Chart, Dash, Marker, RefLine, Series};

/// The value of `key` in a point's `key=value;..` axis values.
fn axis<'a>(p: &'a PointResult, key: &str) -> Option<&'a str> {
    p.values
        .split(';')
        .filter_map(|kv| kv.split_once('='))
        .find(|(k, _)| *k == key)
        .map(|(_, v)| v)
}

/// The error/cost chart of a sweep: every valid point, grouped by k and variant when those
/// are axes, the Pareto front as a line, and the 1 lsb8 line.
pub fn chart(points: &[PointResult], target: Target) -> Chart {
    let xy = |p: &PointResult| {
        p.luts
            .zip(p.shape_total_max_abs)
            .map(|(c, e)| (c as f64, e / LSB8))
    };
    let mut groups: BTreeMap<String, Vec<(f64, f64)>> = BTreeMap::new();
    for p in points {
        if let Some(pt) = xy(p) {
            let name = [("k", "k = "), ("variant", "")]
                .iter()
                .filter_map(|(key, prefix)| axis(p, key).map(|v| format!("{prefix}{v}")))
                .collect::<Vec<_>>()
                .join(", ");
            groups.entry(name).or_default().push(pt);
        }
    }
    // Colour 0 (black) is the front's.
    let mut series: Vec<Series> = groups
        .into_iter()
        .enumerate()
        .map(|(i, (name, pts))| {
            let label = if name.is_empty() {
                format!("{} points", pts.len())
            } else {
                format!("{name} ({} points)", pts.len())
            };
            Series::styled(&label, pts, false, i + 1)
        })
        .collect();
    // The front is over logic cells, DSP blocks and error: drawn as a line through the points
    // that also lead in logic cells and error alone, the others (fewer DSPs) as crosses.
    let front: Vec<(f64, f64)> = points.iter().filter(|p| p.pareto).filter_map(xy).collect();
    let line = front_2d(&front);
    let by_dsps: Vec<(f64, f64)> = front
        .iter()
        .copied()
        .filter(|p| !line.contains(p))
        .collect();
    series.push(Series {
        label: format!("Pareto front in {} and error", target.logic_unit()),
        points: line,
        line: true,
        color: (0, 0, 0),
        dash: Dash::default(),
        marker: Marker::None,
        ..Series::default()
    });
    if !by_dsps.is_empty() {
        series.push(Series {
            label: format!("on the front by fewer DSPs ({} points)", by_dsps.len()),
            points: by_dsps,
            line: false,
            color: (0, 0, 0),
            dash: Dash::default(),
            marker: Marker::Cross,
            ..Series::default()
        });
    }
    Chart {
        title: format!(
            "Sweep: lobe error against cos^n versus analytic cost on {}",
            target.name()
        ),
        x_label: format!(
            "analytic {} on {} (calibrated against yosys)",
            target.logic_unit(),
            target.name()
        ),
        y_label: "max |fixed lobe - cos^n| (lsb8 = 2^-8, log scale)".into(),
        log_x: false,
        log_y: true,
        x_integer: true,
        ref_lines: vec![RefLine {
            at: 1.0,
            label: "1 lsb8".into(),
        }],
        series,
        ..Chart::default()
    }
}
