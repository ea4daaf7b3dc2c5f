//! `specfx cosim`: co-simulates the reference Verilog (or a copy of it) against golden vectors
//! and the cycle model's output cycles, in Icarus Verilog or Verilator.
//!
//! The testbench `hdl_ref/tb/tb_specfx.v` instantiates the parameterized top `specfx_top`
//! with the configuration's values set as Verilog parameters on the simulator's command line
//! (`-P` for Icarus, `-G` for Verilator), so the co-simulation exercises the same top a
//! cocotb, VUnit or FuseSoC flow instantiates.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;

use super::hdl::{write_stimulus, RunOpts};
use super::Outcome;
use specfx::golden::{CaseSelection, Order};
use specfx::hdl::testbench::parse_log;
use specfx::hdl::top_parameters;
use specfx::nset::NSet;
use specfx::tools;
use specfx::tools::simulator::Simulator;

/// Arguments of `specfx cosim`.
#[derive(Debug, Args)]
pub struct CosimArgs {
    /// A vector directory (`specfx vectors --out DIR`). Without it, vectors are written for
    /// --config into the work directory.
    #[arg(long, conflicts_with_all = ["config", "n", "cases"])]
    pub(super) vectors: Option<PathBuf>,
    /// A TOML configuration file or a built-in name (baseline), when no --vectors is given.
    #[arg(long, default_value = "baseline")]
    pub(super) config: String,
    /// Exponents, replacing the configuration's set (with --config).
    #[arg(long)]
    pub(super) n: Option<NSet>,
    /// Which cases to write (with --config): corner, exhaustive, random:N, comma-separated.
    #[arg(long, default_value = "corner,random:1000")]
    pub(super) cases: CaseSelection,
    /// Row order of the vectors written for --config: interleaved (n changes almost every
    /// vector, seeded) or sorted by n then c.
    #[arg(long, default_value = "interleaved", conflicts_with = "vectors", value_parser = super::named_values(&Order::ALL, Order::name, super::no_help))]
    pub(super) order: Order,
    /// The simulator: icarus or verilator. Default: icarus when installed, else verilator.
    #[arg(long, value_parser = super::named_values(&Simulator::ALL, Simulator::name, Simulator::help))]
    pub(super) sim: Option<Simulator>,
    #[command(flatten)]
    pub(super) run: RunOpts,
    /// Build the DUT with RESET_DATA = 1 (data registers cleared on reset; the testbench then
    /// also checks that out_data is 0 in the first cycle).
    #[arg(long)]
    pub(super) reset_data: bool,
    /// First lint the DUT with `verilator --lint-only -Wall` (a warning fails the run).
    #[arg(long)]
    pub(super) lint: bool,
    /// The reference Verilog directory (`rtl/*.v` and `tb/tb_specfx.v`); default: this
    /// repository's hdl_ref/ (or $SPECFX_HDL_REF). Point it at a modified copy to co-simulate
    /// your own RTL behind the same ports.
    #[arg(long)]
    pub(super) hdl_ref: Option<PathBuf>,
    /// Write both traces of the run into this directory, the RTL's (every signal of the
    /// testbench) as rtl.vcd and the model's (under the RTL's names) as model.vcd, and compare
    /// them signal by signal (`specfx trace compare`; exit code 1 when they differ), also
    /// when a vector failed: the first differing cycle and register are printed beside it.
    #[arg(long)]
    pub(super) vcd: Option<PathBuf>,
    /// Replace rtl.vcd and model.vcd in the --vcd directory when they are not an earlier
    /// result of this command.
    #[arg(long)]
    pub(super) force: bool,
    /// Keep the work directory (its path is printed) instead of deleting it.
    #[arg(long)]
    pub(super) keep: bool,
    /// Check with the constrained-random testbench `hdl_ref/dpi/tb_specfx_dpi.sv` instead of
    /// vectors: its scoreboard calls specfx's model through DPI-C for the expected output of
    /// every input as it is accepted, and the cycle model for its cycle (Verilator only;
    /// Icarus Verilog has no DPI-C). `--cases random:N` drives the directed cases of
    /// `specfx vectors`, then N random vectors; `--cases exhaustive` every input code up to 1.0
    /// of every n, one per cycle.
    #[arg(long, conflicts_with_all = ["vcd", "lint", "order"])]
    pub(super) dpi: bool,
    /// The C library the DPI testbench links (`libspecfx_c.a`); default: $SPECFX_DPI_LIB, or
    /// the one beside the specfx executable (`cargo build --release` builds it).
    #[arg(long, requires = "dpi")]
    pub(super) dpi_lib: Option<PathBuf>,
}

