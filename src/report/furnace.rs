//! The furnace report: its document (tables per form, distance from 1, flagged values), the CSV
//! of every reflectance, one chart per form (a panel per exponent, a line per path) and the
//! terminal summary.

use std::io::{self, Write};

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::analysis::furnace::{Curve, FormSummary, FurnacePath, FurnaceReport};
use crate::csv_dialect::CsvWriter;
use crate::error::Error;
use crate::provenance::Provenance;
use crate::report::chart::{
    draw_chart, draw_sample, encode_png, register_font, render_error, Chart, Dash, Marker, RefLine,
    Series, OKABE_ITO,
};
use crate::report::doc::{write_markdown, Block};
use crate::report::table::{Align, TextTable};
use crate::report::{in_memory, json_file, File};

/// The file stem of a form's chart: `furnace_<form>`.
pub fn chart_stem(form: crate::reference::normalisation::Form) -> String {
    format!("furnace_{}", form.name())
}

/// Writes every reflectance as CSV: `form,n,path,theta_deg,rho`, one row per value.
pub fn write_csv(w: &mut impl Write, r: &FurnaceReport) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record(["form", "n", "path", "theta_deg", "rho"])?;
    for f in &r.forms {
        for c in &f.curves {
            for (theta, rho) in r.angles_deg.iter().zip(&c.rho) {
                csv.record([
                    f.form.name().to_string(),
                    c.n.to_string(),
                    c.path.name().to_string(),
                    theta.to_string(),
                    rho.to_string(),
                ])?;
            }
        }
    }
    csv.finish().map(drop)
}

/// Below this, `|rho - 1|` is the quadratures' round-off and is shown as `< 1e-11`.
const ROUND_OFF: f64 = 1e-11;

/// `rho - 1` in scientific notation, or `< 1e-11`.
fn excess(rho: f64) -> String {
    let d = rho - 1.0;
    if d.abs() < ROUND_OFF {
        "< 1e-11".to_string()
    } else {
        format!("{d:+.2e}")
    }
}

fn deviation_cell(rho: f64, n: u32) -> String {
    if (rho - 1.0).abs() < ROUND_OFF {
        excess(rho)
    } else {
        format!("{} (n = {n})", excess(rho))
    }
}

/// Angles as compact runs of the run's grid: `0-25, 40` for consecutive angles of the list.
fn angle_runs(all: &[f64], flagged: &[f64]) -> String {
    let idx: Vec<usize> = flagged
        .iter()
        .filter_map(|a| all.iter().position(|b| b == a))
        .collect();
    let mut parts = Vec::new();
    let mut i = 0;
    while i < idx.len() {
        let mut j = i;
        while j + 1 < idx.len() && idx[j + 1] == idx[j] + 1 {
            j += 1;
        }
        parts.push(if j == i {
            format!("{}", all[idx[i]])
        } else {
            format!("{}-{}", all[idx[i]], all[idx[j]])
        });
        i = j + 1;
    }
    parts.join(", ")
}

fn flag_cell(c: &Curve) -> String {
    if c.flagged_angles_deg.is_empty() {
        String::new()
    } else {
        "> 1".to_string()
    }
}

