//! The stream simulator: drives a [`Machine`] with an input stream, seeded bubbles and output
//! stalls, and gathers what happened on every cycle.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::cycle::{Arch, Folded, Item, Machine, Pipelined, RegisterView};
use crate::pipeline::Datapath;

/// Per-cycle `valid` offers and `out_ready` bits, drawn from ChaCha8 with a seed: for each
/// cycle, first the bubble draw, then the stall draw (`docs/cycle.md`).
#[derive(Debug, Clone)]
pub struct Stimulus {
    rng: ChaCha8Rng,
    bubble: f64,
    stall: f64,
}

impl Stimulus {
    /// A pattern source: `bubble` and `stall` are probabilities in [0, 1).
    pub fn new(seed: u64, bubble: f64, stall: f64) -> Stimulus {
        Stimulus {
            rng: ChaCha8Rng::seed_from_u64(seed),
            bubble,
            stall,
        }
    }

    /// The next cycle's (valid offer, out_ready).
    pub fn next_cycle(&mut self) -> (bool, bool) {
        let valid = self.rng.gen::<f64>() >= self.bubble;
        let ready = self.rng.gen::<f64>() >= self.stall;
        (valid, ready)
    }
}

/// What one cycle looked like at the ports, for traces.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CycleTrace {
    /// Cycle number.
    pub cycle: u64,
    /// `in_valid`.
    pub in_valid: bool,
    /// `in_ready`.
    pub in_ready: bool,
    /// `in_c` (when valid).
    pub in_c: Option<i64>,
    /// `out_valid`.
    pub out_valid: bool,
    /// `out_ready`.
    pub out_ready: bool,
    /// `out_data` (when valid).
    pub out_data: Option<i64>,
    /// Every register.
    pub registers: Vec<RegisterView>,
}

/// One output transfer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct OutputEvent {
    /// The input's sequence number.
    pub tag: u64,
    /// The raw output.
    pub value: i64,
    /// The cycle at the end of which it transferred.
    pub cycle: u64,
    /// Cycles since its input transferred.
    pub latency: u64,
}

/// Statistics of a simulation.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimStats {
    /// The architecture.
    pub arch: Arch,
    /// Cycles simulated.
    pub n_cycles: u64,
    /// Inputs accepted.
    pub n_inputs: u64,
    /// Outputs delivered.
    pub n_outputs: u64,
    /// Smallest input-to-output latency seen, in cycles.
    pub latency_min: u64,
    /// Largest latency seen.
    pub latency_max: u64,
    /// The configured latency without stalls.
    pub latency_nominal: u64,
    /// The initiation interval without stalls.
    pub initiation_interval: u64,
    /// Outputs per cycle.
    pub throughput: f64,
    /// Cycles where the source had data but no offer (bubbles).
    pub bubble_cycles: u64,
    /// Cycles where `out_valid` was high and `out_ready` low.
    pub stall_cycles: u64,
    /// Cycles where the source offered data and the datapath refused it.
    pub backpressure_cycles: u64,
    /// Outputs that differ from the functional model (must be 0).
    pub mismatches: u64,
    /// Outputs out of order (must be 0).
    pub order_errors: u64,
    /// Per unit: name and share of cycles it held valid data.
    pub occupancy: Vec<(String, f64)>,
}

/// The result of a simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct SimResult {
    /// Statistics.
    pub stats: SimStats,
    /// Every output transfer, in order.
    pub outputs: Vec<OutputEvent>,
    /// The `valid` offer bit of every simulated cycle.
    pub valid_bits: Vec<bool>,
    /// The `out_ready` bit of every simulated cycle.
    pub ready_bits: Vec<bool>,
    /// Port and register traces of the first `trace_cycles` cycles.
    pub trace: Vec<CycleTrace>,
}

/// When to stop a simulation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// After exactly this many cycles.
    Cycles(u64),
    /// When every input's output has transferred (or after this many cycles at most).
    Drained(u64),
}

