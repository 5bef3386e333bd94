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

mod birth;
mod swarm;
mod update;

pub use birth::{
    BirthComponent, BirthMode, BirthModel, MAX_BIRTH_CELLS, MAX_BIRTH_COMPONENTS, MAX_REGION_CELLS,
};

use super::dbscan::{Dbscan, DbscanParams};
use super::kmeans::KMeans;
use super::pso::{PsoConfig, Swarm};
use crate::detect::interface::unconfigured_is_zero;
use crate::detect::{Detection, Detector, ScoreKind, Validate};
use crate::math::{self, KahanSum};
use crate::model::power_cube::{CubeGeometry, PointSpread, PowerCube, RadarCoords, DEG_PER_RAD};
use crate::particles::{resample, Scheme};
use crate::rng::Rng;
use crate::{Error, Result};

/// Largest particle intensity (target power, in units of the cell power): a cluster's
/// mean state sums the intensities of up to `N <= u32::MAX` particles, and
/// `4.3e9 * 1e28 < f32::MAX`. The birth intensities and `min_intensity` must not exceed it,
/// and the prediction clamps to it (1e28 is an SNR of 280 dB, beyond any receiver).
pub const MAX_INTENSITY: f32 = 1e28;

/// Largest swarm mutation half-width [`PsoConfig::mutation`] (m): the draw
/// `U[-m, m] = -m + 2 m u` needs `2 m` finite.
pub const MAX_MUTATION: f32 = f32::MAX / 4.0;

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
    /// Lower clamp of the predicted intensity, in `[0, MAX_INTENSITY]` (the upper clamp
    /// is [`MAX_INTENSITY`]).
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
        if !nonneg(self.q_motion) || !nonneg(self.q_intensity) {
            return Err(Error::InvalidConfig("process noise"));
        }
        if !(self.min_intensity >= 0.0 && self.min_intensity <= MAX_INTENSITY) {
            return Err(Error::InvalidConfig("min_intensity (0..=1e28)"));
        }
        if !(self.p_survival > 0.0 && self.p_survival <= 1.0) {
            return Err(Error::InvalidConfig("p_survival"));
        }
        if !pos(self.clutter_lambda) {
            return Err(Error::InvalidConfig("clutter_lambda"));
        }
        let b = &self.birth;
        let region = matches!(b.mode, BirthMode::Region { .. });
        if (b.n_components == 0 && !region) || b.n_components > MAX_BIRTH_COMPONENTS {
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
        if let BirthMode::Region {
            cells,
            tangential_std,
        } = b.mode
        {
            if cells == 0 || cells > MAX_REGION_CELLS || !nonneg(tangential_std) {
                return Err(Error::InvalidConfig("birth region mode (cells 1..=64)"));
            }
        }
        if b.particles == 0 || !pos(b.mass) {
            return Err(Error::InvalidConfig("birth particles / mass"));
        }
        if !(nonneg(b.intensity[0])
            && b.intensity[1] <= MAX_INTENSITY
            && b.intensity[1] >= b.intensity[0])
        {
            return Err(Error::InvalidConfig(
                "birth intensity (0 <= lo <= hi <= 1e28)",
            ));
        }
        if self.particles_per_target == 0 || self.min_particles == 0 {
            return Err(Error::InvalidConfig("particles_per_target / min_particles"));
        }
        if let Some(p) = &self.pso {
            if p.generations > super::pso::MAX_GENERATIONS
                || p.max_generations > super::pso::MAX_GENERATIONS
            {
                return Err(Error::InvalidConfig("pso generations (at most 1000)"));
            }
            if p.points == 0
                || p.max_members == 0
                || !pos(p.fitness_scale)
                || !(p.mutation >= 0.0 && p.mutation <= MAX_MUTATION)
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
                if *max_iter == 0 || *max_iter > super::pso::MAX_GENERATIONS {
                    return Err(Error::InvalidConfig("kmeans max_iter (1..=1000)"));
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
    /// `N_hat = round(sum w)`, capped at the capacity `TARGETS`.
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
    /// `round(sum w)` exceeded `TARGETS` and was capped (documented recovery).
    pub truncated: bool,
    /// Every weight underflowed to zero: the PHD is emptied and refilled by the next
    /// frame's births (documented recovery).
    pub degenerate: bool,
    /// The extractor could not cluster the particles (a state that is not finite): no
    /// estimates this frame, the filter itself is kept (documented recovery; the frame
    /// is not an error because the filter has already taken it in).
    pub extract_failed: bool,
}

/// The stages of one frame, in order, as [`SmcPhdTbd::step_probed`] reports their ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhdStage {
    /// The cube's checks (length, finite, non-negative).
    Check,
    /// The CV prediction of the survivors (eq. 14-15).
    Predict,
    /// The birth particles (eq. 16-17).
    Births,
    /// The swarm's measurement points `Z_m` and their refinement (PSO only).
    Points,
    /// The swarm (PSO only).
    Swarm,
    /// Every particle's log likelihood ratio over its covered cells (eq. 21-24).
    Likelihood,
    /// The grouping by cell and the normalisation of eq. 20, 25.
    Normalise,
    /// `N_hat` and the systematic resampling (eq. 26).
    Resample,
    /// The state extraction (K-means or DBSCAN).
    Extract,
    /// The next frame's birth cells.
    BirthCells,
}

impl PhdStage {
    /// Every stage, in frame order.
    pub const ALL: [Self; 10] = [
        Self::Check,
        Self::Predict,
        Self::Births,
        Self::Points,
        Self::Swarm,
        Self::Likelihood,
        Self::Normalise,
        Self::Resample,
        Self::Extract,
        Self::BirthCells,
    ];

    /// Short name.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Check => "cube check",
            Self::Predict => "prediction",
            Self::Births => "births",
            Self::Points => "swarm points",
            Self::Swarm => "swarm",
            Self::Likelihood => "likelihood",
            Self::Normalise => "normalisation",
            Self::Resample => "resampling",
            Self::Extract => "extraction",
            Self::BirthCells => "birth cells",
        }
    }
}

