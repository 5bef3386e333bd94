//! SMC-PHD track-before-detect on power cubes (Pei et al. 2019, §2.3), optionally with
//! the multi-objective PSO step between prediction and update, and DBSCAN or K-means
//! state extraction.
//!
//! State `x = [x, vx, y, vy, I]` (m, m/s, m, m/s, target power `I = A^2`). One frame:
//! 1. predict survivors with the CV model (eq. 1, 14-15), weight `w Ps`;
//! 2. append `J` birth particles (eq. 16-17), weight `mass / J` each;
//! 3. (PSO variant) move the particles near measurement-derived points (see
//!    [`SmcPhdTbd::step`]);
//! 4. update (eq. 20, 24-25):
//!    `w_i <- w_i L_i / (lambda + rho_c(i))`, `L_i = prod_{covered cells} L(z | x_i)`,
//!    `rho_c = sum_{j in cell c} w_j L_j`, in the log domain, grouping particles by cell
//!    with a sort and a union-find over the occupied cells (O(N) memory). Eq. 25 puts
//!    particle `i` in the cell holding its state; here `c(i)` is the covered cell with the
//!    largest factor `L(z | x_i)`, and with `merge_adjacent_cells` touching cells form
//!    one group: otherwise every cell a target's energy (or its particle cloud) spreads
//!    into claims up to one target and the count comes out 2-3x too high;
//! 5. `N_hat = round(sum w)` (eq. 26), systematic resampling to
//!    `clamp(per_target N_hat, min, N - J)` particles of weight `sum w / L`, and
//!    extraction of `N_hat` states.

#![allow(clippy::needless_range_loop)]

use super::dbscan::{Dbscan, DbscanParams};
use super::kmeans::KMeans;
use super::pso::{PsoConfig, Swarm};
use crate::detect::{Detection, Detector, ScoreKind, Validate};
use crate::math::{self, KahanSum};
use crate::model::power_cube::{
    AxisWeights, CubeGeometry, PointSpread, PowerCube, RadarCoords, DEG_PER_RAD,
};
use crate::particles::{resample, Scheme};
use crate::rng::Rng;
use crate::{Error, Result};

/// Maximum number of birth components.
pub const MAX_BIRTH_COMPONENTS: usize = 4;
/// Maximum cells a measurement-driven birth component samples from.
pub const MAX_BIRTH_CELLS: usize = 16;

/// One birth component: Gaussian over `[x, vx, y, vy]` with independent axes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct BirthComponent {
    /// Mean `[x, vx, y, vy]`.
    pub mean: [f32; 4],
    /// Standard deviations `[x, vx, y, vy]`.
    pub std: [f32; 4],
}

/// How birth particles are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum BirthMode {
    /// From the Gaussian mixture (equal component weights), as in the paper.
    Gaussian,
    /// Measurement-driven: per component, the `cells` strongest cells of the previous
    /// frame inside the component's `3 sigma` position window (all Doppler cells), ranked
    /// by the point-spread-matched statistic `sum h^2 z`; a birth particle is uniform
    /// inside one of them (range, azimuth, radial velocity) with a tangential velocity
    /// `N(0, tangential_std^2)`, propagated one CV step.
    Measurement {
        /// Strongest cells kept per component (1..=16).
        cells: usize,
        /// Standard deviation of the unobserved tangential velocity (m/s).
        tangential_std: f32,
        /// Two-frame velocity (0 = off): a birth particle's tangential velocity is
        /// instead its displacement from a point drawn in one of the component's cells
        /// of the frame before (k-2) over `T`, if that gives a speed of at most this
        /// (m/s) with the particle's Doppler; up to 4 cells tried, else
        /// `N(0, tangential_std^2)`.
        pair_max_speed: f32,
    },
}

/// Birth density.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct BirthModel {
    /// Components (the first `n_components` are used).
    pub components: [BirthComponent; MAX_BIRTH_COMPONENTS],
    /// Number of components in use.
    pub n_components: usize,
    /// Sampling mode.
    pub mode: BirthMode,
    /// Birth particles per frame `J_k`.
    pub particles: usize,
    /// Expected number of births per frame (total birth PHD mass).
    pub mass: f32,
    /// Birth intensities are `U[lo, hi]`.
    pub intensity: [f32; 2],
}

/// State extractor.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum Extractor {
    /// DBSCAN on positions; the `N_hat` largest clusters' mean states.
    Dbscan(DbscanParams),
    /// K-means with `k = N_hat` on positions; the clusters' mean states.
    KMeans {
        /// Lloyd iterations at most.
        max_iter: usize,
    },
}

/// Runtime configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct PhdConfig {
    /// Cube extent and cell sizes.
    pub geometry: CubeGeometry,
    /// Point spread (eq. 3).
    pub psf: PointSpread,
    /// Per-component noise variance `sigma^2` (the power of noise-only cells is
    /// `2 sigma^2 Exp(1)`).
    pub noise_var: f32,
    /// Frame period `T` (s).
    pub dt: f32,
    /// Motion noise intensity `q1` (CV covariance `q1 [[T^3/3, T^2/2], [T^2/2, T]]`).
    pub q_motion: f32,
    /// Intensity noise `q2` (variance `q2 T` per frame).
    pub q_intensity: f32,
    /// Lower clamp of the predicted intensity.
    pub min_intensity: f32,
    /// Survival probability `Ps`.
    pub p_survival: f32,
    /// Birth density.
    pub birth: BirthModel,
    /// Particles kept per estimated target after resampling.
    pub particles_per_target: usize,
    /// Particles kept when `N_hat` is 0.
    pub min_particles: usize,
    /// Clutter normalisation `lambda_k` of eq. 20. With the likelihood-ratio form of
    /// eq. 21-23 (every cell holds the noise-only return) the principled value is 1.
    pub clutter_lambda: f32,
    /// Normalise over groups of touching cells instead of single cells (see `update`).
    pub merge_adjacent_cells: bool,
    /// PSO step (`None` = plain PHD-TBD).
    pub pso: Option<PsoConfig>,
    /// State extractor.
    pub extractor: Extractor,
}

