//! Link-time proof that the DP-TBD detectors (Barniv 1985 / Arnold et al. 1993, Pulford
//! and La Scala 2010, Wang and Zhang 2016) contain no reachable panic: `configure`,
//! `reset`, `step` (good frames, frames needing the clamping path, bad lengths, NaN) and
//! the merit and track queries of `ArnoldDp`, `PulfordDp` and `SecondOrderDp` (3x3 and
//! 5x5 windows, `i16` and `i8` merits, separable and non-separable transition terms) on
//! inputs hidden from the optimiser. As in `panic_never.rs`, the panic handler calls a
//! function that does not exist, so the fat-LTO link fails with an undefined reference to
//! `faint_core_panic_path_survived` if any panic path survives:
//!
//! ```sh
//! cd firmware && cargo run --profile firmware --features panic-never --bin panic-never-dp
//! ```
//!
//! The binary then runs the calls once and exits with status 0 (1 if a result was not
//! the expected `Ok` or `Err`). It prints without `core::fmt`.
#![no_std]
#![no_main]

faint_firmware::panic_never!();

use core::hint::black_box;

use cortex_m_rt::entry;
use faint_core::detect::dp::{
    arnold_words, pulford_words, second_order_words, ArnoldDp, DpConfig, DpTrack, Method,
    PulfordDp, SecondOrderDp, Transition,
};
use faint_core::detect::Detector;
use faint_core::rng::Rng;
use faint_firmware::semihosting::finish;

const M: usize = 16;
const L: usize = 5;

type A9 = ArnoldDp<M, 9, L, { arnold_words(M, 9, L) }>;
type A25i8 = ArnoldDp<M, 25, L, { arnold_words(M, 25, L) }, i8>;
type P9 = PulfordDp<M, 9, L, { pulford_words(M, 9, L) }>;
type P25 = PulfordDp<M, 25, L, { pulford_words(M, 25, L) }>;
type S9 = SecondOrderDp<M, 9, L, { second_order_words(M, 9, L) }>;
type S9i8 = SecondOrderDp<M, 9, L, { second_order_words(M, 9, L) }, i8>;
type S25 = SecondOrderDp<M, 25, L, { second_order_words(M, 25, L) }>;

static mut A9_DET: A9 = A9::unconfigured();
static mut A25_DET: A25i8 = A25i8::unconfigured();
static mut P9_DET: P9 = P9::unconfigured();
static mut P25_DET: P25 = P25::unconfigured();
static mut S9_DET: S9 = S9::unconfigured();
static mut S9I8_DET: S9i8 = S9i8::unconfigured();
static mut S25_DET: S25 = S25::unconfigured();

#[entry]
fn main() -> ! {
    finish(
        run(),
        b"panic-never-dp: DP-TBD detectors linked without a panic path and ran ok\n",
        b"panic-never-dp: a call did not return the expected Ok or Err\n",
    )
}