/// Simulates `arch` on a stream of inputs (`items[i]` gets tag `i`).
///
/// `items` may be an endless iterator when stopping after a number of cycles.
pub fn simulate(
    dp: &Datapath,
    arch: Arch,
    items: impl Iterator<Item = (usize, i64)>,
    stimulus: &mut Stimulus,
    stop: Stop,
    trace_cycles: u64,
) -> SimResult {
    match arch {
        Arch::Pipelined => run(
            dp,
            arch,
            Pipelined::new(dp),
            items,
            stimulus,
            stop,
            trace_cycles,
        ),
        Arch::Folded => run(
            dp,
            arch,
            Folded::new(dp),
            items,
            stimulus,
            stop,
            trace_cycles,
        ),
    }
}

fn run<M: Machine>(
    dp: &Datapath,
    arch: Arch,
    mut machine: M,
    items: impl Iterator<Item = (usize, i64)>,
    stimulus: &mut Stimulus,
    stop: Stop,
    trace_cycles: u64,
) -> SimResult {
    let mut items = items.peekable();
    let mut accepted_at: Vec<u64> = Vec::new();
    let mut inputs: Vec<(usize, i64)> = Vec::new();
    let mut outputs: Vec<OutputEvent> = Vec::new();
    let mut valid_bits = Vec::new();
    let mut ready_bits = Vec::new();
    let mut trace = Vec::new();
    let units = machine.unit_names();
    let mut occupied = vec![0u64; units.len()];
    let (mut bubbles, mut stalls, mut backpressure) = (0, 0, 0);
    let mut order_errors = 0;
    let mut spare = machine.clone();
    let max_cycles = match stop {
        Stop::Cycles(c) | Stop::Drained(c) => c,
    };
    let mut cycle = 0u64;
    while cycle < max_cycles {
        if let Stop::Drained(_) = stop {
            if items.peek().is_none() && outputs.len() == inputs.len() {
                break;
            }
        }
        let (offer, out_ready) = stimulus.next_cycle();
        valid_bits.push(offer);
        ready_bits.push(out_ready);
        let next_item = items.peek().copied();
        let in_valid = offer && next_item.is_some();
        let in_ready = machine.in_ready(out_ready);
        let output = machine.output();
        if cycle < trace_cycles {
            trace.push(CycleTrace {
                cycle,
                in_valid,
                in_ready,
                in_c: next_item.filter(|_| in_valid).map(|(_, c)| c),
                out_valid: output.is_some(),
                out_ready,
                out_data: output.map(|o| o.1),
                registers: machine.registers(dp),
            });
        }
        machine.count_occupancy(&mut occupied);
        if next_item.is_some() && !offer {
            bubbles += 1;
        }
        if in_valid && !in_ready {
            backpressure += 1;
        }
        let transfer_in = in_valid && in_ready;
        let item = if transfer_in {
            let (n_idx, c_raw) = items.next().expect("peeked");
            let tag = inputs.len() as u64;
            inputs.push((n_idx, c_raw));
            accepted_at.push(cycle);
            Some(Item { tag, n_idx, c_raw })
        } else {
            None
        };
        if let Some((tag, value)) = output {
            if out_ready {
                if tag != outputs.len() as u64 {
                    order_errors += 1;
                }
                outputs.push(OutputEvent {
                    tag,
                    value,
                    cycle,
                    latency: cycle - accepted_at[tag as usize],
                });
            } else {
                stalls += 1;
            }
        }
        machine.next_into(dp, item, out_ready, &mut spare);
        std::mem::swap(&mut machine, &mut spare);
        cycle += 1;
    }
    let mismatches = count_mismatches(dp, &inputs, &outputs);
    let latency_min = outputs.iter().map(|o| o.latency).min().unwrap_or(0);
    let latency_max = outputs.iter().map(|o| o.latency).max().unwrap_or(0);
    let cfg = dp.config();
    let stats = SimStats {
        arch,
        n_cycles: cycle,
        n_inputs: inputs.len() as u64,
        n_outputs: outputs.len() as u64,
        latency_min,
        latency_max,
        latency_nominal: arch.latency(cfg),
        initiation_interval: arch.initiation_interval(cfg),
        throughput: if cycle == 0 {
            0.0
        } else {
            outputs.len() as f64 / cycle as f64
        },
        bubble_cycles: bubbles,
        stall_cycles: stalls,
        backpressure_cycles: backpressure,
        mismatches,
        order_errors,
        occupancy: units
            .into_iter()
            .zip(occupied)
            .map(|(u, o)| {
                (
                    u,
                    if cycle == 0 {
                        0.0
                    } else {
                        o as f64 / cycle as f64
                    },
                )
            })
            .collect(),
    };
    SimResult {
        stats,
        outputs,
        valid_bits,
        ready_bits,
        trace,
    }
}

