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

    /// What it is and how specfx runs it, in one line (`--help`).
    pub fn help(self) -> &'static str {
        match self {
            Simulator::Icarus => "Icarus Verilog (`iverilog -g2005`, `vvp`)",
            Simulator::Verilator => "Verilator (`verilator --binary`)",
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

/// Builds a Verilator model of `top` in `wd/obj` (`--binary`'s steps: verilate with a `main`
/// and timing, then make), `args` being the rest of verilator's command line. Verilator's own
/// runtime (`verilated*.cpp`, most of a small model's compile time) is compiled once per set
/// of flags and kept in the synthesis cache (`verilator/<key>`: the objects the makefile
/// would compile, identical for identical flags, so a build with them is the build without).
fn verilator_build(wd: &Path, top: &str, args: &[String], makeflags: &[&str]) -> Result<(), Error> {
    let failed = |o: &Output| {
        let err = String::from_utf8_lossy(&o.stderr);
        let first = err
            .lines()
            .find(|l| l.contains("%Error") || l.contains("error:"))
            .unwrap_or("see its output");
        error("verilator", format!("verilator failed: {}", first.trim()))
    };
    let mut cmd = Command::new("verilator");
    cmd.args([
        "--cc",
        "--exe",
        "--main",
        "--timing",
        "--top-module",
        top,
        "-Mdir",
        "obj",
    ])
    .args(args);
    let o = run(&mut cmd, wd, "verilator", "verilator")?;
    if !o.status.success() {
        return Err(failed(&o));
    }
    let obj = wd.join("obj");
    let classes =
        std::fs::read_to_string(obj.join(format!("V{top}_classes.mk"))).unwrap_or_default();
    // The makefile's settings (VM_TRACE = 0, ...) and the runtime files it compiles.
    let settings: Vec<&str> = classes
        .lines()
        .filter(|l| l.starts_with("VM_") && l.contains(" = "))
        .collect();
    let mut globals = Vec::new();
    let mut in_globals = false;
    for line in classes.lines() {
        if line.starts_with("VM_GLOBAL_") {
            in_globals = true;
        } else if in_globals && line.starts_with('\t') {
            globals.push(line.trim().trim_end_matches('\\').trim().to_string());
        } else {
            in_globals = false;
        }
    }
    let version = |program: &str| {
        Command::new(program)
            .arg("--version")
            .output()
            .map(|o| o.stdout)
            .unwrap_or_default()
    };
    let files: Vec<String> = globals
        .iter()
        .flat_map(|g| [format!("{g}.o"), format!("{g}.d")])
        .collect();
    let names: Vec<&str> = files.iter().map(String::as_str).collect();
    let key = super::cache::key(&[
        &version("verilator"),
        &version("g++"),
        settings.join("\n").as_bytes(),
        names.join(" ").as_bytes(),
        makeflags.join(" ").as_bytes(),
    ]);
    let claim = if globals.is_empty() {
        None
    } else {
        match super::cache::get_or_claim("verilator", &key, &names) {
            Ok(kept) => {
                for (name, bytes) in names.iter().zip(kept) {
                    if let Some(bytes) = bytes {
                        let _ = std::fs::write(obj.join(name), bytes);
                    }
                }
                None
            }
            Err(claim) => Some(claim),
        }
    };
    let mut make = Command::new("make");
    make.args(["-C", "obj", "-f", &format!("V{top}.mk"), "-j", "2"])
        .args(makeflags);
    let o = run(&mut make, wd, "verilator", "make")?;
    if !o.status.success() {
        return Err(failed(&o));
    }
    if let Some(_claim) = claim {
        let kept: Vec<(&str, Vec<u8>)> = names
            .iter()
            .filter_map(|n| std::fs::read(obj.join(n)).ok().map(|b| (*n, b)))
            .collect();
        if kept.len() == names.len() {
            let files: Vec<(&str, &[u8])> = kept.iter().map(|(n, b)| (*n, b.as_slice())).collect();
            super::cache::put("verilator", &key, &files);
        }
    }
    Ok(())
}

/// What a testbench printed and how its process ended.
#[derive(Debug, Clone)]
pub struct SimOutput {
    /// Its output: stdout, then stderr.
    pub log: String,
    /// Its exit status: `None` when it exited with 0, else how it ended (`exit status 1`,
    /// `signal 6 (SIGABRT)`; a testbench's `$fatal` ends it so).
    pub failure: Option<String>,
}

impl SimOutput {
    fn of(o: &Output) -> SimOutput {
        SimOutput {
            log: String::from_utf8_lossy(&o.stdout).into_owned()
                + &String::from_utf8_lossy(&o.stderr),
            failure: (!o.status.success()).then(|| o.status.to_string()),
        }
    }
}

/// Compiles the testbench `tb` with the `rtl` files and runs it in `wd` (which holds its hex
/// files) with the testbench's parameters `params` (`-P` for Icarus, `-G` for Verilator),
/// defining `SPECFX_VCD` when `vcd`; returns the simulation's output and exit status.
pub fn simulate(
    sim: Simulator,
    wd: &Path,
    tb: &Path,
    rtl: &[PathBuf],
    params: &[(String, i64)],
    vcd: bool,
) -> Result<SimOutput, Error> {
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
            Ok(SimOutput::of(&o))
        }
        Simulator::Verilator => {
            let mut args: Vec<String> = ["-Wno-fatal", "-Wno-lint", "-Wno-style"]
                .iter()
                .map(|a| a.to_string())
                .collect();
            args.extend(params.iter().map(|(k, v)| format!("-G{k}={v}")));
            if vcd {
                args.extend(["--trace".to_string(), "-DSPECFX_VCD".to_string()]);
            }
            args.push(tb.display().to_string());
            args.extend(rtl.iter().map(|f| f.display().to_string()));
            verilator_build(wd, "tb_specfx", &args, &[])?;
            let o = run(
                &mut Command::new(wd.join("obj/Vtb_specfx")),
                wd,
                "verilator",
                "the model",
            )?;
            Ok(SimOutput::of(&o))
        }
    }
}

