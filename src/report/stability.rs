//! The stability report: heat maps of where each path fails (SVG and PNG), the overview of
//! every path, the overshoot chart, the region and special-input tables, and the document.

use crate::error::Error;
use crate::report::chart::render_error;
use std::io::{self, Write};

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::analysis::stability::{
    Kind, PathMap, StabilityReport, HEAT_ROWS, OVERSHOOT_J_MAX, SPECIAL_N,
};
use crate::csv_dialect::CsvWriter;
use crate::provenance::Provenance;
use crate::report::chart::{lsb8, register_font, style, Chart, Dash, Series};
use crate::report::doc::{write_html, write_markdown, Block};
use crate::report::{chart_files, in_memory, json_file, File};
use plotters::element::DashedPathElement;

/// Heat-map size in pixels (the SVG uses the same user units).
pub const HEAT_SIZE: (u32, u32) = (960, 600);

/// One colour class of a heat-map cell, with its legend label.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shade {
    /// No sample in the cell.
    Empty,
    /// The datapath cannot hold the exponents of the column.
    Unrepresentable,
    /// NaN or infinity.
    NonFinite,
    /// |err| = 0.
    Exact,
    /// |err| <= tol / 1000, tol / 100, tol / 10, tol (levels 0..=3).
    Within(u8),
    /// |err| <= 4 tol, 16 tol, 64 tol, above (levels 0..=3).
    Beyond(u8),
}

impl Shade {
    /// Every shade, in legend order.
    pub const ALL: [Shade; 11] = [
        Shade::Exact,
        Shade::Within(0),
        Shade::Within(1),
        Shade::Within(2),
        Shade::Within(3),
        Shade::Beyond(0),
        Shade::Beyond(1),
        Shade::Beyond(2),
        Shade::Beyond(3),
        Shade::NonFinite,
        Shade::Unrepresentable,
    ];

    /// The shade of a cell.
    ///
    /// # Examples
    /// ```
    /// use specfx::analysis::stability::Cell;
    /// use specfx::report::stability::Shade;
    /// let cell = |e: f64| Cell { samples: 1, max_abs_err: e, flags: 0 };
    /// assert_eq!(Shade::of(&cell(0.0), 0.01), Shade::Exact);
    /// assert_eq!(Shade::of(&cell(0.01), 0.01), Shade::Within(3));
    /// assert_eq!(Shade::of(&cell(0.02), 0.01), Shade::Beyond(0));
    /// assert_eq!(Shade::of(&cell(1.0), 0.01), Shade::Beyond(3));
    /// ```
    pub fn of(cell: &crate::analysis::stability::Cell, tol: f64) -> Shade {
        if cell.flags & Kind::NonFinite.bit() != 0 {
            return Shade::NonFinite;
        }
        if cell.samples == 0 {
            return if cell.flags & Kind::Unrepresentable.bit() != 0 {
                Shade::Unrepresentable
            } else {
                Shade::Empty
            };
        }
        let e = cell.max_abs_err;
        if e == 0.0 {
            Shade::Exact
        } else if e <= tol {
            let level = [tol / 1000.0, tol / 100.0, tol / 10.0]
                .iter()
                .filter(|&&t| e > t)
                .count();
            Shade::Within(level as u8)
        } else {
            let level = [4.0 * tol, 16.0 * tol, 64.0 * tol]
                .iter()
                .filter(|&&t| e > t)
                .count();
            Shade::Beyond(level as u8)
        }
    }

    /// The RGB colour: blues within the tolerance, oranges to dark brown beyond it (a pair
    /// every kind of colour vision tells apart), white where exact.
    pub fn rgb(self) -> (u8, u8, u8) {
        match self {
            Shade::Empty => (250, 250, 250),
            Shade::Unrepresentable => (170, 170, 170),
            Shade::NonFinite => (0, 0, 0),
            Shade::Exact => (255, 255, 255),
            Shade::Within(0) => (222, 235, 247),
            Shade::Within(1) => (158, 202, 225),
            Shade::Within(2) => (66, 146, 198),
            Shade::Within(_) => (8, 81, 156),
            Shade::Beyond(0) => (254, 217, 142),
            Shade::Beyond(1) => (254, 153, 41),
            Shade::Beyond(2) => (217, 95, 14),
            Shade::Beyond(_) => (127, 39, 4),
        }
    }

