//! The images of `specfx render`: each path's picture as PNG, difference heat maps in display
//! LSBs with a colour bar, the per-material error table (Markdown and terminal) and the CSV of
//! the datapath's inputs.

use std::io::{self, Write};

use plotters::prelude::*;

use crate::csv_dialect::CsvWriter;
use crate::error::Error;
use crate::pipeline::Datapath;
use crate::provenance::Provenance;
use crate::report::chart::{encode_png, encode_png_depth, register_font, render_error};
use crate::report::table::{Align, TextTable};
use crate::report::File;
use crate::scene::render::{
    difference, flip_errors, image_error, ImageError, InputsOfN, Rendered, INPUT_BINS, PATHS,
};
use crate::scene::Scene;

/// One path's picture as PNG: 8 bits per channel, or for 10-bit images 16 bits per channel
/// holding the 10-bit codes scaled to the full range (`code * 65535 / 1023`, rounded).
pub fn path_png(r: &Rendered, path: usize) -> Result<Vec<u8>, Error> {
    let codes = &r.codes[path];
    if r.bits == 8 {
        let rgb: Vec<u8> = codes.iter().flat_map(|c| c.map(|x| x as u8)).collect();
        return encode_png(&rgb, (r.width, r.height));
    }
    let max = u32::from((1u16 << r.bits) - 1);
    let bytes: Vec<u8> = codes
        .iter()
        .flat_map(|c| c.map(|x| ((u32::from(x) * 65535 + max / 2) / max) as u16))
        .flat_map(u16::to_be_bytes)
        .collect();
    encode_png_depth(&bytes, (r.width, r.height), png::BitDepth::Sixteen)
}

/// Width of the colour bar panel beside a heat map.
const BAR: u32 = 110;

/// A colour for `t` in [0, 1]: dark blue through red to yellow-white.
fn heat(t: f64) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let stops = [
        (0.0, [40.0, 30.0, 110.0]),
        (0.35, [170.0, 40.0, 120.0]),
        (0.7, [245.0, 120.0, 40.0]),
        (1.0, [255.0, 245.0, 160.0]),
    ];
    let i = stops.iter().rposition(|s| s.0 <= t).unwrap_or(0).min(2);
    let (t0, c0) = stops[i];
    let (t1, c1) = stops[i + 1];
    let u = (t - t0) / (t1 - t0);
    [0, 1, 2].map(|k| (c0[k] + u * (c1[k] - c0[k])).round() as u8)
}

/// The colour of a difference of `d` LSBs on a scale up to `max` (at least 1): a covered
/// pixel without difference is mid grey, the background black.
fn diff_colour(d: u32, max: u32, covered: bool) -> [u8; 3] {
    match (covered, d) {
        (false, _) => [0, 0, 0],
        (true, 0) => [96, 96, 96],
        (true, d) => heat(f64::from(d) / f64::from(max)),
    }
}

/// A heat map of per-pixel differences in display LSBs, with a colour bar labelled from 1 to
/// the largest difference (grey: no difference; black: background).
pub fn heatmap_png(r: &Rendered, diff: &[u32], title: &str) -> Result<Vec<u8>, Error> {
    let max = diff.iter().copied().max().unwrap_or(0).max(1);
    let colour = |i: usize| diff_colour(diff[i], max, r.material[i].is_some());
    panel_png(
        r,
        colour,
        [title, "display LSBs"],
        (&max.to_string(), "1"),
        true,
    )
}

/// The FLIP error of each pixel (0..1) on the same colour scale, the background black.
pub fn flip_png(r: &Rendered, flip: &[f32], title: &str) -> Result<Vec<u8>, Error> {
    let colour = |i: usize| match r.material[i] {
        None => [0, 0, 0],
        Some(_) => heat(f64::from(flip[i])),
    };
    panel_png(r, colour, [title, "FLIP error"], ("1", "0"), false)
}