/// The furnace document: settings, the distance of rho(0) from 1 per form and coefficient
/// source, every flagged curve, and per form a table and its chart.
pub fn document(r: &FurnaceReport) -> Vec<Block> {
    let summary = r.summary();
    let mut doc = vec![
        Block::Heading(1, format!("White furnace of {}", r.config)),
        Block::Paragraph(format!(
            "Directional-hemispherical reflectance rho(theta_i) = ∫ f_r cos(theta_o) dw_o of each normalised form, by deterministic quadrature (the azimuth integrated in closed form; see `docs/furnace.md`). Configuration `{}`: variant {}, m = {} (k = {}), cutoff {}, input {}, output {}. Exponents {}; incident angles {} degrees. A value is flagged when it exceeds 1 + {:.0e}.",
            r.config,
            r.variant,
            r.m,
            r.k,
            r.cutoff.name(),
            r.c_format,
            r.out_format,
            r.ns.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", "),
            r.angles_deg.iter().map(|a| a.to_string()).collect::<Vec<_>>().join(", "),
            r.flag_tolerance,
        )),
        Block::Paragraph(format!(
            "Paths: `f64_cos_n` f64 cos^n with the classic coefficient; `f64_cs_m_paper` and `f64_cs_m_exact` the configuration's f64 lobe with the paper's (Table 1) and the exact coefficient; `datapath` the bit-accurate datapath with the form's coefficient ({} source), its input x quantized to {} as the renderer does.",
            r.datapath_coef_source.name(),
            r.c_format
        )),
        Block::Heading(2, "Distance of rho(0) from 1".into()),
        Block::Paragraph("Per form and path, rho(0) - 1 at the exponent where |rho(0) - 1| is largest. At normal incidence rho(0) = 2 pi coef Int(n) for every form but the NDF ones, whose reflected directions need h within 45 degrees of N: this is how far each coefficient source is from normalising the lobe it is used with.".into()),
    ];
    let mut header = vec!["form".to_string()];
    header.extend(
        FurnacePath::ALL
            .iter()
            .map(|p| format!("{} ({})", p.name(), r.coef_source(*p).name())),
    );
    let rows = summary
        .iter()
        .map(|s| {
            let mut row = vec![s.form.name().to_string()];
            for p in FurnacePath::ALL {
                row.push(
                    s.deviations
                        .iter()
                        .find(|d| d.path == p)
                        .map_or("unavailable".to_string(), |d| {
                            deviation_cell(d.rho_normal, d.n)
                        }),
                );
            }
            row
        })
        .collect();
    doc.push(Block::Table { header, rows });

    doc.push(Block::Heading(2, "Flagged values".into()));
    let mut flagged_rows = Vec::new();
    for f in &r.forms {
        for c in f.curves.iter().filter(|c| !c.flagged_angles_deg.is_empty()) {
            flagged_rows.push(vec![
                f.form.name().to_string(),
                c.n.to_string(),
                c.path.name().to_string(),
                angle_runs(&r.angles_deg, &c.flagged_angles_deg),
                format!("{:.6}", c.max),
                format!("{}", c.max_angle_deg),
            ]);
        }
    }
    if flagged_rows.is_empty() {
        doc.push(Block::Paragraph(
            "No reflectance exceeds 1: every form conserves energy on every path.".into(),
        ));
    } else {
        doc.push(Block::Paragraph(format!(
            "{} curves exceed 1 somewhere ({} values). For `blinn_phong_ndf` and `blinn_phong_heightfield` a rise towards grazing incidence is the missing masking-shadowing term G of the microfacet BRDF (any normalisation of D gains energy there without it), not the coefficient; a flag at normal incidence is the coefficient's.",
            flagged_rows.len(),
            summary.iter().map(|s| s.n_flagged_values).sum::<usize>()
        )));
        doc.push(Block::Table {
            header: ["form", "n", "path", "angles (deg)", "max rho", "at (deg)"]
                .map(String::from)
                .to_vec(),
            rows: flagged_rows,
        });
    }

    for f in &r.forms {
        doc.push(Block::Heading(2, f.form.name().to_string()));
        if let Some(e) = &f.datapath_unavailable {
            doc.push(Block::Paragraph(format!(
                "The datapath path is unavailable: the configuration with this form's coefficient does not validate ({e})."
            )));
        }
        let rows = f
            .curves
            .iter()
            .map(|c| {
                vec![
                    c.n.to_string(),
                    c.path.name().to_string(),
                    format!("{:.6}", c.coef),
                    format!("{:.6}", c.rho_normal),
                    excess(c.rho_normal),
                    format!("{:.6}", c.max),
                    format!("{}", c.max_angle_deg),
                    flag_cell(c),
                ]
            })
            .collect();
        doc.push(Block::Table {
            header: [
                "n",
                "path",
                "coef",
                "rho(0)",
                "rho(0) - 1",
                "max rho",
                "at (deg)",
                "flag",
            ]
            .map(String::from)
            .to_vec(),
            rows,
        });
        doc.push(Block::Figure {
            stem: chart_stem(f.form),
            caption: format!(
                "{}: reflectance against incident angle, one panel per exponent, one line per path (each its own dash pattern); vermillion triangles exceed 1",
                f.form.name()
            ),
        });
    }
    doc
}

