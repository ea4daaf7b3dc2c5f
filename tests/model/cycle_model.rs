//! The cycle-level model: bit-exact against the functional model under any stall pattern, and
//! the latencies and intervals that docs/cycle.md derives.

use proptest::prelude::*;
use specfx::cycle::sim::{run, simulate, Record, Stimulus, Stop};
use specfx::cycle::{Arch, Item, Machine, Op, Pipelined, RegisterView, Token};
use specfx::pipeline::{Config, Datapath};

/// The pipelined architecture written as the RTL is: every register a token, every clock edge
/// moving each token one register on and applying the register's operation to it, values
/// computed stage by stage with the datapath's stage operations. The oracle of [`Pipelined`],
/// which carries tokens without computing and shows the functional model's values.
#[derive(Clone)]
struct Literal {
    /// The operation computed on entry to each register (`None`: a delay register).
    ops: Vec<Option<Op>>,
    owner: Vec<Op>,
    regs: Vec<Option<Token>>,
}

impl Literal {
    fn new(dp: &Datapath) -> Literal {
        let cfg = dp.config();
        let lat = &cfg.latency;
        let mut plan = vec![(Op::Sub, lat.sub), (Op::MulT, lat.mul), (Op::AddB, lat.add)];
        plan.extend((0..cfg.k as usize).map(|i| (Op::Square(i), lat.mul)));
        plan.push((Op::MulOut, lat.mul));
        let (mut ops, mut owner) = (Vec::new(), Vec::new());
        for (op, l) in plan {
            for r in 0..l {
                ops.push((r == 0).then_some(op));
                owner.push(op);
            }
        }
        let regs = vec![None; ops.len()];
        Literal { ops, owner, regs }
    }

    fn units(&self) -> Vec<Op> {
        let mut v: Vec<Op> = self.owner.clone();
        v.dedup();
        v
    }
}

impl Machine for Literal {
    fn in_ready(&self, out_ready: bool) -> bool {
        self.output().is_none() || out_ready
    }

    fn output(&self) -> Option<(u64, i64)> {
        self.regs
            .last()
            .copied()
            .flatten()
            .map(|t| (t.tag, t.value))
    }

    fn step(&mut self, dp: &Datapath, input: Option<Item>, out_ready: bool) {
        if !self.in_ready(out_ready) {
            return;
        }
        let old = self.regs.clone();
        for r in 0..old.len() {
            let incoming = if r == 0 {
                input.map(|it| Token {
                    tag: it.tag,
                    n_idx: it.n_idx,
                    c: it.c_raw,
                    value: it.c_raw,
                })
            } else {
                old[r - 1]
            };
            self.regs[r] = match self.ops[r] {
                Some(op) => incoming.map(|t| op.apply(dp, t)),
                None => incoming,
            };
        }
    }

    fn unit_names(&self) -> Vec<String> {
        self.units().iter().map(|o| o.name()).collect()
    }

    fn occupancy(&self) -> Vec<bool> {
        self.units()
            .iter()
            .map(|&op| {
                self.owner
                    .iter()
                    .zip(&self.regs)
                    .any(|(&o, r)| o == op && r.is_some())
            })
            .collect()
    }

    fn registers(&self, dp: &Datapath) -> Vec<RegisterView> {
        specfx::cycle::rtl::pipelined_registers(dp, &self.owner, &self.regs)
    }
}

/// The datapath with a per-n depth when `per_n`: n < 300 squares in the first half of the k
/// stages (the rest bypassed), n >= 300 in all of them.
fn with_depth(dp: Datapath, per_n: bool) -> Datapath {
    if !per_n {
        return dp;
    }
    let mut cfg = dp.config().clone();
    let k = cfg.k;
    cfg.depth = specfx::pipeline::Depth::Steps(vec![
        specfx::pipeline::DepthStep {
            from: 1,
            j: k.div_ceil(2),
        },
        specfx::pipeline::DepthStep { from: 300, j: k },
    ]);
    Datapath::new(cfg).unwrap()
}

