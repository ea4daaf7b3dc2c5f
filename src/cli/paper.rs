//! `specfx paper`: the claim-by-claim reproduction of the paper.

use anyhow::Result;
use clap::Args;

use super::output::{print_json, print_with};
use super::Outcome;
use specfx::analysis::paper::reproduce;
use specfx::report::paper::write_paper_table;

/// Arguments of `specfx paper`.
#[derive(Debug, Args)]
pub struct PaperArgs {
    /// Print one JSON object instead of the table.
    #[arg(long)]
    json: bool,
}

/// Runs `specfx paper`. Claims that do not reproduce are findings, not failures: exit 0.
pub fn run(args: &PaperArgs) -> Result<Outcome> {
    let r = reproduce();
    if args.json {
        print_json(&r)?;
    } else {
        print_with(|buf| write_paper_table(buf, &r, super::terminal::table_width()))?;
    }
    Ok(Outcome::Ok)
}
