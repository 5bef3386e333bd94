//! PSO-PHD-TBD (Pei et al. 2019): a deterministic three-target scene at 9 dB, generated in
//! `no_std` code so that the golden case, the firmware's instruction counts and the host
//! tests run on the same cubes, and the golden case itself (the estimated count, the
//! PHD mass and the estimates' bits per frame of PHD-TBD, PSO-PHD-TBD with K-means and
//! PSO-PHD-TBD with DBSCAN, folded).
//!
//! Scene (radar at the origin, 1 s frames, constant velocity, no process noise):
//! two targets born together at (820, 820) m on frame 0 (1.4 and 2.8 m/s radial,
//! +-7 m/s tangential, so they separate by ~14 m per frame) and a third at (900, 760) m on
//! frame 3; all three stay inside range 1150-1240 m, azimuth 40-49 deg, radial velocity
//! 1-9 m/s for the [`FRAMES`] frames. The cube model and the filter settings are those of
//! the host's `six-targets` preset (one-cell point spread, `sigma^2 = 1`,
//! `P = 2 sigma^2 10^(SNR/10)`, measurement-driven births on the previous frame from one
//! component per birth place, `q1 = 1`, `lambda_k = 1`, the paper's PSO settings), in a
//! range x Doppler x azimuth window around the targets instead of the full 1.9 M-cell
//! cube.
//!
//! The golden case uses the [`GOLDEN_WINDOW`] (16 x 16 x 16 cells) and a small filter
//! (`SmcPhdTbd<256, 256, 4, 4>`, 60 particles per target, 64 births) that lives on the
//! stack: stack use is about 70 KiB (filter ~50 KiB, cube 16 KiB).

use faint_core::detect::phd::{
    BirthComponent, BirthMode, BirthModel, DbscanParams, Extractor, PhdConfig, PsoConfig,
    SmcPhdTbd, MAX_BIRTH_COMPONENTS,
};
use faint_core::detect::Detector;
use faint_core::math;
use faint_core::model::power_cube::{CubeGeometry, PointSpread, RadarCoords};
use faint_core::rng::Rng;
use faint_core::Complex32;

use crate::{Fold, ERR, SEED};

/// Frames of the scene.
pub const FRAMES: usize = 10;
/// SNR of every target (dB), `10 log10(P / (2 sigma^2))`.
pub const SNR_DB: f32 = 9.0;
/// Per-component noise variance `sigma^2`.
pub const NOISE_VAR: f32 = 1.0;
/// Frame period (s).
pub const DT: f32 = 1.0;
/// Targets: first frame (0-based) and `[x, vx, y, vy]` on that frame.
pub const TARGETS: [(usize, [f32; 4]); 3] = [
    (0, [820.0, 6.0, 820.0, -4.0]),
    (0, [820.0, -3.0, 820.0, 7.0]),
    (3, [900.0, 4.0, 760.0, 9.0]),
];
/// Birth places (where the targets appear), `[x, y]`.
pub const BIRTHS: [[f32; 2]; 2] = [[820.0, 820.0], [900.0, 760.0]];
/// At most this many targets' point spreads are summed per cube.
const MAX_TARGETS: usize = TARGETS.len();

/// The golden case's window: range [1040, 1360) m x radial velocity [-4, 12) m/s x
/// azimuth [37, 53) deg, 16 cells on each axis (4096 cells, 16 KiB).
pub const GOLDEN_WINDOW: CubeGeometry = CubeGeometry {
    n_range: 16,
    n_doppler: 16,
    n_azimuth: 16,
    range_start: 1040.0,
    range_cell: 20.0,
    doppler_start: -4.0,
    doppler_cell: 1.0,
    azimuth_start_deg: 37.0,
    azimuth_cell_deg: 1.0,
};

