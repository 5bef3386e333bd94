//! Host benchmarks of the core primitives: resampling at N = 1000 / 6000, normal
//! sampling throughput, log-weight normalisation.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use faint::math::normalize_log_weights;
use faint::particles::{resample, Scheme};
use faint::rng::Rng;

fn bench_resampling(c: &mut Criterion) {
    let mut g = c.benchmark_group("resample");
    for n in [1000usize, 6000] {
        let mut rng = Rng::seed_from_u64(1);
        let w: Vec<f32> = (0..n).map(|_| rng.exponential()).collect();
        let mut out = vec![0u16; n];
        g.throughput(Throughput::Elements(n as u64));
        for s in [
            Scheme::Systematic,
            Scheme::Stratified,
            Scheme::Residual,
            Scheme::Multinomial,
        ] {
            g.bench_with_input(BenchmarkId::new(format!("{s:?}"), n), &n, |b, _| {
                b.iter(|| resample(s, black_box(&w), &mut out, &mut rng))
            });
        }
    }
    g.finish();
}

fn bench_sampling(c: &mut Criterion) {
    let mut g = c.benchmark_group("sample");
    let n = 10_000u64;
    g.throughput(Throughput::Elements(n));
    let mut rng = Rng::seed_from_u64(2);
    g.bench_function("normal", |b| {
        b.iter(|| {
            let mut s = 0.0f32;
            for _ in 0..n {
                s += rng.normal();
            }
            black_box(s)
        })
    });
    g.bench_function("uniform", |b| {
        b.iter(|| {
            let mut s = 0.0f32;
            for _ in 0..n {
                s += rng.uniform();
            }
            black_box(s)
        })
    });
    g.finish();
}

fn bench_normalise(c: &mut Criterion) {
    let mut g = c.benchmark_group("normalize_log_weights");
    for n in [1000usize, 6000] {
        let mut rng = Rng::seed_from_u64(3);
        let logs: Vec<f32> = (0..n).map(|_| -400.0 * rng.uniform()).collect();
        let mut w = vec![0.0f32; n];
        g.throughput(Throughput::Elements(n as u64));
        g.bench_with_input(BenchmarkId::from_parameter(n), &n, |b, _| {
            b.iter(|| normalize_log_weights(black_box(&logs), &mut w))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_resampling, bench_sampling, bench_normalise);
criterion_main!(benches);
