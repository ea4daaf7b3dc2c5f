//! The sweep's chart: lobe error against analytic cost, with the Pareto front.

use crate::analysis::sweep::PointResult;
use crate::report::chart::{Chart, Series};

/// The error/cost chart of a sweep: every valid point, and the Pareto front as a line.
pub fn chart(points: &[PointResult]) -> Chart {
    let xy = |p: &PointResult| {
        p.luts
            .zip(p.shape_total_max_abs)
            .map(|(c, e)| (c as f64, e))
    };
    let mut front: Vec<(f64, f64)> = points.iter().filter(|p| p.pareto).filter_map(xy).collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    Chart {
        title: "Sweep: lobe error against cos^n versus cost".into(),
        x_label: "analytic cost (LUTs, every product in logic)".into(),
        y_label: "max |fixed lobe - cos^n| (absolute, log scale)".into(),
        log_x: false,
        log_y: true,
        series: vec![
            Series {
                label: format!("{} points", points.iter().filter_map(xy).count()),
                points: points.iter().filter_map(xy).collect(),
                line: false,
                color: (120, 120, 120),
                ..Series::default()
            },
            Series {
                label: format!("Pareto front ({} points)", front.len()),
                points: front,
                line: true,
                color: (200, 30, 30),
                ..Series::default()
            },
        ],
        ..Chart::default()
    }
}
