//! `specfx cost`: synthesis cost from yosys on the reference Verilog, beside the analytic model.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;

use super::output::{print_json, print_with};
use super::Outcome;
use specfx::cycle::Arch;
use specfx::hdl::cost::{
    analytic_cost, parse_stat_json, yosys_script, AnalyticCost, Target, YosysCost,
};
use specfx::hdl::params_header;
use specfx::hdl::rom::{constant_rom, rom_verilog, ConstantRom};
use specfx::pipeline::Datapath;
use specfx::report::table::{Align, TextTable};

/// Arguments of `specfx cost`.
#[derive(Debug, Args)]
pub struct CostArgs {
    /// A TOML configuration file, a vector directory, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Microarchitecture: pipelined or folded.
    #[arg(long, default_value = "pipelined")]
    arch: Arch,
    /// Synthesis target: generic (gates and a CMOS transistor estimate), ice40 or xilinx.
    #[arg(long, default_value = "ice40")]
    target: Target,
    /// The reference Verilog directory (default: $SPECFX_HDL_REF, else the hdl_ref/ of the
    /// source tree this binary was built from).
    #[arg(long)]
    hdl_ref: Option<PathBuf>,
    /// Only the analytic model: do not run yosys.
    #[arg(long)]
    analytic_only: bool,
    /// Also place and route on an iCE40 device with nextpnr (target ice40): Fmax, critical
    /// path, latency and throughput at Fmax (`specfx timing` for the details).
    #[arg(long, conflicts_with = "analytic_only")]
    timing: bool,
    /// The iCE40 device whose resources the figures are checked against (target ice40): up5k
    /// or hx8k [default: up5k].
    #[arg(long)]
    device: Option<specfx::hdl::pnr::Device>,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// Everything `specfx cost` reports.
#[derive(Debug, Serialize)]
pub struct CostReport {
    /// Configuration name.
    pub config: String,
    /// Architecture.
    pub arch: Arch,
    /// Synthesis target.
    pub target: Target,
    /// The analytic model's figures.
    pub analytic: AnalyticCost,
    /// yosys's figures, when it ran.
    pub yosys: Option<YosysCost>,
    /// yosys LUTs (or gates, for generic).
    pub luts: Option<u64>,
    /// yosys DSP blocks.
    pub dsps: Option<u64>,
    /// yosys flip-flops.
    pub ffs: Option<u64>,
    /// The per-n constant ROM in front of the datapath (not in the figures above).
    pub rom: ConstantRom,
    /// yosys's figures for the ROM alone (`specfx_rom`), when it ran.
    pub rom_yosys: Option<YosysCost>,
    /// `yosys -V`.
    pub yosys_version: Option<String>,
    /// The exact script yosys ran.
    pub yosys_script: Option<String>,
    /// yosys LUTs / analytic LUTs.
    pub lut_ratio: Option<f64>,
    /// yosys flip-flops / analytic flip-flops.
    pub ff_ratio: Option<f64>,
    /// The device the figures are checked against (iCE40 targets only).
    pub device: Option<specfx::hdl::pnr::Device>,
    /// Resources beyond the device, from yosys's figures when it ran, else the analytic ones.
    pub over_limit: Vec<String>,
    /// Place-and-route timing (`--timing`).
    pub timing: Option<specfx::hdl::pnr::Timing>,
}

/// The reference Verilog directory: `arg` (`--hdl-ref`), else `$SPECFX_HDL_REF` (unless empty),
/// else the source tree's `hdl_ref/`.
pub fn hdl_ref_dir(arg: Option<&Path>) -> PathBuf {
    hdl_ref_source(arg).0
}

/// [`hdl_ref_dir`] and how it was chosen, as errors name it (`--hdl-ref DIR`,
/// `SPECFX_HDL_REF=DIR`, or the built-in directory).
fn hdl_ref_source(arg: Option<&Path>) -> (PathBuf, String) {
    let shown = |p: &Path| super::error_text(&p.display().to_string());
    if let Some(p) = arg {
        return (p.to_path_buf(), format!("--hdl-ref {}", shown(p)));
    }
    match std::env::var_os("SPECFX_HDL_REF").filter(|v| !v.is_empty()) {
        Some(v) => {
            let p = PathBuf::from(v);
            let name = format!("SPECFX_HDL_REF={}", shown(&p));
            (p, name)
        }
        None => {
            let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("hdl_ref");
            let name = format!(
                "the reference Verilog {} (pass --hdl-ref or set SPECFX_HDL_REF)",
                shown(&p)
            );
            (p, name)
        }
    }
}

/// The reference Verilog directory of [`hdl_ref_dir`], checked before any work: a directory
/// holding `rtl/*.v` and `specfx_dut.v`, what yosys is given.
pub fn hdl_ref(arg: Option<&Path>) -> Result<PathBuf> {
    let (dir, name) = hdl_ref_source(arg);
    let expected = "expected the reference Verilog directory (rtl/*.v and specfx_dut.v)";
    match std::fs::metadata(&dir) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            bail!("{name}: {expected}, got no such directory")
        }
        Err(e) => bail!("{name}: {expected}, but it cannot be read: {}", e.kind()),
        Ok(m) if !m.is_dir() => bail!("{name}: {expected}, got a file"),
        Ok(_) => {}
    }
    let has_rtl = std::fs::read_dir(dir.join("rtl")).is_ok_and(|entries| {
        entries
            .flatten()
            .any(|e| e.path().extension().is_some_and(|x| x == "v") && e.path().is_file())
    });
    if !has_rtl {
        bail!("{name}: {expected}, but it has no rtl/*.v");
    }
    if !dir.join("specfx_dut.v").is_file() {
        bail!("{name}: {expected}, but it has no specfx_dut.v");
    }
    Ok(dir)
}

