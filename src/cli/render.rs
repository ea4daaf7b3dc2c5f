//! `specfx render`: renders a scene (the built-in one by default) with three specular paths
//! and writes each picture, difference heat maps and the per-material error table.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;

use super::output::{print_json, write_atomic, write_provenance};
use super::Outcome;
use specfx::nset::NSet;
use specfx::pipeline::Datapath;
use specfx::provenance::{Inputs, Provenance};
use specfx::report::scene::{
    flip_png, heatmap_png, path_png, table_markdown, write_inputs_csv, write_table, MaterialRow,
};
use specfx::scene::render::{
    difference, flip_errors, image_error, render_fragments, trace, Fragments, InputsOfN, PATHS,
};
use specfx::scene::Scene;

/// Arguments of `specfx render`.
#[derive(Debug, Args)]
pub struct RenderArgs {
    /// A scene TOML file (default: the built-in cells, vessel and bone scene).
    #[arg(long)]
    scene: Option<PathBuf>,
    /// The datapath: a TOML configuration file or a built-in name; its n set is replaced by
    /// the scene's exponents.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Output directory.
    #[arg(long, default_value = "specfx-render")]
    out: PathBuf,
    /// Replace an existing output directory that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
    /// Print the table as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Runs `specfx render`.
pub fn run(args: &RenderArgs) -> Result<Outcome> {
    let (scene, label) = load_scene(args.scene.as_deref())?;
    let ns = NSet::from_values(&scene.exponents())?;
    let dp: Datapath = super::datapath::load(&args.config, Some(&ns))?;
    let out_dir = super::output::OutDir::begin(
        &args.out,
        "render",
        args.force,
        &super::output::inputs(&args.config, args.scene.as_deref()),
    )?;
    let (rows, _markdown) = render_scene(&scene, &label, &dp, out_dir.path())?;
    out_dir.commit()?;
    if args.json {
        print_json(&rows)?;
    } else {
        super::output::print_with(|w| {
            write_table(w, &rows, scene.image.bits, super::terminal::table_width())
        })?;
        log::info!("render: wrote {}", args.out.display());
    }
    Ok(Outcome::Ok)
}

/// The files [`render_scene`] writes, in its output directory.
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

/// Renders `scene` (named `label` in the document) through `dp` (whose n set holds the scene's
/// exponents) into `out`: the pictures, maps and table. Returns the table's rows and its
/// Markdown.
pub fn render_scene(
    scene: &Scene,
    label: &str,
    dp: &Datapath,
    out: &Path,
) -> Result<(Vec<MaterialRow>, String)> {
    let (w, h) = (scene.image.width, scene.image.height);
    log::info!(
        "render: {w}x{h}, {} objects, {} lights, datapath {}",
        scene.objects.len(),
        scene.lights.len(),
        dp.config().name
    );
    let frags = trace_with_progress(scene);
    let r = render_fragments(scene, &frags, dp);
    let datapath = 2;
    let flip_total = flip_errors(&r, datapath, 0);
    let flip_quant = flip_errors(&r, datapath, 1);
    let mut rows: Vec<MaterialRow> = scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| MaterialRow {
            material: m.name.clone(),
            n: m.n,
            total: image_error(&r, datapath, 0, Some(i as u16), &flip_total),
            quant: image_error(&r, datapath, 1, Some(i as u16), &flip_quant),
        })
        .collect();
    rows.push(MaterialRow {
        material: "all".into(),
        n: 0,
        total: image_error(&r, datapath, 0, None, &flip_total),
        quant: image_error(&r, datapath, 1, None, &flip_quant),
    });
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    for (p, name) in PATHS.iter().enumerate() {
        write_atomic(&out.join(format!("{name}.png")), &path_png(&r, p)?)?;
    }
    let total = difference(&r, datapath, 0);
    let quant = difference(&r, datapath, 1);
    write_atomic(
        &out.join("diff_vs_cos_n.png"),
        &heatmap_png(&r, &total, "vs cos^n")?,
    )?;
    write_atomic(
        &out.join("diff_vs_f64_model.png"),
        &heatmap_png(&r, &quant, "vs f64 model")?,
    )?;
    write_atomic(
        &out.join("flip_vs_cos_n.png"),
        &flip_png(&r, &flip_total, "vs cos^n")?,
    )?;
    write_atomic(
        &out.join("flip_vs_f64_model.png"),
        &flip_png(&r, &flip_quant, "vs f64 model")?,
    )?;
    let table = table_markdown(&rows, r.bits);
    let provenance = Provenance::new(
        &Inputs::new("render")
            .table("scene", scene.canonical())
            .config(dp.config()),
    );
    let mut md = format!(
        "# Render of {} through {}\n\nImages: `f64_cos_n.png` (f64 cos^n, classic coefficient), `f64_model.png` (the f64 model of the datapath's algorithm and coefficient), `datapath.png` (bit-accurate, the fragment's cosine quantized to {}); differences in display LSBs `diff_vs_cos_n.png`, `diff_vs_f64_model.png`, and FLIP maps `flip_vs_cos_n.png`, `flip_vs_f64_model.png`.\n\n\"vs cos^n\" is the total error the viewer sees: the approximation of cos^n by the datapath's algorithm (large near highlights of high n) plus its quantization; \"vs f64 model\" is the quantization alone.\n\n{table}",
        specfx::report::doc::md_escape(label),
        dp.config().name,
        dp.config().c.format,
    );
    md.push_str(&format!("\n{}\n", provenance.line()));
    write_atomic(&out.join("render.md"), md.as_bytes())?;
    let json = serde_json::to_vec_pretty(&rows)?;
    write_atomic(&out.join("render.json"), &json)?;
    let csv = inputs_csv(&r.inputs, dp.config().c.format.lsb());
    write_atomic(&out.join("inputs.csv"), csv.as_bytes())?;
    write_provenance(out, &provenance)?;
    Ok((rows, table))
}

/// Traces a scene, showing its progress in rows.
pub fn trace_with_progress(scene: &Scene) -> Fragments {
    let bar = super::progress::Progress::new("trace", "rows", u64::from(scene.image.height));
    let frags = trace(scene, &|done: usize, _rows: usize| {
        bar.set_position(done as u64)
    });
    bar.finish();
    frags
}

/// The datapath inputs as CSV ([`specfx::report::scene::write_inputs_csv`]).
pub fn inputs_csv(inputs: &[InputsOfN], lsb: f64) -> String {
    let mut csv = Vec::new();
    write_inputs_csv(&mut csv, inputs, lsb).expect("writing into memory cannot fail");
    String::from_utf8(csv).expect("the CSV is UTF-8")
}

/// Reads a scene file (meshes relative to it), or the built-in scene; returns it with how
/// documents name it (its path, or "the built-in scene").
pub fn load_scene(path: Option<&Path>) -> Result<(Scene, String)> {
    let label = path.map_or("the built-in scene".to_string(), |p| {
        p.display().to_string()
    });
    let scene = match path {
        None => Scene::default_scene(),
        Some(path) => {
            let text = super::input::read_text(path, &format!("scene {}", path.display()))?;
            // Mesh files are named relative to the scene file.
            let dir = path.parent().map(|d| d.to_path_buf()).unwrap_or_default();
            let load = |file: &str| {
                let p = dir.join(file);
                super::input::read_bytes(
                    &p,
                    &p.display().to_string(),
                    super::input::MAX_BINARY_BYTES,
                )
                .map_err(|e| std::io::Error::other(format!("{e:#}")))
            };
            Scene::from_toml_with(&text, &load)
                .with_context(|| format!("scene {}", path.display()))?
        }
    };
    Ok((scene, label))
}
