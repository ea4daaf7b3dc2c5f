//! `specfx sim`: the cycle-level simulation of a configuration under random bubbles and stalls.

use std::io::Write;
use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use super::output::{print_json, print_with};
use super::Outcome;
use specfx::cycle::sim::{simulate_stream, Record, SimStats, Stimulus, Stop, Stream};
use specfx::cycle::vcd::write_vcd;
use specfx::cycle::Arch;
use specfx::nset::NSet;

/// Probability in [0, 1).
pub fn parse_probability(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(p) if (0.0..1.0).contains(&p) => Ok(p),
        _ => Err(format!("expected a probability in [0, 1), got '{s}'")),
    }
}

/// Arguments of `specfx sim`.
#[derive(Debug, Args)]
pub struct SimArgs {
    /// A TOML configuration file, a vector directory, or a built-in name: baseline.
    #[arg(long, default_value = "baseline")]
    config: String,
    /// Microarchitecture: pipelined or folded [default: the configuration's `arch` key, else
    /// pipelined].
    #[arg(long, value_parser = super::named_values(&Arch::ALL, Arch::name, super::no_help))]
    arch: Option<Arch>,
    /// Cycles to simulate.
    #[arg(long, default_value_t = 10_000)]
    cycles: u64,
    /// Seed of the input stream and of the bubble/stall patterns.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Probability that the source offers no input in a cycle.
    #[arg(long, default_value = "0.1", value_parser = parse_probability)]
    bubble: f64,
    /// Probability that the sink is not ready in a cycle.
    #[arg(long, default_value = "0.1", value_parser = parse_probability)]
    stall: f64,
    /// Input stream: random (n and c uniform, seeded) or sweep (every code up to 1.0 for each
    /// n in turn, as the co-simulation's sorted order streams them).
    #[arg(long, default_value = "random", value_parser = super::named_values(&Stream::ALL, Stream::name, super::no_help))]
    stream: Stream,
    /// Exponents, replacing the configuration's set.
    #[arg(long)]
    n: Option<NSet>,
    /// Write a VCD trace of the first --vcd-cycles cycles here, under the reference RTL's
    /// hierarchy, names and widths (docs/cycle.md, "Traces").
    #[arg(long)]
    vcd: Option<PathBuf>,
    /// Cycles in the VCD trace (at most 262144: each traced cycle is kept in memory).
    #[arg(long, default_value_t = 500, value_parser = clap::value_parser!(u64).range(1..=specfx::cycle::vcd::MAX_TRACE_CYCLES))]
    vcd_cycles: u64,
    /// Replace an existing output file that is not an earlier result of this command.
    #[arg(long)]
    force: bool,
    /// Print JSON instead of a table.
    #[arg(long)]
    json: bool,
}

/// The most cycles `specfx sim` simulates (about a minute and a half on one core).
const MAX_CYCLES: u64 = 1_000_000_000;

/// Runs `specfx sim`. Exit code 1 when any output differs from the functional model.
pub fn run(args: &SimArgs) -> Result<Outcome> {
    if !(1..=MAX_CYCLES).contains(&args.cycles) {
        bail!("--cycles: expected 1..={MAX_CYCLES}, got {}", args.cycles);
    }
    let dp = specfx::input::load_datapath(&args.config, args.n.as_ref())?;
    let arch = dp.config().resolve_arch(args.arch);
    if let Some(path) = &args.vcd {
        specfx::output::check_file_output(
            path,
            "--vcd",
            &super::output::inputs(&args.config, None),
            Some(specfx::cycle::vcd::VCD_HEADER),
            args.force,
        )?;
    }
    let mut stim = Stimulus::new(args.seed, args.bubble, args.stall);
    let trace_cycles = if args.vcd.is_some() {
        args.vcd_cycles
    } else {
        0
    };
    // Statistics (and a trace) only: no per-cycle records, which a long run cannot afford.
    let record = Record {
        transfers: false,
        trace_cycles,
    };
    let result = simulate_stream(
        &dp,
        arch,
        args.stream,
        args.seed,
        &mut stim,
        Stop::Cycles(args.cycles),
        record,
    );
    if let Some(path) = &args.vcd {
        let mut buf = Vec::new();
        write_vcd(&mut buf, &dp, arch, &result.trace)?;
        specfx::output::write_atomic(path, &buf)?;
    }
    let s = &result.stats;
    if args.json {
        print_json(s)?;
    } else {
        print_with(|w| write_stats(w, s, &dp.config().name))?;
    }
    Ok(if s.mismatches == 0 && s.order_errors == 0 {
        Outcome::Ok
    } else {
        Outcome::CheckFailed
    })
}

fn write_stats(w: &mut impl Write, s: &SimStats, name: &str) -> std::io::Result<()> {
    writeln!(
        w,
        "sim {name}, {}: {} cycles, {} inputs, {} outputs",
        s.arch, s.n_cycles, s.n_inputs, s.n_outputs
    )?;
    writeln!(
        w,
        "  latency {}..{} cycles (nominal {}), initiation interval {}, throughput {:.4} results/cycle",
        s.latency_min, s.latency_max, s.latency_nominal, s.initiation_interval, s.throughput
    )?;
    writeln!(
        w,
        "  bubbles {} cycles, output stalls {} cycles, backpressure {} cycles",
        s.bubble_cycles, s.stall_cycles, s.backpressure_cycles
    )?;
    write!(w, "  occupancy:")?;
    for (unit, o) in &s.occupancy {
        write!(w, " {unit} {:.1}%", 100.0 * o)?;
    }
    writeln!(w)?;
    writeln!(
        w,
        "  against the functional model: {} mismatches, {} out of order",
        s.mismatches, s.order_errors
    )
}