/// Checks before any work that yosys runs; returns `yosys -V`.
pub fn check_yosys() -> Result<String> {
    let out =
        super::child::output(Command::new("yosys").arg("-V")).map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => {
                anyhow::anyhow!("yosys not found: install it (Debian: apt-get install yosys)")
            }
            _ => anyhow::Error::new(e).context("cannot run yosys"),
        })?;
    if !out.status.success() {
        bail!("yosys -V failed: {}", out.status);
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The Verilog sources of the DUT: every `rtl/*.v`, sorted, then `specfx_dut.v`.
pub fn rtl_files(dir: &Path) -> Result<Vec<PathBuf>> {
    let rtl = dir.join("rtl");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&rtl)
        .with_context(|| format!("cannot read the reference Verilog in {}", rtl.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "v"))
        .collect();
    files.sort();
    files.push(dir.join("specfx_dut.v"));
    Ok(files)
}

/// Runs yosys on the configuration and returns (cost, version, script).
pub fn run_yosys(
    dp: &Datapath,
    arch: Arch,
    target: Target,
    hdl_ref: &Path,
) -> Result<(YosysCost, String, String)> {
    let work = super::child::work_dir("yosys").context("cannot create a temporary directory")?;
    std::fs::write(
        work.path().join("specfx_params.vh"),
        params_header(dp, arch),
    )?;
    let files = rtl_files(hdl_ref)?;
    yosys_in(work.path(), &files, "specfx_dut", target)
        .context("yosys failed on the reference Verilog")
}

/// Runs yosys on the configuration's constant ROM (`specfx_rom`, generated).
pub fn run_yosys_rom(dp: &Datapath, target: Target) -> Result<(YosysCost, String, String)> {
    let work = super::child::work_dir("yosys").context("cannot create a temporary directory")?;
    let file = work.path().join("specfx_rom.v");
    std::fs::write(&file, rom_verilog(dp))?;
    yosys_in(work.path(), &[file], "specfx_rom", target).context("yosys failed on the constant ROM")
}