impl Validate for PhdConfig {
    /// Checks every value (called by [`SmcPhdTbd::new`]).
    fn validate(&self) -> Result<()> {
        self.geometry.validate()?;
        self.psf.validate()?;
        let pos = |v: f32| v.is_finite() && v > 0.0;
        let nonneg = |v: f32| v.is_finite() && v >= 0.0;
        if !pos(self.noise_var) {
            return Err(Error::InvalidConfig("noise_var"));
        }
        if !pos(self.dt) {
            return Err(Error::InvalidConfig("dt"));
        }
        if !nonneg(self.q_motion) || !nonneg(self.q_intensity) || !nonneg(self.min_intensity) {
            return Err(Error::InvalidConfig("process noise / min_intensity"));
        }
        if !(self.p_survival > 0.0 && self.p_survival <= 1.0) {
            return Err(Error::InvalidConfig("p_survival"));
        }
        if !pos(self.clutter_lambda) {
            return Err(Error::InvalidConfig("clutter_lambda"));
        }
        let b = &self.birth;
        if b.n_components == 0 || b.n_components > MAX_BIRTH_COMPONENTS {
            return Err(Error::InvalidConfig("birth.n_components"));
        }
        for c in &b.components[..b.n_components] {
            if c.mean.iter().any(|v| !v.is_finite()) || c.std.iter().any(|&v| !nonneg(v)) {
                return Err(Error::InvalidConfig("birth component"));
            }
        }
        if let BirthMode::Measurement {
            cells,
            tangential_std,
            pair_max_speed,
        } = b.mode
        {
            if cells == 0
                || cells > MAX_BIRTH_CELLS
                || !nonneg(tangential_std)
                || !nonneg(pair_max_speed)
            {
                return Err(Error::InvalidConfig("birth measurement mode"));
            }
        }
        if b.particles == 0 || !pos(b.mass) {
            return Err(Error::InvalidConfig("birth particles / mass"));
        }
        if !(nonneg(b.intensity[0])
            && b.intensity[1].is_finite()
            && b.intensity[1] >= b.intensity[0])
        {
            return Err(Error::InvalidConfig("birth intensity"));
        }
        if self.particles_per_target == 0 || self.min_particles == 0 {
            return Err(Error::InvalidConfig("particles_per_target / min_particles"));
        }
        if let Some(p) = &self.pso {
            if p.points == 0
                || p.max_members == 0
                || !pos(p.fitness_scale)
                || !nonneg(p.mutation)
                || ![p.inertia, p.c1, p.c2, p.step, p.threshold, p.gate]
                    .iter()
                    .all(|v| v.is_finite())
            {
                return Err(Error::InvalidConfig("pso"));
            }
        }
        match &self.extractor {
            Extractor::Dbscan(p) => p.validate()?,
            Extractor::KMeans { max_iter } => {
                if *max_iter == 0 {
                    return Err(Error::InvalidConfig("kmeans max_iter"));
                }
            }
        }
        Ok(())
    }
}

/// One extracted target state.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Estimate {
    /// Mean state `[x, vx, y, vy, I]` of the cluster.
    pub state: [f32; 5],
    /// Particles in the cluster.
    pub support: u32,
}

/// Per-frame summary.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PhdReport {
    /// `N_hat = round(sum w)`, capped at the capacity `K`.
    pub n_hat: usize,
    /// Posterior PHD mass `sum w`.
    pub mass: f32,
    /// Number of extracted states (can be below `n_hat` if DBSCAN finds fewer clusters).
    pub estimates: usize,
    /// Particles after resampling.
    pub particles: usize,
    /// Particles that took part in the swarm step.
    pub swarm: usize,
    /// Swarm generations run.
    pub pso_generations: usize,
    /// `round(sum w)` exceeded `K` and was capped (documented recovery).
    pub truncated: bool,
    /// Every weight underflowed to zero: the PHD is emptied and refilled by the next
    /// frame's births (documented recovery).
    pub degenerate: bool,
}

/// The SMC-PHD TBD filter with capacities: `N` particles (survivors plus births), `S`
/// swarm entries (parents plus children, so up to `S / 2` particles move), `M`
/// measurement points (PSO objectives), `K` extracted targets.
///
/// Memory: about `123 N + (56 + 4 M) S` bytes (32-bit target; e.g. 864 KB at
/// `N = S = 4096, M = 8`): build large instances in a `Box`, or zeroed in a `static` and
/// set up by [`SmcPhdTbd::reconfigure`].
#[derive(Debug, Clone)]
pub struct SmcPhdTbd<const N: usize, const S: usize, const M: usize, const K: usize> {
    cfg: PhdConfig,
    x: [[f32; 5]; N],
    w: [f32; N],
    n: usize,
    scratch: [[f32; 5]; N],
    lw: [f32; N],
    key: [u32; N],
    order: [u32; N],
    anc: [u32; N],
    run_key: [u32; N],
    parent: [u32; N],
    pts: [[f32; 2]; N],
    swarm: Swarm<S, M>,
    dbscan: Dbscan<N>,
    kmeans: KMeans<N, K>,
    est: [Estimate; K],
    n_est: usize,
    zpts: [[f32; 2]; M],
    n_z: usize,
    rng: Rng,
    /// Measurement-driven birth cells chosen on the previous frame, per component.
    birth_cells: [[(usize, f32); MAX_BIRTH_CELLS]; MAX_BIRTH_COMPONENTS],
    birth_nb: [usize; MAX_BIRTH_COMPONENTS],
    /// The same, chosen the frame before (for two-frame birth velocities).
    birth_prev: [[(usize, f32); MAX_BIRTH_CELLS]; MAX_BIRTH_COMPONENTS],
    birth_prev_nb: [usize; MAX_BIRTH_COMPONENTS],
}

