//! The trade-off charts: accuracy against software speed, and the error against n.

use crate::analysis::tradeoff::MethodFigures;
use crate::report::chart::{hue, Chart, Series};

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
                points: vec![(f.evals_per_s / 1e6, f.max_abs_err.max(1e-17))],
                line: false,
                color: hue(i, shown.len()),
                ..Series::default()
            })
            .collect(),
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