fn run() -> bool {
    let mut rng = Rng::from_stream(black_box(0x0D9B_7BD0), black_box(3));
    let mut z = [0f32; M * M];
    // SAFETY: single-threaded, the only references to these statics.
    let (a9, a25, p9, p25, s9, s9i8, s25) = unsafe {
        (
            &mut *core::ptr::addr_of_mut!(A9_DET),
            &mut *core::ptr::addr_of_mut!(A25_DET),
            &mut *core::ptr::addr_of_mut!(P9_DET),
            &mut *core::ptr::addr_of_mut!(P25_DET),
            &mut *core::ptr::addr_of_mut!(S9_DET),
            &mut *core::ptr::addr_of_mut!(S9I8_DET),
            &mut *core::ptr::addr_of_mut!(S25_DET),
        )
    };
    let arnold = black_box(DpConfig::dim_point(Method::Arnold, 1));
    let coarse = black_box(DpConfig {
        lsb: 0.25,
        ..arnold
    });
    let pulford = black_box(DpConfig::dim_point(Method::Pulford, 2));
    let second = black_box(DpConfig::dim_point(Method::SecondOrder, 1));
    // sigma_I = 0.7 px: a transition table that is not separable (the general 2-D path)
    let skew = black_box(DpConfig {
        sigma_i: 0.7,
        top_k: 3,
        ..second
    });
    let hard = black_box(DpConfig {
        transition: Transition::Hard,
        ..second
    });
    let mut ok = true;
    ok &= exercise(a9, &arnold, &mut rng, &mut z);
    ok &= exercise(a25, &coarse, &mut rng, &mut z);
    ok &= exercise(p9, &pulford, &mut rng, &mut z);
    ok &= exercise(p25, &pulford, &mut rng, &mut z);
    ok &= exercise(s9, &second, &mut rng, &mut z);
    ok &= exercise(s9, &skew, &mut rng, &mut z);
    ok &= exercise(s9i8, &DpConfig { lsb: 0.25, ..hard }, &mut rng, &mut z);
    ok &= exercise(s25, &skew, &mut rng, &mut z);
    let r = black_box(1i32);
    black_box(s9.pair_merit(black_box(3), black_box(4), r, -r));
    black_box(s9.transition());
    black_box(p9.filter(black_box(2), black_box(9)));
    black_box(a9.ends().len() + p9.ends().len() + s25.ends().len());
    // A configuration of the wrong method, and a bad one, are errors.
    ok &= a9.configure(&second, 0).is_err();
    ok &= s9
        .configure(
            &DpConfig {
                lsb: black_box(f32::NAN),
                ..second
            },
            0,
        )
        .is_err();
    ok
}

/// `configure`, frames (good, huge, wrong length, NaN), `reset`, and every query on
/// positions hidden from the optimiser.
fn exercise<D: DpTrack>(det: &mut D, cfg: &DpConfig, rng: &mut Rng, z: &mut [f32; M * M]) -> bool {
    let mut ok = det.configure(cfg, black_box(1)).is_ok();
    let frames = black_box(7usize);
    let mut acc = 0.0f32;
    for k in 0..frames {
        for v in z.iter_mut() {
            *v = 1.5 * rng.normal();
        }
        if k == 3 {
            // beyond +-ZMAX LSB: the clamping path
            if let Some(v) = z.get_mut(black_box(17)) {
                *v = black_box(3.0e30);
            }
        }
        let frame: &[f32] = black_box(&z[..]);
        match det.step(frame) {
            Ok(r) => acc += r.best.merit + r.clamped as f32,
            Err(_) => ok = false,
        }
    }
    let n = black_box(z.len());
    ok &= det
        .step(z.get(..n.saturating_sub(1)).unwrap_or(&[]))
        .is_err();
    if let Some(v) = z.get_mut(black_box(5)) {
        *v = f32::NAN;
    }
    ok &= det.step(&z[..]).is_err();
    let (x, y) = (black_box(7usize), black_box(40usize));
    acc += det.merit(x, y).unwrap_or(0.0) + det.merit(y, x).unwrap_or(0.0);
    let mut t = [[0u16; 2]; 9];
    let t: &mut [[u16; 2]] = black_box(&mut t[..]);
    acc += det.track(x, black_box(3), t) as f32 + det.track(y, x, t) as f32;
    acc += t.iter().map(|p| f32::from(p[0] ^ p[1])).sum::<f32>();
    if let Some(b) = det.best() {
        acc += b.merit;
    }
    if let Some(b) = det.best_within(x, black_box(9), black_box(3)) {
        acc += b.merit;
    }
    for i in 0..black_box(4usize) {
        if let Some(d) = det.detection(i) {
            acc += d.score + d.state().iter().sum::<f32>();
        }
    }
    acc += det.detection_count() as f32 + det.frames() as f32;
    det.reset(black_box(2));
    ok &= det.merit(x, black_box(2)).is_none();
    for v in z.iter_mut() {
        *v = rng.normal();
    }
    ok &= det.step(black_box(&z[..])).is_ok();
    black_box(acc);
    ok
}
