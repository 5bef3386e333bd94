//! Link-time proof that the `faint-core` primitives and the CBMeMBer filter
//! (`configure`, `step` on `f32` and `u8` maps, `reset`, detections) contain no reachable
//! panic (in the spirit of japaric's `panic-never`): the panic handler calls a function that does not
//! exist, so if any panic path (bounds check, overflow check, `unwrap`, slice index...)
//! survives optimisation, **the link fails** with an undefined reference to
//! `faint_core_panic_path_survived`. Only meaningful with the `firmware` profile (fat LTO):
//!
//! ```sh
//! cd firmware && cargo run --profile firmware --features panic-never --bin panic-never
//! ```
//!
//! The binary then runs the primitives once on data from fixed seeds and exits with status
//! 0 (1 if a call returned `Err`). It prints without `core::fmt` (formatting machinery
//! carries its own panic paths).
#![no_std]
#![no_main]

faint_firmware::panic_never!();

use core::hint::black_box;

use cortex_m_rt::entry;
use faint_core::detect::cbmember::{CbmemberConfig, CbmemberTbd, Likelihood};
use faint_core::detect::Detector;
use faint_core::existence::ExistenceMarkov;
use faint_core::math;
use faint_core::model::range_doppler::PointModel;
use faint_core::particles::{self, Scheme};
use faint_core::rng::Rng;
use faint_firmware::semihosting::finish;
use faint_golden::cbmember::GOLDEN_WINDOW;

const N: usize = 1000;

/// CBMeMBer TBD on the golden case's 32 x 128 map (16-bin blocks: 256 block sums).
type Cbm = CbmemberTbd<2, 64, 256>;
type CbmU8 = CbmemberTbd<2, 64, 256, [u8]>;
static mut CBM: Cbm = Cbm::new_unconfigured();
static mut CBM_U8: CbmU8 = CbmU8::new_unconfigured();
static mut MAP: [f32; 32 * 128] = [0.0; 32 * 128];
static mut MAP_U8: [u8; 32 * 128] = [0; 32 * 128];

#[entry]
fn main() -> ! {
    finish(
        run(),
        b"panic-never: primitives and CbmemberTbd linked without a panic path and ran ok\n",
        b"panic-never: a primitive returned Err\n",
    )
}

fn run() -> bool {
    let mut rng = Rng::from_stream(black_box(0x0FA1_4700), black_box(1));
    let mut logs = [0f32; N];
    let mut w = [0f32; N];
    let mut anc = [0u16; N];
    let mut anc32 = [0u32; N / 2];
    let mut states = [[0f32; 4]; N];
    for (i, s) in states.iter_mut().enumerate() {
        *s = [i as f32, 0.0, 0.0, 1.0];
    }

    for l in logs.iter_mut() {
        *l = 3.0 * rng.normal() + rng.uniform() - rng.exponential() + rng.gaussian(0.0, 0.1);
    }
    // Hide the contents and lengths from the optimiser (the proof must hold for any input).
    let logs: &[f32] = black_box(&logs[..]);
    let w: &mut [f32] = black_box(&mut w[..]);
    let anc: &mut [u16] = black_box(&mut anc[..]);
    let anc32: &mut [u32] = black_box(&mut anc32[..]);
    let states: &mut [[f32; 4]] = black_box(&mut states[..]);
    let mut ok = math::normalize_log_weights(logs, w).is_ok();
    ok &= math::log_sum_exp(logs).is_ok();
    for scheme in [
        Scheme::Systematic,
        Scheme::Stratified,
        Scheme::Residual,
        Scheme::Multinomial,
    ] {
        ok &= particles::resample(scheme, w, anc, &mut rng).is_ok();
        ok &= particles::resample(scheme, w, anc32, &mut rng).is_ok();
    }
    ok &= particles::gather_in_place(states, anc).is_ok();
    ok &= particles::effective_sample_size(w) > 1.0;
    ok &= math::normalize_weights(w).is_ok();
    ok &= math::checked_weight_sum(w).is_ok();
    if let Ok(chain) = ExistenceMarkov::new(black_box(0.1), black_box(0.05)) {
        let mut e = false;
        for _ in 0..100 {
            e = chain.sample(e, &mut rng).exists();
        }
        black_box(chain.predict(black_box(0.5)));
        black_box(e);
    } else {
        ok = false;
    }
    let x = black_box(0.7f32);
    black_box([
        math::exp(x),
        math::ln(x),
        math::sqrt(x),
        math::sin(x),
        math::cos(x),
        math::atan2(x, -x),
        math::powf(x, 2.5),
        math::floor(x),
        math::round(x),
        math::ln1p(x),
        rng.uniform_range(-1.0, 1.0),
        rng.below(17) as f32,
    ]);
    ok &= cbmember(&mut rng);
    ok
}

/// `configure`, `step` (f32 and u8 maps, blocked and exact likelihoods, joint and
/// Doppler-only, bad maps), `reset` and the detections of the CBMeMBer filter, on
/// configurations and maps hidden from the optimiser.
fn cbmember(rng: &mut Rng) -> bool {
    // SAFETY: single-threaded, the only references to these statics.
    let (det, det_u8, map, map_u8) = unsafe {
        (
            &mut *core::ptr::addr_of_mut!(CBM),
            &mut *core::ptr::addr_of_mut!(CBM_U8),
            &mut *core::ptr::addr_of_mut!(MAP),
            &mut *core::ptr::addr_of_mut!(MAP_U8),
        )
    };
    let mut cfg = CbmemberConfig::rotor_uav();
    cfg.geometry = GOLDEN_WINDOW;
    cfg.max_particles = 64;
    cfg.min_particles = 16;
    cfg.birth.particles = 32;
    cfg.gain = 3.0e15;
    let cfg: CbmemberConfig = black_box(cfg);
    for (z, q) in map.iter_mut().zip(map_u8.iter_mut()) {
        *z = 0.18 * rng.exponential();
        *q = (*z * 100.0) as u8;
    }
    let map: &mut [f32] = black_box(&mut map[..]);
    let map_u8: &[u8] = black_box(&map_u8[..]);
    let mut ok = det.configure(&cfg, black_box(7)).is_ok();
    ok &= det_u8.configure(&cfg, black_box(7)).is_ok();
    let mut score = 0.0f32;
    for k in 0..black_box(3usize) {
        ok &= det.step(map).is_ok();
        ok &= det_u8.step(map_u8).is_ok();
        for i in 0..black_box(4usize) {
            if let Some(d) = det.detection(i) {
                score += d.score + d.state().iter().sum::<f32>();
            }
            if let Some(d) = det_u8.detection(i) {
                score += d.score;
            }
        }
        score += det.detection_count() as f32 + k as f32;
    }
    // Bad maps are errors, not panics.
    let n = black_box(map.len());
    ok &= det
        .step(map.get(..n.saturating_sub(1)).unwrap_or(&[]))
        .is_err();
    if let Some(p) = map.get_mut(black_box(5)) {
        *p = f32::NAN;
    }
    ok &= det.step(map).is_err();
    if let Some(p) = map.get_mut(black_box(5)) {
        *p = 0.1;
    }
    let mut other = cfg;
    other.likelihood = Likelihood::Exact;
    other.model = PointModel::DopplerOnly;
    other.estimate_blades = true;
    ok &= det.configure(&black_box(other), 3).is_ok();
    ok &= det.step(map).is_ok();
    det.reset(black_box(9));
    ok &= det.step(map).is_ok();
    let mut bad = cfg;
    bad.noise_var = black_box(0.0);
    ok &= det.configure(&bad, 1).is_err();
    black_box(score);
    ok
}