    /// The legend label for a tolerance, in lsb8 (2^-8).
    ///
    /// # Examples
    /// ```
    /// use specfx::report::stability::Shade;
    /// let tol = 1.0 / 256.0;
    /// assert_eq!(Shade::Within(0).label(tol), "\u{2264} 0.001 lsb8");
    /// assert_eq!(Shade::Beyond(1).label(tol), "\u{2264} 16 lsb8");
    /// assert_eq!(Shade::Beyond(3).label(tol), "> 64 lsb8");
    /// ```
    pub fn label(self, tol: f64) -> String {
        match self {
            Shade::Empty => "no sample".into(),
            Shade::Unrepresentable => "n's constants do not fit".into(),
            Shade::NonFinite => "NaN or infinite".into(),
            Shade::Exact => "exact".into(),
            Shade::Within(l) => format!(
                "\u{2264} {}",
                lsb8(tol / [1000.0, 100.0, 10.0, 1.0][usize::from(l.min(3))])
            ),
            Shade::Beyond(l) if l < 3 => {
                format!("\u{2264} {}", lsb8(tol * [4.0, 16.0, 64.0][usize::from(l)]))
            }
            Shade::Beyond(_) => format!("> {}", lsb8(64.0 * tol)),
        }
    }
}

/// Where column `col` of a heat map ends on the n axis: the next column's first n (the last
/// column ends one past its last n).
fn column_end(m: &PathMap, col: usize) -> f64 {
    let cols = &m.heat.columns;
    match cols.get(col + 1) {
        Some(next) => f64::from(next.0),
        None => f64::from(cols[col].1) + 1.0,
    }
}

/// The rectangles of a heat map: along each row, a run of cells of equal `key` becomes one
/// rectangle `[(x0, row), (x1, row + 1)]`, with the run's key.
fn row_runs<K: PartialEq + Copy>(
    m: &PathMap,
    key: impl Fn(usize, usize) -> K,
) -> Vec<([(f64, f64); 2], K)> {
    let cols = &m.heat.columns;
    let x_edge = |col: usize| column_end(m, col);
    let mut v = Vec::new();
    for row in 0..HEAT_ROWS {
        let mut start = 0;
        while start < cols.len() {
            let k = key(start, row);
            let mut end = start + 1;
            while end < cols.len() && key(end, row) == k {
                end += 1;
            }
            let y = row as f64;
            v.push((
                [(f64::from(cols[start].0), y), (x_edge(end - 1), y + 1.0)],
                k,
            ));
            start = end;
        }
    }
    v
}

/// Flags drawn as a cross on a heat-map cell.
const CROSS_FLAGS: [Kind; 3] = [Kind::NegativeBase, Kind::NonMonotonic, Kind::Wrap];

