//! `specfx timing`: place and route on iCE40 with yosys and nextpnr, for Fmax, the critical
//! path, utilisation, and latency and throughput at that Fmax.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};
use clap::Args;

use super::cost::{hdl_ref, rtl_files};
use super::output::{print_json, print_with};
use super::Outcome;
use specfx::cycle::Arch;
use specfx::hdl::cost::parse_stat_json;
use specfx::hdl::params_header;
use specfx::hdl::pnr::{
    harness_verilog, nextpnr_args, parse_report, pnr_yosys_script, utilisation_rows, Device,
    SynthCells, Timing,
};
use specfx::pipeline::Datapath;
use specfx::report::table::{Align, TextTable};

/// Arguments of `specfx timing`.
#[derive(Debug, Args)]
pub struct TimingArgs {
    /// A TOML configuration file, a vector directory, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Microarchitecture: pipelined or folded.
    #[arg(long, default_value = "pipelined")]
    arch: Arch,
    /// Device: up5k (iCE40 UltraPlus UP5K, SG48, 8 DSPs) or hx8k (iCE40 HX8K, CT256, no DSPs).
    #[arg(long, default_value = "up5k")]
    device: Device,
    /// The reference Verilog directory (default: $SPECFX_HDL_REF, else the hdl_ref/ of the
    /// source tree this binary was built from).
    #[arg(long)]
    hdl_ref: Option<PathBuf>,
    /// Print JSON instead of text.
    #[arg(long)]
    json: bool,
}

/// Runs `tool` with `args` in `dir`; a missing tool is one clear line.
fn run_tool(tool: &str, args: &[String], dir: &Path) -> Result<std::process::Output> {
    super::child::output(Command::new(tool).args(args).current_dir(dir)).map_err(|e| {
        match e.kind() {
            std::io::ErrorKind::NotFound => {
                anyhow::anyhow!("{tool} not found: install it (Debian: apt-get install {tool})")
            }
            _ => anyhow::Error::new(e).context(format!("cannot run {tool}")),
        }
    })
}

/// Checks before any work that nextpnr-ice40 runs.
pub fn check_nextpnr() -> Result<()> {
    run_tool("nextpnr-ice40", &["--version".into()], Path::new(".")).map(|_| ())
}

/// The first line of a tool's complaint that says something.
fn first_error(out: &std::process::Output, log: Option<&str>) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr);
    let text = log.map_or(stderr.to_string(), |l| format!("{stderr}\n{l}"));
    text.lines()
        .find(|l| l.starts_with("ERROR") || l.contains("error"))
        .or_else(|| text.lines().find(|l| !l.trim().is_empty()))
        .unwrap_or("no message")
        .trim()
        .to_string()
}

/// Places and routes a datapath on a device: writes the parameter header, the harness and the
/// scripts into a temporary directory, runs yosys then nextpnr-ice40, and reads nextpnr's
/// report. A design nextpnr cannot place (more DSPs or logic than the device has) gives a
/// [`Timing`] without Fmax and with its over-limit flags, not an error.
pub fn run_timing(dp: &Datapath, arch: Arch, device: Device, hdl_ref: &Path) -> Result<Timing> {
    let work = super::child::work_dir("pnr").context("cannot create a temporary directory")?;
    let dir = work.path();
    // A missing nextpnr is reported before yosys spends seconds on synthesis.
    run_tool("nextpnr-ice40", &["--version".into()], dir)?;
    std::fs::write(dir.join("specfx_params.vh"), params_header(dp, arch))?;
    std::fs::write(dir.join("specfx_pnr_top.v"), harness_verilog())?;
    // The work directory's files by relative names: the netlist's source attributes then do
    // not depend on the temporary directory's name, and neither do nextpnr's results.
    let mut files: Vec<String> = rtl_files(hdl_ref)?
        .iter()
        .map(|p| std::path::absolute(p).unwrap_or_else(|_| p.clone()))
        .map(|p| p.display().to_string())
        .collect();
    files.push("specfx_pnr_top.v".into());
    std::fs::write(dir.join("pnr.ys"), pnr_yosys_script(device, &files, "."))?;
    let yosys = run_tool("yosys", &["-q".into(), "-s".into(), "pnr.ys".into()], dir)?;
    if !yosys.status.success() {
        bail!(
            "yosys failed on the reference Verilog: {}",
            first_error(&yosys, None)
        );
    }
    let stat =
        std::fs::read_to_string(dir.join("stat.json")).context("yosys wrote no statistics")?;
    let stat = parse_stat_json(&stat, None).map_err(anyhow::Error::msg)?;
    let cells = SynthCells {
        luts: stat.luts,
        ffs: stat.ffs,
        dsps: stat.dsps,
    };
    let nextpnr = run_tool("nextpnr-ice40", &nextpnr_args(device), dir)?;
    let report = if nextpnr.status.success() {
        let text = std::fs::read_to_string(dir.join("report.json"))
            .context("nextpnr-ice40 wrote no report")?;
        Some(parse_report(&text).map_err(anyhow::Error::msg)?)
    } else {
        let log = std::fs::read_to_string(dir.join("nextpnr.log")).unwrap_or_default();
        let timing = Timing::new(dp, arch, device, None, cells);
        // Not placing a design that needs more than the device has is an answer; any other
        // failure is an error.
        let no_room = log.contains("no Bels remaining") || log.contains("Unable to place");
        if !no_room && timing.over_limit.is_empty() {
            bail!(
                "nextpnr-ice40 failed: {}",
                first_error(&nextpnr, Some(&log))
            );
        }
        return Ok(timing);
    };
    Ok(Timing::new(dp, arch, device, report.as_ref(), cells))
}