/// The 13 "forward" neighbours of a cell (the other 13 are found from the other side).
const NEIGHBOURS: [(i64, i64, i64); 13] = [
    (0, 0, 1),
    (0, 1, -1),
    (0, 1, 0),
    (0, 1, 1),
    (1, -1, -1),
    (1, -1, 0),
    (1, -1, 1),
    (1, 0, -1),
    (1, 0, 0),
    (1, 0, 1),
    (1, 1, -1),
    (1, 1, 0),
    (1, 1, 1),
];

/// Union-find root with path halving.
fn find(parent: &mut [u32], mut r: usize) -> usize {
    while parent[r] as usize != r {
        let gp = parent[parent[r] as usize];
        parent[r] = gp;
        r = gp as usize;
    }
    r
}

impl<const N: usize, const S: usize, const M: usize, const K: usize> SmcPhdTbd<N, S, M, K> {
    /// A filter with an empty PHD (the first frame's births populate it).
    /// Errors: invalid config, `J >= N`, more PSO points than `M`, `K == 0`.
    pub fn new(cfg: PhdConfig, seed: u64) -> Result<Self> {
        Self::check(&cfg)?;
        Ok(Self {
            cfg,
            x: [[0.0; 5]; N],
            w: [0.0; N],
            n: 0,
            scratch: [[0.0; 5]; N],
            lw: [0.0; N],
            key: [0; N],
            order: [0; N],
            anc: [0; N],
            run_key: [0; N],
            parent: [0; N],
            pts: [[0.0; 2]; N],
            swarm: Swarm::new(),
            dbscan: Dbscan::new(),
            kmeans: KMeans::new(),
            est: [Estimate::default(); K],
            n_est: 0,
            zpts: [[0.0; 2]; M],
            n_z: 0,
            rng: Rng::seed_from_u64(seed),
            birth_cells: [[(0, 0.0); MAX_BIRTH_CELLS]; MAX_BIRTH_COMPONENTS],
            birth_nb: [0; MAX_BIRTH_COMPONENTS],
            birth_prev: [[(0, 0.0); MAX_BIRTH_CELLS]; MAX_BIRTH_COMPONENTS],
            birth_prev_nb: [0; MAX_BIRTH_COMPONENTS],
        })
    }

    fn check(cfg: &PhdConfig) -> Result<()> {
        cfg.validate()?;
        if K == 0 || N < 2 || N > u32::MAX as usize {
            return Err(Error::InvalidConfig("capacities"));
        }
        if cfg.birth.particles >= N {
            return Err(Error::Capacity {
                capacity: N - 1,
                requested: cfg.birth.particles,
            });
        }
        if let Some(p) = &cfg.pso {
            if p.points > M {
                return Err(Error::Capacity {
                    capacity: M,
                    requested: p.points,
                });
            }
        }
        Ok(())
    }

    /// Extracted states of the last frame.
    pub fn estimates(&self) -> &[Estimate] {
        &self.est[..self.n_est]
    }

    /// Current particles `[x, vx, y, vy, I]` and their weights.
    pub fn particles(&self) -> (&[[f32; 5]], &[f32]) {
        (&self.x[..self.n], &self.w[..self.n])
    }

    /// Measurement-derived points of the last PSO step.
    pub fn measurement_points(&self) -> &[[f32; 2]] {
        &self.zpts[..self.n_z]
    }

    /// One power cube (the [`Detector::step`]; `geometry.len()` cells, layout of
    /// [`crate::model::power_cube`]). Bad cubes (wrong length, NaN/inf, negative power)
    /// are rejected before any state changes.
    ///
    /// PSO variant, measurement-derived points `Z_m`: the cells holding the predicted
    /// *surviving* particles are ranked by the point-spread-matched power
    /// `sum_{covered cells} h^2 z` of a target at the cell centre (the TBD statistic;
    /// a single cell's power at 9 dB is matched by the strongest noise cell among the
    /// few hundred cells a predicted cloud covers, and the swarm then pulled whole
    /// clouds onto noise) and the strongest `points` of them,
    /// thinned so that no two lie within one range and one azimuth cell of each other,
    /// are mapped to the position of the local maximum of the frame's log likelihood
    /// ratio inside their cell (`PsoConfig::refine_points`; the cell centre is 8 m RMS
    /// off a target, more than the filter's own error, and a 10-generation swarm pulled
    /// the clouds onto that error). Restricting the
    /// candidates to the predicted PHD support keeps single-frame noise peaks elsewhere
    /// in the cube (at 9 dB the cube maximum is noise) from attracting the swarm.
    /// Particles whose best eq.-18 fitness is at least `gate` form the swarm (position
    /// only; velocity and intensity ride along; moving the velocity by the position
    /// change over `T` as well was measured to lose most tracks), grouped by nearest
    /// point: the elitist selection keeps each group's particle count and the PHD mass
    /// is preserved per group.
    fn step_cube(&mut self, cube: &[f32]) -> Result<PhdReport> {
        let cube = PowerCube::new(cube, self.cfg.geometry)?;
        let mut report = PhdReport::default();
        self.predict();
        let n_surv = self.n;
        self.add_births();
        if let Some(pso) = self.cfg.pso {
            self.select_points(&cube, n_surv, pso.points);
            let (sw, gens) = self.swarm_step(&pso);
            report.swarm = sw;
            report.pso_generations = gens;
        }
        let mass = self.update(&cube);
        report.mass = mass;
        let nh = if mass.is_finite() && mass > 0.0 {
            math::round(mass) as usize
        } else {
            0
        };
        report.truncated = nh > K;
        report.n_hat = nh.min(K);
        if !(mass.is_finite() && mass > 0.0 && self.resample(report.n_hat, mass)) {
            report.degenerate = true;
            report.mass = 0.0;
            report.n_hat = 0;
            self.n = 0;
        }
        report.particles = self.n;
        self.extract(report.n_hat)?;
        self.choose_birth_cells(&cube);
        report.estimates = self.n_est;
        Ok(report)
    }