/// Runs yosys in `work` on `files` with `top`: (cost, version, script).
fn yosys_in(
    work: &Path,
    files: &[PathBuf],
    top: &str,
    target: Target,
) -> Result<(YosysCost, String, String)> {
    let version = check_yosys()?;
    let files: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
    let script = yosys_script(target, &files, &work.display().to_string(), top);
    std::fs::write(work.join("cost.ys"), &script)?;
    let out = super::child::output(
        Command::new("yosys")
            .args(["-q", "-s", "cost.ys"])
            .current_dir(work),
    )
    .context("cannot run yosys")?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        let first = err
            .lines()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("no message");
        bail!("{first}");
    }
    let stat =
        std::fs::read_to_string(work.join("stat.json")).context("yosys wrote no statistics")?;
    let cmos = std::fs::read_to_string(work.join("stat_cmos.txt")).ok();
    let cost = parse_stat_json(&stat, cmos.as_deref()).map_err(anyhow::Error::msg)?;
    Ok((cost, version, script))
}

/// Builds the report (running yosys unless `analytic_only`).
pub fn cost_report(
    dp: &Datapath,
    arch: Arch,
    target: Target,
    hdl_ref: &Path,
    analytic_only: bool,
) -> Result<CostReport> {
    let analytic = analytic_cost(dp, arch, target);
    let (yosys, version, script, rom_yosys) = if analytic_only {
        (None, None, None, None)
    } else {
        let (c, v, s) = run_yosys(dp, arch, target, hdl_ref)?;
        let (rom, _, _) = run_yosys_rom(dp, target)?;
        (Some(c), Some(v), Some(s), Some(rom))
    };
    let ratio = |a: u64, b: u64| (b > 0).then(|| a as f64 / b as f64);
    Ok(CostReport {
        config: dp.config().name.clone(),
        arch,
        target,
        luts: yosys.as_ref().map(|y| y.luts),
        dsps: yosys.as_ref().map(|y| y.dsps),
        ffs: yosys.as_ref().map(|y| y.ffs),
        lut_ratio: yosys.as_ref().and_then(|y| ratio(y.luts, analytic.luts)),
        ff_ratio: yosys.as_ref().and_then(|y| ratio(y.ffs, analytic.ffs)),
        analytic,
        yosys,
        rom: constant_rom(dp, target),
        rom_yosys,
        yosys_version: version,
        yosys_script: script,
        device: None,
        over_limit: Vec::new(),
        timing: None,
    })
}

