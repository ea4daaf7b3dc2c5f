//! `specfx furnace`: the white-furnace check of every normalised form (reflectance against
//! incident angle for f64 cos^n, the configuration's f64 lobe with the paper's and the exact
//! coefficient, and the bit-accurate datapath), with tables, CSV, JSON and a chart per form.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use super::output::{print_json, write_atomic, write_figure, write_provenance};
use super::Outcome;
use specfx::analysis::furnace::{
    furnace_with_progress, parse_angles, FurnaceReport, FurnaceSettings, DEFAULT_ANGLES,
};
use specfx::nset::NSet;
use specfx::provenance::{Inputs, Provenance};
use specfx::report::doc::{write_markdown, Block};
use specfx::report::furnace::{
    chart_png, chart_stem, chart_svg, document, write_csv, write_summary,
};

/// Arguments of `specfx furnace`.
#[derive(Debug, Args)]
pub struct FurnaceArgs {
    /// The datapath: a TOML configuration file or a built-in name.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Exponents, inside the configuration's n set (default: its powers of two, its minimum
    /// and its maximum).
    #[arg(long)]
    n: Option<NSet>,
    /// Incident angles in degrees, in [0, 90): a comma list (0,30,60) or ranges with a step
    /// (0..85:5, both ends included).
    #[arg(long, default_value = DEFAULT_ANGLES)]
    angles: String,
    /// Output directory.
    #[arg(long, default_value = "specfx-furnace")]
    out: PathBuf,
    /// Replace an existing output directory that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
    /// Print the summary as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// Runs `specfx furnace`.
pub fn run(args: &FurnaceArgs) -> Result<Outcome> {
    let angles = parse_angles(&args.angles).context("--angles")?;
    let dp = super::datapath::load(&args.config, None)?;
    let settings = FurnaceSettings::new(&dp, args.n.as_ref(), angles)
        .with_context(|| format!("config {}", args.config))?;
    let out_dir = super::output::OutDir::begin(
        &args.out,
        "furnace",
        args.force,
        &super::output::inputs(&args.config, None),
    )?;
    log::info!(
        "furnace: 6 forms x {} exponents x {} angles, 4 paths, datapath {}",
        settings.ns().len(),
        settings.angles_deg().len(),
        dp.config().name
    );
    let report = write_furnace(&dp, &settings, out_dir.path())?;
    out_dir.commit()?;
    let out = &args.out;
    let summary = report.summary();
    if args.json {
        print_json(&summary)?;
    } else {
        super::output::print_with(|w| write_summary(w, &summary, super::terminal::table_width()))?;
        log::info!("furnace: wrote {}", out.display());
    }
    Ok(Outcome::Ok)
}

/// Runs the furnace and writes its files into `out` (charts, `furnace.md`, `.csv`, `.json`);
/// returns the report and the files written.
pub fn write_furnace(
    dp: &specfx::pipeline::Datapath,
    settings: &FurnaceSettings,
    out: &std::path::Path,
) -> Result<FurnaceReport> {
    let bar = super::progress::Progress::new("furnace", "form-exponent pairs", 0);
    let report = furnace_with_progress(dp, settings, &|done, total| {
        bar.set_len(total as u64);
        bar.set_position(done as u64);
    });
    bar.finish();
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    for (i, f) in report.forms.iter().enumerate() {
        let svg = chart_svg(&report, i)?;
        let png = chart_png(&report, i)?;
        write_figure(out, &chart_stem(f.form), &svg, &png)?;
    }
    let provenance = Provenance::new(
        &Inputs::new("furnace")
            .config(dp.config())
            .option("n", settings.ns().to_vec())
            .option("angles", settings.angles_deg().to_vec()),
    );
    let mut doc = document(&report);
    doc.push(Block::Paragraph(provenance.line()));
    let mut md = Vec::new();
    write_markdown(&mut md, &doc)?;
    write_atomic(&out.join("furnace.md"), &md)?;
    let mut csv = Vec::new();
    write_csv(&mut csv, &report)?;
    write_atomic(&out.join("furnace.csv"), &csv)?;
    let mut json = serde_json::to_vec_pretty(&report)?;
    json.push(b'\n');
    write_atomic(&out.join("furnace.json"), &json)?;
    write_provenance(out, &provenance)?;
    Ok(report)
}