fn datapath(k: u32, lat: (u32, u32, u32), n: &str) -> Datapath {
    let mut cfg = Config::baseline();
    cfg.k = k;
    cfg.square = vec![cfg.square[0]; k as usize];
    cfg.latency.sub = lat.0;
    cfg.latency.mul = lat.1;
    cfg.latency.add = lat.2;
    cfg.n = n.parse().unwrap();
    Datapath::new(cfg).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn outputs_equal_the_functional_model_for_any_stalls(
        k in 1u32..=7,
        lat in (1u32..=3, 1u32..=4, 1u32..=3),
        folded in any::<bool>(),
        seed in any::<u64>(),
        bubble in 0.0f64..0.9,
        stall in 0.0f64..0.9,
        inputs in prop::collection::vec((0usize..3, 0i64..=65535), 1..120),
        per_n in any::<bool>(),
    ) {
        // A per-n depth changes values, not timing (docs/cycle.md): the same latencies.
        let dp = with_depth(datapath(k, lat, "16,300,1024"), per_n);
        let arch = if folded { Arch::Folded } else { Arch::Pipelined };
        let mut stim = Stimulus::new(seed, bubble, stall);
        let r = simulate(&dp, arch, inputs.iter().copied(), &mut stim, Stop::Drained(1_000_000), 0);
        prop_assert_eq!(r.outputs.len(), inputs.len());
        for (i, o) in r.outputs.iter().enumerate() {
            prop_assert_eq!(o.tag, i as u64, "order");
            let (n_idx, c) = inputs[i];
            let want = dp.eval(c, &dp.constants()[n_idx]).values[dp.stage_out()];
            prop_assert_eq!(o.value, want, "output {}", i);
            prop_assert!(o.latency >= arch.latency(dp.config()));
        }
        prop_assert_eq!(r.stats.mismatches, 0);
        // Stalls only delay: without them every latency is the nominal one.
        let mut free = Stimulus::new(seed, 0.0, 0.0);
        let r = simulate(&dp, arch, inputs.iter().copied(), &mut free, Stop::Drained(1_000_000), 0);
        prop_assert_eq!(r.stats.latency_min, arch.latency(dp.config()));
        prop_assert_eq!(r.stats.latency_max, arch.latency(dp.config()));
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// The ring of tokens is the register-by-register pipeline: the same outputs on the same
    /// cycles, the same statistics and occupancy, and the same value in every register of the
    /// trace on every cycle, for any latencies validation accepts (1..=8 each), k, cutoff,
    /// stream and stall pattern (the stream's inputs reach past 1.0 and into the cut region).
    /// Half the cases run at full rate (no bubbles, no stalls), where statistics alone take
    /// `run`'s steady loop. The deepest pipeline has its own test below.
    #[test]
    fn the_pipeline_ring_equals_the_literal_pipeline(
        k in 1u32..=7,
        lat in (1u32..=8, 1u32..=8, 1u32..=8),
        cutoff in 0usize..3,
        seed in any::<u64>(),
        bubble in 0.0f64..0.9,
        stall in 0.0f64..0.9,
        steady in any::<bool>(),
        inputs in prop::collection::vec((0usize..3, 0i64..=65535), 1..200),
        per_n in any::<bool>(),
    ) {
        let (bubble, stall) = if steady { (0.0, 0.0) } else { (bubble, stall) };
        ring_equals_literal(k, lat, cutoff, per_n, &inputs, (seed, bubble, stall));
    }
}

/// A pipeline of 88 registers holds more inputs in flight than the simulator's first ring of
/// them (64): it grows, and the pipeline still equals the literal one, at full rate (the
/// steady loop) and with bubbles and stalls, stopped after a number of cycles or drained.
#[test]
fn a_pipeline_longer_than_the_in_flight_ring_equals_the_literal_pipeline() {
    let dp = datapath(7, (8, 8, 8), "16,300,1024");
    assert_eq!(Arch::Pipelined.latency(dp.config()), 88);
    let inputs: Vec<(usize, i64)> = (0..300).map(|i| (i % 3, 30_000 + 7 * i as i64)).collect();
    for (bubble, stall) in [(0.0, 0.0), (0.2, 0.3)] {
        for stop in [Stop::Cycles(250), Stop::Drained(100_000)] {
            let go = |machine_is_ring: bool, record: Record| {
                let mut stim = Stimulus::new(7, bubble, stall);
                let items = inputs.iter().copied();
                if machine_is_ring {
                    run(
                        &dp,
                        Arch::Pipelined,
                        Pipelined::new(&dp),
                        items,
                        &mut stim,
                        stop,
                        record,
                    )
                } else {
                    run(
                        &dp,
                        Arch::Pipelined,
                        Literal::new(&dp),
                        items,
                        &mut stim,
                        stop,
                        record,
                    )
                }
            };
            let all = Record {
                transfers: true,
                trace_cycles: 0,
            };
            let lean = Record {
                transfers: false,
                trace_cycles: 0,
            };
            let (ring, literal) = (go(true, all), go(false, all));
            assert_eq!(ring, literal, "bubble {bubble}, stall {stall}, {stop:?}");
            assert_eq!(go(true, lean).stats, ring.stats);
            if bubble == 0.0 && stop == Stop::Cycles(250) {
                // 88 in flight at the end.
                assert_eq!(ring.stats.n_inputs - ring.stats.n_outputs, 88);
            }
        }
    }
}

#[test]
fn pipelined_timing_without_stalls() {
    // lat_sub 2, lat_mul 3, lat_add 1, k = 4: L = 2 + 1 + 6 * 3 = 21; one result per cycle.
    let dp = datapath(4, (2, 3, 1), "64");
    let inputs: Vec<(usize, i64)> = (0..50).map(|i| (0, 30_000 + i)).collect();
    let mut stim = Stimulus::new(1, 0.0, 0.0);
    let r = simulate(
        &dp,
        Arch::Pipelined,
        inputs.into_iter(),
        &mut stim,
        Stop::Drained(10_000),
        0,
    );
    let cycles: Vec<u64> = r.outputs.iter().map(|o| o.cycle).collect();
    let want: Vec<u64> = (0..50).map(|i| 21 + i).collect();
    assert_eq!(cycles, want);
}

#[test]
fn folded_timing_without_stalls() {
    // k = 4, lat_mul 2: each input needs (4 + 2) * 2 = 12 multiplier cycles; the first output
    // is in the output register 13 cycles after its input, and a new input starts every 12.
    let dp = datapath(4, (1, 2, 1), "64");
    let inputs: Vec<(usize, i64)> = (0..10).map(|i| (0, 30_000 + i)).collect();
    let mut stim = Stimulus::new(1, 0.0, 0.0);
    let r = simulate(
        &dp,
        Arch::Folded,
        inputs.into_iter(),
        &mut stim,
        Stop::Drained(10_000),
        0,
    );
    let cycles: Vec<u64> = r.outputs.iter().map(|o| o.cycle).collect();
    let want: Vec<u64> = (0..10).map(|i| 13 + 12 * i).collect();
    assert_eq!(cycles, want);
}

#[test]
fn a_stalled_output_holds_and_blocks_the_input() {
    // Ready low for the first 30 cycles: the pipeline fills (8 inputs, one per register) and
    // then refuses input; the first output leaves on the first ready cycle, 30.
    let dp = datapath(4, (1, 1, 1), "64");
    let inputs: Vec<(usize, i64)> = (0..20).map(|i| (0, 32_000 + i)).collect();
    let r = simulate_with_ready(&dp, &inputs, 30);
    assert_eq!(r[0], 30);
    assert_eq!(r.len(), 20);
    // After the stall, one output per cycle.
    for w in r.windows(2) {
        assert_eq!(w[1], w[0] + 1);
    }
}

/// Drives the pipelined machine directly: out_ready low for `stall` cycles, then high.
fn simulate_with_ready(dp: &Datapath, inputs: &[(usize, i64)], stall: u64) -> Vec<u64> {
    use specfx::cycle::{Item, Machine, Pipelined};
    let mut m = Pipelined::new(dp);
    let mut next = 0;
    let mut out = Vec::new();
    for cycle in 0..200u64 {
        let ready = cycle >= stall;
        let in_ready = m.in_ready(ready);
        let item = (next < inputs.len() && in_ready).then(|| {
            let (n_idx, c_raw) = inputs[next];
            next += 1;
            Item::new(dp, next as u64 - 1, n_idx, c_raw)
        });
        if m.output().is_some() && ready {
            out.push(cycle);
        }
        m = m.next(dp, item, ready);
    }
    out
}

#[test]
fn vcd_trace_parses_back() {
    let dp = datapath(4, (1, 1, 1), "16,64");
    let mut stim = Stimulus::new(5, 0.3, 0.3);
    let inputs = (0..40).map(|i| ((i % 2) as usize, 20_000 + 300 * i));
    let r = simulate(
        &dp,
        Arch::Pipelined,
        inputs,
        &mut stim,
        Stop::Cycles(120),
        100,
    );
    let mut buf = Vec::new();
    specfx::cycle::vcd::write_vcd(&mut buf, &dp, Arch::Pipelined, &r.trace).unwrap();
    let mut parser = vcd::Parser::new(&buf[..]);
    let header = parser.parse_header().unwrap();
    let core = ["tb_specfx", "dut", "g_pipelined", "u_core"];
    assert!(header
        .find_var(&["tb_specfx", "dut", "out_valid"])
        .is_some());
    let y_q = header
        .find_var(&[&core[..], &["g_square[4]", "y_q"]].concat())
        .unwrap();
    assert_eq!(y_q.size, 17);
    let word = header
        .find_var(&[&core[..], &["r_mul_t", "g_regs", "g_stage[0]", "r"]].concat())
        .unwrap();
    // {depth_2, coef_2, threshold_2, offset_2, c_cl_2, t_2}: 3 + 24 + 16 + 1 + 16 + 18 bits.
    assert_eq!(word.size, 78);
    let n_commands = parser.count();
    assert!(n_commands > 100 * 8);
}

/// A machine whose outputs pass through `tamper` (tag, value) on their way out: the
/// simulator must count what the tampering breaks.
#[derive(Clone)]
struct Tampered<M> {
    machine: M,
    tamper: fn((u64, i64)) -> (u64, i64),
}

impl<M: Machine> Machine for Tampered<M> {
    fn in_ready(&self, out_ready: bool) -> bool {
        self.machine.in_ready(out_ready)
    }
    fn output(&self) -> Option<(u64, i64)> {
        self.machine.output().map(self.tamper)
    }
    fn step(&mut self, dp: &Datapath, input: Option<Item>, out_ready: bool) {
        self.machine.step(dp, input, out_ready)
    }
    fn unit_names(&self) -> Vec<String> {
        self.machine.unit_names()
    }
    fn occupancy(&self) -> Vec<bool> {
        self.machine.occupancy()
    }
    fn registers(&self, dp: &Datapath) -> Vec<RegisterView> {
        self.machine.registers(dp)
    }
}

/// A folded unit whose output is off by one for input 17: the simulator's mismatch count
/// compares every output with the functional model and finds exactly that one.
#[test]
fn a_wrong_output_is_counted_as_a_mismatch() {
    let dp = datapath(4, (1, 2, 1), "16,64,1000");
    let inputs: Vec<(usize, i64)> = (0..300).map(|i| (i % 3, 32768 - 5 * i as i64)).collect();
    let go = |m| {
        let mut stim = Stimulus::new(3, 0.2, 0.2);
        let stop = Stop::Drained(100_000);
        let record = Record {
            transfers: false,
            trace_cycles: 0,
        };
        run(
            &dp,
            Arch::Folded,
            m,
            inputs.iter().copied(),
            &mut stim,
            stop,
            record,
        )
        .stats
    };
    let honest = go(Tampered {
        machine: specfx::cycle::Folded::new(&dp),
        tamper: |(tag, v)| (tag, if tag == 17 { v + 1 } else { v }),
    });
    assert_eq!(honest.n_outputs, 300);
    assert_eq!(honest.mismatches, 1);
    assert_eq!(honest.order_errors, 0);
}

/// A pipelined unit that shows input 10's output under the tag 10,000 (no input in flight):
/// an output whose tag names no input in flight is one order error, compared with nothing
/// (latency 0, no mismatch), and input 10 stays in flight: every later input with it, so the
/// simulator's record of them outgrows its first 64 places and grows while the run goes on.
#[test]
fn an_output_under_an_unknown_tag_is_an_order_error_only() {
    let dp = datapath(4, (1, 2, 1), "16,64,1000");
    let inputs: Vec<(usize, i64)> = (0..300).map(|i| (i % 3, 32768 - 5 * i as i64)).collect();
    let record = Record {
        transfers: false,
        trace_cycles: 0,
    };
    let s = run(
        &dp,
        Arch::Pipelined,
        Tampered {
            machine: Pipelined::new(&dp),
            tamper: |(tag, v)| (if tag == 10 { 10_000 } else { tag }, v),
        },
        inputs.iter().copied(),
        &mut Stimulus::new(3, 0.0, 0.0),
        Stop::Drained(100_000),
        record,
    )
    .stats;
    // Registers: sub 1, mul_t 2, add 1, four squarings of 2, the coefficient's 2: 14, and an
    // input leaves 14 cycles after it entered.
    assert_eq!((s.n_inputs, s.n_outputs), (300, 300));
    assert_eq!((s.order_errors, s.mismatches), (1, 0));
    assert_eq!((s.latency_min, s.latency_max), (0, 14));
}

/// [`the_pipeline_ring_equals_the_literal_pipeline`]'s comparison for one case (`stim`: the
/// stimulus' seed, bubble and stall probabilities).
fn ring_equals_literal(
    k: u32,
    lat: (u32, u32, u32),
    cutoff: usize,
    per_n: bool,
    inputs: &[(usize, i64)],
    stim: (u64, f64, f64),
) {
    let mut cfg = with_depth(datapath(k, lat, "16,300,1024"), per_n)
        .config()
        .clone();
    cfg.cutoff = specfx::reference::lobe::Cutoff::ALL[cutoff];
    let dp = Datapath::new(cfg).unwrap();
    let cycles = Stop::Cycles(2 * inputs.len() as u64 + 40);
    let go = |m, record| {
        run(
            &dp,
            Arch::Pipelined,
            m,
            inputs.iter().copied(),
            &mut Stimulus::new(stim.0, stim.1, stim.2),
            cycles,
            record,
        )
    };
    let trace = Record {
        transfers: true,
        trace_cycles: u64::MAX,
    };
    let ring = go(Pipelined::new(&dp), trace);
    let literal = run(
        &dp,
        Arch::Pipelined,
        Literal::new(&dp),
        inputs.iter().copied(),
        &mut Stimulus::new(stim.0, stim.1, stim.2),
        cycles,
        trace,
    );
    assert!(ring
        .trace
        .iter()
        .any(|c| c.registers.iter().any(|r| r.value.is_some())));
    // Statistics do not depend on what is recorded.
    let lean = Record {
        transfers: false,
        trace_cycles: 0,
    };
    let stats = go(Pipelined::new(&dp), lean);
    assert!(stats.outputs.is_empty() && stats.trace.is_empty());
    assert_eq!(stats.stats, ring.stats);
    assert_eq!(ring, literal);
}

/// The deepest pipeline validation accepts (k = 7, every latency 8: 88 registers), full for
/// most of the run at full rate, and under bubbles and stalls: the ring is the literal
/// pipeline.
#[test]
fn the_deepest_pipeline_ring_equals_the_literal_pipeline() {
    let inputs: Vec<(usize, i64)> = (0..300).map(|i| (i % 3, 65535 - 97 * i as i64)).collect();
    let dp = datapath(7, (8, 8, 8), "16,300,1024");
    assert_eq!(Arch::Pipelined.latency(dp.config()), 88);
    for (cutoff, per_n, stim) in [
        (0, false, (1, 0.0, 0.0)),
        (1, true, (2, 0.3, 0.3)),
        (2, false, (3, 0.05, 0.6)),
    ] {
        ring_equals_literal(7, (8, 8, 8), cutoff, per_n, &inputs, stim);
    }
}