fn draw_heatmap<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    m: &PathMap,
    tol: f64,
) -> Result<(), Error> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| render_error(e.to_string());
    root.fill(&WHITE).map_err(err)?;
    let (w, _) = root.dim_in_pixel();
    let (plot, legend) = root.split_horizontally(w - 200);
    let cols = &m.heat.columns;
    let x_lo = f64::from(cols[0].0);
    let x_hi = f64::from(cols[cols.len() - 1].1) + 1.0;
    let worst = format!(
        "max |err| {} at n = {}, theta = {:.2} deg",
        lsb8(m.max_abs_err),
        m.worst_n,
        m.worst_c.clamp(-1.0, 1.0).acos().to_degrees()
    );
    let mut chart = ChartBuilder::on(&plot)
        .caption(
            format!("{} ({}): |lobe - cos^n|, {worst}", m.path, m.precision),
            ("sans-serif", 18),
        )
        .margin(12)
        .x_label_area_size(44)
        .y_label_area_size(60)
        .build_cartesian_2d((x_lo..x_hi).log_scale(), 0f64..90f64)
        .map_err(err)?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_label_formatter(&|x| format!("{x:.0}"))
        .y_label_formatter(&|y| format!("{y:.0}"))
        .x_desc("specular exponent n (log scale)")
        .y_desc("theta = arccos(c) (degrees)")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .draw()
        .map_err(err)?;
    let rects = row_runs(m, |col, row| Shade::of(m.heat.cell(col, row), tol))
        .into_iter()
        .map(|(corners, shade)| {
            let (r, g, b) = shade.rgb();
            Rectangle::new(corners, RGBColor(r, g, b).filled())
        });
    chart.draw_series(rects).map_err(err)?;
    let mark = |bits: u16| {
        let mut v = Vec::new();
        for (col, &(first, _)) in cols.iter().enumerate() {
            for row in 0..HEAT_ROWS {
                if m.heat.cell(col, row).flags & bits != 0 {
                    let x = (f64::from(first) * column_end(m, col)).sqrt();
                    v.push((x, row as f64 + 0.5));
                }
            }
        }
        v
    };
    let cross_bits = CROSS_FLAGS.iter().fold(0, |a, k| a | k.bit());
    chart
        .draw_series(
            mark(cross_bits)
                .into_iter()
                .map(|p| Cross::new(p, 3, BLACK.stroke_width(1))),
        )
        .map_err(err)?;
    chart
        .draw_series(
            mark(Kind::Underflow.bit())
                .into_iter()
                .map(|p| Circle::new(p, 1, BLACK.filled())),
        )
        .map_err(err)?;
    if let Some((lo, hi)) = m.design_n {
        chart
            .draw_series(std::iter::once(design_box(lo, hi)))
            .map_err(err)?;
    }
    // The legend, drawn by hand beside the plot.
    let font = ("sans-serif", 13).into_font();
    let mut y = 40;
    legend
        .draw(&Text::new(
            format!("|err|, tol = {}", lsb8(tol)),
            (6, y),
            font.clone(),
        ))
        .map_err(err)?;
    y += 22;
    for shade in Shade::ALL {
        let (r, g, b) = shade.rgb();
        legend
            .draw(&Rectangle::new(
                [(6, y), (24, y + 14)],
                RGBColor(r, g, b).filled(),
            ))
            .map_err(err)?;
        legend
            .draw(&Rectangle::new(
                [(6, y), (24, y + 14)],
                BLACK.stroke_width(1),
            ))
            .map_err(err)?;
        legend
            .draw(&Text::new(shade.label(tol), (30, y), font.clone()))
            .map_err(err)?;
        y += 20;
    }
    y += 10;
    legend
        .draw(&Cross::new((15, y + 7), 4, BLACK.stroke_width(1)))
        .map_err(err)?;
    legend
        .draw(&Text::new("negative base, non-", (30, y), font.clone()))
        .map_err(err)?;
    legend
        .draw(&Text::new("monotonic or wrap", (30, y + 16), font.clone()))
        .map_err(err)?;
    y += 40;
    legend
        .draw(&Circle::new((15, y + 7), 2, BLACK.filled()))
        .map_err(err)?;
    legend
        .draw(&Text::new("underflow", (30, y), font.clone()))
        .map_err(err)?;
    if let Some((lo, hi)) = m.design_n {
        y += 30;
        legend
            .draw(&DashedPathElement::new(
                vec![(6, y + 7), (24, y + 7)],
                5,
                3,
                BLACK.stroke_width(2),
            ))
            .map_err(err)?;
        legend
            .draw(&Text::new("design range", (30, y), font.clone()))
            .map_err(err)?;
        legend
            .draw(&Text::new(format!("n = {lo}..={hi}"), (30, y + 16), font))
            .map_err(err)?;
    }
    root.present().map_err(err)
}

/// The dashed outline of a datapath's design range on a map: its exponents, every angle.
fn design_box(lo: u32, hi: u32) -> DashedPathElement<std::vec::IntoIter<(f64, f64)>, i32> {
    let (x0, x1) = (f64::from(lo), f64::from(hi) + 1.0);
    DashedPathElement::new(
        vec![(x0, 0.0), (x0, 90.0), (x1, 90.0), (x1, 0.0), (x0, 0.0)],
        6,
        4,
        BLACK.stroke_width(2),
    )
}