/// The terminal summary: one row per form with its worst reflectance and the flags, fitted
/// into `width` characters (`None`: as wide as its content; see [`TextTable::write`]).
pub fn write_summary(
    w: &mut impl Write,
    summary: &[FormSummary],
    width: Option<u16>,
) -> io::Result<()> {
    let mut table = TextTable::new(&[
        ("form", Align::Left),
        ("max rho", Align::Right),
        ("at", Align::Left),
        ("flags", Align::Left),
    ]);
    for f in summary {
        let (rho, at) = f
            .worst
            .map_or(("-".to_string(), "no values".to_string()), |w| {
                (
                    format!("{:.6}", w.rho),
                    format!("{}, n = {}, {} deg", w.path.name(), w.n, w.theta_deg),
                )
            });
        let flags = if f.n_flagged_values == 0 {
            "no flags".to_string()
        } else {
            format!(
                "{} values > 1 on {} curves",
                f.n_flagged_values, f.n_flagged_curves
            )
        };
        let unavailable = if f.datapath_unavailable.is_some() {
            "; datapath unavailable"
        } else {
            ""
        };
        table.row([
            f.form.name().to_string(),
            rho,
            at,
            format!("{flags}{unavailable}"),
        ]);
    }
    table.write(w, width)
}

/// How each path is drawn: an Okabe-Ito colour and a dash pattern of its own, so that lines
/// on top of each other stay visible.
fn path_style(p: FurnacePath) -> ((u8, u8, u8), Dash) {
    match p {
        FurnacePath::F64CosN => (OKABE_ITO[0], Dash::Solid),
        FurnacePath::F64CsMPaper => (OKABE_ITO[1], Dash::Dashed),
        FurnacePath::F64CsMExact => (OKABE_ITO[5], Dash::Dotted),
        FurnacePath::Datapath => (OKABE_ITO[3], Dash::DashDot),
    }
}

/// Reflectance values above 1 (plus the tolerance): vermillion triangles.
fn flagged_series(points: Vec<(f64, f64)>) -> Series {
    Series {
        label: "> 1".into(),
        points,
        line: false,
        color: OKABE_ITO[6],
        marker: Marker::TriangleUp,
        ..Series::default()
    }
}

const PANEL_COLS: usize = 4;

fn chart_size(n_panels: usize) -> (u32, u32) {
    let cols = n_panels.clamp(1, PANEL_COLS) as u32;
    let rows = n_panels.div_ceil(PANEL_COLS).max(1) as u32;
    (60 + 300 * cols, 90 + 280 * rows)
}

/// The panel of one exponent: a line per path, the flagged values, the line rho = 1.
fn panel(r: &FurnaceReport, f: &crate::analysis::furnace::FormFurnace, n: u32) -> Chart {
    let curves: Vec<&Curve> = f.curves.iter().filter(|c| c.n == n).collect();
    let mut series: Vec<Series> = curves
        .iter()
        .map(|c| {
            let (color, dash) = path_style(c.path);
            Series {
                label: c.path.label().into(),
                points: r
                    .angles_deg
                    .iter()
                    .copied()
                    .zip(c.rho.iter().copied())
                    .collect(),
                line: true,
                color,
                dash,
                marker: Marker::None,
                bar_width: None,
            }
        })
        .collect();
    let flagged: Vec<(f64, f64)> = curves
        .iter()
        .flat_map(|c| {
            r.angles_deg
                .iter()
                .copied()
                .zip(c.rho.iter().copied())
                .filter(|&(_, v)| v > 1.0 + r.flag_tolerance)
        })
        .collect();
    if !flagged.is_empty() {
        series.push(flagged_series(flagged));
    }
    Chart {
        title: format!("n = {n}"),
        x_label: "theta_i (deg)".into(),
        y_label: "rho".into(),
        x_integer: r.angles_deg.iter().all(|a| a.fract() == 0.0),
        series,
        ref_lines: vec![RefLine {
            at: 1.0,
            label: "1".into(),
        }],
        ..Chart::default()
    }
}

