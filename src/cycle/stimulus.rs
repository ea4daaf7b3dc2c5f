//! The co-simulation stimulus: the cycle model run on a vector directory's inputs in file
//! order under seeded bubbles and stalls, rendered as the testbench's files
//! (`stim_valid.hex`, `stim_ready.hex`, `expected_cycle.hex`, `stim.json`) and, on request,
//! the model's VCD trace of that run.

use std::fmt::Write as _;

use super::sim::{simulate, Stimulus, Stop};
use super::vcd::write_vcd;
use super::Arch;
use crate::error::Error;
use crate::pipeline::Datapath;

/// The longest stimulus `specfx hdl stimulus` writes, in cycles (a line of each of its bit
/// files per cycle).
pub const MAX_STIMULUS_CYCLES: u64 = 1 << 26;

/// How the stimulus is run: the architecture, and the seeded probabilities of an input bubble
/// and an output stall in each cycle.
#[derive(Debug, Clone, Copy)]
pub struct StimulusRun {
    /// The microarchitecture.
    pub arch: Arch,
    /// The seed of the bubbles and stalls.
    pub seed: u64,
    /// Probability of an input bubble per cycle.
    pub bubble: f64,
    /// Probability of an output stall per cycle.
    pub stall: f64,
}

/// A stimulus: the testbench's files and the run's size and latency range.
pub struct CosimStimulus {
    /// `(name, bytes)`: `stim_valid.hex`, `stim_ready.hex`, `expected_cycle.hex`, `stim.json`
    /// (last: a directory holding it holds a complete stimulus).
    pub files: Vec<(String, Vec<u8>)>,
    /// The model's VCD trace of the run, when asked for.
    pub vcd: Option<Vec<u8>>,
    /// Vectors streamed.
    pub n_vectors: usize,
    /// Lines of `stim_valid.hex` and `stim_ready.hex`.
    pub n_cycles: u64,
    /// Shortest and longest input-to-output latency of the run, in cycles.
    pub latency: (u64, u64),
}

/// One bit a line.
fn bits_file(bits: &[bool]) -> String {
    bits.iter()
        .map(|&b| if b { "1\n" } else { "0\n" })
        .collect()
}

/// The stimulus of `inputs` (`(n, c code)` in file order, every n in the datapath's set) for
/// the testbench, with the model's trace when `vcd`. A stimulus longer than its limit
/// ([`MAX_STIMULUS_CYCLES`], or the trace's with `vcd`) or one that does not drain is refused
/// with what to change.
pub fn cosim_stimulus(
    dp: &Datapath,
    inputs: &[(u32, i64)],
    run: StimulusRun,
    vcd: bool,
) -> Result<CosimStimulus, Error> {
    let StimulusRun {
        arch,
        seed,
        bubble,
        stall,
    } = run;
    let refuse = |problem: String| Error::Stimulus { problem };
    let ns = dp.config().n.values();
    let items: Vec<(usize, i64)> = inputs
        .iter()
        .map(|&(n, c)| {
            (
                ns.binary_search(&n)
                    .expect("every n of the inputs is in the set"),
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
    let (max, what) = if vcd {
        (super::vcd::MAX_TRACE_CYCLES, "with --vcd, the trace")
    } else {
        (MAX_STIMULUS_CYCLES, "the stimulus")
    };
    if expected > max as f64 {
        let fit = (max as f64 / per_vector).floor();
        let advice = if fit < 1.0 {
            "lower them".to_string()
        } else {
            format!(
                "about {fit:.0} vectors fit at these probabilities: lower them or use fewer vectors"
            )
        };
        return Err(refuse(format!(
            "--bubble {bubble} and --stall {stall} would need about {expected:.0} cycles for {} vectors; {what} is limited to {max} cycles ({advice})",
            items.len()
        )));
    }
    // The run stops at the limit: a stimulus that has not drained by then is refused below.
    let limit = (20.0 * expected + 100.0 * arch.latency(dp.config()) as f64 + 1_000.0)
        .min(max as f64) as u64;
    let trace_cycles = if vcd { max } else { 0 };
    let result = simulate(
        dp,
        arch,
        items.iter().copied(),
        &mut stim,
        Stop::Drained(limit),
        trace_cycles,
    );
    let s = &result.stats;
    if s.n_outputs != items.len() as u64 && s.mismatches == 0 && s.order_errors == 0 {
        return Err(refuse(format!(
            "the stimulus did not drain within {limit} cycles ({} of {} outputs, --bubble {bubble}, --stall {stall}): lower the probabilities or change --seed",
            s.n_outputs,
            items.len()
        )));
    }
    assert!(
        s.n_outputs == items.len() as u64 && s.mismatches == 0 && s.order_errors == 0,
        "the cycle model delivered {} of {} outputs with {} mismatches: this is a bug",
        s.n_outputs,
        items.len(),
        s.mismatches
    );
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
    let mut json = serde_json::to_vec_pretty(&info).expect("a JSON object serialises");
    json.push(b'\n');
    let files = vec![
        (
            "stim_valid.hex".to_string(),
            bits_file(&result.valid_bits).into_bytes(),
        ),
        (
            "stim_ready.hex".to_string(),
            bits_file(&result.ready_bits).into_bytes(),
        ),
        ("expected_cycle.hex".to_string(), cycles.into_bytes()),
        ("stim.json".to_string(), json),
    ];
    let vcd = if vcd {
        let mut buf = Vec::new();
        write_vcd(&mut buf, dp, arch, &result.trace).expect("writing into memory cannot fail");
        Some(buf)
    } else {
        None
    };
    Ok(CosimStimulus {
        files,
        vcd,
        n_vectors: items.len(),
        n_cycles: s.n_cycles,
        latency: (s.latency_min, s.latency_max),
    })
}
