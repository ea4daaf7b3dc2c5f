//! The sweep's chart: lobe error in lsb8 against the analytic cost on the space's target,
//! points grouped by k and variant, the Pareto front and a line at 1 lsb8.

use std::collections::BTreeMap;

use crate::analysis::sweep::PointResult;
use crate::analysis::LSB8;
use crate::hdl::cost::Target;
use crate::report::chart::{Chart, Series, PALETTE};

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
    let mut series: Vec<Series> = groups
        .into_iter()
        .enumerate()
        .map(|(i, (name, pts))| Series {
            label: if name.is_empty() {
                format!("{} points", pts.len())
            } else {
                format!("{name} ({} points)", pts.len())
            },
            points: pts,
            line: false,
            color: PALETTE[(i + 1) % PALETTE.len()],
        })
        .collect();
    let mut front: Vec<(f64, f64)> = points.iter().filter(|p| p.pareto).filter_map(xy).collect();
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (lo, hi) = points
        .iter()
        .filter_map(xy)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), (x, _)| {
            (l.min(x), h.max(x))
        });
    series.push(Series {
        label: format!("Pareto front ({} points)", front.len()),
        points: front,
        line: true,
        color: PALETTE[0],
    });
    if lo.is_finite() {
        series.push(Series {
            label: "1 lsb8 (2^-8, one 8-bit display step)".into(),
            points: vec![(lo, 1.0), (hi, 1.0)],
            line: true,
            color: PALETTE[6],
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
        series,
    }
}
