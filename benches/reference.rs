//! Criterion benchmarks of the f64 reference: lobe evaluation and normalisation.

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use specfx::reference::lobe::{cos_pow, cs_m, Cutoff};
use specfx::reference::normalisation::{clamp_integral_by_quadrature, exact_integral, Form};

fn lobes(c: &mut Criterion) {
    let cs: Vec<f64> = (0..=32_768).map(|i| f64::from(i) / 32_768.0).collect();
    let mut g = c.benchmark_group("lobe_eval");
    g.throughput(Throughput::Elements(cs.len() as u64));
    g.bench_function("cos_pow/n256/32769", |b| {
        b.iter(|| cs.iter().map(|&x| cos_pow(x, 256.0)).sum::<f64>())
    });
    g.bench_function("cs16_clamp/n256/32769", |b| {
        b.iter(|| {
            cs.iter()
                .map(|&x| cs_m(x, black_box(256.0), 4, Cutoff::Clamp))
                .sum::<f64>()
        })
    });
    g.finish();
}

fn normalisation(c: &mut Criterion) {
    let mut g = c.benchmark_group("normalisation");
    g.bench_function("exact_integral/blinn_phong_modified/k7", |b| {
        b.iter(|| exact_integral(Form::BlinnPhongModified, black_box(300.0), 7))
    });
    g.bench_function("quadrature/blinn_phong_modified/k7", |b| {
        b.iter(|| clamp_integral_by_quadrature(Form::BlinnPhongModified, black_box(300.0), 7))
    });
    g.finish();
}

criterion_group!(benches, lobes, normalisation);
criterion_main!(benches);