/// The firmware's filter (with its cube window it fits 1 MiB of RAM): 6144 particles,
/// a 1024-entry swarm, 8 points, 8 targets.
pub type SmcPhdTbdM4 = SmcPhdTbd<6144, 1024, 8, 8>;
/// The firmware's filter within 512 KiB of static RAM with its 32^3-cell cube window
/// (375 544 + 131 072 B on the Cortex-M4F): 2048 particles (three targets at 500 plus
/// 500 births), the preset's 1024-entry swarm (512 particles move), 8 points, 8 targets.
pub type SmcPhdTbdM4Half = SmcPhdTbd<2048, 1024, 8, 8>;
/// The host's filter: 8192 particles, a 16384-entry swarm, 10 points, 16 targets.
pub type SmcPhdTbdHost = SmcPhdTbd<8192, 16384, 10, 16>;
/// The golden case's filter: 256 particles, a 256-entry swarm, 4 points, 4 targets.
pub type SmcPhdTbdSmall = SmcPhdTbd<256, 256, 4, 4>;
/// The soak run's filter: 1024 particles, a 64-entry swarm, 8 points, 16 targets.
pub type SmcPhdTbdSoak = SmcPhdTbd<1024, 64, 8, 16>;

/// The SMC-PHD TBD filter with capacities: `PARTICLES` (survivors plus births), `SWARM`
/// entries (parents plus children, so up to `SWARM / 2` particles move), `POINTS`
/// measurement points (PSO objectives), `TARGETS` extracted targets.
///
/// Memory: about `123 N + (64 + 4 M) S` bytes with `N = PARTICLES`, `M = POINTS`,
/// `S = SWARM` (32-bit target; e.g. 897 KB at `N = S = 4096, M = 8`): build large instances in a `Box` or a `static` from
/// [`SmcPhdTbd::new_unconfigured`] and set up by [`Detector::configure`].
#[derive(Debug, Clone)]
pub struct SmcPhdTbd<
    const PARTICLES: usize,
    const SWARM: usize,
    const POINTS: usize,
    const TARGETS: usize,
