//! `specfx cosim --dpi`: `specfx_top` in Verilator under the constrained-random testbench
//! `hdl_ref/dpi/tb_specfx_dpi.sv`, whose scoreboard calls specfx's model through DPI-C
//! (`libspecfx_c.a`, built from `capi/`): the expected value of every input as it is accepted,
//! and the cycle of every output from the cycle model. Icarus Verilog has no DPI-C support.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use super::cosim::{print_verdict, rtl_sources, CosimArgs};
use super::Outcome;
use specfx::hdl::testbench::parse_log;
use specfx::hdl::top_parameters;
use specfx::tools;

/// A library the user named (`what` says how): a regular file that begins as a static
/// library (an ar archive, `!<arch>`) or a shared one (ELF) does, checked before Verilator
/// builds anything (a linker error would not name it).
fn checked_library(p: &Path, what: &str) -> Result<PathBuf> {
    use std::io::Read as _;
    if !p.is_file() {
        bail!("{what}: no such file, expected libspecfx_c.a");
    }
    let mut magic = [0u8; 8];
    let n = std::fs::File::open(p)
        .and_then(|mut f| f.read(&mut magic))
        .with_context(|| format!("{what}: cannot read it"))?;
    let magic = &magic[..n];
    if !(magic == b"!<arch>\n" || magic == b"!<thin>\n" || magic.starts_with(b"\x7fELF")) {
        bail!(
            "{what}: not a library, expected libspecfx_c.a (an ar archive, beginning with !<arch>) or libspecfx_c.so"
        );
    }
    Ok(std::path::absolute(p)?)
}

/// The C library the testbench links: `--dpi-lib`, `$SPECFX_DPI_LIB`, or `libspecfx_c.a`
/// beside the specfx executable (where `cargo build` puts both).
fn dpi_library(arg: Option<&Path>) -> Result<PathBuf> {
    if let Some(p) = arg {
        return checked_library(p, &format!("--dpi-lib {}", p.display()));
    }
    if let Some(v) = std::env::var_os("SPECFX_DPI_LIB").filter(|v| !v.is_empty()) {
        let p = PathBuf::from(v);
        return checked_library(&p, &format!("SPECFX_DPI_LIB={}", p.display()));
    }
    let exe = std::env::current_exe().context("cannot find the specfx executable's directory")?;
    let dir = exe.parent().unwrap_or(Path::new("."));
    // `cargo build` puts it beside the executable; `cargo test` builds it in deps/.
    match [dir.to_path_buf(), dir.join("deps")]
        .iter()
        .map(|d| d.join("libspecfx_c.a"))
        .find(|l| l.is_file())
    {
        Some(lib) => Ok(lib),
        None => bail!(
            "--dpi: no libspecfx_c.a beside the specfx executable in {} (build it with `cargo build --release`, which builds capi/ too, or pass --dpi-lib)",
            dir.display()
        ),
    }
}

/// A probability as the testbench's whole percent.
fn percent(p: f64) -> i64 {
    (p * 100.0).round() as i64
}

/// Runs `specfx cosim --dpi`. Exit code 1 when a vector failed or nothing was checked.
pub fn run(args: &CosimArgs) -> Result<Outcome> {
    use tools::simulator::Simulator;
    if args.sim == Some(Simulator::Icarus) {
        bail!(
            "--dpi --sim icarus: Icarus Verilog has no DPI-C support (and no plan for it); the DPI testbench runs in Verilator (--sim verilator), and Icarus runs the vector testbench (without --dpi) and cocotb"
        );
    }
    if !Simulator::Verilator.installed() {
        bail!(
            "--dpi: verilator not found on PATH (Debian/Ubuntu: apt-get install -y verilator; ./scripts/test installs it)"
        );
    }
    for (given, what) in [(args.vcd.is_some(), "--vcd"), (args.lint, "--lint")] {
        if given {
            bail!("{what} is not available with --dpi (use the vector testbench for it)");
        }
    }
    let library = dpi_library(args.dpi_lib.as_deref())?;
    let hdl = super::hdl_ref::hdl_ref_dir(args.hdl_ref.as_deref());
    let hdl = std::path::absolute(&hdl)
        .with_context(|| format!("--hdl-ref {}: cannot resolve it", hdl.display()))?;
    let rtl = rtl_sources(&hdl)?;
    let testbench = [
        hdl.join("dpi/specfx_dpi.sv"),
        hdl.join("dpi/tb_specfx_dpi.sv"),
    ];
    if let Some(missing) = testbench.iter().find(|f| !f.is_file()) {
        bail!("{}: the DPI testbench is missing", missing.display());
    }
    let dp = match &args.vectors {
        Some(v) => specfx::input::load_vectors(v)?,
        None => specfx::input::load_datapath(&args.config, args.n.as_ref())?,
    };
    let work = tools::child::work_dir("cosim-dpi").context("cannot create a work directory")?;
    let wd = work.path();
    // The model the testbench opens is this datapath, --n and all, as TOML.
    let config = wd.join("config.toml");
    specfx::output::write_atomic(&config, dp.config().to_toml().as_bytes())?;
    let run = &args.run;
    let arch = dp.config().resolve_arch(run.arch);
    let mut plusargs = vec![
        format!("config={}", config.display()),
        format!("seed={}", run.seed),
        // Registers without a reset start random (Verilator's seed is never 0: 0 asks it for a
        // seed of its own).
        "verilator+rand+reset+2".to_string(),
        format!("verilator+seed+{}", run.seed % (1 << 31) + 1),
    ];
    let exhaustive = args.cases.exhaustive;
    let what = if exhaustive {
        plusargs.push("exhaustive".to_string());
        "every input code up to 1.0 of every n".to_string()
    } else {
        let n = args.cases.random.max(1);
        plusargs.push(format!("nvec={n}"));
        format!("the directed vectors and {n} random ones")
    };
    // Exhaustive runs drive one input per cycle (the random runs exercise the handshakes).
    let (bubble, stall) = if exhaustive {
        (0.0, 0.0)
    } else {
        (run.bubble, run.stall)
    };
    plusargs.push(format!("bubble={}", percent(bubble)));
    plusargs.push(format!("stall={}", percent(stall)));
    let params = top_parameters(&dp, arch, args.reset_data);
    log::info!(
        "cosim --dpi: verilator, {}, {} ({}), seed {}{}",
        arch,
        what,
        dp.config().name,
        run.seed,
        if exhaustive {
            ", no bubbles or stalls".to_string()
        } else {
            format!(", bubble {bubble}, stall {stall}")
        }
    );
    log::info!(
        "cosim --dpi: building with verilator and {}",
        library.display()
    );
    let out = tools::simulator::simulate_dpi(
        wd,
        &tools::simulator::DpiRun {
            testbench: &testbench,
            rtl: &rtl,
            library: &library,
            params: &params,
            plusargs: &plusargs,
            optimize: exhaustive,
        },
    )?;
    let verdict = parse_log(&out.log);
    if args.keep {
        let kept = work.keep();
        log::info!("cosim --dpi: work directory {}", kept.display());
    }
    match print_verdict(&verdict, out.failure.as_deref())? {
        None => Ok(Outcome::Ok),
        Some(why) => {
            log::error!("cosim --dpi: FAIL (verilator, {}): {why}", arch);
            Ok(Outcome::CheckFailed)
        }
    }
}