    fn predict(&mut self) {
        let c = &self.cfg;
        let t = c.dt;
        let q = c.q_motion;
        let a = math::sqrt(q * t * t * t / 3.0);
        let b = if a > 0.0 { q * t * t / 2.0 / a } else { 0.0 };
        let cc = math::sqrt((q * t - b * b).max(0.0));
        let si = math::sqrt(c.q_intensity * t);
        for i in 0..self.n {
            let s = &mut self.x[i];
            for k in [0usize, 2] {
                let n1 = self.rng.normal();
                let n2 = self.rng.normal();
                s[k] += t * s[k + 1] + a * n1;
                s[k + 1] += b * n1 + cc * n2;
            }
            s[4] = (s[4] + si * self.rng.normal()).max(c.min_intensity);
            self.w[i] *= c.p_survival;
        }
    }

    fn add_births(&mut self) {
        let b = self.cfg.birth;
        let g = self.cfg.geometry;
        let j = b.particles.min(N - self.n);
        if j == 0 {
            return;
        }
        let wb = b.mass / j as f32;
        let nc = b.n_components;
        let mut k = self.n;
        for ci in 0..nc {
            let comp = b.components[ci];
            let count = j / nc + usize::from(ci < j % nc);
            // Measurement-driven: strongest cells of the component's window on the
            // *previous* frame, propagated one step (`choose_birth_cells`).
            let cells = self.birth_cells[ci];
            let nb = self.birth_nb[ci];
            let (tang, vmax) = match b.mode {
                BirthMode::Measurement {
                    tangential_std,
                    pair_max_speed,
                    ..
                } => (tangential_std, pair_max_speed),
                BirthMode::Gaussian => (0.0, 0.0),
            };
            let prev = self.birth_prev[ci];
            let np = if vmax > 0.0 {
                self.birth_prev_nb[ci]
            } else {
                0
            };
            for _ in 0..count {
                let s = if nb > 0 {
                    let (idx, _) = cells[self.rng.below(nb as u32) as usize];
                    let (ir, jd, lb) = g.unindex(idx);
                    let r = g.range_start + (ir as f32 + self.rng.uniform()) * g.range_cell;
                    let d = g.doppler_start + (jd as f32 + self.rng.uniform()) * g.doppler_cell;
                    let az = (g.azimuth_start_deg
                        + (lb as f32 + self.rng.uniform()) * g.azimuth_cell_deg)
                        / DEG_PER_RAD;
                    let (sb, cb) = (math::sin(az), math::cos(az));
                    let mut vt = tang * self.rng.normal();
                    for _ in 0..np.min(4) {
                        let (pidx, _) = prev[self.rng.below(np as u32) as usize];
                        let (pr, _, pl) = g.unindex(pidx);
                        let r2 = g.range_start + (pr as f32 + self.rng.uniform()) * g.range_cell;
                        let a2 = (g.azimuth_start_deg
                            + (pl as f32 + self.rng.uniform()) * g.azimuth_cell_deg)
                            / DEG_PER_RAD;
                        let (dx, dy) = (r * cb - r2 * math::cos(a2), r * sb - r2 * math::sin(a2));
                        // Tangential part of the displacement (the radial velocity comes
                        // from the Doppler cell).
                        let v2 = (-dx * sb + dy * cb) / self.cfg.dt;
                        if d * d + v2 * v2 <= vmax * vmax {
                            vt = v2;
                            break;
                        }
                    }
                    let (vx, vy) = (d * cb - vt * sb, d * sb + vt * cb);
                    let t = self.cfg.dt;
                    [r * cb + t * vx, vx, r * sb + t * vy, vy]
                } else {
                    let mut s = [0.0f32; 4];
                    for (d, v) in s.iter_mut().enumerate() {
                        *v = comp.mean[d] + comp.std[d] * self.rng.normal();
                    }
                    s
                };
                let inten = self.rng.uniform_range(b.intensity[0], b.intensity[1]);
                self.x[k] = [s[0], s[1], s[2], s[3], inten.max(self.cfg.min_intensity)];
                self.w[k] = wb;
                k += 1;
            }
        }
        self.n = k;
    }

