//! The co-simulation stimulus: the cycle model run on a vector directory's inputs in file
//! order under seeded bubbles and stalls, rendered as the testbench's files
//! (`stim_valid.hex`, `stim_ready.hex`, `expected_cycle.hex`, `stim.json`) and, on request,
//! the model's VCD trace of that run; and [`Handshake`], the pattern of `in_valid` offers and
//! `out_ready` every testbench drives (docs/cycle.md, "The handshake pattern").

use std::fmt::Write as _;

use rand::Rng;

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

/// The handshake pattern of the co-simulation (docs/cycle.md, "The handshake pattern"): a
/// block of directed episodes, then [`Handshake::RANDOM_CYCLES`] random cycles, repeated. The
/// episodes start from an empty machine (each after a drain: no offer, ready, for
/// `latency + ii + 2` cycles) and have the handshakes a folded machine can meet, with
/// `s = ii + 1`:
///
/// 1. inputs offered at 0, ii, 2 ii, 3 ii (back to back at the initiation interval), the first
///    output stalled from its first cycle (`latency`) for `s` cycles;
/// 2. inputs at 0 and `latency + s`, the first output stalled for `s` cycles from its first:
///    the stall ends on the cycle a new input is offered;
/// 3. inputs at 0 and 1, the first output stalled on its first cycle only;
/// 4. an input offered on every cycle 0..=2 ii, a stall of `s` cycles from `latency + 1`.
///
/// In the random cycles, each offers with probability `1 - bubble` (independent draws), and
/// `out_ready` falls in bursts: in a cycle outside a burst a burst starts with probability
/// `stall / (stall + B (1 - stall))`, `B = ii + 1`, and lasts a length drawn uniformly from
/// `1..=2B - 1` (mean `B`), so that a fraction `stall` of the cycles is stalled and bursts as
/// long as two initiation intervals occur; a burst in progress ends when a block begins. Draws
/// per random cycle: the offer, then (outside a burst) the start, then (when it starts) the
/// length.
///
/// # Examples
/// ```
/// use specfx::cycle::stimulus::Handshake;
/// // Pipelined, latency 3: episode 3 after its drain of 3 + 1 + 2 cycles.
/// let block = Handshake::block(3, 1);
/// let drain = vec![(false, true); 6];
/// let third: Vec<(bool, bool)> = vec![(true, true), (true, true), (false, true), (false, false)];
/// let at = block.len() - (drain.len() + 6) - (drain.len() + third.len());
/// assert_eq!(&block[at..at + 6], &drain[..]);
/// assert_eq!(&block[at + 6..at + 10], &third[..]);
/// ```
#[derive(Debug, Clone)]
pub struct Handshake {
    block: Vec<(bool, bool)>,
    bubble: f64,
    burst_start: f64,
    burst_max: u64,
    burst_left: u64,
    cycle: u64,
}

impl Handshake {
    /// Random cycles between two blocks of directed episodes.
    pub const RANDOM_CYCLES: u64 = 4096;

    /// The pattern of a machine of this latency and initiation interval, with these
    /// probabilities of a bubble and of a stalled cycle (in [0, 1)).
    pub fn new(latency: u64, ii: u64, bubble: f64, stall: f64) -> Handshake {
        let b = (ii + 1) as f64;
        Handshake {
            block: Handshake::block(latency, ii),
            bubble,
            burst_start: if stall > 0.0 {
                stall / (stall + b * (1.0 - stall))
            } else {
                0.0
            },
            burst_max: 2 * (ii + 1) - 1,
            burst_left: 0,
            cycle: 0,
        }
    }

    /// The block of directed episodes, each after its drain: `(offer, out_ready)` per cycle.
    pub fn block(latency: u64, ii: u64) -> Vec<(bool, bool)> {
        let s = ii + 1;
        let drain = latency + ii + 2;
        let episodes: [(Vec<u64>, u64, u64); 4] = [
            (vec![0, ii, 2 * ii, 3 * ii], latency, s),
            (vec![0, latency + s], latency, s),
            (vec![0, 1], latency, 1),
            ((0..=2 * ii).collect(), latency + 1, s),
        ];
        let mut block = Vec::new();
        for (inputs, stall_at, stall_len) in episodes {
            block.extend((0..drain).map(|_| (false, true)));
            let end = inputs
                .iter()
                .copied()
                .max()
                .unwrap_or(0)
                .max(stall_at + stall_len - 1);
            block.extend((0..=end).map(|t| {
                (
                    inputs.contains(&t),
                    !(stall_at..stall_at + stall_len).contains(&t),
                )
            }));
        }
        block
    }

    /// The number of cycles of the directed blocks among `cycles` cycles of a run.
    pub fn block_cycles(&self, cycles: u64) -> u64 {
        let len = self.block.len() as u64;
        (cycles / (len + Self::RANDOM_CYCLES) + 1) * len
    }