/// Renders the timing as text, its table fitted into `width` characters (`None`: as wide as its
/// content).
pub fn write_timing(
    w: &mut impl std::io::Write,
    t: &Timing,
    width: Option<u16>,
) -> std::io::Result<()> {
    writeln!(
        w,
        "timing {}, {}, {} ({}): latency {} cycles, initiation interval {}",
        t.config, t.arch, t.device_name, t.package, t.latency_cycles, t.initiation_interval
    )?;
    match t.fmax_mhz {
        Some(f) => {
            let bound = if t.fmax_is_upper_bound { "<= " } else { "" };
            writeln!(
                w,
                "  Fmax {bound}{f:.2} MHz (register to register inside the harness; nextpnr {:.2} MHz)",
                t.nextpnr_fmax_mhz.unwrap_or(f)
            )?;
        }
        None => writeln!(
            w,
            "  Fmax -: the design does not fit the device (nextpnr could not place it)"
        )?,
    }
    if let Some(u) = &t.untimed_dsp {
        let ns = |x: Option<f64>| x.map_or("-".to_string(), |v| format!("{v:.2} ns"));
        writeln!(
            w,
            "  combinational DSPs: nextpnr times paths into them ({}) and out of them ({}), not through them",
            ns(u.into_ns),
            ns(u.out_of_ns)
        )?;
    }
    if t.fmax_is_upper_bound {
        writeln!(
            w,
            "  Fmax is an upper bound: nextpnr does not time the delay through the {} DSP blocks",
            t.synthesis.dsps
        )?;
    }
    if let Some(p) = &t.critical_path {
        writeln!(
            w,
            "  critical path {:.2} ns ({:.2} logic, {:.2} routing), {} logic levels, {} segments",
            p.delay_ns, p.logic_ns, p.routing_ns, p.logic_levels, p.segments
        )?;
        writeln!(w, "    from {}.{}", p.start.cell, p.start.port)?;
        writeln!(w, "    to   {}.{}", p.end.cell, p.end.port)?;
    }
    if let (Some(ns), Some(sps)) = (t.latency_ns, t.throughput_samples_per_s) {
        writeln!(
            w,
            "  latency {} cycles = {ns:.1} ns, throughput {:.3} Msamples/s (Fmax / {})",
            t.latency_cycles,
            sps / 1e6,
            t.initiation_interval
        )?;
    }
    writeln!(
        w,
        "  yosys: {} LUT4s, {} flip-flops ({} of them the harness's), {} DSPs",
        t.synthesis.luts, t.synthesis.ffs, t.harness_ffs, t.synthesis.dsps
    )?;
    let rows = utilisation_rows(&t.utilisation);
    if !rows.is_empty() {
        let mut table = TextTable::new(&[
            ("resource", Align::Left),
            ("used", Align::Right),
            ("available", Align::Right),
            ("%", Align::Right),
        ])
        .indent(2);
        for u in rows {
            table.row([
                u.resource.to_string(),
                u.used.to_string(),
                u.available.to_string(),
                format!("{:.1}%", 100.0 * u.used as f64 / u.available as f64),
            ]);
        }
        table.write(w, width)?;
    }
    for flag in &t.over_limit {
        writeln!(w, "  OVER LIMIT: {flag}")?;
    }
    Ok(())
}

/// Runs `specfx timing`.
pub fn run(args: &TimingArgs) -> Result<Outcome> {
    let dp = super::datapath::load(&args.config, None)?;
    let dir = hdl_ref(args.hdl_ref.as_deref())?;
    super::cost::check_yosys()?;
    let t = run_timing(&dp, args.arch, args.device, &dir)?;
    if args.json {
        print_json(&t)?;
    } else {
        print_with(|w| write_timing(w, &t, super::terminal::table_width()))?;
    }
    // A design that does not fit the device is a failed check (exit code 1), not an error.
    Ok(if t.fits && t.over_limit.is_empty() {
        Outcome::Ok
    } else {
        Outcome::CheckFailed
    })
}
