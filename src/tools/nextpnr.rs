//! nextpnr-ice40: place and route of the reference Verilog on an iCE40 device (after yosys's
//! `synth_ice40`), for the Fmax and critical path of `timing`, `cost --timing` and `report`.

use std::path::Path;

use super::{cache, error, first_error, io_error, run, work_dir, write};
use crate::cycle::Arch;
use crate::error::Error;
use crate::hdl::cost::parse_stat_json;
use crate::hdl::params_header;
use crate::hdl::pnr::{
    harness_verilog, nextpnr_args, parse_report, pnr_yosys_script, Device, SynthCells, Timing,
};
use crate::pipeline::Datapath;

/// Checks before any work that nextpnr-ice40 runs.
pub fn check() -> Result<(), Error> {
    run("nextpnr-ice40", &["--version".into()], Path::new(".")).map(|_| ())
}

/// Places and routes a datapath on a device: writes the parameter header, the harness and the
/// scripts into a work directory, runs yosys then nextpnr-ice40, and reads nextpnr's report.
/// A design nextpnr cannot place (more DSPs or logic than the device has) gives a [`Timing`]
/// without Fmax and with its over-limit flags, not an error.
pub fn place_and_route(
    dp: &Datapath,
    arch: Arch,
    device: Device,
    hdl_ref: &Path,
) -> Result<Timing, Error> {
    let work = work_dir("nextpnr-ice40", "pnr")?;
    let dir = work.path();
    // A missing nextpnr is reported before yosys spends seconds on synthesis.
    let nextpnr_version = run("nextpnr-ice40", &["--version".into()], dir)?;
    write(
        "nextpnr-ice40",
        &dir.join("specfx_params.vh"),
        &params_header(dp, arch),
    )?;
    write(
        "nextpnr-ice40",
        &dir.join("specfx_pnr_top.v"),
        &harness_verilog(),
    )?;
    // The work directory's files by relative names: the netlist's source attributes then do
    // not depend on the temporary directory's name, and neither do nextpnr's results.
    let mut files: Vec<String> = super::rtl_files(hdl_ref)?
        .iter()
        .map(|p| std::path::absolute(p).unwrap_or_else(|_| p.clone()))
        .map(|p| p.display().to_string())
        .collect();
    files.push("specfx_pnr_top.v".into());
    write(
        "nextpnr-ice40",
        &dir.join("pnr.ys"),
        &pnr_yosys_script(device, &files, "."),
    )?;
    // The synthesis cache: the same inputs to the same tools give the same answer.
    let args = nextpnr_args(device);
    let key = {
        let yosys_version = super::yosys::check()?;
        let mut parts: Vec<Vec<u8>> = vec![
            b"nextpnr place and route 1".to_vec(),
            yosys_version.into_bytes(),
            nextpnr_version.stdout,
            nextpnr_version.stderr,
            args.join("\0").into_bytes(),
        ];
        for f in &files {
            parts.push(f.as_bytes().to_vec());
            parts.push(cache::file_bytes(&dir.join(f)));
        }
        for f in ["pnr.ys", "specfx_params.vh"] {
            parts.push(cache::file_bytes(&dir.join(f)));
        }
        cache::key(&parts.iter().map(Vec::as_slice).collect::<Vec<_>>())
    };
    // Held until the entry is kept (or place and route failed): a run that needs the same
    // entry meanwhile waits for it.
    let _claim = match cache::get_or_claim("nextpnr", &key, &["stat.json", "report.json"]) {
        Ok(cached) => {
            let text = |b: &Option<Vec<u8>>| b.clone().and_then(|b| String::from_utf8(b).ok());
            let stat = text(&cached[0]).and_then(|t| parse_stat_json(&t, None).ok());
            let report = text(&cached[1]).and_then(|t| parse_report(&t).ok());
            if let (Some(stat), Some(report)) = (stat, report) {
                let cells = SynthCells {
                    luts: stat.luts,
                    ffs: stat.ffs,
                    dsps: stat.dsps,
                };
                return Ok(Timing::new(dp, arch, device, Some(&report), cells));
            }
            None
        }
        Err(claim) => Some(claim),
    };
    let yosys = run("yosys", &["-q".into(), "-s".into(), "pnr.ys".into()], dir)?;
    if !yosys.status.success() {
        return Err(error(
            "yosys",
            format!(
                "yosys failed on the reference Verilog: {}",
                first_error(&yosys, None)
            ),
        ));
    }
    let stat = std::fs::read_to_string(dir.join("stat.json"))
        .map_err(|e| io_error("yosys", "yosys wrote no statistics", e))?;
    let stat_text = stat;
    let stat = parse_stat_json(&stat_text, None)?;
    let cells = SynthCells {
        luts: stat.luts,
        ffs: stat.ffs,
        dsps: stat.dsps,
    };
    let nextpnr = run("nextpnr-ice40", &args, dir)?;
    let report = if nextpnr.status.success() {
        let text = std::fs::read_to_string(dir.join("report.json"))
            .map_err(|e| io_error("nextpnr-ice40", "nextpnr-ice40 wrote no report", e))?;
        let report = parse_report(&text)?;
        cache::put(
            "nextpnr",
            &key,
            &[
                ("stat.json", stat_text.as_bytes()),
                ("report.json", text.as_bytes()),
            ],
        );
        Some(report)
    } else {
        let log = std::fs::read_to_string(dir.join("nextpnr.log")).unwrap_or_default();
        let timing = Timing::new(dp, arch, device, None, cells);
        // Not placing a design that needs more than the device has is an answer; any other
        // failure is an error.
        let no_room = log.contains("no Bels remaining") || log.contains("Unable to place");
        if !no_room && timing.over_limit.is_empty() {
            return Err(error(
                "nextpnr-ice40",
                format!(
                    "nextpnr-ice40 failed: {}",
                    first_error(&nextpnr, Some(&log))
                ),
            ));
        }
        return Ok(timing);
    };
    Ok(Timing::new(dp, arch, device, report.as_ref(), cells))
}
