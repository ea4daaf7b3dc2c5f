//! `specfx check`: the exhaustive accuracy check of a datapath.

use anyhow::{anyhow, Result};
use clap::Args;

use super::output::{print_json, print_with};
use super::Outcome;
use specfx::analysis::check::check;
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

/// Runs `specfx check`.
pub fn run(args: &CheckArgs) -> Result<Outcome> {
    let dp = specfx::input::load_datapath(&args.config, args.n.as_ref())?;
    let report = check(&dp).map_err(|e| anyhow!("config {}: {e}", args.config))?;
    if args.json {
        print_json(&report)?;
    } else {
        print_with(|buf| write_check_table(buf, &report, super::terminal::table_width()))?;
    }
    Ok(Outcome::Ok)
}