/// How many outputs differ from the functional model's output for their input (outputs whose
/// tag names no input are not counted here; they are order errors). The expected outputs are
/// computed in batches per n with [`Datapath::eval_outputs`].
fn count_mismatches(dp: &Datapath, inputs: &[(usize, i64)], outputs: &[OutputEvent]) -> u64 {
    let mut by_n: Vec<Vec<usize>> = vec![Vec::new(); dp.constants().len()];
    for (i, o) in outputs.iter().enumerate() {
        if let Some(&(n_idx, _)) = inputs.get(o.tag as usize) {
            by_n[n_idx].push(i);
        }
    }
    let mut scratch = crate::pipeline::OutputScratch::default();
    let mut mismatches = 0;
    for (n_idx, which) in by_n.iter().enumerate() {
        let nc = &dp.constants()[n_idx];
        for part in which.chunks(4096) {
            let codes: Vec<i64> = part
                .iter()
                .map(|&i| inputs[outputs[i].tag as usize].1)
                .collect();
            let mut expected = vec![0; codes.len()];
            dp.eval_outputs(nc, &codes, &mut expected, &mut scratch);
            mismatches += part
                .iter()
                .zip(&expected)
                .filter(|(&i, &e)| outputs[i].value != e)
                .count() as u64;
        }
    }
    mismatches
}

/// An endless seeded stream of random inputs: n uniform over the set, c uniform over the
/// input codes (a separate ChaCha8 stream from the stall pattern's).
pub fn random_inputs(dp: &Datapath, seed: u64) -> impl Iterator<Item = (usize, i64)> + '_ {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(1);
    let codes = dp.input_codes();
    let n_count = dp.constants().len();
    std::iter::repeat_with(move || (rng.gen_range(0..n_count), rng.gen_range(codes.clone())))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::Config;

    /// Outputs equal to `eval`'s count nothing; each changed value counts once, whatever n it
    /// belongs to; an output whose tag names no input is left to the order check.
    #[test]
    fn mismatches_are_counted_against_eval() {
        let dp = Datapath::new(Config::baseline()).unwrap();
        let inputs: Vec<(usize, i64)> = (0..5000)
            .map(|i| (i % dp.constants().len(), 32768 - (i as i64 * 7) % 900))
            .collect();
        let mut outputs: Vec<OutputEvent> = inputs
            .iter()
            .enumerate()
            .map(|(tag, &(n_idx, c))| OutputEvent {
                tag: tag as u64,
                value: dp.eval(c, &dp.constants()[n_idx]).values[dp.stage_out()],
                cycle: tag as u64,
                latency: 0,
            })
            .collect();
        assert_eq!(count_mismatches(&dp, &inputs, &outputs), 0);
        outputs[17].value += 1;
        outputs[4321].value -= 1;
        outputs.push(OutputEvent {
            tag: 99_999,
            value: 0,
            cycle: 0,
            latency: 0,
        });
        assert_eq!(count_mismatches(&dp, &inputs, &outputs), 2);
    }
}
