//! `specfx hdl`: the bridge to the reference Verilog (parameter headers, co-simulation
//! stimulus).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::{Args, Subcommand};

use super::output::write_atomic;
use super::sim::parse_probability;
use super::Outcome;
use specfx::cycle::sim::{simulate, Stimulus, Stop};
use specfx::cycle::vcd::write_vcd;
use specfx::cycle::Arch;
use specfx::hdl::rom::rom_verilog;
use specfx::hdl::{render_parameters, ParamsFormat};

/// `--format` of `specfx hdl params`: the library's [`ParamsFormat`], with its help.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum FormatArg {
    /// `specfx_params.vh`: `` `define SPECFX_<NAME> <value> `` lines for `specfx_dut.v`.
    Define,
    /// A JSON object `{"NAME": value, ...}` (cocotb, VUnit, FuseSoC scripts).
    Json,
    /// Icarus Verilog flags, one per line: `-P<top>.<NAME>=<value>`.
    Iverilog,
    /// Verilator flags, one per line: `-G<NAME>=<value>` (for the top module).
    Verilator,
    /// A Verilog instantiation of `specfx_top` with every parameter set.
    Instance,
}

impl From<FormatArg> for ParamsFormat {
    fn from(f: FormatArg) -> ParamsFormat {
        match f {
            FormatArg::Define => ParamsFormat::Define,
            FormatArg::Json => ParamsFormat::Json,
            FormatArg::Iverilog => ParamsFormat::Iverilog,
            FormatArg::Verilator => ParamsFormat::Verilator,
            FormatArg::Instance => ParamsFormat::Instance,
        }
    }
}

/// Arguments of `specfx hdl`.
#[derive(Debug, Args)]
pub struct HdlArgs {
    #[command(subcommand)]
    command: HdlCommand,
}

#[derive(Debug, Subcommand)]
enum HdlCommand {
    /// Prints the values of `specfx_top`'s Verilog parameters for a configuration: the
    /// `specfx_params.vh` header of `specfx_dut.v`, JSON, simulator flags or an instance.
    Params(ParamsArgs),
    /// Prints the per-n constant ROM (`specfx_rom.v`) of a configuration: a `case` on n (a
    /// contiguous n range) or on the index of n in the set (a list, e.g. a fitted scene's).
    Rom(RomArgs),
    /// Writes the valid/ready patterns and expected output cycles for co-simulating a vector
    /// directory.
    Stimulus(StimulusArgs),
}

#[derive(Debug, Args)]
struct ParamsArgs {
    /// A TOML configuration file, a vector directory, or a built-in name: baseline.
    #[arg(long, default_value = "baseline", conflicts_with = "vectors")]
    config: String,
    /// A vector directory: use the configuration of its manifest.
    #[arg(long)]
    vectors: Option<PathBuf>,
    /// Microarchitecture: pipelined or folded.
    #[arg(long, default_value = "pipelined")]
    arch: Arch,
    /// How to render the parameters of `specfx_top`: define (the `specfx_params.vh` header of
    /// `specfx_dut.v`), json, iverilog (`-P` flags), verilator (`-G` flags) or instance (a
    /// Verilog instantiation).
    #[arg(long, default_value = "define")]
    format: FormatArg,
    /// The module whose parameters the iverilog `-P` flags set.
    #[arg(long, default_value = "specfx_top", value_parser = verilog_identifier)]
    top: String,
    /// Clear the data registers on reset too (`RESET_DATA = 1`), so out_data is 0 until the
    /// first result.
    #[arg(long)]
    reset_data: bool,
    /// Write the parameters here instead of printing them.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace an existing output file that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
}

#[derive(Debug, Args)]
struct RomArgs {
    /// A TOML configuration file, a vector directory, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Write the module here instead of printing it.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace an existing output file that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
}