/// Runs `specfx cosim`. Exit code 1 when a vector failed or nothing was checked.
pub fn run(args: &CosimArgs) -> Result<Outcome> {
    if args.dpi {
        return super::cosim_dpi::run(args);
    }
    let sim = choose_simulator(args.sim)?;
    if args.lint && !Simulator::Verilator.installed() {
        bail!("--lint: verilator not found on PATH (Debian/Ubuntu: apt-get install -y verilator)");
    }
    check_vcd_output(args)?;
    // Absolute: the simulator runs in the work directory.
    let hdl = super::hdl_ref::hdl_ref_dir(args.hdl_ref.as_deref());
    let hdl = std::path::absolute(&hdl)
        .with_context(|| format!("--hdl-ref {}: cannot resolve it", hdl.display()))?;
    let rtl = rtl_sources(&hdl)?;
    let tb = hdl.join("tb/tb_specfx.v");
    if !tb.is_file() {
        bail!("{}: the testbench is missing", tb.display());
    }
    let work = tools::child::work_dir("cosim").context("cannot create a work directory")?;
    let wd = work.path();
    let (vectors, opened) = vector_dir(args, wd)?;
    let dp = specfx::pipeline::Datapath::new(opened.config.clone())
        .context("the manifest's configuration")?;
    let arch = dp.config().resolve_arch(args.run.arch);
    // The --vcd directory is made with the model's trace, once the stimulus is known to fit.
    let model_vcd = args.vcd.as_ref().map(|d| d.join("model.vcd"));
    let stim = write_stimulus(&opened, args.run, wd, model_vcd.as_deref())?;
    for port in specfx::golden::testbench_ports(&dp) {
        let from = vectors.join(port.file_name());
        std::fs::copy(&from, wd.join(port.file_name()))
            .with_context(|| format!("cannot copy {}", from.display()))?;
    }
    let mut params = vec![
        ("NVEC".to_string(), stim.n_vectors as i64),
        ("NCYC".to_string(), stim.n_cycles as i64),
    ];
    params.extend(top_parameters(&dp, arch, args.reset_data));
    if args.lint && !lint_clean(&rtl, &params)? {
        return Ok(Outcome::CheckFailed);
    }
    log::info!(
        "cosim: {}, {}, {} vectors ({}), {} stimulus cycles (seed {}, bubble {}, stall {}){}",
        sim.name(),
        arch,
        stim.n_vectors,
        dp.config().name,
        stim.n_cycles,
        args.run.seed,
        args.run.bubble,
        args.run.stall,
        if args.reset_data {
            ", RESET_DATA = 1"
        } else {
            ""
        }
    );
    if sim == Simulator::Verilator {
        log::info!("cosim: building with verilator (a minute or less)");
    }
    let out = tools::simulator::simulate(sim, wd, &tb, &rtl, &params, args.vcd.is_some())?;
    let verdict = parse_log(&out.log);
    // The RTL's trace: a testbench that ran to its summary must have written it; one that
    // died may have written none, and then there is nothing to compare.
    let traces = match &args.vcd {
        Some(dir) => {
            let from = wd.join("rtl.vcd");
            if verdict.is_ok() || from.is_file() {
                std::fs::copy(&from, dir.join("rtl.vcd"))
                    .with_context(|| format!("the simulator wrote no {}", from.display()))?;
                Some((dir.join("model.vcd"), dir.join("rtl.vcd")))
            } else {
                log::error!("cosim: the simulation wrote no trace to compare");
                None
            }
        }
        None => None,
    };
    if args.keep {
        let kept = work.keep();
        log::info!("cosim: work directory {}", kept.display());
    }
    let failure = print_verdict(&verdict, out.failure.as_deref())?;
    let traces_differ = match &traces {
        Some((model, rtl)) => compare_traces(model, rtl, failure.is_some())?,
        None => None,
    };
    let at = format!("({}, {})", sim.name(), arch);
    match (failure, traces_differ) {
        (None, None) => Ok(Outcome::Ok),
        (failure, differ) => {
            let why: Vec<String> = failure.into_iter().chain(differ).collect();
            log::error!("cosim: FAIL {at}: {}", why.join("; "));
            Ok(Outcome::CheckFailed)
        }
    }
}