/// A picture coloured pixel by pixel, with a colour bar (top and bottom labels) and, for
/// difference maps, a grey "0" swatch.
fn panel_png(
    r: &Rendered,
    colour: impl Fn(usize) -> [u8; 3],
    title: [&str; 2],
    labels: (&str, &str),
    zero_swatch: bool,
) -> Result<Vec<u8>, Error> {
    register_font();
    let (w, h) = (r.width, r.height.max(160));
    let size = (w + BAR, h);
    let mut rgb = vec![255u8; (size.0 * size.1 * 3) as usize];
    for y in 0..r.height {
        for x in 0..r.width {
            let c = colour((y * r.width + x) as usize);
            let o = ((y * size.0 + x) * 3) as usize;
            rgb[o..o + 3].copy_from_slice(&c);
        }
    }
    {
        let root = BitMapBackend::with_buffer(&mut rgb, size).into_drawing_area();
        let err = |e: DrawingAreaErrorKind<_>| render_error(e.to_string());
        let font = ("sans-serif", 13).into_font().color(&BLACK);
        let x0 = w as i32 + 14;
        let (top, bottom) = (34, h as i32 - 24);
        root.draw(&Text::new(title[0].to_string(), (x0 - 6, 4), font.clone()))
            .map_err(err)?;
        root.draw(&Text::new(title[1].to_string(), (x0 - 6, 18), font.clone()))
            .map_err(err)?;
        let span = (bottom - top).max(1);
        for yy in top..bottom {
            let t = f64::from(bottom - 1 - yy) / f64::from(span - 1).max(1.0);
            let c = heat(t);
            root.draw(&Rectangle::new(
                [(x0, yy), (x0 + 24, yy + 1)],
                RGBColor(c[0], c[1], c[2]).filled(),
            ))
            .map_err(err)?;
        }
        root.draw(&Text::new(
            labels.0.to_string(),
            (x0 + 30, top - 2),
            font.clone(),
        ))
        .map_err(err)?;
        root.draw(&Text::new(
            labels.1.to_string(),
            (x0 + 30, bottom - 12),
            font.clone(),
        ))
        .map_err(err)?;
        if zero_swatch {
            root.draw(&Rectangle::new(
                [(x0, bottom + 6), (x0 + 24, bottom + 18)],
                RGBColor(96, 96, 96).filled(),
            ))
            .map_err(err)?;
            root.draw(&Text::new("0", (x0 + 30, bottom + 5), font))
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    encode_png(&rgb, size)
}

/// One row of the per-material table.
#[derive(Debug, Clone, serde::Serialize)]
pub struct MaterialRow {
    /// The material's name, or "all".
    pub material: String,
    /// Its exponent (0 for "all").
    pub n: u32,
    /// The datapath against f64 cos^n with its classic coefficient: the total error.
    pub total: ImageError,
    /// The datapath against the f64 model of its own algorithm: the quantization error.
    pub quant: ImageError,
}

/// What the table's figures mean, after it.
fn table_legend(bits: u32) -> String {
    format!(
        "Errors are in display LSBs of the {bits}-bit sRGB image (the largest channel difference of a pixel); \"differing\" is the share of the material's pixels where any channel differs; FLIP is the mean of NVIDIA's FLIP (LDR, 67 pixels per degree) over the material's pixels."
    )
}

/// Writes the table for the terminal, fitted into `width` characters (`None`: as wide as its
/// content; see [`TextTable::write`]), and what its figures mean.
pub fn write_table(
    w: &mut impl Write,
    rows: &[MaterialRow],
    bits: u32,
    width: Option<u16>,
) -> io::Result<()> {
    let mut table = TextTable::new(&[
        ("material", Align::Left),
        ("n", Align::Right),
        ("pixels", Align::Right),
        ("max vs cos^n", Align::Right),
        ("mean vs cos^n", Align::Right),
        ("differing vs cos^n", Align::Right),
        ("FLIP vs cos^n", Align::Right),
        ("max vs f64 model", Align::Right),
        ("mean vs f64 model", Align::Right),
        ("differing vs f64 model", Align::Right),
        ("FLIP vs f64 model", Align::Right),
    ]);
    for r in rows {
        table.row([
            r.material.clone(),
            if r.n == 0 {
                "-".to_string()
            } else {
                r.n.to_string()
            },
            r.total.pixels.to_string(),
            r.total.max_lsb.to_string(),
            format!("{:.4}", r.total.mean_lsb),
            format!("{:.2}%", 100.0 * r.total.differing),
            format!("{:.5}", r.total.flip_mean),
            r.quant.max_lsb.to_string(),
            format!("{:.4}", r.quant.mean_lsb),
            format!("{:.2}%", 100.0 * r.quant.differing),
            format!("{:.5}", r.quant.flip_mean),
        ]);
    }
    table.write(w, width)?;
    writeln!(w)?;
    writeln!(w, "{}", table_legend(bits))
}

/// Writes the datapath's inputs as CSV: per n the count, code and c range, and the histogram
/// of c in [`INPUT_BINS`] bins (`h00`, `h01`, ..).
pub fn write_inputs_csv(w: &mut impl Write, inputs: &[InputsOfN], lsb: f64) -> io::Result<()> {
    let mut csv = CsvWriter::new(w);
    csv.record(
        ["n", "count", "code_min", "code_max", "c_min", "c_max"]
            .map(String::from)
            .into_iter()
            .chain((0..INPUT_BINS).map(|i| format!("h{i:02}"))),
    )?;
    for e in inputs {
        csv.record(
            [
                e.n.to_string(),
                e.count.to_string(),
                e.code_min.to_string(),
                e.code_max.to_string(),
                (e.code_min as f64 * lsb).to_string(),
                (e.code_max as f64 * lsb).to_string(),
            ]
            .into_iter()
            .chain(e.histogram.iter().map(|h| h.to_string())),
        )?;
    }
    csv.finish().map(drop)
}

/// The table as Markdown (names are escaped for Markdown and HTML).
pub fn table_markdown(rows: &[MaterialRow], bits: u32) -> String {
    let mut s = "| material | n | pixels | max vs cos^n | mean vs cos^n | differing vs cos^n | FLIP vs cos^n | max vs f64 model | mean vs f64 model | differing vs f64 model | FLIP vs f64 model |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n".to_string();
    for r in rows {
        let name: String = r
            .material
            .chars()
            .flat_map(|c| match c {
                '<' => "&lt;".chars().collect::<Vec<_>>(),
                '>' => "&gt;".chars().collect(),
                '&' => "&amp;".chars().collect(),
                '|' | '\\' | '*' | '_' | '`' | '[' | ']' => vec!['\\', c],
                c if c.is_control() => vec![' '],
                c => vec![c],
            })
            .collect();
        s.push_str(&format!(
            "| {name} | {} | {} | {} | {:.4} | {:.2}% | {:.5} | {} | {:.4} | {:.2}% | {:.5} |\n",
            if r.n == 0 {
                "-".to_string()
            } else {
                r.n.to_string()
            },
            r.total.pixels,
            r.total.max_lsb,
            r.total.mean_lsb,
            100.0 * r.total.differing,
            r.total.flip_mean,
            r.quant.max_lsb,
            r.quant.mean_lsb,
            100.0 * r.quant.differing,
            r.quant.flip_mean,
        ));
    }
    s.push_str(&format!("\n{}\n", table_legend(bits)));
    s
}

/// The files [`render_files`] renders, in its order.
pub const RENDER_FILES: [&str; 10] = [
    "f64_cos_n.png",
    "f64_model.png",
    "datapath.png",
    "diff_vs_cos_n.png",
    "diff_vs_f64_model.png",
    "flip_vs_cos_n.png",
    "flip_vs_f64_model.png",
    "render.md",
    "render.json",
    "inputs.csv",
];

/// The per-pixel FLIP of a render's datapath image against f64 cos^n (the total error) and
/// against the f64 model (the quantization), computed once for the table and the maps.
pub struct Flips {
    /// Against f64 cos^n.
    pub total: Vec<f32>,
    /// Against the f64 model.
    pub quant: Vec<f32>,
}

impl Flips {
    /// The FLIP maps of `r`'s datapath image.
    pub fn of(r: &Rendered) -> Flips {
        Flips {
            total: flip_errors(r, 2, 0),
            quant: flip_errors(r, 2, 1),
        }
    }
}

/// The error table of a render of `scene` through a datapath: a row per material and one for
/// the whole image.
pub fn material_rows(scene: &Scene, r: &Rendered, flips: &Flips) -> Vec<MaterialRow> {
    let datapath = 2;
    let (flip_total, flip_quant) = (&flips.total, &flips.quant);
    let mut rows: Vec<MaterialRow> = scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| MaterialRow {
            material: m.name.clone(),
            n: m.n,
            total: image_error(r, datapath, 0, Some(i as u16), flip_total),
            quant: image_error(r, datapath, 1, Some(i as u16), flip_quant),
        })
        .collect();
    rows.push(MaterialRow {
        material: "all".into(),
        n: 0,
        total: image_error(r, datapath, 0, None, flip_total),
        quant: image_error(r, datapath, 1, None, flip_quant),
    });
    rows
}

/// Every file of a render's directory, provenance included ([`RENDER_FILES`] and then the
/// provenance's), rendered in memory: the three pictures, the difference and FLIP maps, the
/// document (naming the scene `label`), the table's JSON and the datapath's inputs.
pub fn render_files(
    r: &Rendered,
    flips: &Flips,
    rows: &[MaterialRow],
    label: &str,
    dp: &Datapath,
    provenance: &Provenance,
) -> Result<Vec<File>, Error> {
    let datapath = 2;
    let mut files: Vec<File> = Vec::new();
    for (p, name) in PATHS.iter().enumerate() {
        files.push((format!("{name}.png"), path_png(r, p)?));
    }
    let (total, quant) = (difference(r, datapath, 0), difference(r, datapath, 1));
    files.push((
        "diff_vs_cos_n.png".into(),
        heatmap_png(r, &total, "vs cos^n")?,
    ));
    files.push((
        "diff_vs_f64_model.png".into(),
        heatmap_png(r, &quant, "vs f64 model")?,
    ));
    files.push((
        "flip_vs_cos_n.png".into(),
        flip_png(r, &flips.total, "vs cos^n")?,
    ));
    files.push((
        "flip_vs_f64_model.png".into(),
        flip_png(r, &flips.quant, "vs f64 model")?,
    ));
    let md = format!(
        "# Render of {} through {}\n\nImages: `f64_cos_n.png` (f64 cos^n, classic coefficient), `f64_model.png` (the f64 model of the datapath's algorithm and coefficient), `datapath.png` (bit-accurate, the fragment's cosine quantized to {}); differences in display LSBs `diff_vs_cos_n.png`, `diff_vs_f64_model.png`, and FLIP maps `flip_vs_cos_n.png`, `flip_vs_f64_model.png`.\n\n\"vs cos^n\" is the total error the viewer sees: the approximation of cos^n by the datapath's algorithm (large near highlights of high n) plus its quantization; \"vs f64 model\" is the quantization alone.\n\n{}\n{}\n",
        crate::report::doc::md_escape(label),
        dp.config().name,
        dp.config().c.format,
        table_markdown(rows, r.bits),
        provenance.line(),
    );
    files.push(("render.md".into(), md.into_bytes()));
    // Pretty JSON without a final newline, as render.json has always been written.
    let json = serde_json::to_vec_pretty(rows).map_err(|e| Error::Render {
        message: format!("render.json: {e}"),
    })?;
    files.push(("render.json".into(), json));
    let lsb = dp.config().c.format.lsb();
    let csv = crate::report::in_memory(|w| write_inputs_csv(w, &r.inputs, lsb));
    files.push(("inputs.csv".into(), csv));
    files.extend(provenance.files());
    Ok(files)
}
