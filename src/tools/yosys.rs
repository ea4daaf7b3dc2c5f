//! yosys: the synthesis of the reference Verilog (and of the constant ROM) whose statistics
//! are the cost figures of `cost`, `report`, `fit`, sweeps, calibration and the optimiser.

use std::path::{Path, PathBuf};
use std::process::Command;

use super::{cache, child, error, io_error, work_dir, write};
use crate::cycle::Arch;
use crate::error::Error;
use crate::hdl::cost::{parse_stat_json, yosys_script, CostReport, Synthesis, Target};
use crate::hdl::params_header;
use crate::hdl::rom::rom_verilog;
use crate::pipeline::Datapath;

/// Checks before any work that yosys runs; returns `yosys -V`.
pub fn check() -> Result<String, Error> {
    let out = child::output(Command::new("yosys").arg("-V")).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => error(
            "yosys",
            "yosys not found: install it (Debian: apt-get install yosys)".into(),
        ),
        _ => io_error("yosys", "cannot run yosys", e),
    })?;
    if !out.status.success() {
        return Err(error("yosys", format!("yosys -V failed: {}", out.status)));
    }
    Ok(String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// Synthesises the datapath: the reference Verilog in `hdl_ref` with the configuration's
/// parameter header, on `target`.
pub fn synthesise(
    dp: &Datapath,
    arch: Arch,
    target: Target,
    hdl_ref: &Path,
) -> Result<Synthesis, Error> {
    let work = work_dir("yosys", "yosys")?;
    write(
        "yosys",
        &work.path().join("specfx_params.vh"),
        &params_header(dp, arch),
    )?;
    let files = super::rtl_files(hdl_ref)?;
    run_in(work.path(), &files, "specfx_dut", target).map_err(|e| {
        error(
            "yosys",
            format!("yosys failed on the reference Verilog: {e}"),
        )
    })
}

/// Synthesises the configuration's constant ROM (`specfx_rom`, generated) on `target`.
pub fn synthesise_rom(dp: &Datapath, target: Target) -> Result<Synthesis, Error> {
    let work = work_dir("yosys", "yosys")?;
    let file = work.path().join("specfx_rom.v");
    write("yosys", &file, &rom_verilog(dp))?;
    run_in(work.path(), &[file], "specfx_rom", target)
        .map_err(|e| error("yosys", format!("yosys failed on the constant ROM: {e}")))
}

/// Runs yosys in `work` on `files` with `top`, or takes its answer from the synthesis cache
/// ([`super::cache`]) when it already synthesised exactly these inputs.
fn run_in(work: &Path, files: &[PathBuf], top: &str, target: Target) -> Result<Synthesis, Error> {
    let version = check()?;
    let names: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
    let script = yosys_script(target, &names, &work.display().to_string(), top);
    write("yosys", &work.join("cost.ys"), &script)?;
    let key = cache_key(work, files, &version, &script);
    // Held until the entry is kept (or the synthesis failed): a run that needs the same
    // entry meanwhile waits for it.
    let _claim = match cache::get_or_claim("yosys", &key, &["stat.json", "stat_cmos.txt"]) {
        Ok(cached) => {
            let text = |b: &Option<Vec<u8>>| b.clone().and_then(|b| String::from_utf8(b).ok());
            if let Some(cost) = text(&cached[0])
                .and_then(|stat| parse_stat_json(&stat, text(&cached[1]).as_deref()).ok())
            {
                return Ok(Synthesis {
                    cost,
                    version,
                    script,
                });
            }
            None
        }
        Err(claim) => Some(claim),
    };
    let out = child::output(
        Command::new("yosys")
            .args(["-q", "-s", "cost.ys"])
            .current_dir(work),
    )
    .map_err(|e| io_error("yosys", "cannot run yosys", e))?;
    if !out.status.success() {
        let err = String::from_utf8_lossy(&out.stderr);
        let first = err
            .lines()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("no message");
        return Err(error("yosys", first.to_string()));
    }
    let stat = std::fs::read_to_string(work.join("stat.json"))
        .map_err(|e| io_error("yosys", "yosys wrote no statistics", e))?;
    let cmos = std::fs::read_to_string(work.join("stat_cmos.txt")).ok();
    let cost = parse_stat_json(&stat, cmos.as_deref())?;
    let mut kept: Vec<(&str, &[u8])> = vec![("stat.json", stat.as_bytes())];
    if let Some(c) = &cmos {
        kept.push(("stat_cmos.txt", c.as_bytes()));
    }
    cache::put("yosys", &key, &kept);
    Ok(Synthesis {
        cost,
        version,
        script,
    })
}

/// The synthesis cache's key of a run of yosys in `work`: its version, its script and every
/// file it reads (the sources, and the work directory's files such as the parameter header),
/// the work directory's own name left out.
fn cache_key(work: &Path, files: &[PathBuf], version: &str, script: &str) -> String {
    let shown = work.display().to_string();
    let mut parts: Vec<Vec<u8>> = vec![
        b"yosys synthesis 1".to_vec(),
        version.as_bytes().to_vec(),
        script.replace(&shown, "<work>").into_bytes(),
    ];
    for f in files {
        parts.push(
            f.display()
                .to_string()
                .replace(&shown, "<work>")
                .into_bytes(),
        );
        parts.push(cache::file_bytes(f));
    }
    let mut own: Vec<PathBuf> = std::fs::read_dir(work)
        .map(|d| d.flatten().map(|e| e.path()).collect())
        .unwrap_or_default();
    own.sort();
    for f in own
        .iter()
        .filter(|f| f.is_file() && !f.ends_with("cost.ys"))
    {
        parts.push(
            f.file_name()
                .unwrap_or_default()
                .as_encoded_bytes()
                .to_vec(),
        );
        parts.push(cache::file_bytes(f));
    }
    cache::key(&parts.iter().map(Vec::as_slice).collect::<Vec<_>>())
}

/// The cost report of `specfx cost`: the analytic model's figures, beside yosys's for the
/// datapath and its constant ROM unless `analytic_only`.
pub fn cost_report(
    dp: &Datapath,
    arch: Arch,
    target: Target,
    hdl_ref: &Path,
    analytic_only: bool,
) -> Result<CostReport, Error> {
    cost_report_steps(dp, arch, target, hdl_ref, analytic_only, &mut |_| {})
}

/// How many runs of yosys [`cost_report_steps`] starts: the datapath's and its ROM's (none
/// when `analytic_only`).
pub const COST_REPORT_STEPS: u64 = 2;

/// [`cost_report`], calling `step` with what it starts before each synthesis (each may take
/// minutes; a cached one is instant), for the caller's progress.
pub fn cost_report_steps(
    dp: &Datapath,
    arch: Arch,
    target: Target,
    hdl_ref: &Path,
    analytic_only: bool,
    step: &mut dyn FnMut(&str),
) -> Result<CostReport, Error> {
    let synthesis = if analytic_only {
        None
    } else {
        let name = &dp.config().name;
        let target_name = target.name();
        step(&format!(
            "synthesising {name} ({arch}) with yosys on {target_name}"
        ));
        let datapath = synthesise(dp, arch, target, hdl_ref)?;
        step(&format!(
            "synthesising the constant ROM of {name} with yosys on {target_name}"
        ));
        let rom = synthesise_rom(dp, target)?;
        Some((datapath, rom.cost))
    };
    Ok(CostReport::new(dp, arch, target, synthesis))
}