/// The run a stimulus describes: the microarchitecture and the seeded valid/ready patterns
/// (`specfx hdl stimulus`, `specfx cosim`).
#[derive(Debug, Clone, Copy, Args)]
pub struct RunOpts {
    /// Microarchitecture: pipelined or folded.
    #[arg(long, default_value = "pipelined")]
    pub arch: Arch,
    /// Seed of the bubble/stall patterns (`cosim`: also of the vectors it writes).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Probability that the source offers no input in a cycle.
    #[arg(long, default_value = "0.2", value_parser = parse_probability)]
    pub bubble: f64,
    /// Probability that the sink is not ready in a cycle.
    #[arg(long, default_value = "0.2", value_parser = parse_probability)]
    pub stall: f64,
}

#[derive(Debug, Args)]
struct StimulusArgs {
    /// The vector directory (written by `specfx vectors`).
    #[arg(long)]
    vectors: PathBuf,
    #[command(flatten)]
    run: RunOpts,
    /// Directory for stim_valid.hex, stim_ready.hex, expected_cycle.hex and stim.json.
    #[arg(long)]
    out: PathBuf,
    /// Also write the model's VCD trace of this run here (every cycle until the last output,
    /// under the RTL's names), to compare with the testbench's dump (`specfx trace compare`).
    #[arg(long)]
    vcd: Option<PathBuf>,
    /// Replace existing files that are not an earlier result of this command.
    #[arg(long)]
    force: bool,
}

/// Runs `specfx hdl ...`.
pub fn run(args: &HdlArgs) -> Result<Outcome> {
    match &args.command {
        HdlCommand::Params(a) => params(a),
        HdlCommand::Rom(a) => rom(a),
        HdlCommand::Stimulus(a) => stimulus(a),
    }
}

fn rom(args: &RomArgs) -> Result<Outcome> {
    let dp = super::datapath::load(&args.config, None)?;
    let out = Output {
        path: args.out.as_deref(),
        inputs: super::output::inputs(&args.config, None),
        own_header: Some("// specfx_rom: "),
        force: args.force,
    };
    print_or_write(out, &rom_verilog(&dp))
}

/// Where `hdl params` and `hdl rom` put their text: a file (checked before it is written)
/// or stdout.
struct Output<'a> {
    path: Option<&'a Path>,
    inputs: Vec<(&'static str, PathBuf)>,
    own_header: Option<&'static str>,
    force: bool,
}

/// Writes `text` to the output's file, or prints it.
fn print_or_write(out: Output, text: &str) -> Result<Outcome> {
    match out.path {
        Some(path) => {
            super::output::check_file_output(
                path,
                "--out",
                &out.inputs,
                out.own_header,
                out.force,
            )?;
            write_atomic(path, text.as_bytes())?
        }
        None => super::output::print_with(|w| {
            use std::io::Write;
            w.write_all(text.as_bytes())
        })?,
    }
    Ok(Outcome::Ok)
}

fn params(args: &ParamsArgs) -> Result<Outcome> {
    let dp = match &args.vectors {
        Some(dir) => super::datapath::load_vectors(dir)?,
        None => super::datapath::load(&args.config, None)?,
    };
    let text = render_parameters(
        &dp,
        args.arch,
        args.reset_data,
        args.format.into(),
        &args.top,
    );
    let inputs = match &args.vectors {
        Some(dir) => super::output::config_inputs_as("--vectors", &dir.to_string_lossy()),
        None => super::output::config_inputs_as("--config", &args.config),
    };
    let own_header = match ParamsFormat::from(args.format) {
        ParamsFormat::Define => Some("// specfx parameters: "),
        ParamsFormat::Instance => Some("// specfx_top for configuration "),
        _ => None,
    };
    let out = Output {
        path: args.out.as_deref(),
        inputs,
        own_header,
        force: args.force,
    };
    print_or_write(out, &text)
}

fn bits_file(bits: &[bool]) -> String {
    bits.iter()
        .map(|&b| if b { "1\n" } else { "0\n" })
        .collect()
}

