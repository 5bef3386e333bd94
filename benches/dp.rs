//! Per-frame cost of DP-TBD on the host at 128 x 128, `L = 8` (the firmware's rows):
//! first order 3x3 and 5x5 (Barniv 1985, Arnold et al. 1993), Pulford 3x3 (Pulford, La
//! Scala 2010), second order 3x3/3x3 (Wang, Zhang 2016) with `i16` and `i8` merits. The
//! scene is noise `N(0, 1.5^2)` plus a target at SNR 2; each detector first runs 8 frames
//! (the window filled), then every measured `step` takes the next of 16 cycled frames (the
//! recursion's cost does not depend on the frame count).
//!
//! `cargo bench --bench dp -- --warm-up-time 1 --measurement-time 5`

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use faint::detect::dp::{DpConfig, DpTrack, Method};
use faint::dp_tbd;
use faint::rng::Rng;

const M: usize = 128;
const L: usize = 8;
const SIGMA: f32 = 1.5;

type A9 = dp_tbd!(Arnold, M, 9, L);
type A25 = dp_tbd!(Arnold, M, 25, L);
type P9 = dp_tbd!(Pulford, M, 9, L);
type S9 = dp_tbd!(SecondOrder, M, 9, L);
type S9i8 = dp_tbd!(SecondOrder, M, 9, L, i8);

/// 16 frames: noise plus `2 sigma` in the pixel of a target moving at (0.8, 0.5) px/frame.
fn frames() -> Vec<Vec<f32>> {
    let mut rng = Rng::seed_from_u64(0x0D9B);
    (0..16)
        .map(|k| {
            let mut z: Vec<f32> = (0..M * M).map(|_| SIGMA * rng.normal()).collect();
            let (x, y) = (32.0 + 0.8 * k as f32, 38.4 + 0.5 * k as f32);
            z[y as usize * M + x as usize] += 2.0 * SIGMA;
            z
        })
        .collect()
}

// The detectors are boxed by the caller to keep the 0.6 MB states off the stack.
#[allow(clippy::boxed_local)]
fn bench_one<D: DpTrack>(c: &mut Criterion, name: &str, mut det: Box<D>, cfg: DpConfig) {
    let fr = frames();
    det.configure(&cfg, 0).unwrap();
    for f in &fr[..8] {
        det.step(f).unwrap();
    }
    let mut g = c.benchmark_group("dp_frame_128x128");
    g.throughput(Throughput::Elements((M * M) as u64));
    let mut k = 8;
    g.bench_function(name, |b| {
        b.iter(|| {
            k = (k + 1) % fr.len();
            det.step(black_box(&fr[k])).unwrap()
        })
    });
    g.finish();
}

fn bench_dp(c: &mut Criterion) {
    let arnold = DpConfig::dim_point(Method::Arnold, 1);
    let second = DpConfig::dim_point(Method::SecondOrder, 1);
    bench_one(c, "arnold_3x3", Box::new(A9::new_unconfigured()), arnold);
    bench_one(c, "arnold_5x5", Box::new(A25::new_unconfigured()), arnold);
    let pulford = DpConfig::dim_point(Method::Pulford, 1);
    bench_one(c, "pulford_3x3", Box::new(P9::new_unconfigured()), pulford);
    bench_one(
        c,
        "second_order_3x3_i16",
        Box::new(S9::new_unconfigured()),
        second,
    );
    let coarse = DpConfig {
        lsb: 0.25,
        ..second
    };
    bench_one(
        c,
        "second_order_3x3_i8",
        Box::new(S9i8::new_unconfigured()),
        coarse,
    );
}

criterion_group!(benches, bench_dp);
criterion_main!(benches);
