//! Criterion benchmarks of the bit-accurate datapath: batch evaluation and the exhaustive check.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use specfx::analysis::check::check;
use specfx::pipeline::{Config, Datapath, ProbeColumns};

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

fn exhaustive_check(c: &mut Criterion) {
    let mut cfg = Config::baseline();
    cfg.n = "16..=1024".parse().unwrap();
    let dp = Datapath::new(cfg).unwrap();
    let mut g = c.benchmark_group("check");
    g.sample_size(10);
    g.throughput(Throughput::Elements(1009 * 32_769));
    g.bench_function("baseline/16..=1024", |b| b.iter(|| check(&dp).unwrap()));
    g.finish();
}

criterion_group!(benches, batch_eval, exhaustive_check);
criterion_main!(benches);
