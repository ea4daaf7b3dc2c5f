//! Criterion benchmarks of the bit-accurate datapath: one evaluation, the batch path, the
//! outputs over every code and n, the exhaustive check, one sweep point, the built-in sweep and
//! the cycle model.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use specfx::analysis::check::check;
use specfx::analysis::sweep::{evaluate, Evaluator, Space};
use specfx::cycle::sim::{
    random_inputs, simulate, simulate_stream, Record, Stimulus, Stop, Stream,
};
use specfx::cycle::Arch;
use specfx::engine::output_sum;
use specfx::pipeline::{Config, Datapath, ProbeColumns};

fn baseline_all_n() -> Datapath {
    let mut cfg = Config::baseline();
    cfg.n = "16..=1024".parse().unwrap();
    Datapath::new(cfg).unwrap()
}

fn one_evaluation(c: &mut Criterion) {
    let dp = Datapath::new(Config::baseline()).unwrap();
    let nc = *dp.constants_for(256).unwrap();
    let mut g = c.benchmark_group("eval");
    g.throughput(Throughput::Elements(1));
    g.bench_function("baseline/scalar", |b| {
        b.iter(|| dp.eval(std::hint::black_box(32_700), &nc))
    });
    g.finish();
}

fn batch_eval(c: &mut Criterion) {
    let dp = Datapath::new(Config::baseline()).unwrap();
    let nc = *dp.constants_for(256).unwrap();
    let codes: Vec<i64> = (0..=32_768).collect();
    let mut cols = ProbeColumns::default();
    let mut g = c.benchmark_group("batch_eval");
    g.throughput(Throughput::Elements(codes.len() as u64));
    g.bench_function("baseline/32769", |b| {
        b.iter(|| dp.eval_batch(&nc, &codes, &mut cols))
    });
    g.bench_function("baseline_scalar/32769", |b| {
        b.iter(|| {
            codes
                .iter()
                .map(|&k| dp.eval(k, &nc).values[8])
                .sum::<i64>()
        })
    });
    g.finish();
}

fn outputs(c: &mut Criterion) {
    let dp = baseline_all_n();
    let mut g = c.benchmark_group("outputs");
    g.sample_size(20);
    g.throughput(Throughput::Elements(1009 * 32_769));
    g.bench_function("baseline/16..=1024", |b| {
        b.iter(|| output_sum(&dp, 0..32_769))
    });
    g.finish();
}

fn exhaustive_check(c: &mut Criterion) {
    let dp = baseline_all_n();
    let mut g = c.benchmark_group("check");
    g.sample_size(10);
    g.throughput(Throughput::Elements(1009 * 32_769));
    g.bench_function("baseline/16..=1024", |b| b.iter(|| check(&dp).unwrap()));
    g.finish();
}

fn sweep_point(c: &mut Criterion) {
    // One point of a space holding only the baseline: validation, exhaustive check and cost.
    let space = Space::from_toml("n = \"16..=1024\"\n[vary]\nk = [4]\n").unwrap();
    let mut g = c.benchmark_group("sweep");
    g.sample_size(10);
    g.bench_function("point/baseline", |b| b.iter(|| evaluate(&space, 0)));
    // The built-in space's 54 points through one evaluator, as `specfx sweep` runs them
    // (cos^n and the f64 floors shared between the points).
    let builtin = Space::builtin();
    g.bench_function("builtin/54-points", |b| {
        b.iter(|| {
            let e = Evaluator::new(&builtin);
            (0..builtin.n_points())
                .map(|i| e.evaluate(i))
                .collect::<Vec<_>>()
        })
    });
    g.finish();
}

/// The cycle model, in cycles/s: both architectures on the sweep stream (every code for each
/// n in turn, as `scripts/bench-peers`' Verilator harness streams them) without bubbles or
/// stalls, keeping statistics only, as `specfx sim --stream sweep` runs it; and the pipelined one on the random stream under 10%
/// bubbles and stalls, keeping every transfer as the co-simulation's stimulus does.
fn cycle_model(c: &mut Criterion) {
    let dp = Datapath::new(Config::baseline()).unwrap();
    const CYCLES: u64 = 1_000_000;
    let mut g = c.benchmark_group("cycle");
    g.sample_size(10);
    g.throughput(Throughput::Elements(CYCLES));
    let lean = Record {
        transfers: false,
        trace_cycles: 0,
    };
    for arch in [Arch::Pipelined, Arch::Folded] {
        g.bench_function(format!("{arch}/baseline"), |b| {
            b.iter(|| {
                let mut stimulus = Stimulus::new(1, 0.0, 0.0);
                let stop = Stop::Cycles(CYCLES);
                simulate_stream(&dp, arch, Stream::Sweep, 1, &mut stimulus, stop, lean)
            })
        });
    }
    g.bench_function("pipelined/baseline/random-stalls-recorded", |b| {
        b.iter(|| {
            let mut stimulus = Stimulus::new(1, 0.1, 0.1);
            let stop = Stop::Cycles(CYCLES);
            simulate(
                &dp,
                Arch::Pipelined,
                random_inputs(&dp, 1),
                &mut stimulus,
                stop,
                0,
            )
        })
    });
    g.finish();
}

criterion_group!(
    benches,
    one_evaluation,
    batch_eval,
    outputs,
    exhaustive_check,
    sweep_point,
    cycle_model
);
criterion_main!(benches);
