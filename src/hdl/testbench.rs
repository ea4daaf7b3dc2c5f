//! The reference testbenches' log (`hdl_ref/tb/tb_specfx.v` in any simulator, and
//! `hdl_ref/dpi/tb_specfx_dpi.sv` in Verilator): its problem and coverage lines and its
//! `N passed, N failed` summary. Fuzzed (`fuzz/fuzz_targets/testbench_log.rs`).

use crate::error::{Error, OneLine};

/// What the testbench counted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Tally {
    /// Vectors whose output and cycle matched.
    pub passed: u64,
    /// Vectors that did not, plus protocol failures.
    pub failed: u64,
    /// The testbench's problem lines (mismatch, protocol, unexpected, timeout) and its
    /// coverage line (the DPI testbench's), in log order.
    pub problems: Vec<String>,
}

/// The testbench's problem lines and its `N passed, N failed` summary (the last one).
///
/// # Errors
/// When the summary line is missing (the simulation died or never finished): the error
/// quotes the log's last lines (control characters escaped, so that it is one line).
pub fn parse_log(log: &str) -> Result<Tally, Error> {
    let problems: Vec<String> = log
        .lines()
        .filter(|l| {
            ["mismatch", "protocol", "unexpected", "timeout", "coverage:"]
                .iter()
                .any(|p| l.starts_with(p))
        })
        .map(str::to_string)
        .collect();
    let summary = log.lines().rev().find_map(|l| {
        let (p, f) = l.trim().split_once(" passed, ")?;
        let f = f.strip_suffix(" failed")?;
        Some((p.parse::<u64>().ok()?, f.parse::<u64>().ok()?))
    });
    match summary {
        Some((passed, failed)) => Ok(Tally {
            passed,
            failed,
            problems,
        }),
        None => {
            let tail: Vec<&str> = log.lines().rev().take(5).collect();
            Err(Error::Tool {
                tool: "simulator",
                message: format!(
                    "the simulation printed no `N passed, N failed` line; its last lines: {}",
                    OneLine(&tail.into_iter().rev().collect::<Vec<_>>().join(" | "))
                ),
            })
        }
    }
}