/// A Verilog identifier (`--top`): a letter or `_`, then letters, digits, `_` or `$`, at most
/// 1024 characters; anything else would go into the simulator's flags as more than a name.
fn verilog_identifier(s: &str) -> std::result::Result<String, String> {
    let mut chars = s.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    let rest_ok = chars.all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$');
    if first_ok && rest_ok && s.len() <= 1024 {
        Ok(s.to_string())
    } else {
        Err(format!(
            "expected a Verilog module name (a letter or '_', then letters, digits, '_' or '$'), got '{}'",
            s.escape_debug()
        ))
    }
}

/// The longest stimulus `specfx hdl stimulus` writes, in cycles (a line of each of its bit
/// files per cycle).
pub const MAX_STIMULUS_CYCLES: u64 = 1 << 26;

/// What [`write_stimulus`] wrote: the run's size and latency range.
pub struct StimulusInfo {
    /// Vectors streamed.
    pub n_vectors: usize,
    /// Lines of `stim_valid.hex` and `stim_ready.hex`.
    pub n_cycles: u64,
    /// Shortest and longest input-to-output latency of the run, in cycles.
    pub latency: (u64, u64),
}

/// Writes the co-simulation stimulus of an opened vector directory into `out`:
/// `stim_valid.hex`, `stim_ready.hex`, `expected_cycle.hex` and `stim.json`, from the cycle
/// model run on the vectors in file order under seeded bubbles and stalls; with `vcd`, also
/// the model's trace of that run (every cycle until the last output transfers) to that file.
pub fn write_stimulus(
    vectors: &super::vectordir::VectorDir,
    run: RunOpts,
    out: &Path,
    vcd: Option<&Path>,
) -> Result<StimulusInfo> {
    let RunOpts {
        arch,
        seed,
        bubble,
        stall,
    } = run;
    let dp = specfx::pipeline::Datapath::new(vectors.config.clone())
        .context("the manifest's configuration")?;
    let ns = dp.config().n.values();
    // open() checked that every n is in the manifest's n set.
    let items: Vec<(usize, i64)> = vectors
        .inputs
        .iter()
        .map(|&(n, c)| {
            (
                ns.binary_search(&n).expect("n checked by vectordir::open"),
                c,
            )
        })
        .collect();
    let mut stim = Stimulus::new(seed, bubble, stall);
    // Each vector needs about one offer (1 / (1 - bubble) cycles) and, folded, an initiation
    // interval of accepted outputs (ii / (1 - stall)); twenty times that, plus the latency,
    // drains any run but one of vanishing probability. Longer stimuli are refused up front.
    let ii = arch.initiation_interval(dp.config()) as f64;
    let per_vector = 1.0 / (1.0 - bubble) + ii / (1.0 - stall);
    let expected = (items.len() as f64 * per_vector).ceil();
    // With a trace, every cycle is kept in memory: a tighter limit.
    let (max, what) = match vcd {
        Some(_) => (
            specfx::cycle::vcd::MAX_TRACE_CYCLES,
            "with --vcd, the trace",
        ),
        None => (MAX_STIMULUS_CYCLES, "the stimulus"),
    };
    if expected > max as f64 {
        let fit = (max as f64 / per_vector).floor();
        let advice = if fit < 1.0 {
            "lower them".to_string()
        } else {
            format!("about {fit:.0} vectors fit at these probabilities: lower them or use fewer vectors")
        };
        bail!(
            "--bubble {bubble} and --stall {stall} would need about {expected:.0} cycles for {} vectors; {what} is limited to {max} cycles ({advice})",
            items.len()
        );
    }
    // The run stops at the limit: a stimulus that has not drained by then is refused below.
    let limit = (20.0 * expected + 100.0 * arch.latency(dp.config()) as f64 + 1_000.0)
        .min(max as f64) as u64;
    let trace_cycles = if vcd.is_some() { max } else { 0 };
    let result = simulate(
        &dp,
        arch,
        items.iter().copied(),
        &mut stim,
        Stop::Drained(limit),
        trace_cycles,
    );
    let s = &result.stats;
    if s.n_outputs != items.len() as u64 && s.mismatches == 0 && s.order_errors == 0 {
        bail!(
            "the stimulus did not drain within {limit} cycles ({} of {} outputs, --bubble {bubble}, --stall {stall}): lower the probabilities or change --seed",
            s.n_outputs,
            items.len()
        );
    }
    if s.n_outputs != items.len() as u64 || s.mismatches != 0 || s.order_errors != 0 {
        bail!(
            "the cycle model delivered {} of {} outputs with {} mismatches: this is a bug",
            s.n_outputs,
            items.len(),
            s.mismatches
        );
    }
    let mut cycles = String::new();
    for o in &result.outputs {
        writeln!(cycles, "{:08x}", o.cycle).expect("write to String");
    }
    let info = serde_json::json!({
        "arch": arch.name(),
        "latency": arch.latency(dp.config()),
        "initiation_interval": arch.initiation_interval(dp.config()),
        "seed": seed,
        "bubble": bubble,
        "stall": stall,
        "n_cycles": s.n_cycles,
        "n_vectors": items.len(),
        "latency_min": s.latency_min,
        "latency_max": s.latency_max,
    });
    let mut json = serde_json::to_vec_pretty(&info)?;
    json.push(b'\n');
    // All or nothing, stim.json last (see STIMULUS_FILES).
    let mut files = vec![
        (
            out.join("stim_valid.hex"),
            bits_file(&result.valid_bits).into_bytes(),
        ),
        (
            out.join("stim_ready.hex"),
            bits_file(&result.ready_bits).into_bytes(),
        ),
        (out.join("expected_cycle.hex"), cycles.into_bytes()),
        (out.join("stim.json"), json),
    ];
    if let Some(path) = vcd {
        let mut buf = Vec::new();
        write_vcd(&mut buf, &dp, arch, &result.trace)?;
        files.push((path.to_path_buf(), buf));
    }
    super::output::write_all_atomic(&files)?;
    Ok(StimulusInfo {
        n_vectors: items.len(),
        n_cycles: s.n_cycles,
        latency: (s.latency_min, s.latency_max),
    })
}