/// Pass and fail on the overview: light blue and vermillion.
const PASS: (u8, u8, u8) = (158, 202, 225);
const FAIL: (u8, u8, u8) = (213, 94, 0);

fn draw_overview<DB: DrawingBackend>(
    root: DrawingArea<DB, Shift>,
    maps: &[PathMap],
    tol: f64,
) -> Result<(), Error> {
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| render_error(e.to_string());
    root.fill(&WHITE).map_err(err)?;
    let n_range = maps.first().map_or((1, 1), |m| {
        (
            m.heat.columns[0].0,
            m.heat.columns[m.heat.columns.len() - 1].1,
        )
    });
    // The design range marked on every tile: the first datapath's (the baseline's in the
    // default map), so each path is judged where that hardware is meant to work.
    let design = maps
        .iter()
        .find_map(|m| m.design_n.map(|d| (m.path.clone(), d)));
    let (top, body) = root.split_vertically(OVERVIEW_HEADER);
    let font = ("sans-serif", 16).into_font();
    top.draw(&Text::new(
        format!(
            "Where each path stays within {} of cos^n and where it fails; x: n = {}..={} (log), y: theta 0..90 deg",
            lsb8(tol),
            n_range.0,
            n_range.1
        ),
        (10, 8),
        font.clone(),
    ))
    .map_err(err)?;
    let mut x = 10;
    for (rgb, label) in [(PASS, "within tolerance"), (FAIL, "fails")] {
        top.draw(&Rectangle::new(
            [(x, 34), (x + 18, 48)],
            RGBColor(rgb.0, rgb.1, rgb.2).filled(),
        ))
        .map_err(err)?;
        top.draw(&Text::new(label, (x + 24, 33), font.clone()))
            .map_err(err)?;
        x += 170;
    }
    top.draw(&Rectangle::new(
        [(x, 34), (x + 18, 48)],
        RGBColor(170, 170, 170).filled(),
    ))
    .map_err(err)?;
    top.draw(&Text::new(
        "n's constants do not fit",
        (x + 24, 33),
        font.clone(),
    ))
    .map_err(err)?;
    x += 230;
    if let Some((path, (lo, hi))) = &design {
        top.draw(&DashedPathElement::new(
            vec![(x, 41), (x + 22, 41)],
            6,
            4,
            BLACK.stroke_width(2),
        ))
        .map_err(err)?;
        top.draw(&Text::new(
            format!("{path}'s design range: n = {lo}..={hi}, every input code (theta 0..90)"),
            (x + 28, 33),
            font,
        ))
        .map_err(err)?;
    }
    let n_cols = 6;
    let n_rows = maps.len().div_ceil(n_cols).max(1);
    let tiles = body.split_evenly((n_rows, n_cols));
    for (tile, m) in tiles.iter().zip(maps) {
        let cols = &m.heat.columns;
        let x_lo = f64::from(cols[0].0);
        let x_hi = f64::from(cols[cols.len() - 1].1) + 1.0;
        let verdict = if m.passes() { "passes" } else { "fails" };
        let mut chart = ChartBuilder::on(tile)
            .caption(format!("{} ({verdict})", m.path), ("sans-serif", 13))
            .margin(4)
            .build_cartesian_2d((x_lo..x_hi).log_scale(), 0f64..90f64)
            .map_err(err)?;
        let class = |col: usize, row: usize| {
            let c = m.heat.cell(col, row);
            let structural =
                c.flags & (Kind::NonFinite.bit() | Kind::Over.bit() | Kind::Under.bit()) != 0;
            if c.flags & Kind::Unrepresentable.bit() != 0 {
                (170, 170, 170)
            } else if c.samples == 0 {
                (250, 250, 250)
            } else if structural {
                FAIL
            } else {
                PASS
            }
        };
        let rects = row_runs(m, class)
            .into_iter()
            .map(|(corners, k)| Rectangle::new(corners, RGBColor(k.0, k.1, k.2).filled()));
        chart.draw_series(rects).map_err(err)?;
        if let Some((_, (lo, hi))) = design {
            chart
                .draw_series(std::iter::once(design_box(lo, hi)))
                .map_err(err)?;
        }
    }
    root.present().map_err(err)
}

