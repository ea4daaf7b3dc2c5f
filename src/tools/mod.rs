//! External programs: yosys, nextpnr-ice40, gappa and the simulators, each run as a child that
//! ends with specfx, in a work directory of its own. The one place of specfx that starts a
//! process or writes a file; the rest of the library receives a tool as a closure (as
//! `analysis::budget_expr::Synthesise`) or a tool's text to parse.

use std::io;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use crate::error::Error;

pub mod cache;
pub mod child;
pub mod gappa;
pub mod nextpnr;
pub mod simulator;
pub mod yosys;

/// An error of `tool`, its message one line.
fn error(tool: &'static str, message: String) -> Error {
    Error::Tool { tool, message }
}

/// `context: e`, as an error of `tool`.
fn io_error(tool: &'static str, context: &str, e: impl std::fmt::Display) -> Error {
    error(tool, format!("{context}: {e}"))
}

/// Runs `tool` with `args` in `dir` to completion; a missing tool is one clear line naming the
/// Debian package.
fn run(tool: &'static str, args: &[String], dir: &Path) -> Result<Output, Error> {
    child::output(Command::new(tool).args(args).current_dir(dir)).map_err(|e| match e.kind() {
        io::ErrorKind::NotFound => error(
            tool,
            format!("{tool} not found: install it (Debian: apt-get install {tool})"),
        ),
        _ => io_error(tool, &format!("cannot run {tool}"), e),
    })
}

/// The first line of `tool flag`'s output when the tool runs, else None: the version a result
/// records.
pub fn version(tool: &str, flag: &str) -> Option<String> {
    child::output(Command::new(tool).arg(flag))
        .ok()
        .filter(|o| o.status.success())
        .map(|o| {
            let text = String::from_utf8_lossy(&o.stdout).into_owned()
                + &String::from_utf8_lossy(&o.stderr);
            text.lines().next().unwrap_or("").trim().to_string()
        })
}

/// The Verilog sources of the DUT in the reference Verilog directory `dir`: every `rtl/*.v`,
/// sorted, then `specfx_dut.v`.
pub fn rtl_files(dir: &Path) -> Result<Vec<PathBuf>, Error> {
    let rtl = dir.join("rtl");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&rtl)
        .map_err(|e| {
            io_error(
                "yosys",
                &format!("cannot read the reference Verilog in {}", rtl.display()),
                e,
            )
        })?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "v"))
        .collect();
    files.sort();
    files.push(dir.join("specfx_dut.v"));
    Ok(files)
}

/// A work directory for `tool` ([`child::work_dir`]), its failure one line.
fn work_dir(tool: &'static str, tag: &str) -> Result<child::WorkDir, Error> {
    child::work_dir(tag).map_err(|e| io_error(tool, "cannot create a temporary directory", e))
}

/// Writes `text` to `path` in a work directory; a failure is the I/O error's text.
fn write(tool: &'static str, path: &Path, text: &str) -> Result<(), Error> {
    std::fs::write(path, text).map_err(|e| error(tool, e.to_string()))
}

/// The first line of a tool's complaint that says something: a line with `ERROR` or `error`
/// in its stderr (then its `log`), else its first non-blank line.
fn first_error(out: &Output, log: Option<&str>) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr);
    let text = log.map_or(stderr.to_string(), |l| format!("{stderr}\n{l}"));
    text.lines()
        .find(|l| l.starts_with("ERROR") || l.contains("error"))
        .or_else(|| text.lines().find(|l| !l.trim().is_empty()))
        .unwrap_or("no message")
        .trim()
        .to_string()
}