    /// Top cells by power inside the `3 sigma` position window of `comp`.
    /// Measurement-driven birth: picks each component's strongest cells on this frame
    /// for the births of the *next* frame. Births placed on a frame's strongest cells and
    /// updated with the same frame use the data twice: their likelihood ratio is biased
    /// up by the selection (the strongest noise cells of a ~4500-cell window look like a
    /// target), and noise births were confirmed as persistent false tracks at the birth
    /// windows. Drawing from the previous frame (Ristic, Clark, Vo, Vo 2012, adaptive
    /// target birth) keeps the update's data independent of where births were placed.
    fn choose_birth_cells(&mut self, cube: &PowerCube<'_>) {
        let b = self.cfg.birth;
        let g = self.cfg.geometry;
        self.birth_prev = self.birth_cells;
        self.birth_prev_nb = self.birth_nb;
        for ci in 0..b.n_components.min(MAX_BIRTH_COMPONENTS) {
            self.birth_nb[ci] = match b.mode {
                BirthMode::Measurement { cells: want, .. } => Self::strongest_in_window(
                    cube,
                    &g,
                    &self.cfg.psf,
                    &b.components[ci],
                    &mut self.birth_cells[ci][..want.min(MAX_BIRTH_CELLS)],
                ),
                BirthMode::Gaussian => 0,
            };
        }
    }

    fn strongest_in_window(
        cube: &PowerCube<'_>,
        g: &CubeGeometry,
        psf: &PointSpread,
        comp: &BirthComponent,
        out: &mut [(usize, f32)],
    ) -> usize {
        let c = RadarCoords::from_state(comp.mean[0], 0.0, comp.mean[2], 0.0);
        let dr = 3.0 * comp.std[0].max(comp.std[2]);
        let db = if c.range > 1.0 {
            dr / c.range * DEG_PER_RAD
        } else {
            180.0
        };
        let lo = |v: f32, start: f32, size: f32| math::floor((v - start) / size).max(0.0) as usize;
        let hi = |v: f32, start: f32, size: f32, n: usize| {
            let h = math::floor((v - start) / size);
            if h < 0.0 {
                0
            } else {
                (h as usize + 1).min(n)
            }
        };
        let r0 = lo(c.range - dr, g.range_start, g.range_cell);
        let r1 = hi(c.range + dr, g.range_start, g.range_cell, g.n_range);
        let b0 = lo(c.azimuth_deg - db, g.azimuth_start_deg, g.azimuth_cell_deg);
        let b1 = hi(
            c.azimuth_deg + db,
            g.azimuth_start_deg,
            g.azimuth_cell_deg,
            g.n_azimuth,
        );
        let data = cube.data();
        let mut n = 0usize;
        // The spread of a target at a cell centre, one axis at a time (each axis depends
        // on one cell index only, so it is computed once per grid line, not per cell;
        // bit-identical to `for_each_cell` at the centre). Azimuth weights are cached
        // for windows up to `AZ_CACHE` cells wide.
        const AZ_CACHE: usize = 16;
        let frac = |ir: usize, jd: usize, lb: usize| {
            g.fractional(&RadarCoords {
                range: g.range_centre(ir),
                doppler: g.doppler_centre(jd),
                azimuth_deg: g.azimuth_centre(lb),
            })
        };
        let mut az = [AxisWeights::NONE; AZ_CACHE];
        let cached = b1.saturating_sub(b0) <= AZ_CACHE;
        if cached {
            for lb in b0..b1 {
                az[lb - b0] = psf.axis_weights(frac(0, 0, lb).2, g.n_azimuth, psf.loss_azimuth);
            }
        }
        for ir in r0..r1 {
            let wr = psf.axis_weights(frac(ir, 0, 0).0, g.n_range, psf.loss_range);
            for jd in 0..g.n_doppler {
                let wd = psf.axis_weights(frac(0, jd, 0).1, g.n_doppler, psf.loss_doppler);
                for lb in b0..b1 {
                    let idx = g.index(ir, jd, lb);
                    // Point-spread-matched statistic `sum h^2 z` of a target at the cell
                    // centre, as for the swarm's points.
                    let wb = match az.get(lb - b0) {
                        Some(w) if cached => *w,
                        _ => psf.axis_weights(frac(0, 0, lb).2, g.n_azimuth, psf.loss_azimuth),
                    };
                    let mut z = 0.0f32;
                    psf.for_each_cell_of(g, &wr, &wd, &wb, |i, h| {
                        if let Some(&v) = data.get(i) {
                            z += h * h * v;
                        }
                    });
                    if n < out.len() {
                        out[n] = (idx, z);
                        n += 1;
                    } else if let Some(min) = out
                        .iter_mut()
                        .min_by(|a, b| a.1.partial_cmp(&b.1).unwrap_or(core::cmp::Ordering::Equal))
                    {
                        if z > min.1 {
                            *min = (idx, z);
                        }
                    }
                }
            }
        }
        n
    }