/// Height of the overview's title and key.
const OVERVIEW_HEADER: u32 = 60;

/// Renders into an SVG string with a drawing function.
fn svg_with(
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<SVGBackend<'_>, Shift>) -> Result<(), Error>,
) -> Result<String, Error> {
    register_font();
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, size).into_drawing_area();
        draw(root)?;
    }
    // Rectangles meet edge to edge: no anti-aliased seams between them when the browser
    // scales the picture.
    let text = text.replacen("<svg ", "<svg shape-rendering=\"crispEdges\" ", 1);
    Ok(text + "\n")
}

/// Renders into PNG bytes with a drawing function.
fn png_with(
    size: (u32, u32),
    draw: impl FnOnce(DrawingArea<BitMapBackend<'_>, Shift>) -> Result<(), Error>,
) -> Result<Vec<u8>, Error> {
    register_font();
    let (w, h) = size;
    let mut rgb = vec![0u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        draw(root)?;
    }
    crate::report::chart::encode_png(&rgb, size)
}

/// The heat map of one path as SVG text.
pub fn heatmap_svg(m: &PathMap, tol: f64) -> Result<String, Error> {
    svg_with(HEAT_SIZE, |root| draw_heatmap(root, m, tol))
}

/// The heat map of one path as PNG bytes.
pub fn heatmap_png(m: &PathMap, tol: f64) -> Result<Vec<u8>, Error> {
    png_with(HEAT_SIZE, |root| draw_heatmap(root, m, tol))
}

fn overview_size(n_maps: usize) -> (u32, u32) {
    let rows = n_maps.div_ceil(6).max(1) as u32;
    (1200, OVERVIEW_HEADER + 150 * rows)
}

/// The pass/fail overview of every path as SVG text.
pub fn overview_svg(maps: &[PathMap], tol: f64) -> Result<String, Error> {
    svg_with(overview_size(maps.len()), |root| {
        draw_overview(root, maps, tol)
    })
}

/// The pass/fail overview of every path as PNG bytes.
pub fn overview_png(maps: &[PathMap], tol: f64) -> Result<Vec<u8>, Error> {
    png_with(overview_size(maps.len()), |root| {
        draw_overview(root, maps, tol)
    })
}

/// The overshoot chart: the smallest f32-ulp excess over 1 that makes each path overshoot.
/// The paths' lines lie nearly on top of each other, so each has its own dash pattern and a
/// label at its end.
pub fn overshoot_chart(r: &StabilityReport) -> Chart {
    let shown: Vec<_> = r
        .overshoot
        .iter()
        .filter(|o| {
            [
                "powf",
                "powf_f32",
                "schlick",
                "exp_limit",
                "cs16_clamp",
                "cs128_clamp",
                "minimax16",
            ]
            .contains(&o.path.as_str())
        })
        .collect();
    Chart {
        title: format!(
            "Inputs above 1: smallest excess that lifts the lobe more than {}",
            lsb8(r.grid.tol.value)
        ),
        x_label: "specular exponent n (log scale)".into(),
        y_label: "c \u{2212} 1 at the first overshoot (f32 ulps of 1 = 2^-23, log scale)".into(),
        log_x: true,
        log_y: true,
        x_integer: true,
        y_integer: true,
        series: shown
            .iter()
            .enumerate()
            .map(|(i, o)| {
                let (color, _, marker) = style(i);
                Series {
                    label: o.path.clone(),
                    points: o
                        .per_n
                        .iter()
                        .filter_map(|&(n, j)| j.map(|j| (f64::from(n), f64::from(j))))
                        .collect(),
                    line: true,
                    color,
                    dash: Dash::ALL[i % Dash::ALL.len()],
                    marker,
                    bar_width: None,
                }
            })
            .collect(),
        direct_labels: true,
        ..Chart::default()
    }
}

fn deg(c: f64) -> f64 {
    c.clamp(-1.0, 1.0).acos().to_degrees()
}

/// Writes the region table as CSV: one row per path and kind.
pub fn write_regions_csv(w: &mut impl Write, r: &StabilityReport) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record([
        "path",
        "precision",
        "kind",
        "fails",
        "samples",
        "failing",
        "n_min",
        "n_max",
        "c_min",
        "c_max",
        "theta_min_deg",
        "theta_max_deg",
        "worst_abs_err",
        "worst_n",
        "worst_c",
        "stages",
    ])?;
    for m in &r.maps {
        for g in &m.regions {
            csv.record([
                m.path.to_string(),
                m.precision.to_string(),
                g.kind.to_string(),
                g.fails.to_string(),
                g.samples.to_string(),
                g.failing.to_string(),
                g.n_min.to_string(),
                g.n_max.to_string(),
                format!("{:e}", g.c_min),
                format!("{:e}", g.c_max),
                format!("{:.4}", deg(g.c_max)),
                format!("{:.4}", deg(g.c_min)),
                format!("{:e}", g.worst_abs_err),
                g.worst_n.to_string(),
                format!("{:e}", g.worst_c),
                g.stages.join(" "),
            ])?;
        }
    }
    csv.finish().map(drop)
}

