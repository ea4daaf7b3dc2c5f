//! The Verilog simulators of `specfx cosim`: Icarus Verilog (`iverilog -g2005`, `vvp`) and
//! Verilator (`verilator --binary`), and Verilator's lint. The testbench's log is read by
//! `hdl::testbench`.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use super::{child, error, io_error};
use crate::error::Error;

/// A Verilog simulator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Simulator {
    /// Icarus Verilog (`iverilog -g2005`, `vvp`).
    Icarus,
    /// Verilator (`verilator --binary`).
    Verilator,
}

impl Simulator {
    /// Every simulator, in the order a default is chosen.
    pub const ALL: [Simulator; 2] = [Simulator::Icarus, Simulator::Verilator];

    /// Its name: `icarus` or `verilator`.
    pub fn name(self) -> &'static str {
        match self {
            Simulator::Icarus => "icarus",
            Simulator::Verilator => "verilator",
        }
    }

    /// The programs it needs and the Debian package that has them.
    pub fn programs(self) -> (&'static [&'static str], &'static str) {
        match self {
            Simulator::Icarus => (&["iverilog", "vvp"], "iverilog"),
            Simulator::Verilator => (&["verilator"], "verilator"),
        }
    }

    /// Whether every program it needs is on `PATH`.
    pub fn installed(self) -> bool {
        self.programs().0.iter().all(|p| find_program(p).is_some())
    }
}

crate::names::named_enum!(Simulator, "simulator", "icarus or verilator");

/// The program's path on `PATH`, if it is there.
pub fn find_program(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path)
        .map(|dir| dir.join(name))
        .find(|p| p.is_file())
}

/// Runs `cmd` in `wd` to completion; a failure to start it names `what`.
fn run(cmd: &mut Command, wd: &Path, tool: &'static str, what: &str) -> Result<Output, Error> {
    child::output(cmd.current_dir(wd)).map_err(|e| io_error(tool, &format!("cannot run {what}"), e))
}

/// Lints `specfx_top` (the `rtl` files) with `verilator --lint-only -Wall` under the given
/// parameters: `Ok(None)` when clean, else `Ok(Some(verilator's complaints))`.
pub fn lint(rtl: &[PathBuf], params: &[(String, i64)]) -> Result<Option<String>, Error> {
    let mut cmd = Command::new("verilator");
    cmd.args(["--lint-only", "-Wall", "--top-module", "specfx_top"])
        .args(params.iter().map(|(k, v)| format!("-G{k}={v}")))
        .args(rtl);
    let o =
        child::output(&mut cmd).map_err(|e| io_error("verilator", "cannot run verilator", e))?;
    Ok((!o.status.success() || !o.stderr.is_empty())
        .then(|| String::from_utf8_lossy(&o.stderr).trim_end().to_string()))
}

/// Compiles the testbench `tb` with the `rtl` files and runs it in `wd` (which holds its hex
/// files) with the testbench's parameters `params` (`-P` for Icarus, `-G` for Verilator),
/// defining `SPECFX_VCD` when `vcd`; returns the simulation's output (stdout, then stderr).
pub fn simulate(
    sim: Simulator,
    wd: &Path,
    tb: &Path,
    rtl: &[PathBuf],
    params: &[(String, i64)],
    vcd: bool,
) -> Result<String, Error> {
    let text = |o: &Output| {
        String::from_utf8_lossy(&o.stdout).into_owned() + &String::from_utf8_lossy(&o.stderr)
    };
    match sim {
        Simulator::Icarus => {
            let mut cmd = Command::new("iverilog");
            cmd.args(["-g2005", "-s", "tb_specfx", "-o", "tb.vvp"])
                .args(params.iter().map(|(k, v)| format!("-Ptb_specfx.{k}={v}")));
            if vcd {
                cmd.arg("-DSPECFX_VCD");
            }
            let o = run(cmd.arg(tb).args(rtl), wd, "iverilog", "iverilog")?;
            if !o.status.success() {
                return Err(error(
                    "iverilog",
                    format!(
                        "iverilog failed: {}",
                        String::from_utf8_lossy(&o.stderr).trim()
                    ),
                ));
            }
            let o = run(Command::new("vvp").args(["-n", "tb.vvp"]), wd, "vvp", "vvp")?;
            Ok(text(&o))
        }
        Simulator::Verilator => {
            let mut cmd = Command::new("verilator");
            cmd.args([
                "--binary",
                "-j",
                "0",
                "-Wno-fatal",
                "-Wno-lint",
                "-Wno-style",
                "--top-module",
                "tb_specfx",
                "-Mdir",
                "obj",
            ])
            .args(params.iter().map(|(k, v)| format!("-G{k}={v}")));
            if vcd {
                cmd.args(["--trace", "-DSPECFX_VCD"]);
            }
            let o = run(cmd.arg(tb).args(rtl), wd, "verilator", "verilator")?;
            if !o.status.success() {
                let err = String::from_utf8_lossy(&o.stderr);
                let first = err
                    .lines()
                    .find(|l| l.contains("%Error"))
                    .unwrap_or("see its output");
                return Err(error(
                    "verilator",
                    format!("verilator failed: {}", first.trim()),
                ));
            }
            let o = run(
                &mut Command::new(wd.join("obj/Vtb_specfx")),
                wd,
                "verilator",
                "the model",
            )?;
            Ok(text(&o))
        }
    }
}