    fn select_points(&mut self, cube: &PowerCube<'_>, n_surv: usize, want: usize) {
        let g = *cube.geometry();
        let data = cube.data();
        let want = want.min(M);
        let psf = self.cfg.psf;
        // (z, ir, lb, jd) sorted descending by z.
        let mut top = [(0.0f32, 0usize, 0usize, 0usize); M];
        let mut amp = [0.0f32; M];
        let mut nt = 0usize;
        let mut last_cell = usize::MAX;
        for i in 0..n_surv {
            let s = self.x[i];
            let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
            let Some((ir, jd, lb)) = g.cell_of(&c) else {
                continue;
            };
            let cell = g.index(ir, jd, lb);
            if cell == last_cell {
                continue;
            }
            last_cell = cell;
            // Point-spread-matched statistic `sum h^2 z` over the cells a target at the
            // cell centre would cover (the small-signal form of the log likelihood
            // ratio, `ln I0(x) ~ x^2 / 4`), not the single cell's power.
            let centre = RadarCoords {
                range: g.range_centre(ir),
                doppler: g.doppler_centre(jd),
                azimuth_deg: g.azimuth_centre(lb),
            };
            let mut z = 0.0f32;
            psf.for_each_cell(&g, &centre, |idx, h| {
                if let Some(&v) = data.get(idx) {
                    z += h * h * v;
                }
            });
            if nt == want && z <= top[nt - 1].0 {
                continue;
            }
            // Thinning in range, azimuth *and* Doppler: targets born at the same place
            // (Table 1: three at (250, 1500), three at (1750, 500)) share range/azimuth
            // cells for several frames but not Doppler cells; thinning on position alone
            // left one point for two targets and the swarm merged their clouds.
            let near = |e: &(f32, usize, usize, usize)| {
                e.1.abs_diff(ir) <= 1 && e.2.abs_diff(lb) <= 1 && e.3.abs_diff(jd) <= 1
            };
            if top[..nt].iter().any(|e| near(e) && e.0 >= z) {
                continue;
            }
            // Drop weaker neighbours, then insert.
            let mut k = 0;
            for t in 0..nt {
                if !near(&top[t]) {
                    top[k] = top[t];
                    amp[k] = amp[t];
                    k += 1;
                }
            }
            nt = k;
            let mut p = nt.min(want - 1);
            if nt < want {
                nt += 1;
            }
            while p > 0 && top[p - 1].0 < z {
                top[p] = top[p - 1];
                amp[p] = amp[p - 1];
                p -= 1;
            }
            top[p] = (z, ir, lb, jd);
            amp[p] = math::sqrt(s[4].max(0.0));
        }
        let refine = self.cfg.pso.is_some_and(|p| p.refine_points);
        for (k, e) in top[..nt].iter().enumerate() {
            let (x, y) = if refine {
                self.refine_point(cube, e.1, e.3, e.2, amp[k])
            } else {
                g.cell_position(e.1, e.2)
            };
            self.zpts[k] = [x, y];
        }
        self.n_z = nt;
    }

    /// Sub-cell `Z_m`: the (range, Doppler, azimuth) maximising the frame's log
    /// likelihood ratio `sum ln L(z | x)` (eq. 20-23) of a target with amplitude `amp`
    /// within cell `(ir, jd, lb)`: a 5 x 3 x 5 grid of quarter-cell steps, then a
    /// 3 x 3 x 3 grid of eighth-cell steps around its best. Returns `(x, y)`.
    fn refine_point(
        &self,
        cube: &PowerCube<'_>,
        ir: usize,
        jd: usize,
        lb: usize,
        amp: f32,
    ) -> (f32, f32) {
        let g = *cube.geometry();
        let psf = self.cfg.psf;
        let s2 = self.cfg.noise_var;
        let mut best = (
            f32::NEG_INFINITY,
            g.range_centre(ir),
            g.doppler_centre(jd),
            g.azimuth_centre(lb),
        );
        for (half, step) in [(2i32, 0.25f32), (1, 0.125)] {
            let (r0, d0, b0) = (best.1, best.2, best.3);
            for a in -half..=half {
                for c in -half..=half {
                    for d in -1i32..=1 {
                        let rc = RadarCoords {
                            range: r0 + a as f32 * step * g.range_cell,
                            doppler: d0 + d as f32 * step * g.doppler_cell,
                            azimuth_deg: b0 + c as f32 * step * g.azimuth_cell_deg,
                        };
                        let l = cube.log_lr(&psf, &rc, amp, s2);
                        if l > best.0 {
                            best = (l, rc.range, rc.doppler, rc.azimuth_deg);
                        }
                    }
                }
            }
        }
        let b = best.3 / DEG_PER_RAD;
        (best.1 * math::cos(b), best.1 * math::sin(b))
    }

    /// The swarm over at most `pso.max_members` of the gated particles.
    fn swarm_step(&mut self, pso: &PsoConfig) -> (usize, usize) {
        let m = self.n_z;
        if m == 0 {
            return (0, 0);
        }
        let inv = 1.0 / (2.0 * pso.fitness_scale * pso.fitness_scale);
        let nearest = |p: [f32; 2], z: &[[f32; 2]]| {
            let mut best = (0usize, f32::INFINITY);
            for (k, q) in z.iter().enumerate() {
                let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
                let d = dx * dx + dy * dy;
                if d < best.1 {
                    best = (k, d);
                }
            }
            best
        };
        self.swarm.clear();
        // The gated particles (index in `order`, nearest point in `key`).
        let mut gated = 0usize;
        for i in 0..self.n {
            let p = [self.x[i][0], self.x[i][2]];
            let (k, d) = nearest(p, &self.zpts[..m]);
            if math::exp(-d * inv) >= pso.gate {
                self.order[gated] = i as u32;
                self.key[gated] = k as u32;
                gated += 1;
            }
        }
        // At most `max_members` of them (and the swarm's capacity), evenly spaced:
        // member `j` is gated particle `floor(j gated / take)`.
        let take = gated.min(pso.max_members).min(Swarm::<S, M>::capacity());
        let mut before = [0.0f32; M];
        let mut n_s = 0usize;
        for j in 0..take {
            let g = (j as u64 * gated as u64 / take as u64) as usize;
            let (i, k) = (self.order[g] as usize, self.key[g] as usize);
            let p = [self.x[i][0], self.x[i][2]];
            if !self.swarm.push(p, self.w[i], i as u32, k as u16) {
                break;
            }
            // `g >= j`: slot `j` of `order` is free once read.
            self.order[n_s] = i as u32;
            before[k] += self.w[i];
            n_s += 1;
        }
        if n_s == 0 {
            return (0, 0);
        }
        let rep = self.swarm.run(pso, &self.zpts[..m], &mut self.rng);
        let mut after = [0.0f32; M];
        for k in 0..n_s {
            let (g, _) = nearest(self.swarm.pos[k], &self.zpts[..m]);
            after[g] += self.swarm.weight[k];
        }

        let mut scale = [1.0f32; M];
        for g in 0..m {
            if after[g] > 0.0 {
                scale[g] = before[g] / after[g];
            }
        }
        for k in 0..n_s {
            let src = self.swarm.src[k] as usize;
            let mut s = self.x[src];
            s[0] = self.swarm.pos[k][0];
            s[2] = self.swarm.pos[k][1];
            self.scratch[k] = s;
            let (g, _) = nearest(self.swarm.pos[k], &self.zpts[..m]);
            self.lw[k] = self.swarm.weight[k] * scale[g];
        }
        for k in 0..n_s {
            let slot = self.order[k] as usize;
            self.x[slot] = self.scratch[k];
            self.w[slot] = self.lw[k];
        }
        (n_s, rep.generations)
    }