/// Writes the special-input outcomes as CSV.
pub fn write_special_csv(w: &mut impl Write, r: &StabilityReport) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record(["path", "input", "n", "output", "verdict"])?;
    for s in &r.special {
        csv.record([
            s.path.to_string(),
            s.input.to_string(),
            s.n.to_string(),
            s.output.to_string(),
            s.verdict.name().to_string(),
        ])?;
    }
    csv.finish().map(drop)
}

/// Writes the overshoot thresholds as CSV: one row per n, one column per float path (empty
/// where no j up to the maximum overshoots).
pub fn write_overshoot_csv(w: &mut impl Write, r: &StabilityReport) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record(
        std::iter::once("n".to_string()).chain(r.overshoot.iter().map(|o| o.path.to_string())),
    )?;
    for (i, &n) in r.grid.n.values().iter().enumerate() {
        csv.record(
            std::iter::once(n.to_string()).chain(
                r.overshoot
                    .iter()
                    .map(|o| o.per_n[i].1.map_or(String::new(), |j| j.to_string())),
            ),
        )?;
    }
    csv.finish().map(drop)
}

/// The file stem of a path's heat map: `heatmap_<name>`, any character outside
/// `A-Za-z0-9_-.+` replaced by `_` (names are unique, see `specfx stability`).
pub fn heatmap_stem(path: &str) -> String {
    let safe: String = path
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.' | '+') {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("heatmap_{safe}")
}