/// Checks `--vcd` before any work: never inside the input vector directory; created when
/// missing; an earlier cosim's traces there (model.vcd begins with the model's header) are
/// replaced, other files of those names only with --force, never an input.
fn check_vcd_output(args: &CosimArgs) -> Result<()> {
    if let (Some(vcd), Some(v)) = (&args.vcd, &args.vectors) {
        let vector_dir = specfx::input::dir_of(v);
        specfx::output::refuse_inside_input_dir(vcd, "--vcd", &vector_dir, "--vectors")?;
    }
    if let Some(dir) = args.vcd.as_ref().filter(|d| !d.is_dir()) {
        specfx::output::check_can_create(dir, "--vcd")?;
    } else if let Some(dir) = &args.vcd {
        let mut inputs = super::output::inputs(&args.config, None);
        if let Some(v) = &args.vectors {
            inputs.extend(super::output::config_inputs_as(
                "--vectors",
                &v.to_string_lossy(),
            ));
        }
        let model = dir.join("model.vcd");
        let header = Some(specfx::cycle::vcd::VCD_HEADER);
        specfx::output::check_file_output(&model, "--vcd", &inputs, header, args.force)?;
        let earlier = model.is_file();
        let rtl = dir.join("rtl.vcd");
        specfx::output::check_file_output(&rtl, "--vcd", &inputs, None, args.force || earlier)?;
    }
    Ok(())
}

/// The vector directory to co-simulate and its vectors: --vectors, opened (its files
/// verified), or the vectors of --config written into the work directory, handed over as made.
fn vector_dir(
    args: &CosimArgs,
    wd: &std::path::Path,
) -> Result<(PathBuf, specfx::input::VectorDir)> {
    if let Some(dir) = &args.vectors {
        if !dir.join("manifest.json").is_file() {
            bail!(
                "{}: no manifest.json (write a vector directory with specfx vectors --out {})",
                dir.display(),
                dir.display()
            );
        }
        return Ok((dir.clone(), specfx::input::open_vectors(dir)?));
    }
    let dp = specfx::input::load_datapath(&args.config, args.n.as_ref())?;
    let dir = wd.join("vectors");
    let (inputs, _) = super::vectors::write_dir(
        &dp,
        &dir,
        &args.cases,
        args.order,
        args.run.seed,
        false,
        &[],
    )?;
    let made = specfx::input::VectorDir {
        config: dp.config().clone(),
        inputs,
    };
    Ok((dir, made))
}

