//! The sweep's CSV, and its chart: lobe error in lsb8 against the analytic cost on the
//! space's target, points grouped by k and variant, the Pareto front and the 1 lsb8 line.

use std::collections::BTreeMap;
use std::io::{self, Write};

use crate::analysis::sweep::PointResult;
use crate::analysis::LSB8;
use crate::csv_dialect::CsvWriter;
use crate::hdl::cost::Target;
use crate::report::chart::{front_2d, Chart, Dash, Marker, RefLine, Series};

/// The CSV of a sweep: one row per point, in index order; the cost columns are named with the
/// target and unit (`ice40_luts,ice40_dsps,ice40_ffs`, `generic_gates,..`). Empty cells where
/// a figure is missing (an invalid point, no yosys run).
pub fn write_csv(w: &mut impl Write, points: &[PointResult], target: Target) -> io::Result<()> {
    let t = target.name().replace('-', "_");
    let unit = target.logic_unit().to_lowercase();
    let mut csv = CsvWriter::new(w);
    csv.record([
        "index".to_string(),
        "values".into(),
        "invalid".into(),
        "shape_total_max_abs".into(),
        "shape_quant_max_abs".into(),
        "out_max_ulp".into(),
        "out_correctly_rounded".into(),
        "monotonic".into(),
        format!("{t}_{unit}"),
        format!("{t}_dsps"),
        format!("{t}_ffs"),
        "register_bits".into(),
        "multiplier_bits".into(),
        "latency".into(),
        "initiation_interval".into(),
        "pareto".into(),
        format!("yosys_{t}_{unit}"),
        format!("yosys_{t}_ffs"),
        format!("yosys_{t}_dsps"),
    ])?;
    let f = |x: Option<f64>| x.map_or(String::new(), |v| format!("{v:e}"));
    let u = |x: Option<u64>| x.map_or(String::new(), |v| v.to_string());
    for p in points {
        csv.record([
            p.index.to_string(),
            p.values.clone(),
            p.invalid.clone().unwrap_or_default(),
            f(p.shape_total_max_abs),
            f(p.shape_quant_max_abs),
            f(p.out_max_ulp),
            f(p.out_correctly_rounded),
            p.monotonic.map_or(String::new(), |m| m.to_string()),
            u(p.luts),
            u(p.dsps),
            u(p.ffs),
            u(p.register_bits),
            u(p.multiplier_bits),
            u(p.latency),
            u(p.initiation_interval),
            p.pareto.to_string(),
            u(p.yosys_luts),
            u(p.yosys_ffs),
            u(p.yosys_dsps),
        ])?;
    }
    csv.finish().map(drop)
}

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

/// Every file of a sweep's results rendered in memory, `(name, bytes)`: `sweep.csv`,
/// `sweep.json`, the chart (`sweep.svg`, `sweep.png`) and the provenance's two files.
pub fn sweep_files(
    points: &[PointResult],
    target: Target,
    provenance: &crate::provenance::Provenance,
) -> Result<Vec<(String, Vec<u8>)>, crate::error::Error> {
    let mut csv = Vec::new();
    write_csv(&mut csv, points, target).expect("writing into memory cannot fail");
    let mut json = serde_json::to_vec_pretty(&points).map_err(|e| crate::error::Error::Render {
        message: format!("sweep.json: {e}"),
    })?;
    json.push(b'\n');
    let chart = chart(points, target);
    let svg = crate::report::chart::render_svg(&chart)?;
    let png = crate::report::chart::render_png(&chart)?;
    let mut files = vec![
        ("sweep.csv".to_string(), csv),
        ("sweep.json".to_string(), json),
        ("sweep.svg".to_string(), svg.into_bytes()),
        ("sweep.png".to_string(), png),
    ];
    files.extend(provenance.files());
    Ok(files)
}

#[cfg(test)]
mod csv_tests {
    use super::*;

    fn point(index: u64, values: &str, invalid: Option<&str>) -> PointResult {
        let valid = invalid.is_none();
        PointResult {
            index,
            values: values.into(),
            invalid: invalid.map(String::from),
            shape_total_max_abs: valid.then_some(0.0123),
            shape_quant_max_abs: valid.then_some(2.5e-4),
            out_max_ulp: valid.then_some(12.0),
            out_correctly_rounded: valid.then_some(0.75),
            monotonic: valid.then_some(true),
            luts: valid.then_some(187),
            dsps: valid.then_some(9),
            ffs: valid.then_some(355),
            register_bits: valid.then_some(300),
            multiplier_bits: valid.then_some(1000),
            latency: valid.then_some(9),
            initiation_interval: valid.then_some(1),
            pareto: valid,
            yosys_luts: None,
            yosys_ffs: None,
            yosys_dsps: None,
        }
    }

    /// Cells holding a comma, a quote and a line break come back unchanged through a CSV
    /// reader; plain cells are written as they are, numbers as `{:e}`.
    #[test]
    fn cells_that_need_quoting_round_trip() {
        let values = "n=16,64;k=4";
        let invalid = "square.format: expected \"u1.N\", got u1.70\nsecond line";
        let points = [point(0, values, None), point(1, "k=5", Some(invalid))];
        let mut out = Vec::new();
        write_csv(&mut out, &points, Target::Ice40).unwrap();
        let text = String::from_utf8(out.clone()).unwrap();
        // The quoted cells by hand: commas and line breaks inside quotes, quotes doubled.
        assert!(text.contains("\n0,\"n=16,64;k=4\",,1.23e-2,2.5e-4,1.2e1,7.5e-1,true,187,9,355,300,1000,9,1,true,,,\n"), "{text}");
        assert!(text.contains("\n1,k=5,\"square.format: expected \"\"u1.N\"\", got u1.70\nsecond line\",,,,,,,,,,,,,false,,,\n"), "{text}");
        let mut reader = ::csv::Reader::from_reader(out.as_slice());
        let header = reader.headers().unwrap().clone();
        assert_eq!(&header[8], "ice40_luts");
        let rows: Vec<::csv::StringRecord> = reader.records().map(Result::unwrap).collect();
        assert_eq!(rows.len(), 2);
        assert_eq!(&rows[0][1], values);
        assert_eq!(&rows[0][2], "");
        assert_eq!(&rows[1][2], invalid);
        assert!(rows.iter().all(|r| r.len() == header.len()));
    }
}