fn draw_form<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    r: &FurnaceReport,
    form_idx: usize,
) -> Result<(), Error> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| render_error(e.to_string());
    let f = &r.forms[form_idx];
    root.fill(&WHITE).map_err(err)?;
    let (top, body) = root.split_vertically(70);
    top.draw(&Text::new(
        format!(
            "White furnace, {} ({}): reflectance against incident angle",
            f.form.name(),
            r.config
        ),
        (16, 8),
        ("sans-serif", 20),
    ))
    .map_err(err)?;
    // The key, shared by every panel.
    let mut x = 16;
    let mut key: Vec<Series> = FurnacePath::ALL
        .iter()
        .map(|&p| {
            let (color, dash) = path_style(p);
            Series {
                label: p.label().into(),
                line: true,
                color,
                dash,
                marker: Marker::None,
                ..Series::default()
            }
        })
        .collect();
    key.push(flagged_series(Vec::new()));
    for s in &key {
        draw_sample(&top, s, (x, 50))?;
        top.draw(&Text::new(
            s.label.clone(),
            (x + 30, 42),
            ("sans-serif", 14),
        ))
        .map_err(err)?;
        x += 220;
    }

    let n_panels = r.ns.len();
    let cols = n_panels.clamp(1, PANEL_COLS);
    let rows = n_panels.div_ceil(PANEL_COLS).max(1);
    let tiles = body.split_evenly((rows, cols));
    for (tile, &n) in tiles.iter().zip(&r.ns) {
        draw_chart(tile, &panel(r, f, n), true)?;
    }
    root.present().map_err(err)
}

/// A form's chart (index into [`FurnaceReport::forms`]) as SVG text.
pub fn chart_svg(r: &FurnaceReport, form_idx: usize) -> Result<String, Error> {
    register_font();
    let size = chart_size(r.ns.len());
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        draw_form(root, r, form_idx)?;
    }
    text.push('\n');
    Ok(text)
}

/// A form's chart (index into [`FurnaceReport::forms`]) as PNG bytes.
pub fn chart_png(r: &FurnaceReport, form_idx: usize) -> Result<Vec<u8>, Error> {
    register_font();
    let size = chart_size(r.ns.len());
    let mut rgb = vec![0u8; (size.0 * size.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        draw_form(root, r, form_idx)?;
    }
    encode_png(&rgb, size)
}

/// Every file of a furnace's directory, provenance included, rendered in memory: a chart per
/// form (SVG and PNG), `furnace.md` (ending with the provenance's line), `.csv` and `.json`.
pub fn furnace_files(r: &FurnaceReport, provenance: &Provenance) -> Result<Vec<File>, Error> {
    let mut files: Vec<File> = Vec::new();
    for (i, f) in r.forms.iter().enumerate() {
        let stem = chart_stem(f.form);
        files.push((format!("{stem}.svg"), chart_svg(r, i)?.into_bytes()));
        files.push((format!("{stem}.png"), chart_png(r, i)?));
    }
    let mut doc = document(r);
    doc.push(Block::Paragraph(provenance.line()));
    files.push(("furnace.md".into(), in_memory(|w| write_markdown(w, &doc))));
    files.push(("furnace.csv".into(), in_memory(|w| write_csv(w, r))));
    files.push(json_file("furnace.json", r)?);
    files.extend(provenance.files());
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angle_runs_merge_consecutive_angles_of_the_grid() {
        let all = [0.0, 5.0, 10.0, 15.0, 20.0];
        assert_eq!(angle_runs(&all, &[0.0, 5.0, 10.0, 20.0]), "0-10, 20");
        assert_eq!(angle_runs(&all, &[15.0]), "15");
    }
}