    /// Weight update of eq. 20/24-25; returns `sum w`.
    fn update(&mut self, cube: &PowerCube<'_>) -> f32 {
        let g = *cube.geometry();
        let psf = self.cfg.psf;
        let s2 = self.cfg.noise_var;
        let n = self.n;
        for i in 0..n {
            let s = self.x[i];
            let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
            let (ll, cell) = if self.w[i] > 0.0 && g.cell_of(&c).is_some() {
                cube.log_lr_argmax(&psf, &c, math::sqrt(s[4].max(0.0)), s2)
            } else {
                (0.0, usize::MAX)
            };
            if cell == usize::MAX {
                // Outside the surveillance cube (or zero weight): the particle dies.
                self.key[i] = u32::MAX;
                self.lw[i] = f32::NEG_INFINITY;
            } else {
                // Resolution cell of eq. 25: the covered cell with the largest factor.
                self.key[i] = cell as u32;
                let l = math::ln(self.w[i]) + ll;
                self.lw[i] = if l.is_nan() || l == f32::INFINITY {
                    f32::NEG_INFINITY
                } else {
                    l
                };
            }
            self.order[i] = i as u32;
        }
        {
            let key = &self.key;
            self.order[..n].sort_unstable_by_key(|&i| (key[i as usize], i));
        }
        let ln_lambda = math::ln(self.cfg.clutter_lambda);
        // Runs of equal cell; `run_of[i]` for every particle (u32::MAX outside).
        let mut nr = 0usize;
        let mut s = 0usize;
        while s < n {
            let k = self.key[self.order[s] as usize];
            let mut e = s;
            while e < n && self.key[self.order[e] as usize] == k {
                self.anc[self.order[e] as usize] = if k == u32::MAX { u32::MAX } else { nr as u32 };
                e += 1;
            }
            if k != u32::MAX {
                self.run_key[nr] = k;
                self.parent[nr] = nr as u32;
                nr += 1;
            }
            s = e;
        }
        // Merge runs whose cells touch (|d| <= 1 on every axis): one target's energy
        // spreads over neighbouring cells, and particles attributed to either are one
        // "resolution cell" for the normalisation of eq. 20 (else every neighbour cell
        // claims up to one target).
        if self.cfg.merge_adjacent_cells {
            for r in 0..nr {
                let (ir, jd, lb) = g.unindex(self.run_key[r] as usize);
                for (a, b, c) in NEIGHBOURS {
                    let (x, y, z) = (ir as i64 + a, jd as i64 + b, lb as i64 + c);
                    if x < 0
                        || y < 0
                        || z < 0
                        || x >= g.n_range as i64
                        || y >= g.n_doppler as i64
                        || z >= g.n_azimuth as i64
                    {
                        continue;
                    }
                    let idx = g.index(x as usize, y as usize, z as usize) as u32;
                    if let Ok(q) = self.run_key[..nr].binary_search(&idx) {
                        let (ra, rb) = (find(&mut self.parent, r), find(&mut self.parent, q));
                        if ra != rb {
                            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
                            self.parent[hi] = lo as u32;
                        }
                    }
                }
            }
        }
        // Per group: max log weight, then sum, then denominator (in `pts[root]`).
        for r in 0..nr {
            self.pts[r] = [f32::NEG_INFINITY, 0.0];
        }
        for i in 0..n {
            let r = self.anc[i];
            if r != u32::MAX {
                let root = find(&mut self.parent, r as usize);
                self.anc[i] = root as u32;
                self.pts[root][0] = self.pts[root][0].max(self.lw[i]);
            }
        }
        for i in 0..n {
            let r = self.anc[i];
            if r != u32::MAX && self.pts[r as usize][0] > f32::NEG_INFINITY {
                self.pts[r as usize][1] += math::exp(self.lw[i] - self.pts[r as usize][0]);
            }
        }
        for r in 0..nr {
            if self.parent[r] as usize == r && self.pts[r][0] > f32::NEG_INFINITY {
                let log_rho = self.pts[r][0] + math::ln(self.pts[r][1]);
                self.pts[r][1] = math::log_add_exp(ln_lambda, log_rho);
            }
        }
        let mut total = KahanSum::new();
        for i in 0..n {
            let r = self.anc[i];
            let wi = if r == u32::MAX || self.lw[i] == f32::NEG_INFINITY {
                0.0
            } else {
                math::exp(self.lw[i] - self.pts[r as usize][1])
            };
            self.w[i] = wi;
            total.add(wi);
        }
        total.value()
    }