/// The firmware measurement's window: range [880, 1520) m x radial velocity [-12, 20) m/s
/// x azimuth [29, 61) deg, 32 cells on each axis (32 768 cells, 128 KiB).
pub const FIRMWARE_WINDOW: CubeGeometry = CubeGeometry {
    n_range: 32,
    n_doppler: 32,
    n_azimuth: 32,
    range_start: 880.0,
    range_cell: 20.0,
    doppler_start: -12.0,
    doppler_cell: 1.0,
    azimuth_start_deg: 29.0,
    azimuth_cell_deg: 1.0,
};

/// The preset's point spread: one-cell standard deviation, 3 x 3 x 3 cells.
pub const PSF: PointSpread = PointSpread {
    loss_range: 1.0,
    loss_doppler: 1.0,
    loss_azimuth: 1.0,
    half_width: [1, 1, 1],
};

/// Target power `P = 2 sigma^2 10^(SNR/10)`.
pub fn power() -> f32 {
    2.0 * NOISE_VAR * math::powf(10.0, SNR_DB / 10.0)
}

/// The targets alive on frame `k` (0-based): writes their `[x, vx, y, vy]` to `out` and
/// returns how many.
pub fn truth(k: usize, out: &mut [[f32; 4]; MAX_TARGETS]) -> usize {
    let mut n = 0;
    for (first, s) in TARGETS {
        if k >= first {
            let t = (k - first) as f32 * DT;
            out[n] = [s[0] + t * s[1], s[1], s[2] + t * s[3], s[3]];
            n += 1;
        }
    }
    n
}

/// One frame's power cube (eq. 2) for the targets alive on frame `k`, in window `g`:
/// noise-only cells `2 sigma^2 Exp(1)`, cells a target spreads into
/// `|sum_t A_t h_t + n|^2` with `A_t = sqrt(P) e^{j phi_t}` (random phase per target and
/// frame) and complex Gaussian `n` of variance `sigma^2` per component; the host preset's
/// generator, in fixed memory. Cells of `out` beyond `g.len()` are left alone.
pub fn cube(g: &CubeGeometry, k: usize, rng: &mut Rng, out: &mut [f32]) {
    let two_s2 = 2.0 * NOISE_VAR;
    for z in out.iter_mut().take(g.len()) {
        *z = two_s2 * rng.exponential();
    }
    let amp = math::sqrt(power());
    let mut states = [[0.0f32; 4]; MAX_TARGETS];
    let nt = truth(k, &mut states);
    let mut cells = [(usize::MAX, Complex32::new(0.0, 0.0)); MAX_TARGETS * 27];
    let mut nc = 0;
    for s in &states[..nt] {
        let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
        let phase = 2.0 * math::PI * rng.uniform();
        let a = Complex32::new(amp * math::cos(phase), amp * math::sin(phase));
        PSF.for_each_cell(g, &c, |idx, h| {
            if let Some(e) = cells.get_mut(nc) {
                *e = (idx, a * h);
                nc += 1;
            }
        });
    }
    let mut order = [0u32; MAX_TARGETS * 27];
    let cells = cells.get_mut(..nc).unwrap_or(&mut []);
    faint_core::simulate::cube_returns(out, cells, &mut order, NOISE_VAR, rng);
}

/// One of Pei et al.'s three algorithms, as the golden cases and the firmware rows run it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Algorithm {
    /// Display name (the firmware rows).
    pub name: &'static str,
    /// Golden case name.
    pub case: &'static str,
    /// With the PSO step.
    pub pso: bool,
    /// DBSCAN extraction (K-means otherwise).
    pub dbscan: bool,
}

/// PHD-TBD, PSO-PHD-TBD with K-means, PSO-PHD-TBD with DBSCAN, in the paper's order.
pub const ALGORITHMS: [Algorithm; 3] = [
    Algorithm {
        name: "PHD-TBD",
        case: "phd.phd_tbd",
        pso: false,
        dbscan: false,
    },
    Algorithm {
        name: "PSO-PHD-TBD (K-means)",
        case: "phd.pso_kmeans",
        pso: true,
        dbscan: false,
    },
    Algorithm {
        name: "PSO-PHD-TBD (DBSCAN)",
        case: "phd.pso_dbscan",
        pso: true,
        dbscan: true,
    },
];

