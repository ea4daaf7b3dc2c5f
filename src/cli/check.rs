//! `specfx check`: the exhaustive accuracy check of a datapath.

use anyhow::{anyhow, Result};
use clap::Args;

use super::output::{print_json, print_with};
use super::Outcome;
use specfx::analysis::check::check_with_progress;
use specfx::nset::NSet;
use specfx::report::check::write_check_table;

/// Arguments of `specfx check`.
#[derive(Debug, Args)]
pub struct CheckArgs {
    /// A TOML configuration file, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Exponents to check, replacing the configuration's set (e.g. 16..=1024).
    #[arg(long)]
    n: Option<NSet>,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    json: bool,
}

/// Evaluations from which `check` shows its progress.
const PROGRESS_FROM: u64 = 1 << 32;

/// Runs `specfx check`.
pub fn run(args: &CheckArgs) -> Result<Outcome> {
    let dp = specfx::input::load_datapath(&args.config, args.n.as_ref())?;
    // A bar only for a check long enough to watch (a 22-bit input and wider: seconds).
    let evaluations = dp.constants().len() as u64 * (dp.one_code() + 1) as u64;
    let bar = if evaluations >= PROGRESS_FROM {
        super::progress::Progress::new("check", "exponents", dp.constants().len() as u64)
    } else {
        super::progress::Progress::off("check", "exponents", 0)
    };
    let report = check_with_progress(&dp, &|done, _| bar.set_position(done as u64))
        .map_err(|e| anyhow!("config {}: {e}", args.config))?;
    bar.finish();
    if args.json {
        print_json(&report)?;
    } else {
        print_with(|buf| write_check_table(buf, &report, super::terminal::table_width()))?;
    }
    Ok(Outcome::Ok)
}