    fn resample(&mut self, n_hat: usize, mass: f32) -> bool {
        let cap = N - self.cfg.birth.particles;
        let l = self
            .cfg
            .particles_per_target
            .saturating_mul(n_hat)
            .max(self.cfg.min_particles)
            .min(cap);
        if l == 0 || self.n == 0 {
            return false;
        }
        if resample(
            Scheme::Systematic,
            &self.w[..self.n],
            &mut self.anc[..l],
            &mut self.rng,
        )
        .is_err()
        {
            return false;
        }
        for j in 0..l {
            self.scratch[j] = self.x[self.anc[j] as usize];
        }
        self.x[..l].copy_from_slice(&self.scratch[..l]);
        let wl = mass / l as f32;
        for w in self.w[..l].iter_mut() {
            *w = wl;
        }
        self.n = l;
        true
    }

    fn extract(&mut self, n_hat: usize) -> Result<()> {
        self.n_est = 0;
        let n = self.n;
        if n_hat == 0 || n == 0 {
            return Ok(());
        }
        for i in 0..n {
            self.pts[i] = [self.x[i][0], self.x[i][2]];
        }
        match self.cfg.extractor {
            Extractor::Dbscan(p) => {
                let x = &self.x;
                let est = &mut self.est;
                let n_est = &mut self.n_est;
                let want = n_hat.min(K);
                self.dbscan.run(&self.pts[..n], &p, |members| {
                    let size = members.len() as u32;
                    if *n_est == want && est[want - 1].support >= size {
                        return;
                    }
                    let mut acc = [0.0f32; 5];
                    for &m in members {
                        for (a, v) in acc.iter_mut().zip(&x[m as usize]) {
                            *a += v;
                        }
                    }
                    let inv = 1.0 / size as f32;
                    let e = Estimate {
                        state: acc.map(|a| a * inv),
                        support: size,
                    };
                    let mut pos = (*n_est).min(want - 1);
                    if *n_est < want {
                        *n_est += 1;
                    }
                    while pos > 0 && est[pos - 1].support < size {
                        est[pos] = est[pos - 1];
                        pos -= 1;
                    }
                    est[pos] = e;
                })?;
            }
            Extractor::KMeans { max_iter } => {
                let k = self
                    .kmeans
                    .run(&self.pts[..n], n_hat, max_iter, &mut self.rng)?;
                let mut acc = [[0.0f32; 5]; K];
                for i in 0..n {
                    let c = self.kmeans.assign[i] as usize;
                    if c < k {
                        for (a, v) in acc[c].iter_mut().zip(&self.x[i]) {
                            *a += v;
                        }
                    }
                }
                for c in 0..k {
                    let cnt = self.kmeans.counts[c];
                    if cnt > 0 {
                        let inv = 1.0 / cnt as f32;
                        self.est[self.n_est] = Estimate {
                            state: acc[c].map(|a| a * inv),
                            support: cnt,
                        };
                        self.n_est += 1;
                    }
                }
            }
        }
        Ok(())
    }
}

impl<const N: usize, const S: usize, const M: usize, const K: usize> Detector
    for SmcPhdTbd<N, S, M, K>
{
    type Frame = [f32];
    type Config = PhdConfig;
    type Report = PhdReport;
    const STATE: &'static [&'static str] = &["x_m", "vx_m_per_s", "y_m", "vy_m_per_s", "intensity"];
    const SCORE: ScoreKind = ScoreKind::Mass;

    /// Re-validates `cfg` and restarts in place from `seed`, behaving exactly as
    /// [`SmcPhdTbd::new`]`(cfg, seed)` would, without building the (large) filter by
    /// value: how one that lives in a `static` is set up, including from the all-zero
    /// value (e.g. the firmware's `.bss` detectors). On error `self` is unchanged.
    fn configure(&mut self, cfg: &PhdConfig, seed: u64) -> Result<()> {
        Self::check(cfg)?;
        self.cfg = *cfg;
        self.reset(seed);
        Ok(())
    }

    fn config(&self) -> &PhdConfig {
        &self.cfg
    }

    /// Empties the PHD and reseeds (same configuration).
    fn reset(&mut self, seed: u64) {
        self.n = 0;
        self.n_est = 0;
        self.n_z = 0;
        self.rng = Rng::seed_from_u64(seed);
        self.birth_nb = [0; MAX_BIRTH_COMPONENTS];
        self.birth_prev_nb = [0; MAX_BIRTH_COMPONENTS];
    }

    fn step(&mut self, cube: &[f32]) -> Result<PhdReport> {
        self.step_cube(cube)
    }

    fn detection_count(&self) -> usize {
        self.n_est
    }

    /// Extracted state `i` (largest cluster first), scored by its PHD mass: the
    /// resampled particles carry equal weights `w = mass / n`, so a cluster of `support`
    /// particles holds `support * w`.
    fn detection(&self, i: usize) -> Option<Detection> {
        let e = self.estimates().get(i)?;
        let w = self
            .w
            .get(..self.n)
            .and_then(|w| w.first())
            .copied()
            .unwrap_or(0.0);
        Some(Detection::new(&e.state, e.support as f32 * w, None))
    }
}