/// The `six-targets` preset's filter settings in window `g`, with `particles_per_target`
/// particles per estimated target, `births` birth particles per frame (also the minimum
/// kept) and `points` swarm measurement points (at most the filter's `M`).
pub fn config(
    g: CubeGeometry,
    alg: Algorithm,
    particles_per_target: usize,
    births: usize,
    points: usize,
) -> PhdConfig {
    let p = power();
    let mut components = [BirthComponent {
        mean: [0.0; 4],
        std: [20.0; 4],
    }; MAX_BIRTH_COMPONENTS];
    for (c, b) in components.iter_mut().zip(BIRTHS) {
        c.mean = [b[0], 0.0, b[1], 0.0];
    }
    PhdConfig {
        geometry: g,
        psf: PSF,
        noise_var: NOISE_VAR,
        dt: DT,
        q_motion: 1.0,
        q_intensity: 0.01,
        min_intensity: 0.05 * p,
        p_survival: 0.98,
        birth: BirthModel {
            components,
            n_components: BIRTHS.len(),
            mode: BirthMode::Measurement {
                cells: 8,
                tangential_std: 40.0,
                pair_max_speed: 0.0,
            },
            particles: births,
            mass: 0.02 * BIRTHS.len() as f32,
            intensity: [0.75 * p, 1.25 * p],
        },
        particles_per_target,
        min_particles: births,
        clutter_lambda: 1.0,
        merge_adjacent_cells: true,
        pso: alg.pso.then(|| PsoConfig {
            points,
            ..PsoConfig::paper()
        }),
        extractor: if alg.dbscan {
            Extractor::Dbscan(DbscanParams {
                eps: 5.0,
                min_pts: 10,
            })
        } else {
            Extractor::KMeans { max_iter: 20 }
        },
    }
}

/// Runs `det` (already configured) over the [`FRAMES`] frames of the scene in window `g`
/// (cubes from `Rng::from_stream(SEED, 500)`), folding per frame `N_hat`, the PHD mass
/// and every estimate's state bits and support; returns
/// `[fold, N_hat of the last frame, estimates of the last frame]`, or `[ERR; 3]`.
pub fn run<const N: usize, const S: usize, const M: usize, const K: usize>(
    det: &mut SmcPhdTbd<N, S, M, K>,
    g: &CubeGeometry,
    buf: &mut [f32],
) -> [u32; 3] {
    let Some(buf) = buf.get_mut(..g.len()) else {
        return [ERR; 3];
    };
    let mut rng = Rng::from_stream(SEED, 500);
    let mut fold = Fold::new();
    let mut last = [0u32; 2];
    for k in 0..FRAMES {
        cube(g, k, &mut rng, buf);
        let Ok(r) = det.step(buf) else {
            return [ERR; 3];
        };
        fold.push(r.n_hat as u32);
        fold.push_f32(r.mass);
        fold.push(r.estimates as u32);
        for e in det.estimates() {
            for v in e.state {
                fold.push_f32(v);
            }
            fold.push(e.support);
        }
        last = [r.n_hat as u32, r.estimates as u32];
    }
    [fold.value(), last[0], last[1]]
}

/// The golden case's filter.
pub type GoldenFilter = SmcPhdTbd<256, 256, 4, 4>;

pub(crate) fn cases(emit: &mut dyn FnMut(&str, &[u32])) {
    let mut buf = [0.0f32; 4096];
    for alg in ALGORITHMS {
        match GoldenFilter::new(config(GOLDEN_WINDOW, alg, 60, 64, 4), SEED) {
            Ok(mut d) => emit(alg.case, &run(&mut d, &GOLDEN_WINDOW, &mut buf)),
            Err(_) => emit(alg.case, &[ERR]),
        }
    }
}