/// What a DPI-C simulation builds and runs: the testbench `tb_specfx_dpi` (its files, the
/// package first), the RTL, the C library it links, its parameters and plusargs.
pub struct DpiRun<'a> {
    /// `specfx_dpi.sv` and `tb_specfx_dpi.sv`, in that order.
    pub testbench: &'a [PathBuf],
    /// `rtl/*.v`.
    pub rtl: &'a [PathBuf],
    /// `libspecfx_c.a`.
    pub library: &'a Path,
    /// The testbench's parameters (`-G`).
    pub params: &'a [(String, i64)],
    /// Its plusargs (`+config=...`, `+seed=...`), without the `+`.
    pub plusargs: &'a [String],
    /// Optimize the C++ of the model (`-O2`, slower to build) for a long run; `-O0` otherwise.
    pub optimize: bool,
}

/// Builds `tb_specfx_dpi` with Verilator (`--binary`, the C library linked) in `wd` and runs it;
/// returns its output and exit status. Icarus Verilog has no DPI-C support.
pub fn simulate_dpi(wd: &Path, run_spec: &DpiRun) -> Result<SimOutput, Error> {
    let opt = [
        if run_spec.optimize {
            "OPT_FAST=-O2"
        } else {
            "OPT_FAST=-O0"
        },
        "OPT_SLOW=-O0",
    ];
    let mut args: Vec<String> = [
        "-O3",
        "--x-assign",
        "fast",
        // Registers a reset does not clear start with seeded random values (a two-state
        // simulator's stand-in for X), so a missing reset shows.
        "--x-initial",
        "unique",
        "-Wno-fatal",
        "-Wno-lint",
        "-Wno-style",
        "-LDFLAGS",
        "-lstdc++ -lpthread -ldl -lm",
    ]
    .iter()
    .map(|a| a.to_string())
    .collect();
    args.extend(run_spec.params.iter().map(|(k, v)| format!("-G{k}={v}")));
    args.extend(run_spec.testbench.iter().map(|f| f.display().to_string()));
    args.extend(run_spec.rtl.iter().map(|f| f.display().to_string()));
    args.push(run_spec.library.display().to_string());
    verilator_build(wd, "tb_specfx_dpi", &args, &opt)?;
    let o = run(
        Command::new(wd.join("obj/Vtb_specfx_dpi"))
            .args(run_spec.plusargs.iter().map(|p| format!("+{p}"))),
        wd,
        "verilator",
        "the model",
    )?;
    Ok(SimOutput::of(&o))
}
