//! The cycle-level model: bit-exact against the functional model under any stall pattern, and
//! the latencies and intervals that docs/cycle.md derives.

use proptest::prelude::*;
use specfx::cycle::sim::{simulate, Stimulus, Stop};
use specfx::cycle::Arch;
use specfx::pipeline::{Config, Datapath};

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
    ) {
        let dp = datapath(k, lat, "16,300,1024");
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
            Item {
                tag: next as u64 - 1,
                n_idx,
                c_raw,
            }
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
    specfx::cycle::vcd::write_vcd(&mut buf, &r.trace, 16, 24).unwrap();
    let mut parser = vcd::Parser::new(&buf[..]);
    let header = parser.parse_header().unwrap();
    assert!(header.find_var(&["specfx", "out_valid"]).is_some());
    assert!(header
        .find_var(&["specfx", "registers", "mul_out_q0"])
        .is_some());
    let n_commands = parser.count();
    assert!(n_commands > 100 * 8);
}