/// The files `hdl stimulus` writes into its `--out` directory; `stim.json` last, so that a
/// directory holding it holds an earlier complete stimulus.
const STIMULUS_FILES: [&str; 4] = [
    "stim_valid.hex",
    "stim_ready.hex",
    "expected_cycle.hex",
    "stim.json",
];

fn stimulus(args: &StimulusArgs) -> Result<Outcome> {
    // The stimulus goes into a directory of its own, never into the vector directory it
    // reads; an earlier stimulus there (its stim.json) is replaced, other files of the same
    // names only with --force. The outputs are checked before the vectors are read.
    let vector_dir = super::vectordir::dir_of(&args.vectors);
    super::output::refuse_inside_input_dir(&args.out, "--out", &vector_dir, "--vectors")?;
    if let Some(vcd) = &args.vcd {
        super::output::refuse_inside_input_dir(vcd, "--vcd", &vector_dir, "--vectors")?;
    }
    let inputs = super::output::config_inputs_as("--vectors", &args.vectors.to_string_lossy());
    let earlier = args.out.join("stim.json").is_file();
    super::output::check_files_in(
        &args.out,
        &STIMULUS_FILES,
        "--out",
        &inputs,
        None,
        args.force || earlier,
    )?;
    if let Some(vcd) = &args.vcd {
        let mut inputs = inputs.clone();
        inputs.extend(STIMULUS_FILES.map(|f| ("--out", args.out.join(f))));
        super::output::check_file_output(
            vcd,
            "--vcd",
            &inputs,
            Some(specfx::cycle::vcd::VCD_HEADER),
            args.force,
        )?;
    }
    let vectors = super::vectordir::open(&args.vectors)?;
    let s = write_stimulus(&vectors, args.run, &args.out, args.vcd.as_deref())?;
    super::output::outln!(
        "{} vectors over {} cycles ({}, latency {}..{})",
        s.n_vectors,
        s.n_cycles,
        args.run.arch,
        s.latency.0,
        s.latency.1
    )?;
    Ok(Outcome::Ok)
}