/// Renders the report as text, its tables fitted into `width` characters (`None`: as wide as
/// their content).
pub fn write_cost(
    w: &mut impl std::io::Write,
    r: &CostReport,
    width: Option<u16>,
) -> std::io::Result<()> {
    let a = &r.analytic;
    writeln!(
        w,
        "cost {}, {}, target {}: latency {} cycles, initiation interval {}",
        r.config, r.arch, r.target, a.latency, a.initiation_interval
    )?;
    let opt = |x: Option<u64>| x.map_or("-".to_string(), |v| v.to_string());
    let rat = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2}"));
    let mut table = TextTable::new(&[
        ("", Align::Left),
        ("analytic", Align::Right),
        ("yosys", Align::Right),
        ("ratio", Align::Right),
    ])
    .indent(2);
    table.row([
        a.logic_unit.to_string(),
        a.luts.to_string(),
        opt(r.luts),
        rat(r.lut_ratio),
    ]);
    table.row([
        "flip-flops".to_string(),
        a.ffs.to_string(),
        opt(r.ffs),
        rat(r.ff_ratio),
    ]);
    table.row([
        "DSP blocks".to_string(),
        a.dsps.to_string(),
        opt(r.dsps),
        String::new(),
    ]);
    if let Some(y) = &r.yosys {
        table.row([
            "carry cells".to_string(),
            "-".into(),
            y.carries.to_string(),
            String::new(),
        ]);
        table.row([
            "cells".to_string(),
            "-".into(),
            y.cells.to_string(),
            String::new(),
        ]);
        if let Some(t) = y.transistors {
            table.row([
                "transistors (CMOS)".to_string(),
                "-".into(),
                t.to_string(),
                String::new(),
            ]);
        }
    }
    table.write(w, width)?;
    let cal = specfx::hdl::calibrate::calibration(r.target);
    writeln!(
        w,
        "  analytic model: calibrated against yosys on {} configurations; {} within {:.0}% (median), {:.0}% (90th percentile)",
        cal.error.records,
        a.logic_unit,
        100.0 * cal.error.median_rel,
        100.0 * cal.error.p90_rel
    )?;
    write!(
        w,
        "  multipliers ({} partial-product bits, {} left to logic):",
        a.features.multiplier_bits, a.features.soft_multiplier_bits
    )?;
    for m in &a.features.multipliers {
        write!(w, " {} {}x{}", m.name, m.a_bits, m.b_bits)?;
    }
    writeln!(w)?;
    let rom = &r.rom;
    writeln!(
        w,
        "  constant ROM (beside the datapath): {} entries x {} bits ({}), addressed by {}: analytic {} LUTs, yosys {}",
        rom.entries,
        rom.fields.iter().map(|f| f.bits).sum::<u32>(),
        rom.fields
            .iter()
            .map(|f| format!("{} {}", f.name, f.bits))
            .collect::<Vec<_>>()
            .join(", "),
        if rom.addressed_by_n { "n" } else { "index" },
        rom.luts,
        r.rom_yosys
            .as_ref()
            .map_or("-".to_string(), |y| format!("{} LUTs, {} cells", y.luts, y.cells))
    )?;
    if let Some(d) = r.device {
        if r.over_limit.is_empty() {
            writeln!(
                w,
                "  fits the {d} ({})",
                if r.luts.is_some() {
                    "yosys figures"
                } else {
                    "analytic figures"
                }
            )?;
        }
        for flag in &r.over_limit {
            writeln!(w, "  EXCEEDS THE DEVICE: {flag}")?;
        }
    }
    if let Some(t) = &r.timing {
        writeln!(w, "timing (nextpnr place and route on the {}):", t.device)?;
        super::pnr::write_timing(w, t, width)?;
    }
    if let Some(v) = &r.yosys_version {
        writeln!(w, "  {v}")?;
    }
    Ok(())
}

/// Runs `specfx cost`.
pub fn run(args: &CostArgs) -> Result<Outcome> {
    // Everything that can be refused is refused before yosys spends seconds on synthesis:
    // the options that go together, the configuration, the reference Verilog and the tools.
    if args.target != Target::Ice40 {
        if args.timing {
            bail!(
                "--timing: place and route is available for --target ice40 only (nextpnr-ice40), got --target {}",
                args.target.name()
            );
        }
        if let Some(d) = args.device {
            bail!(
                "--device {d}: the device check is for --target ice40 only, got --target {}",
                args.target.name()
            );
        }
    }
    let device = args.device.unwrap_or(specfx::hdl::pnr::Device::Up5k);
    let dp = super::datapath::load(&args.config, None)?;
    let dir = if args.analytic_only {
        hdl_ref_dir(args.hdl_ref.as_deref())
    } else {
        let dir = hdl_ref(args.hdl_ref.as_deref())?;
        check_yosys()?;
        if args.timing {
            super::pnr::check_nextpnr()?;
        }
        dir
    };
    let mut r = cost_report(&dp, args.arch, args.target, &dir, args.analytic_only)?;
    if args.target == Target::Ice40 {
        let (dsps, luts, ffs) = match &r.yosys {
            Some(y) => (y.dsps, y.luts, y.ffs),
            None => (r.analytic.dsps, r.analytic.luts, r.analytic.ffs),
        };
        r.device = Some(device);
        r.over_limit = specfx::hdl::pnr::device_check(dsps, luts, ffs, device);
    }
    if args.timing {
        r.timing = Some(super::pnr::run_timing(&dp, args.arch, device, &dir)?);
    }
    if args.json {
        print_json(&r)?;
    } else {
        print_with(|w| write_cost(w, &r, super::terminal::table_width()))?;
    }
    Ok(Outcome::Ok)
}