/// The stability report as a document: summary, regions, special inputs, overshoot, figures.
pub fn document(r: &StabilityReport) -> Vec<Block> {
    let tol = r.grid.tol.value;
    let ns = r.grid.n.values();
    let mut doc = vec![
        Block::Heading(1, "Where the methods fail".into()),
        Block::Paragraph(format!(
            "Every path is evaluated at every n = {} and every cosine of its grid in [0, 1] (float paths: steps of 2^-{}; datapaths: every code of their input format), and compared with cos^n in f64. The tolerance is {} = {tol:.3e} on |lobe - cos^n|. A region gathers every sample of a path flagged with one kind; it fails when a sample in it is off by more than the tolerance, when the lobe falls by more than the tolerance in it (`non_monotonic`), or when it is `non_finite` or `unrepresentable`. Other regions are shown as within tolerance: they are where a method is fragile, not yet wrong. Angles are theta = arccos(c).",
            r.grid.n, r.grid.c_bits, r.grid.tol
        )),
        Block::Heading(2, "Kinds".into()),
        Block::Table {
            header: vec!["kind".into(), "meaning".into()],
            rows: Kind::ALL
                .iter()
                .map(|k| vec![format!("`{k}`"), k.describe().to_string()])
                .collect(),
        },
        Block::Heading(2, "Overview".into()),
        Block::Paragraph(format!(
            "{} of {} paths stay within the tolerance with no failing region.",
            r.maps.iter().filter(|m| m.passes()).count(),
            r.maps.len()
        )),
        Block::Figure {
            stem: "overview".into(),
            caption: "Pass (light blue) or fail (vermillion) per path, over n (log) and theta; the dashed box is the first datapath's design range.".into(),
        },
        Block::Table {
            header: vec![
                "path".into(),
                "precision".into(),
                "max |err|".into(),
                "at n".into(),
                "at theta (deg)".into(),
                "failing regions".into(),
                "heat map".into(),
            ],
            rows: r
                .maps
                .iter()
                .map(|m| {
                    let failing: Vec<String> = m
                        .regions
                        .iter()
                        .filter(|g| g.fails)
                        .map(|g| g.kind.to_string())
                        .collect();
                    vec![
                        m.path.clone(),
                        m.precision.clone(),
                        format!("{:.3e}", m.max_abs_err),
                        m.worst_n.to_string(),
                        format!("{:.3}", deg(m.worst_c)),
                        if failing.is_empty() {
                            "none".into()
                        } else {
                            failing.join(", ")
                        },
                        format!("{}.png", heatmap_stem(&m.path)),
                    ]
                })
                .collect(),
        },
        Block::Heading(2, "Failure regions".into()),
        Block::Paragraph(
            "theta range: from the smallest to the largest flagged angle over all n of the region; at n: the extent at the region's last n (largest exponent). Every region's exact extent at every n is in stability.json (`at_n`) for the powers of two, and in the library's `Region::per_n`.".into(),
        ),
    ];
    let mut rows = Vec::new();
    for m in &r.maps {
        for g in &m.regions {
            let last = g.per_n.last();
            rows.push(vec![
                m.path.clone(),
                format!("`{}`", g.kind),
                if g.fails { "fails" } else { "within tolerance" }.into(),
                format!("{}..={}", g.n_min, g.n_max),
                format!("{:.2}..{:.2}", deg(g.c_max), deg(g.c_min)),
                last.map_or(String::new(), |b| {
                    let (a, z) = b.theta_deg();
                    format!("n = {}: {a:.2}..{z:.2}", b.n)
                }),
                g.samples.to_string(),
                g.failing.to_string(),
                format!("{:.3e}", g.worst_abs_err),
                format!("n = {}, theta = {:.2}", g.worst_n, deg(g.worst_c)),
                if let Some(note) = &g.note {
                    note.clone()
                } else {
                    g.stages.join(" ")
                },
            ]);
        }
    }
    doc.push(Block::Table {
        header: vec![
            "path".into(),
            "kind".into(),
            "status".into(),
            "n".into(),
            "theta (deg)".into(),
            "at the last n".into(),
            "samples".into(),
            "beyond tol".into(),
            "worst |err|".into(),
            "worst at".into(),
            "stages / note".into(),
        ],
        rows,
    });
    doc.push(Block::Heading(2, "Special inputs".into()));
    doc.push(Block::Paragraph(format!(
        "Each path's lobe for NaN, the infinities, -0 and cosines just outside [0, 1] as float dot products produce them, at n = {}. Datapaths see the input rounded to their format with saturation (NaN and infinities have no code and are left out). Verdicts: `ok` within the tolerance of cos^n(clamp(c, 0, 1)); `absorbed` a NaN or infinite input gave a finite lobe in [0, 1 + tol]; `nan`, `inf`, `negative`; `off` beyond the tolerance. The table shows n = {}; every n is in special_inputs.csv.",
        SPECIAL_N.map(|n| n.to_string()).join(", "),
        SPECIAL_N[2]
    )));
    let inputs: Vec<String> = {
        let mut v: Vec<String> = Vec::new();
        for s in &r.special {
            if !v.contains(&s.input) {
                v.push(s.input.clone());
            }
        }
        v
    };
    let mut header = vec!["path".to_string()];
    header.extend(inputs.iter().map(|i| format!("c = {i}")));
    let mut rows = Vec::new();
    for m in &r.maps {
        let mut row = vec![m.path.clone()];
        for i in &inputs {
            row.push(
                r.special
                    .iter()
                    .find(|s| s.path == m.path && &s.input == i && s.n == SPECIAL_N[2])
                    .map_or("-".into(), |s| {
                        format!("{} ({})", s.output, s.verdict.name())
                    }),
            );
        }
        rows.push(row);
    }
    doc.push(Block::Table { header, rows });
    doc.push(Block::Heading(2, "Cosines above 1".into()));
    doc.push(Block::Paragraph(format!(
        "A dot product of unit vectors computed in floating point can exceed 1 by a few ulps (2^-23 in f32; about 2^-10 with half-precision normals). For each float path and n, the smallest j in 1..={OVERSHOOT_J_MAX} for which c = 1 + j 2^-23 lifts the lobe more than the tolerance above its value at c = 1 (or makes it NaN, infinite or negative). Datapaths clamp codes above 1.0 and never overshoot. Every n is in overshoot.csv."
    )));
    doc.push(Block::Figure {
        stem: "overshoot".into(),
        caption: "The smallest overshooting excess above 1, per n.".into(),
    });
    let n_max = ns[ns.len() - 1];
    doc.push(Block::Table {
        header: vec![
            "path".into(),
            "smallest n that overshoots".into(),
            format!("first overshooting j at n = {n_max}"),
        ],
        rows: r
            .overshoot
            .iter()
            .map(|o| {
                vec![
                    o.path.clone(),
                    o.n_min.map_or("none".into(), |n| n.to_string()),
                    o.j_at_n_max.map_or("none".into(), |j| j.to_string()),
                ]
            })
            .collect(),
    });
    doc.push(Block::Heading(2, "Heat maps".into()));
    for m in &r.maps {
        doc.push(Block::Image {
            src: format!("{}.png", heatmap_stem(&m.path)),
            caption: format!(
                "{}: |lobe - cos^n| over n and theta (crosses: negative base, non-monotonic or wrap; dots: underflow).",
                m.path
            ),
        });
    }
    doc
}

