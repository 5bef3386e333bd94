//! Per-frame cost of CBMeMBer TBD on the `rotor-uav` preset (256 x 512 maps, -10 dB, model
//! generator): joint at 700 / 1000 / 1500 particles and Doppler-only at 1500 (the paper's
//! Table 3 rows), plus the joint filter on the quantised `u8` map and with the exact
//! per-pixel likelihood, measured on frame 21 from the state reached after 20 frames.
//! Before criterion, the mean CPU time per frame over whole 40-frame runs (3 seeds), which
//! a shared machine's waiting for a core does not inflate.
//!
//! `cargo bench --bench cbmember -- --warm-up-time 1 --measurement-time 5`

use criterion::{criterion_group, BatchSize, Criterion};
use faint::detect::cbmember::Likelihood;
use faint::detect::Detector;
use faint::host::instances::boxed;
use faint::host::instances::cbmember::{HostFilter, HostFilterU8};
use faint::host::simulate::cbmember::{MapSource, RotorUav};
use faint::model::range_doppler::{quantise, Dequant, PointModel};
use faint::rng::Rng;

const ROWS: [(&str, PointModel, usize); 4] = [
    ("doppler_only_1500", PointModel::DopplerOnly, 1500),
    ("joint_700", PointModel::Joint, 700),
    ("joint_1000", PointModel::Joint, 1000),
    ("joint_1500", PointModel::Joint, 1500),
];

fn maps(sc: &RotorUav, seed: u64, n: usize) -> Vec<Vec<f32>> {
    let truth = sc.truth();
    let mut src = MapSource::new(sc);
    let mut rng = Rng::seed_from_u64(seed);
    truth
        .iter()
        .take(n)
        .enumerate()
        .map(|(k, t)| {
            let mut m = Vec::new();
            src.power(sc, t, k, &mut rng, &mut m);
            m
        })
        .collect()
}

fn bench_cbmember(c: &mut Criterion) {
    let sc = RotorUav::new(-10.0);
    let frames = maps(&sc, 11, 21);
    let mut g = c.benchmark_group("cbmember_frame");
    g.sample_size(30);
    for (name, model, particles) in ROWS {
        let mut f = boxed::<HostFilter>(&sc.config(model, particles), 5).unwrap();
        for m in &frames[..20] {
            f.step(m).unwrap();
        }
        g.bench_function(name, |b| {
            b.iter_batched(
                || f.clone(),
                |mut f| {
                    let r = f.step(&frames[20]).unwrap();
                    (r, f)
                },
                BatchSize::LargeInput,
            )
        });
    }
    // The quantised map and the exact likelihood (joint, 1500).
    let cfg = sc.config(PointModel::Joint, 1500);
    let dq = Dequant::new(cfg.noise_var, cfg.quant_step);
    let q: Vec<Vec<u8>> = frames
        .iter()
        .map(|m| {
            m.iter()
                .map(|&z| quantise(z * dq.scale, cfg.quant_step))
                .collect()
        })
        .collect();
    let mut f = boxed::<HostFilterU8>(&cfg, 5).unwrap();
    for m in &q[..20] {
        f.step(m).unwrap();
    }
    g.bench_function("joint_1500_u8_map", |b| {
        b.iter_batched(
            || f.clone(),
            |mut f| {
                let r = f.step(&q[20]).unwrap();
                (r, f)
            },
            BatchSize::LargeInput,
        )
    });
    let mut ce = cfg;
    ce.likelihood = Likelihood::Exact;
    let mut f = boxed::<HostFilter>(&ce, 5).unwrap();
    for m in &frames[..20] {
        f.step(m).unwrap();
    }
    g.sample_size(10);
    g.bench_function("joint_1500_exact_likelihood", |b| {
        b.iter_batched(
            || f.clone(),
            |mut f| {
                let r = f.step(&frames[20]).unwrap();
                (r, f)
            },
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

criterion_group!(benches, bench_cbmember);

/// CPU time of this thread in ns (Linux `/proc/thread-self/schedstat`), or None.
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Mean CPU time per frame over whole 40-frame runs (3 seeds, -10 dB).
fn cpu_time_per_frame() {
    if thread_cpu_ns().is_none() {
        return;
    }
    let sc = RotorUav::new(-10.0);
    for (name, model, particles) in ROWS {
        let (mut ns, mut n, mut parts) = (0u64, 0u64, 0usize);
        for seed in 0..3u64 {
            let ms = maps(&sc, 70 + seed, sc.frames);
            let mut f = boxed::<HostFilter>(&sc.config(model, particles), seed).unwrap();
            for m in &ms {
                let t0 = thread_cpu_ns().unwrap_or(0);
                let r = f.step(m).unwrap();
                ns += thread_cpu_ns().unwrap_or(0) - t0;
                parts += r.particles;
                n += 1;
            }
        }
        println!(
            "cpu time per frame, {name}: {:.3} ms (mean over {n} frames, 3 runs of 40, -10 dB; {:.0} particles updated per frame)",
            ns as f64 / n as f64 / 1e6,
            parts as f64 / n as f64
        );
    }
}

fn main() {
    std::thread::Builder::new()
        .stack_size(64 << 20)
        .spawn(|| {
            cpu_time_per_frame();
            benches();
            criterion::Criterion::default()
                .configure_from_args()
                .final_summary();
        })
        .unwrap()
        .join()
        .unwrap();
}