    /// The next cycle's `(offer, out_ready)`.
    pub fn next(&mut self, rng: &mut impl Rng) -> (bool, bool) {
        let len = self.block.len() as u64;
        let phase = self.cycle % (len + Self::RANDOM_CYCLES);
        self.cycle += 1;
        if phase < len {
            self.burst_left = 0;
            return self.block[phase as usize];
        }
        let offer = rng.r#gen::<f64>() >= self.bubble;
        let ready = if self.burst_left > 0 {
            self.burst_left -= 1;
            false
        } else if rng.r#gen::<f64>() < self.burst_start {
            self.burst_left = rng.gen_range(1..=self.burst_max) - 1;
            false
        } else {
            true
        };
        (offer, ready)
    }
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
    let latency = arch.latency(dp.config());
    let handshake = Handshake::new(
        latency,
        arch.initiation_interval(dp.config()),
        bubble,
        stall,
    );
    // Each vector needs about one offer (1 / (1 - bubble) cycles) and, folded, an initiation
    // interval of accepted outputs (ii / (1 - stall)), besides the directed episodes; twenty
    // times that, plus the latency, drains any run but one of vanishing probability. Longer
    // stimuli are refused up front.
    let ii = arch.initiation_interval(dp.config()) as f64;
    let per_vector = 1.0 / (1.0 - bubble) + ii / (1.0 - stall);
    let random = (items.len() as f64 * per_vector).ceil();
    let expected = random + handshake.block_cycles(random as u64) as f64;
    let mut stim = Stimulus::with_handshake(seed, handshake);
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

#[cfg(test)]
mod tests {
    use super::Handshake;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// The first episode of a folded machine of latency 7 and initiation interval 6, by hand:
    /// a drain of 7 + 6 + 2 = 15 cycles, then offers at 0, 6, 12, 18 and out_ready low from 7
    /// to 13 (s = 7 cycles from the first output's first cycle).
    #[test]
    fn the_first_episode_of_a_folded_machine() {
        let block = Handshake::block(7, 6);
        assert!(block[..15].iter().all(|&b| b == (false, true)));
        let episode = &block[15..15 + 19];
        for (t, &(offer, ready)) in episode.iter().enumerate() {
            assert_eq!(offer, [0, 6, 12, 18].contains(&t), "offer at {t}");
            assert_eq!(ready, !(7..=13).contains(&t), "ready at {t}");
        }
        // Then the second episode's drain.
        assert!(block[34..34 + 15].iter().all(|&b| b == (false, true)));
    }

    /// In the random cycles a fraction `stall` of the cycles is stalled, in bursts of 1 to
    /// 2 (ii + 1) - 1 cycles whose mean is ii + 1; offers have probability 1 - bubble.
    #[test]
    fn random_cycles_stall_in_bursts_of_the_asked_fraction() {
        let (latency, ii, bubble, stall) = (7, 6, 0.25, 0.2);
        let mut h = Handshake::new(latency, ii, bubble, stall);
        let skip = Handshake::block(latency, ii).len();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for _ in 0..skip {
            h.next(&mut rng);
        }
        let n = Handshake::RANDOM_CYCLES as usize;
        let (mut stalled, mut offered, mut run) = (0, 0, 0);
        let mut bursts = Vec::new();
        // Many periods' random cycles (each period's block skipped).
        for _ in 0..100 {
            for _ in 0..n {
                let (offer, ready) = h.next(&mut rng);
                offered += usize::from(offer);
                if ready {
                    if run > 0 {
                        bursts.push(run);
                    }
                    run = 0;
                } else {
                    stalled += 1;
                    run += 1;
                }
            }
            for _ in 0..skip {
                h.next(&mut rng);
            }
        }
        let total = (100 * n) as f64;
        assert!((stalled as f64 / total - stall).abs() < 0.01, "{stalled}");
        assert!(
            (offered as f64 / total - (1.0 - bubble)).abs() < 0.01,
            "{offered}"
        );
        // Adjacent bursts merge into longer runs, so runs reach past 2 (ii + 1) - 1 = 13 only
        // by merging; runs at least an initiation interval long are common.
        let long = bursts.iter().filter(|&&b| b > ii).count();
        assert!(long * 10 > bursts.len(), "{long} of {}", bursts.len());
        assert_eq!(bursts.iter().min(), Some(&1));
    }

    /// Without bubbles or stalls, the random cycles offer and accept on every cycle and draw
    /// only the offers; the blocks come back every RANDOM_CYCLES cycles.
    #[test]
    fn without_probabilities_only_the_blocks_stall() {
        let mut h = Handshake::new(8, 1, 0.0, 0.0);
        let block = Handshake::block(8, 1);
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let period = block.len() + Handshake::RANDOM_CYCLES as usize;
        for cycle in 0..2 * period {
            let phase = cycle % period;
            let want = block.get(phase).copied().unwrap_or((true, true));
            assert_eq!(h.next(&mut rng), want, "cycle {cycle}");
        }
    }
}