/// Every file of a stability map's directory, provenance included, rendered in memory:
/// `(name, bytes)`. The heat maps, the overview and the overshoot chart each as SVG and PNG,
/// the three tables, the document (Markdown and HTML, ending with the provenance's line) and
/// the JSON.
pub fn stability_files(r: &StabilityReport, provenance: &Provenance) -> Result<Vec<File>, Error> {
    let tol = r.grid.tol.value;
    let mut files: Vec<File> = Vec::new();
    let mut figure = |stem: &str, svg: &str, png: Vec<u8>| {
        files.push((format!("{stem}.svg"), svg.as_bytes().to_vec()));
        files.push((format!("{stem}.png"), png));
    };
    for m in &r.maps {
        figure(
            &heatmap_stem(&m.path),
            &heatmap_svg(m, tol)?,
            heatmap_png(m, tol)?,
        );
    }
    let overview = overview_svg(&r.maps, tol)?;
    figure("overview", &overview, overview_png(&r.maps, tol)?);
    let (overshoot, chart) = chart_files("overshoot", &overshoot_chart(r))?;
    files.extend(chart);
    files.push(("regions.csv".into(), in_memory(|w| write_regions_csv(w, r))));
    files.push((
        "special_inputs.csv".into(),
        in_memory(|w| write_special_csv(w, r)),
    ));
    files.push((
        "overshoot.csv".into(),
        in_memory(|w| write_overshoot_csv(w, r)),
    ));
    let mut doc = document(r);
    doc.push(Block::Paragraph(provenance.line()));
    files.push((
        "stability.md".into(),
        in_memory(|w| write_markdown(w, &doc)),
    ));
    let html = in_memory(|w| {
        write_html(w, "specfx stability", &doc, |stem| match stem {
            "overview" => Some(overview.clone()),
            "overshoot" => Some(overshoot.clone()),
            _ => None,
        })
    });
    files.push(("stability.html".into(), html));
    files.push(json_file("stability.json", r)?);
    files.extend(provenance.files());
    Ok(files)
}
