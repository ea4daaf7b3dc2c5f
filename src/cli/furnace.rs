//! `specfx furnace`: the white-furnace check of every normalised form (reflectance against
//! incident angle for f64 cos^n, the configuration's f64 lobe with the paper's and the exact
//! coefficient, and the bit-accurate datapath), with tables, CSV, JSON and a chart per form.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use super::output::print_json;
use super::Outcome;
use specfx::analysis::furnace::{
    furnace_with_progress, inputs, parse_angles, FurnaceReport, FurnaceSettings, DEFAULT_ANGLES,
};
use specfx::nset::NSet;
use specfx::output::write_all_in;
use specfx::provenance::Provenance;
use specfx::report::furnace::{furnace_files, write_summary};

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
    let dp = specfx::input::load_datapath(&args.config, None)?;
    let settings = FurnaceSettings::new(&dp, args.n.as_ref(), angles)
        .with_context(|| format!("config {}", args.config))?;
    let out_dir = specfx::output::OutDir::begin(
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
    let provenance = Provenance::new(&inputs(dp, settings));
    write_all_in(out, &furnace_files(&report, &provenance)?)?;
    Ok(report)
}
