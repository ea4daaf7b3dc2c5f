//! `specfx stability`: maps where every method and datapath fails, with heat maps and tables.

use std::io::Write;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;

use super::output::print_json;
use super::Outcome;
use specfx::analysis::stability::{
    analyse, default_paths, FloatPath, Grid, MapPath, StabilityReport, Tolerance,
};
use specfx::nset::NSet;
use specfx::output::write_all_in;
use specfx::provenance::Provenance;
use specfx::report::stability::stability_files;
use specfx::report::table::{Align, TextTable};

/// Arguments of `specfx stability`.
#[derive(Debug, Args)]
pub struct StabilityArgs {
    /// Output directory.
    #[arg(long, default_value = "specfx-stability")]
    out: PathBuf,
    /// Replace an existing output directory that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
    /// Exponents of the map.
    #[arg(long, default_value = "1..=4096")]
    n: NSet,
    /// Float paths are sampled at every c = j / 2^C_BITS in [0, 1].
    #[arg(long, default_value_t = 15)]
    c_bits: u32,
    /// Tolerance on |lobe - cos^n|: "1 lsb8" (2^-8), "0.5 lsb10", or a number.
    #[arg(long, default_value = "1 lsb8")]
    tol: Tolerance,
    /// Datapaths to map (TOML files or built-in names), repeatable; replaces the built-in
    /// baseline, narrow_sat and narrow_wrap.
    #[arg(long)]
    config: Vec<String>,
    /// Float paths: "all", "none", or a comma list of names (powf, powf_f32, powi, schlick,
    /// exp_limit, cs16_clamp, minimax16, ...).
    #[arg(long, default_value = "all")]
    float: String,
    /// Print the report as JSON on stdout.
    #[arg(long)]
    json: bool,
}

/// `name`, or `name-2`, `name-3` ... : the first that no path of `paths` has (compared
/// without case, since the names become file names, on file systems that may ignore case).
fn unique_name(name: &str, paths: &[MapPath]) -> String {
    let taken = |candidate: &str| {
        paths
            .iter()
            .any(|p| p.name().eq_ignore_ascii_case(candidate))
    };
    if !taken(name) {
        return name.to_string();
    }
    (2..)
        .map(|i| format!("{name}-{i}"))
        .find(|c| !taken(c))
        .expect("some suffix is free")
}

fn select_paths(args: &StabilityArgs) -> Result<Vec<MapPath>> {
    let defaults = default_paths();
    let floats: Vec<FloatPath> = FloatPath::default_set();
    let mut paths: Vec<MapPath> = match args.float.trim() {
        "all" => floats.into_iter().map(MapPath::Float).collect(),
        "none" => Vec::new(),
        list => {
            let mut v = Vec::new();
            for name in list.split(',').map(str::trim) {
                let Some(p) = floats.iter().find(|p| p.name() == name) else {
                    bail!(
                        "--float: unknown path '{name}'; expected all, none or names among {}",
                        floats
                            .iter()
                            .map(|p| p.name())
                            .collect::<Vec<_>>()
                            .join(", ")
                    );
                };
                if v.iter().any(|q: &MapPath| q.name() == name) {
                    bail!("--float: '{name}' is listed twice");
                }
                v.push(MapPath::Float(*p));
            }
            v
        }
    };
    if args.config.is_empty() {
        paths.extend(
            defaults
                .into_iter()
                .filter(|p| matches!(p, MapPath::Fixed(_))),
        );
    } else {
        for arg in &args.config {
            let dp = specfx::input::load_datapath(arg, None)?;
            let mut config = dp.config().clone();
            let name = unique_name(&config.name, &paths);
            if name != config.name {
                log::warn!(
                    "stability: another path is already named '{}'; --config {arg} is shown as '{name}'",
                    config.name
                );
                config.name = name;
            }
            paths.push(MapPath::Fixed(Box::new(config)));
        }
    }
    if paths.is_empty() {
        bail!("--float none and no datapath: nothing to map");
    }
    Ok(paths)
}

/// Maps every path of `paths` over `grid` and writes the report into `dir`; returns the report.
pub fn stability(dir: &Path, paths: &[MapPath], grid: &Grid) -> Result<StabilityReport> {
    let bar = super::progress::Progress::new("stability", "path-exponent columns", 0);
    let progress = |done: usize, total: usize| {
        bar.set_len(total as u64);
        bar.set_position(done as u64);
    };
    log::info!(
        "stability: {} paths, n = {}, c in steps of 2^-{}, tolerance {}",
        paths.len(),
        grid.n,
        grid.c_bits,
        grid.tol
    );
    let report = analyse(paths, grid, &progress)?;
    bar.finish();
    log::info!("stability: writing heat maps and tables");
    let provenance = Provenance::new(&specfx::analysis::stability::inputs(paths, grid));
    write_all_in(dir, &stability_files(&report, &provenance)?)?;
    Ok(report)
}

/// Runs `specfx stability`.
pub fn run(args: &StabilityArgs) -> Result<Outcome> {
    let paths = select_paths(args)?;
    let grid = Grid {
        n: args.n.clone(),
        c_bits: args.c_bits,
        tol: args.tol.clone(),
    };
    if !(1..=24).contains(&grid.c_bits) {
        bail!("--c-bits: expected 1..=24, got {}", grid.c_bits);
    }
    let work = specfx::analysis::stability::samples(&paths, &grid);
    if work > specfx::analysis::stability::MAX_SAMPLES {
        bail!(
            "--n, --c-bits, --float and --config: {} paths x {} exponents x their cosines is {work} samples, \
             above the limit of 2^34 = {}; map fewer exponents, a coarser --c-bits or fewer paths",
            paths.len(),
            grid.n.values().len(),
            specfx::analysis::stability::MAX_SAMPLES
        );
    }
    let out_dir = specfx::output::OutDir::begin(
        &args.out,
        "stability",
        args.force,
        &args
            .config
            .iter()
            .flat_map(|c| super::output::config_input(c))
            .map(|p| ("--config", p))
            .collect::<Vec<_>>(),
    )?;
    let report = stability(out_dir.path(), &paths, &grid)?;
    out_dir.commit()?;
    if args.json {
        print_json(&report)?;
        return Ok(Outcome::Ok);
    }
    let mut table = TextTable::new(&[
        ("path", Align::Left),
        ("precision", Align::Left),
        ("max |err|", Align::Right),
        ("at n", Align::Right),
        ("theta", Align::Right),
        ("failing regions", Align::Left),
    ])
    .gap_before(5, 1);
    for m in &report.maps {
        let failing: Vec<String> = m
            .regions
            .iter()
            .filter(|g| g.fails)
            .map(|g| format!("{} (n {}..={})", g.kind, g.n_min, g.n_max))
            .collect();
        table.row([
            m.path.clone(),
            m.precision.clone(),
            format!("{:.3e}", m.max_abs_err),
            m.worst_n.to_string(),
            format!("{:.3}", m.worst_c.clamp(-1.0, 1.0).acos().to_degrees()),
            if failing.is_empty() {
                "none".to_string()
            } else {
                failing.join(", ")
            },
        ]);
    }
    let mut out = super::output::stdout();
    table.write(&mut out, super::terminal::table_width())?;
    writeln!(
        out,
        "written to {} (stability.html, stability.md, stability.json, regions.csv, heat maps)",
        args.out.display()
    )?;
    Ok(Outcome::Ok)
}
