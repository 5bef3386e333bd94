//! Per-frame cost of CRPF-TBD and its comparators on the OTHR scenario (5 dB, Gaussian).
//!
//! One iteration = `reset` + a whole 32-frame run; throughput is reported per frame
//! (`elements` = frames). Paper (MATLAB, PC): CRPF-TBD 2.51 s per 32-frame run at
//! N = 6000 (78 ms per frame). Goal: CRPF-TBD N = 6000 under 0.5 ms per frame.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use faint::detect::crpf::{CrpfConfig, CrpfTbd};
use faint::detect::jott::JottTbd;
use faint::detect::pf_lrt::PfLrt;
use faint::detect::pf_tbd::{GaussConfig, PfTbd};
use faint::detect::{run, Detector};
use faint::host::instances::boxed;
use faint::host::simulate::crpf::{Noise, Othr};
use faint::model::doppler::{estimate_noise_variance, DopplerReport};
use faint::rng::Rng;
use faint::Complex32;
use std::hint::black_box;

fn run_all<D: Detector<Frame = [Complex32], Report = DopplerReport>>(
    d: &mut D,
    frames: &[Vec<Complex32>],
) -> f32 {
    d.reset(7);
    let mut acc = 0.0;
    let _ = run(
        d,
        frames.iter().map(|z| black_box(z.as_slice())),
        |_, _, r| acc += r.existence,
    );
    acc
}

fn bench_n<const N: usize>(c: &mut Criterion) {
    let run = Othr::default().simulate(Some(5.0), Noise::Gaussian, &mut Rng::seed_from_u64(1));
    let var = estimate_noise_variance(run.frames.iter().map(|f| f.as_slice()), 32).unwrap();
    let g = GaussConfig::othr(var);
    let mut group = c.benchmark_group(format!("othr_frame_n{N}"));
    group.throughput(Throughput::Elements(run.frames.len() as u64));
    group.sample_size(20);
    let frames = &run.frames;
    let mut crpf = boxed::<CrpfTbd<N>>(&CrpfConfig::othr(), 1).unwrap();
    group.bench_function("crpf_tbd", |b| b.iter(|| run_all(crpf.as_mut(), frames)));
    let mut pf = boxed::<PfTbd<N>>(&g, 1).unwrap();
    group.bench_function("pf_tbd", |b| b.iter(|| run_all(pf.as_mut(), frames)));
    let mut jott = boxed::<JottTbd<N>>(&g, 1).unwrap();
    group.bench_function("jott", |b| b.iter(|| run_all(jott.as_mut(), frames)));
    let mut lrt = boxed::<PfLrt<N>>(&g, 1).unwrap();
    group.bench_function("pf_lrt", |b| b.iter(|| run_all(lrt.as_mut(), frames)));
    group.finish();
}

fn benches(c: &mut Criterion) {
    bench_n::<1000>(c);
    bench_n::<6000>(c);
}

criterion_group!(crpf, benches);
criterion_main!(crpf);
