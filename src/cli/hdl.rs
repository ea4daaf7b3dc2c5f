//! `specfx hdl`: the bridge to the reference Verilog (parameter headers, co-simulation
//! stimulus).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::{Args, Subcommand};

use super::sim::parse_probability;
use super::Outcome;
use specfx::cycle::stimulus::{cosim_stimulus, StimulusRun};
use specfx::cycle::Arch;
use specfx::hdl::rom::rom_verilog;
use specfx::hdl::{render_parameters, ParamsFormat};
use specfx::output::write_atomic;

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
    /// Microarchitecture: pipelined or folded [default: the configuration's `arch` key, else
    /// pipelined].
    #[arg(long, value_parser = super::named_values(&Arch::ALL, Arch::name, super::no_help))]
    arch: Option<Arch>,
    /// How to render the parameters of `specfx_top`: define (the `specfx_params.vh` header of
    /// `specfx_dut.v`), json, iverilog (`-P` flags), verilator (`-G` flags) or instance (a
    /// Verilog instantiation).
    #[arg(long, default_value = "define",
          value_parser = super::named_values(&ParamsFormat::ALL, ParamsFormat::name, ParamsFormat::help))]
    format: ParamsFormat,
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
    /// Microarchitecture: pipelined or folded [default: the `arch` key of the configuration
    /// (of the vectors' manifest), else pipelined].
    #[arg(long, value_parser = super::named_values(&Arch::ALL, Arch::name, super::no_help))]
    pub arch: Option<Arch>,
    /// Seed of the bubble/stall patterns (`cosim`: also of the vectors it writes).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Probability that the source offers no input in a random cycle.
    #[arg(long, default_value = "0.2", value_parser = parse_probability)]
    pub bubble: f64,
    /// Fraction of the random cycles in which the sink is not ready: stalls come in bursts
    /// averaging one initiation interval plus one cycle, between blocks of directed stall
    /// episodes (the handshake pattern, docs/cycle.md).
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
    let dp = specfx::input::load_datapath(&args.config, None)?;
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
            specfx::output::check_file_output(
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
        Some(dir) => specfx::input::load_vectors(dir)?,
        None => specfx::input::load_datapath(&args.config, None)?,
    };
    let text = render_parameters(
        &dp,
        dp.config().resolve_arch(args.arch),
        args.reset_data,
        args.format,
        &args.top,
    );
    let inputs = match &args.vectors {
        Some(dir) => super::output::config_inputs_as("--vectors", &dir.to_string_lossy()),
        None => super::output::config_inputs_as("--config", &args.config),
    };
    let own_header = match args.format {
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

/// What [`write_stimulus`] wrote: the run's size and latency range.
pub struct StimulusInfo {
    /// Vectors streamed.
    pub n_vectors: usize,
    /// Lines of `stim_valid.hex` and `stim_ready.hex`.
    pub n_cycles: u64,
    /// Shortest and longest input-to-output latency of the run, in cycles.
    pub latency: (u64, u64),
    /// The microarchitecture of the run (`--arch`, else the manifest's `arch` key).
    pub arch: Arch,
}

/// Writes the co-simulation stimulus of an opened vector directory into `out`
/// ([`cosim_stimulus`]), all files or none; with `vcd`, also the model's trace of that run to
/// that file.
pub fn write_stimulus(
    vectors: &specfx::input::VectorDir,
    run: RunOpts,
    out: &Path,
    vcd: Option<&Path>,
) -> Result<StimulusInfo> {
    let dp = specfx::pipeline::Datapath::new(vectors.config.clone())
        .context("the manifest's configuration")?;
    let RunOpts {
        arch,
        seed,
        bubble,
        stall,
    } = run;
    let arch = dp.config().resolve_arch(arch);
    let run = StimulusRun {
        arch,
        seed,
        bubble,
        stall,
    };
    // open() checked that every n is in the manifest's n set.
    let s = cosim_stimulus(&dp, &vectors.inputs, run, vcd.is_some())?;
    let mut files: Vec<(PathBuf, Vec<u8>)> = s
        .files
        .into_iter()
        .map(|(name, bytes)| (out.join(name), bytes))
        .collect();
    if let (Some(path), Some(trace)) = (vcd, s.vcd) {
        files.push((path.to_path_buf(), trace));
    }
    specfx::output::write_all_atomic(&files)?;
    Ok(StimulusInfo {
        n_vectors: s.n_vectors,
        n_cycles: s.n_cycles,
        latency: s.latency,
        arch,
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
    let vector_dir = specfx::input::dir_of(&args.vectors);
    specfx::output::refuse_inside_input_dir(&args.out, "--out", &vector_dir, "--vectors")?;
    if let Some(vcd) = &args.vcd {
        specfx::output::refuse_inside_input_dir(vcd, "--vcd", &vector_dir, "--vectors")?;
    }
    let inputs = super::output::config_inputs_as("--vectors", &args.vectors.to_string_lossy());
    let earlier = args.out.join("stim.json").is_file();
    specfx::output::check_files_in(
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
        specfx::output::check_file_output(
            vcd,
            "--vcd",
            &inputs,
            Some(specfx::cycle::vcd::VCD_HEADER),
            args.force,
        )?;
    }
    let vectors = specfx::input::open_vectors(&args.vectors)?;
    let s = write_stimulus(&vectors, args.run, &args.out, args.vcd.as_deref())?;
    super::output::outln!(
        "{} vectors over {} cycles ({}, latency {}..{})",
        s.n_vectors,
        s.n_cycles,
        s.arch,
        s.latency.0,
        s.latency.1
    )?;
    Ok(Outcome::Ok)
}