/// `verilator --lint-only -Wall` of `specfx_top` and the RTL with the top's parameters (the
/// testbench's own are left out); logs the complaints and returns false when there are some.
fn lint_clean(rtl: &[PathBuf], params: &[(String, i64)]) -> Result<bool> {
    log::info!("cosim: verilator --lint-only -Wall (specfx_top + rtl)");
    let top: Vec<(String, i64)> = params
        .iter()
        .filter(|(k, _)| k != "NVEC" && k != "NCYC")
        .cloned()
        .collect();
    if let Some(complaints) = tools::simulator::lint(rtl, &top)? {
        log::error!("{complaints}");
        log::error!("cosim: lint failed");
        return Ok(false);
    }
    Ok(true)
}

/// Prints the testbench's verdict (its problems, then `N passed, N failed`); returns why the
/// run failed, if it did: a failed vector or nothing checked by the count, or a testbench
/// whose process failed (`exit_failure`, its exit status: a `$fatal`) whatever it counted.
pub(super) fn print_verdict(
    verdict: &std::result::Result<specfx::hdl::testbench::Tally, specfx::Error>,
    exit_failure: Option<&str>,
) -> Result<Option<String>> {
    Ok(match verdict {
        Ok(v) => {
            for line in &v.problems {
                super::output::outln!("{line}")?;
            }
            super::output::outln!("{} passed, {} failed", v.passed, v.failed)?;
            if v.failed != 0 {
                Some(format!(
                    "{} of {} vectors failed",
                    v.failed,
                    v.failed + v.passed
                ))
            } else if v.passed == 0 {
                Some("nothing was checked".to_string())
            } else {
                exit_failure.map(|status| {
                    format!(
                        "the testbench counted {} passed, 0 failed but ended with {status}",
                        v.passed
                    )
                })
            }
        }
        Err(e) => Some(match exit_failure {
            Some(status) => format!("{e} (it ended with {status})"),
            None => e.to_string(),
        }),
    })
}

/// Compares the model's and the RTL's traces: where a vector failed, the first differing
/// register tells where the RTL went wrong. A trace that cannot be read does not hide a
/// `failed` run (it is logged); otherwise it is the error.
fn compare_traces(
    model: &std::path::Path,
    rtl: &std::path::Path,
    failed: bool,
) -> Result<Option<String>> {
    let options = specfx::cycle::compare::Options::default();
    match super::trace::compare_files(model, rtl, &options) {
        Ok(c) if c.agrees() => Ok(None),
        Ok(c) => Ok(Some(match &c.first_difference {
            Some(d) => format!(
                "the model's and the RTL's traces first differ at cycle {}, {}",
                d.cycle, d.signal
            ),
            None => "the model's and the RTL's traces differ".to_string(),
        })),
        Err(e) if failed => {
            log::error!("cosim: the traces cannot be compared: {e:#}");
            Ok(None)
        }
        Err(e) => Err(e),
    }
}

fn choose_simulator(asked: Option<Simulator>) -> Result<Simulator> {
    let hint = |s: Simulator| {
        let (programs, package) = s.programs();
        format!(
            "{} not found on PATH (Debian/Ubuntu: apt-get install -y {package}; ./scripts/test installs it)",
            programs.join(" and ")
        )
    };
    match asked {
        Some(s) if s.installed() => Ok(s),
        Some(s) => bail!("--sim {}: {}", s.name(), hint(s)),
        None => Simulator::ALL
            .into_iter()
            .find(|s| s.installed())
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "no Verilog simulator: {}; or {}",
                    hint(Simulator::Icarus),
                    hint(Simulator::Verilator)
                )
            }),
    }
}

/// Every `rtl/*.v` of a reference Verilog directory, sorted.
pub(super) fn rtl_sources(hdl: &Path) -> Result<Vec<PathBuf>> {
    let mut files = tools::rtl_files(hdl)?;
    // rtl_files ends with specfx_dut.v, the `define top; the co-simulation uses specfx_top.
    files.retain(|f| f.parent().is_some_and(|p| p.ends_with("rtl")));
    if !files.iter().any(|f| f.ends_with("specfx_top.v")) {
        bail!("{}: no rtl/specfx_top.v", hdl.display());
    }
    Ok(files)
}
