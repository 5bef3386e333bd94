//! DP-TBD (Barniv 1985 / Arnold et al. 1993, Pulford and La Scala 2010, Wang and Zhang
//! 2016): best merits, the merits of every pixel and the recovered best tracks of the
//! three recursions on a 12 x 12 scene of 10 frames (noise `N(0, 1.5^2)`, one target at
//! SNR 3 moving at (0.8, 0.5) px/frame), with `q_B = 9` and, for the first and second
//! order, 25 (`q_B = 9` also with `i8` merits for both orders); and one frame of huge finite values. Stack use ~15 KiB (the detectors live
//! on the stack).
//!
//! [`frame`] is also the firmware's scene (at 128 x 128 and 64 x 64).

use crate::{Fold, ERR, SEED};
use faint_core::detect::dp::{DpConfig, DpTrack, Method};
use faint_core::detect::Detector;
use faint_core::dp_tbd;
use faint_core::rng::Rng;

/// Noise standard deviation of the scene.
pub const SIGMA: f32 = 1.5;

/// Target position (continuous, pixel units) at frame `k` (0-based) of an `m x m` scene.
pub fn target(m: usize, k: usize) -> (f32, f32) {
    let m = m as f32;
    (0.25 * m + 0.8 * k as f32, 0.3 * m + 0.5 * k as f32)
}

/// Frame `k` of the scene: `N(0, SIGMA^2)` noise plus `amp` in the pixel holding the
/// target (if inside), row-major into `out` (`m * m` values).
pub fn frame(m: usize, k: usize, amp: f32, rng: &mut Rng, out: &mut [f32]) {
    for v in out.iter_mut() {
        *v = SIGMA * rng.normal();
    }
    let (x, y) = target(m, k);
    if x >= 0.0 && y >= 0.0 {
        let (i, j) = (x as usize, y as usize);
        if i < m && j < m {
            if let Some(v) = out.get_mut(j * m + i) {
                *v += amp;
            }
        }
    }
}

const M: usize = 12;
const L: usize = 6;
const FRAMES: usize = 10;

fn emit_run<D: DpTrack>(
    name: &str,
    det: &mut D,
    cfg: &DpConfig,
    emit: &mut dyn FnMut(&str, &[u32]),
) {
    if det.configure(cfg, 0).is_err() {
        emit(name, &[ERR]);
        return;
    }
    let mut rng = Rng::from_stream(SEED, 40);
    let mut z = [0f32; M * M];
    let mut reports = Fold::new();
    for k in 0..FRAMES {
        frame(M, k, 3.0 * SIGMA, &mut rng, &mut z);
        match det.step(&z) {
            Ok(r) => {
                reports.push(r.frame);
                reports.push_f32(r.best.merit);
                reports.push(u32::from(r.best.x) | (u32::from(r.best.y) << 16));
            }
            Err(_) => {
                emit(name, &[ERR]);
                return;
            }
        }
    }
    let mut merits = Fold::new();
    for y in 0..M {
        for x in 0..M {
            merits.push_f32(det.merit(x, y).unwrap_or(f32::NAN));
        }
    }
    let mut track = Fold::new();
    let mut t = [[0u16; 2]; L];
    let (bx, by) = det
        .best()
        .map_or((0, 0), |b| (usize::from(b.x), usize::from(b.y)));
    let n = det.track(bx, by, &mut t);
    for p in t.iter().take(n) {
        track.push(u32::from(p[0]) | (u32::from(p[1]) << 16));
    }
    let d = det.detection(0);
    let state = d.map_or([ERR; 4], |d| {
        let s = d.state();
        core::array::from_fn(|i| s.get(i).map_or(ERR, |v| v.to_bits()))
    });
    emit(
        name,
        &[
            reports.value(),
            merits.value(),
            track.value(),
            n as u32,
            state[0],
            state[1],
            state[2],
            state[3],
        ],
    );
}

pub(crate) fn cases(emit: &mut dyn FnMut(&str, &[u32])) {
    let a = DpConfig::dim_point(Method::Arnold, 1);
    let p = DpConfig::dim_point(Method::Pulford, 1);
    let s = DpConfig::dim_point(Method::SecondOrder, 1);
    emit_run(
        "dp.arnold9",
        &mut <dp_tbd!(Arnold, M, 9, L)>::new_unconfigured(),
        &a,
        emit,
    );
    emit_run(
        "dp.arnold9_i8",
        &mut <dp_tbd!(Arnold, M, 9, L, i8)>::new_unconfigured(),
        &a,
        emit,
    );
    emit_run(
        "dp.arnold25",
        &mut <dp_tbd!(Arnold, M, 25, L)>::new_unconfigured(),
        &a,
        emit,
    );
    emit_run(
        "dp.pulford9",
        &mut <dp_tbd!(Pulford, M, 9, L)>::new_unconfigured(),
        &p,
        emit,
    );
    emit_run(
        "dp.second9",
        &mut <dp_tbd!(SecondOrder, M, 9, L)>::new_unconfigured(),
        &s,
        emit,
    );
    emit_run(
        "dp.second9_i8",
        &mut <dp_tbd!(SecondOrder, M, 9, L, i8)>::new_unconfigured(),
        &s,
        emit,
    );
    emit_run(
        "dp.second25",
        &mut <dp_tbd!(SecondOrder, M, 25, L)>::new_unconfigured(),
        &s,
        emit,
    );
    // Huge finite values: clamped, finite merits.
    let mut det = <dp_tbd!(SecondOrder, M, 9, L)>::new_unconfigured();
    let mut words = [ERR; 3];
    if det.configure(&s, 0).is_ok() {
        let mut z = [0f32; M * M];
        for (i, v) in z.iter_mut().enumerate() {
            *v = if i % 3 == 0 { 1.0e30 } else { -3.0e38 };
        }
        let mut r = det.step(&z);
        for _ in 0..3 {
            r = det.step(&z);
        }
        if let Ok(r) = r {
            words = [r.best.merit.to_bits(), r.clamped, u32::from(r.best.x)];
        }
    }
    emit("dp.huge", &words);
}
