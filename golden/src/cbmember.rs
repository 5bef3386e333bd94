//! CBMeMBer TBD with the joint Doppler / micro-Doppler model (rotor-UAV paper, 2023): the
//! `rotor-uav` scene generated in `no_std` code (so the golden case, the firmware's
//! instruction counts and the host run on the same maps), and the golden case.
//!
//! Scene: the preset's target (`r0 = 20 010` m, `v = 1` m/s, `omega = 0.06 pi` rad/s,
//! `theta0 = 0`, `B = 2`, `V = 10` m/s, `rho = 1`) at [`SNR_DB`], maps drawn pixel by
//! pixel from the model (`faint_core::model::range_doppler::simulate_power`).
//!
//! The golden case runs a small filter (`CbmemberTbd<3, 96, 256>`: 3 components, 96
//! particles, 48 births) on a [`GOLDEN_WINDOW`] of 32 x 128 pixels around the target for
//! [`FRAMES`] frames, joint and Doppler-only with the blocked likelihood and joint with
//! the exact one, and emits per variant the fold of every frame's report and reported
//! estimates (bits), the last frame's count and largest existence. Stack: about 40 KiB
//! (filter ~24 KiB, map 16 KiB).

use faint_core::detect::cbmember::{gain_for_snr, CbmemberConfig, CbmemberTbd, Likelihood};
use faint_core::detect::Detector;
use faint_core::model::range_doppler::{
    point_velocities, simulate_power, LitTarget, PointModel, RdGeometry, MAX_POINTS,
};
use faint_core::rng::Rng;

use crate::{Fold, ERR, SEED};

/// Frames of the golden case.
pub const FRAMES: usize = 8;
/// Peak SNR of the scene (dB, eq. 19).
pub const SNR_DB: f32 = -10.0;
/// Initial range (m).
pub const R0: f32 = 20_010.0;

/// The golden case's window: range `[19 997.5, 20 022.5)` m x velocity `[-4, 6)` m/s,
/// 32 x 128 pixels of the preset's bin sizes.
pub const GOLDEN_WINDOW: RdGeometry = RdGeometry {
    n_range: 32,
    n_velocity: 128,
    range_start: 19_997.5,
    range_bin: 0.781_25,
    velocity_start: -4.0,
    velocity_bin: 0.078_125,
};

/// The target in frame `k` (1 s frames).
pub fn target(k: usize) -> LitTarget {
    let t = k as f32;
    let mut vels = [0f32; MAX_POINTS];
    let n = point_velocities(
        PointModel::Joint,
        1.0,
        10.0,
        0.06 * faint_core::math::PI * t,
        2,
        &mut vels,
    );
    let r = R0 + t;
    // A = 10^(snr/10) (r0 / r)^4.
    let q = R0 / r;
    LitTarget {
        range: r,
        amp: faint_core::math::powf(10.0, SNR_DB / 10.0) * q * q * q * q,
        vels,
        n,
    }
}

/// The preset's filter on `geometry` with `particles` = `L_max` and `births` birth
/// particles (`L_min` = the smaller of 450 and `births`).
pub fn config(
    geometry: RdGeometry,
    model: PointModel,
    particles: usize,
    births: usize,
) -> CbmemberConfig {
    let mut c = CbmemberConfig::rotor_uav();
    c.geometry = geometry;
    c.model = model;
    c.gain = gain_for_snr(SNR_DB, R0, 1.0, c.noise_var);
    c.max_particles = particles;
    c.birth.particles = births;
    c.min_particles = births.min(450).min(particles);
    c
}

/// Frame `k` of the scene on `g` into `out` (`g.len()` pixels).
pub fn map(g: &RdGeometry, k: usize, rng: &mut Rng, out: &mut [f32]) {
    let c = CbmemberConfig::rotor_uav();
    simulate_power(g, &c.spread, c.noise_var, &[target(k)], rng, out);
}

type Small = CbmemberTbd<3, 96, 256>;
const CELLS: usize = 32 * 128;

fn variant(emit: &mut dyn FnMut(&str, &[u32]), name: &str, cfg: CbmemberConfig) {
    let Ok(mut det) = Small::new(cfg, SEED ^ 0xCB) else {
        emit(name, &[ERR]);
        return;
    };
    let mut rng = Rng::from_stream(SEED, 601);
    let mut z = [0f32; CELLS];
    let mut fold = Fold::new();
    let mut last = (0u32, 0u32);
    for k in 0..FRAMES {
        map(&GOLDEN_WINDOW, k, &mut rng, &mut z);
        match det.step(&z[..]) {
            Ok(r) => {
                for w in [r.components, r.reported, r.particles, r.pruned, r.merged] {
                    fold.push(w as u32);
                }
                fold.push(r.birth as u32);
                fold.push_f32(r.max_existence);
                for e in det.estimates() {
                    fold.push(e.id);
                    fold.push_f32(e.existence);
                    e.state.iter().for_each(|&v| fold.push_f32(v));
                }
                last = (r.reported as u32, r.max_existence.to_bits());
            }
            Err(_) => fold.push(ERR),
        }
    }
    emit(name, &[fold.value(), last.0, last.1]);
}

/// The golden case (see the module doc).
pub(crate) fn cases(emit: &mut dyn FnMut(&str, &[u32])) {
    let joint = config(GOLDEN_WINDOW, PointModel::Joint, 96, 48);
    variant(emit, "cbmember.joint_blocked", joint);
    variant(
        emit,
        "cbmember.doppler_blocked",
        config(GOLDEN_WINDOW, PointModel::DopplerOnly, 96, 48),
    );
    let mut exact = joint;
    exact.likelihood = Likelihood::Exact;
    variant(emit, "cbmember.joint_exact", exact);
}