> {
    cfg: PhdConfig,
    x: [[f32; 5]; PARTICLES],
    w: [f32; PARTICLES],
    n: usize,
    scratch: [[f32; 5]; PARTICLES],
    lw: [f32; PARTICLES],
    key: [u32; PARTICLES],
    order: [u32; PARTICLES],
    anc: [u32; PARTICLES],
    run_key: [u32; PARTICLES],
    parent: [u32; PARTICLES],
    pts: [[f32; 2]; PARTICLES],
    swarm: Swarm<SWARM, POINTS>,
    dbscan: Dbscan<PARTICLES>,
    kmeans: KMeans<PARTICLES, TARGETS>,
    est: [Estimate; TARGETS],
    n_est: usize,
    zpts: [[f32; 2]; POINTS],
    n_z: usize,
    rng: Rng,
    /// Measurement-driven birth cells chosen on the previous frame, per component.
    birth_cells: [[(usize, f32); MAX_BIRTH_CELLS]; MAX_BIRTH_COMPONENTS],
    birth_nb: [usize; MAX_BIRTH_COMPONENTS],
    /// The same, chosen the frame before (for two-frame birth velocities).
    birth_prev: [[(usize, f32); MAX_BIRTH_CELLS]; MAX_BIRTH_COMPONENTS],
    birth_prev_nb: [usize; MAX_BIRTH_COMPONENTS],
    /// Peaks of [`BirthMode::Region`] in `birth_cells` (pooled).
    region_nb: usize,
}

