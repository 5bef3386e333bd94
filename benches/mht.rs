//! MHT-TBD speed: censoring per scan, the period-end step (censoring of the last window +
//! DMHT + smoothing + peaks + association), the classic detector per period, and the
//! f32 vs fixed-point rho quantiser, at lambda = 80 and 398 (sea-clutter preset).
use criterion::{criterion_group, criterion_main, BatchSize, Criterion};
use faint::detect::mht::Geometry;
use faint::detect::Detector;
use faint::host::reproduce::mht::{detectors, thresholds};
use faint::host::simulate::mht::SeaClutter;
use faint::rng::Rng;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    for lambda in [80.0f32, 398.0] {
        let sc = SeaClutter::paper(lambda);
        let (g1, gc) = thresholds(&sc, 1e-4);
        let mut rng = Rng::seed_from_u64(5);
        let trial = sc.generate(&mut rng);
        let (mut det, mut classic) = detectors(&sc, g1.min(255) as u8, gc.min(255) as u8).unwrap();
        for s in 0..15 {
            det.step(&trial.scans[s].plots).unwrap();
        }
        let mid = det.clone();
        for s in 15..29 {
            det.step(&trial.scans[s].plots).unwrap();
        }
        let before_last = det.clone();
        let mut g = c.benchmark_group(format!("mht/lambda{lambda}"));
        g.bench_function("censoring_per_scan", |b| {
            b.iter_batched_ref(
                || mid.clone(),
                |d| black_box(d.step(black_box(&trial.scans[15].plots)).unwrap()),
                BatchSize::LargeInput,
            )
        });
        g.bench_function("period_end_step", |b| {
            b.iter_batched_ref(
                || before_last.clone(),
                |d| black_box(d.step(black_box(&trial.scans[29].plots)).unwrap()),
                BatchSize::LargeInput,
            )
        });
        g.bench_function("classic_per_period", |b| {
            b.iter(|| {
                for sd in &trial.scans {
                    black_box(classic.step(black_box(&sd.plots)).unwrap());
                }
            })
        });
        let geom = Geometry::<256, 180>::for_area(sc.area);
        let plots = &trial.scans[0].plots;
        g.bench_function("curves_f32", |b| {
            b.iter(|| {
                let mut s = 0usize;
                for p in plots {
                    for a in 0..180 {
                        s += geom.rho_index_f32(p.x, p.y, a);
                    }
                }
                black_box(s)
            })
        });
        g.bench_function("curves_fixed", |b| {
            b.iter(|| {
                let mut s = 0usize;
                for p in plots {
                    let (xq, yq) = geom.quantise(p.x, p.y);
                    for a in 0..180 {
                        s += geom.rho_index_q(xq, yq, a);
                    }
                }
                black_box(s)
            })
        });
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
