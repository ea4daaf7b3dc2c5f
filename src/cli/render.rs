//! `specfx render`: renders a scene (the built-in one by default) with three specular paths
//! and writes each picture, difference heat maps and the per-material error table.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;

use super::output::print_json;
use super::Outcome;
use specfx::nset::NSet;
use specfx::output::write_all_in;
use specfx::pipeline::Datapath;
use specfx::provenance::Provenance;
use specfx::report::scene::{material_rows, render_files, write_table, Flips, MaterialRow};
use specfx::scene::render::{inputs, render_fragments, trace, Fragments};
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
    let dp: Datapath = specfx::input::load_datapath(&args.config, Some(&ns))?;
    let out_dir = specfx::output::OutDir::begin(
        &args.out,
        "render",
        args.force,
        &super::output::inputs(&args.config, args.scene.as_deref()),
    )?;
    let rows = render_scene(&scene, &label, &dp, out_dir.path())?;
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

/// Renders `scene` (named `label` in the document) through `dp` (whose n set holds the scene's
/// exponents) into `out` (the files of [`RENDER_FILES`]); returns the table's rows.
pub fn render_scene(
    scene: &Scene,
    label: &str,
    dp: &Datapath,
    out: &Path,
) -> Result<Vec<MaterialRow>> {
    let (w, h) = (scene.image.width, scene.image.height);
    log::info!(
        "render: {w}x{h}, {} objects, {} lights, datapath {}",
        scene.objects.len(),
        scene.lights.len(),
        dp.config().name
    );
    let frags = trace_with_progress(scene);
    let r = render_fragments(scene, &frags, dp);
    let flips = Flips::of(&r);
    let rows = material_rows(scene, &r, &flips);
    let provenance = Provenance::new(&inputs(scene, dp));
    write_all_in(
        out,
        &render_files(&r, &flips, &rows, label, dp, &provenance)?,
    )?;
    Ok(rows)
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

/// Reads a scene file (meshes relative to it), or the built-in scene; returns it with how
/// documents name it (its path, or "the built-in scene").
pub fn load_scene(path: Option<&Path>) -> Result<(Scene, String)> {
    let label = path.map_or("the built-in scene".to_string(), |p| {
        p.display().to_string()
    });
    let scene = match path {
        None => Scene::default_scene(),
        Some(path) => {
            let text = specfx::input::read_text(path, &format!("scene {}", path.display()))?;
            // Mesh files are named relative to the scene file.
            let dir = path.parent().map(|d| d.to_path_buf()).unwrap_or_default();
            let load = |file: &str| {
                let p = dir.join(file);
                specfx::input::read_bytes(
                    &p,
                    &p.display().to_string(),
                    specfx::input::MAX_BINARY_BYTES,
                )
                .map_err(|e| std::io::Error::other(format!("{e:#}")))
            };
            Scene::from_toml_with(&text, &load)
                .with_context(|| format!("scene {}", path.display()))?
        }
    };
    Ok((scene, label))
}