impl<const PARTICLES: usize, const SWARM: usize, const POINTS: usize, const TARGETS: usize>
    SmcPhdTbd<PARTICLES, SWARM, POINTS, TARGETS>
{
    /// The unconfigured filter (a compile-time constant, [`Detector::UNCONFIGURED`]):
    /// every call but [`Detector::configure`] returns a typed error or nothing until a
    /// configuration succeeds. For a `static` or a `Box`.
    pub const fn new_unconfigured() -> Self {
        <Self as Detector>::UNCONFIGURED
    }

    /// A filter with an empty PHD (the first frame's births populate it).
    /// Errors: invalid config, `J >= PARTICLES`, more PSO points than `POINTS`,
    /// `TARGETS == 0`.
    pub fn new(cfg: PhdConfig, seed: u64) -> Result<Self> {
        Self::check(&cfg)?;
        Ok(Self {
            cfg,
            x: [[0.0; 5]; PARTICLES],
            w: [0.0; PARTICLES],
            n: 0,
            scratch: [[0.0; 5]; PARTICLES],
            lw: [0.0; PARTICLES],
            key: [0; PARTICLES],
            order: [0; PARTICLES],
            anc: [0; PARTICLES],
            run_key: [0; PARTICLES],
            parent: [0; PARTICLES],
            pts: [[0.0; 2]; PARTICLES],
            swarm: Swarm::new(),
            dbscan: Dbscan::new(),
            kmeans: KMeans::new(),
            est: [Estimate::default(); TARGETS],
            n_est: 0,
            zpts: [[0.0; 2]; POINTS],
            n_z: 0,
            rng: Rng::seed_from_u64(seed),
            birth_cells: [[(0, 0.0); MAX_BIRTH_CELLS]; MAX_BIRTH_COMPONENTS],
            birth_nb: [0; MAX_BIRTH_COMPONENTS],
            birth_prev: [[(0, 0.0); MAX_BIRTH_CELLS]; MAX_BIRTH_COMPONENTS],
            birth_prev_nb: [0; MAX_BIRTH_COMPONENTS],
            region_nb: 0,
        })
    }

    fn check(cfg: &PhdConfig) -> Result<()> {
        cfg.validate()?;
        if TARGETS == 0 || PARTICLES < 2 || PARTICLES > u32::MAX as usize {
            return Err(Error::InvalidConfig("capacities"));
        }
        if cfg.birth.particles >= PARTICLES {
            return Err(Error::Capacity {
                capacity: PARTICLES - 1,
                requested: cfg.birth.particles,
            });
        }
        if let Some(p) = &cfg.pso {
            if p.points > POINTS {
                return Err(Error::Capacity {
                    capacity: POINTS,
                    requested: p.points,
                });
            }
        }
        Ok(())
    }

    /// Extracted states of the last frame.
    pub fn estimates(&self) -> &[Estimate] {
        self.est.get(..self.n_est).unwrap_or(&[])
    }

    /// Current particles `[x, vx, y, vy, I]` and their weights.
    pub fn particles(&self) -> (&[[f32; 5]], &[f32]) {
        match (self.x.get(..self.n), self.w.get(..self.n)) {
            (Some(x), Some(w)) => (x, w),
            _ => (&[], &[]),
        }
    }

    /// Measurement-derived points of the last PSO step.
    pub fn measurement_points(&self) -> &[[f32; 2]] {
        self.zpts.get(..self.n_z).unwrap_or(&[])
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
        self.step_probed(cube, |_| {})
    }

    /// [`Detector::step`] calling `probe(stage)` as each stage of the frame ends (for
    /// per-stage cost measurements, e.g. the firmware's stage rows; the results are
    /// those of `step`).
    pub fn step_probed(
        &mut self,
        cube: &[f32],
        mut probe: impl FnMut(PhdStage),
    ) -> Result<PhdReport> {
        let cube = PowerCube::new(cube, self.cfg.geometry)?;
        probe(PhdStage::Check);
        let mut report = PhdReport::default();
        self.predict();
        probe(PhdStage::Predict);
        let n_surv = self.n;
        self.add_births();
        probe(PhdStage::Births);
        if let Some(pso) = self.cfg.pso {
            self.select_points(&cube, n_surv, pso.points);
            probe(PhdStage::Points);
            let (sw, gens) = self.swarm_step(&pso);
            probe(PhdStage::Swarm);
            report.swarm = sw;
            report.pso_generations = gens;
        }
        self.likelihood(&cube);
        probe(PhdStage::Likelihood);
        let mass = self.update();
        probe(PhdStage::Normalise);
        report.mass = mass;
        let nh = if mass.is_finite() && mass > 0.0 {
            math::round(mass) as usize
        } else {
            0
        };
        report.truncated = nh > TARGETS;
        report.n_hat = nh.min(TARGETS);
        if !(mass.is_finite() && mass > 0.0 && self.resample(report.n_hat, mass)) {
            report.degenerate = true;
            report.mass = 0.0;
            report.n_hat = 0;
            self.n = 0;
        }
        probe(PhdStage::Resample);
        report.particles = self.n;
        if self.extract(report.n_hat).is_err() {
            self.n_est = 0;
            report.extract_failed = true;
        }
        probe(PhdStage::Extract);
        self.choose_birth_cells(&cube);
        probe(PhdStage::BirthCells);
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
        for (s, w) in self.x.iter_mut().zip(self.w.iter_mut()).take(self.n) {
            for k in [0usize, 2] {
                let n1 = self.rng.normal();
                let n2 = self.rng.normal();
                s[k] += t * s[k + 1] + a * n1;
                s[k + 1] += b * n1 + cc * n2;
            }
            s[4] = (s[4] + si * self.rng.normal())
                .max(c.min_intensity)
                .min(MAX_INTENSITY);
            *w *= c.p_survival;
        }
    }
}

impl<const PARTICLES: usize, const SWARM: usize, const POINTS: usize, const TARGETS: usize> Detector
    for SmcPhdTbd<PARTICLES, SWARM, POINTS, TARGETS>
{
    type Frame = [f32];
    type Config = PhdConfig;
    type Report = PhdReport;
    const STATE: &'static [&'static str] = &["x_m", "vx_m_per_s", "y_m", "vy_m_per_s", "intensity"];
    const SCORE: ScoreKind = ScoreKind::Mass;
    unconfigured_is_zero!();

    /// Re-validates `cfg` and restarts in place from `seed`, behaving exactly as
    /// [`SmcPhdTbd::new`]`(cfg, seed)` would, without building the (large) filter by
    /// value: how one that lives in a `static` is set up, from
    /// [`SmcPhdTbd::new_unconfigured`] (e.g. the firmware's `.bss` detectors). On error
    /// `self` is unchanged.
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
        self.region_nb = 0;
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
