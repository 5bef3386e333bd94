//! SMC cardinality-balanced multi-Bernoulli (CBMeMBer) track-before-detect on
//! range-Doppler maps with the joint Doppler / micro-Doppler model of the rotor-UAV paper
//! (*Weak targets detection and estimation based on joint use of Doppler and
//! micro-Doppler*, Journal of Radars, 2023, §3, Algorithm 1): the CBMeMBer filter of
//! Vo, Vo, Cantoni 2009 in the image-observation form of Vo, Vo, Pham, Suter 2010, with
//! the measurement model of [`crate::model::range_doppler`].
//!
//! State `x = [r, v, rho, V, omega, theta, B]` (eq. 14): range (m), radial velocity (m/s,
//! receding positive), mean RCS coefficient, maximum blade velocity spread (m/s), rotor
//! rate (rad/s), micro-Doppler phase (rad), blade count. One frame:
//! 1. **predict** (eq. 15-16, steps 4-8): every particle moves by
//!    `r += eps v + eps^2/2 n1`, `v += eps n1`, `rho += n2`, `V += n3`,
//!    `omega += eps n4`, `theta += eps omega + eps^2/2 n4` (`rho`, `V` reflected at 0,
//!    `theta` wrapped to `[0, 2 pi)`; `B` moves to a neighbour in `1..=4` with probability
//!    `blade_move` when estimated), and every existence `r_P = p_S r` (the shared
//!    [`ExistenceMarkov`] with no birth and death `1 - p_S`);
//! 2. **birth** (steps 1-3, 9-10): one Bernoulli component per frame, existence
//!    `r_Gamma`, particles from the initial density (Table 2; `V`, `omega`, `theta`
//!    uniform);
//! 3. **update** (eq. 22, steps 11-15), per component, in the log domain:
//!    `ln rho = LSE_j(ln w_j + ln g(x_j))`,
//!    `r = r_P rho / (1 - r_P + r_P rho) = sigmoid(logit r_P + ln rho)`, `w_j` renormalised
//!    ([`math::normalize_log_weights`]);
//! 4. **estimate** (eq. 25): `x_hat = sum_j w_j x_j` (circular mean for `theta`);
//! 5. **resample** (step 16) each component to `L = clamp(round(r L_max), L_min, L_max)`
//!    particles (Vo, Vo, Cantoni 2009, §V), systematic, equal weights;
//! 6. **prune and merge**: a component with `r` below `prune_below` is dropped; two whose
//!    estimates lie within `merge_gate` (range, velocity; the preset's is one spread,
//!    `[zeta_r, zeta_v]`: their supports overlap, which the separability assumption of the
//!    image-observation filter, Vo, Vo, Pham, Suter 2010, excludes for two targets) are
//!    one: the one with the larger existence is kept, with its own particles and
//!    existence (`max`, not a sum: births placed every frame on the same prior would
//!    otherwise add up their small existences); capacity: a birth takes a free slot, else the slot of the weakest
//!    component if that one's existence is below the birth's, else it is skipped
//!    ([`CbmemberReport::birth`]);
//! 7. **report** the components whose existence exceeds `report_threshold`, each with a
//!    stable id (given at birth) and its age in frames.
//!
//! Bad input: a map of the wrong size, NaN/inf or negative pixels are typed errors before
//! any state change; a component whose likelihoods all underflow, whose estimate is not
//! finite (particles beyond the range of `f32`), or whose existence falls below
//! `prune_below`, is dropped (no NaN: existences stay in `[0, 1]`).

#![allow(clippy::needless_range_loop)]

use core::marker::PhantomData;

use crate::detect::interface::unconfigured_is_zero;
use crate::detect::{Detection, Detector, ScoreKind, TrackInfo, Validate};
use crate::existence::ExistenceMarkov;
use crate::math;
use crate::model::range_doppler::{
    log_lr_blocked, log_lr_exact, peak_snr, point_velocities, BlockMap, Dequant, Kernel,
    PointModel, PowerMap, RdGeometry, RdSpread, KAPPA, MAX_BLADES, MAX_POINTS, MAX_VELOCITY_BINS,
};
use crate::particles::{gather_resized_in_place, resample, Scheme};
use crate::rng::Rng;
use crate::{Error, Result};

/// Dimension of the particle state `[r, v, rho, V, omega, theta, B]`.
pub const DIM: usize = 7;

/// Index of each state component.
pub mod idx {
    /// Range (m).
    pub const R: usize = 0;
    /// Radial velocity (m/s).
    pub const V: usize = 1;
    /// RCS coefficient `rho`.
    pub const RHO: usize = 2;
    /// Maximum blade velocity spread `V` (m/s).
    pub const SPREAD: usize = 3;
    /// Rotor rate `omega` (rad/s).
    pub const OMEGA: usize = 4;
    /// Micro-Doppler phase `theta` (rad).
    pub const THETA: usize = 5;
    /// Blade count `B`.
    pub const BLADES: usize = 6;
}

/// How the likelihood ratio of eq. 22 is evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case", deny_unknown_fields)
)]
pub enum Likelihood {
    /// Pixel by pixel over the truncated supports ([`log_lr_exact`]; the reference).
    Exact,
    /// Over blocks of `bins` velocity bins pre-summed once per frame
    /// ([`log_lr_blocked`]); `bins` must divide `n_velocity`.
    Blocked {
        /// Velocity bins per block.
        bins: usize,
    },
}

/// Process noise of eq. 15-16, standard deviations per frame.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct ProcessNoise {
    /// `s_v` (m/s): `n1 ~ N(0, s_v^2)`.
    pub velocity: f32,
    /// `s_rho`: `n2`.
    pub rho: f32,
    /// `s_V` (m/s): `n3`.
    pub blade_speed: f32,
    /// `s_omega` (rad/s): `n4`.
    pub omega: f32,
    /// Probability that an estimated blade count moves to a neighbour per frame.
    pub blade_move: f32,
}

/// Where birth particles' range and velocity come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum BirthPlacement {
    /// `r ~ N(range)`, `v ~ N(velocity)` (Table 2, the paper).
    #[default]
    Prior,
    /// From the previous frame: `v ~ U` over the whole velocity axis (the body's Doppler
    /// is not taken from the map: a blade can outshine it) and
    /// `r ~ N(r_peak + v eps, range[1]^2)`, `r_peak` the peak of the previous frame's
    /// range profile (row sums of the map summed over `+-zeta_r`, rows within
    /// `KAPPA zeta_r` of a reported component skipped) moved on by one frame. Prior
    /// before the first frame.
    RangePeak,
}

/// Birth density: the initial density of Table 2, `V`, `omega`, `theta` uniform.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct BirthDensity {
    /// Existence `r_Gamma` of the birth component.
    pub existence: f32,
    /// Particles of a birth component.
    pub particles: usize,
    /// Range `N(mean, std^2)` (m).
    pub range: [f32; 2],
    /// Velocity `N(mean, std^2)` (m/s).
    pub velocity: [f32; 2],
    /// `rho ~ N(mean, std^2)`.
    pub rho: [f32; 2],
    /// `V ~ U[lo, hi]` (m/s).
    pub blade_speed: [f32; 2],
    /// `omega ~ U[lo, hi]` (rad/s).
    pub omega: [f32; 2],
    /// `theta ~ U[lo, hi]` (rad).
    pub theta: [f32; 2],
    /// `theta` is the phase at frame 0: a birth on frame `k` gets
    /// `theta + omega k eps` (a rotor-phase prior referenced to the first frame; with
    /// point ranges for `V`, `omega`, `theta` this is the paper's "micro-Doppler known").
    pub phase_from_frame0: bool,
    /// Range and velocity placement (default: the prior).
    #[cfg_attr(feature = "serde", serde(default))]
    pub placement: BirthPlacement,
    /// `rho = 10^(U[lo, hi] / 10)` instead of `N(rho)` (a log-uniform SNR prior when
    /// `gain` makes `rho` the linear SNR; default `None`).
    #[cfg_attr(feature = "serde", serde(default))]
    pub rho_db: Option<[f32; 2]>,
}

/// Runtime configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct CbmemberConfig {
    /// Map axes.
    pub geometry: RdGeometry,
    /// Point spread `zeta_r`, `zeta_v`.
    pub spread: RdSpread,
    /// Per-component noise variance `zeta_s^2`.
    pub noise_var: f32,
    /// Radar system gain `k_s` (eq. 18-19).
    pub gain: f32,
    /// Frame interval `eps` (s).
    pub dt: f32,
    /// Joint (body and blades) or Doppler-only (body) measurement model.
    pub model: PointModel,
    /// Likelihood evaluation.
    pub likelihood: Likelihood,
    /// Process noise.
    pub process: ProcessNoise,
    /// Survival probability `p_S`.
    pub p_survival: f32,
    /// Birth density.
    pub birth: BirthDensity,
    /// Blade count `B` (known), and of births when estimated.
    pub blades: u32,
    /// Estimate `B` in `1..=4` (births uniform, moves with `process.blade_move`).
    pub estimate_blades: bool,
    /// Particles of a component of existence 1 (`L_max`, at most the capacity `PARTICLES`).
    pub max_particles: usize,
    /// Fewest particles of a component (`L_min`).
    pub min_particles: usize,
    /// Components with existence below this are dropped.
    pub prune_below: f32,
    /// Components whose estimates differ by at most `[range m, velocity m/s]` are merged
    /// (`[0, 0]`: off).
    pub merge_gate: [f32; 2],
    /// Components with existence above this are reported.
    pub report_threshold: f32,
    /// Step of the linear `u8` quantiser of a quantised map, in normalised power
    /// `|y|^2 / (2 zeta_s^2)` ([`crate::model::range_doppler::quantise`]).
    pub quant_step: f32,
}

/// `k_s` that gives a peak SNR of `snr_db` (eq. 19) at `range` for `rho`:
/// `k_s = 10^(snr/10) 2 r^4 zeta_s^2 / rho`.
pub fn gain_for_snr(snr_db: f32, range: f32, rho: f32, noise_var: f32) -> f32 {
    let r2 = range * range;
    math::powf(10.0, snr_db / 10.0) * 2.0 * r2 * r2 * noise_var / rho
}

impl CbmemberConfig {
    /// The rotor-UAV preset (Tables 1-2 and the specification's open values): 256 x 512
    /// map over range `[19 910, 20 110)` m and velocity `[-20, 20)` m/s, `zeta_r = 3` m,
    /// `zeta_v = 5` m/s, `zeta_s = 0.3`, `k_s = 1e19`, `eps = 1` s, joint model with
    /// `B = 2` known, `p_S = 0.9`, `L_max = 1500`, `L_min = 450`, births of existence 0.01
    /// with 450 particles from `r ~ N(20 010, 2^2)`, `v ~ N(1, 0.4^2)`,
    /// `rho ~ N(1, 0.1^2)`, `V ~ U[9, 11]`, `omega ~ U[0.03 pi, 0.09 pi]`,
    /// `theta ~ U[0, 2 pi)`, blocked likelihood with 16-bin blocks, merge gate of one
    /// spread `[3 m, 5 m/s]`, report threshold 0.5.
    pub fn rotor_uav() -> Self {
        Self {
            geometry: RdGeometry {
                n_range: 256,
                n_velocity: 512,
                range_start: 19_910.0,
                range_bin: 200.0 / 256.0,
                velocity_start: -20.0,
                velocity_bin: 40.0 / 512.0,
            },
            spread: RdSpread {
                zeta_r: 3.0,
                zeta_v: 5.0,
            },
            noise_var: 0.09,
            gain: 1.0e19,
            dt: 1.0,
            model: PointModel::Joint,
            likelihood: Likelihood::Blocked { bins: 16 },
            process: ProcessNoise {
                velocity: 0.05,
                rho: 0.01,
                blade_speed: 0.1,
                omega: 0.002,
                blade_move: 0.05,
            },
            p_survival: 0.9,
            birth: BirthDensity {
                existence: 0.01,
                particles: 450,
                range: [20_010.0, 2.0],
                velocity: [1.0, 0.4],
                rho: [1.0, 0.1],
                blade_speed: [9.0, 11.0],
                omega: [0.03 * math::PI, 0.09 * math::PI],
                theta: [0.0, 2.0 * math::PI],
                phase_from_frame0: false,
                placement: BirthPlacement::Prior,
                rho_db: None,
            },
            blades: 2,
            estimate_blades: false,
            max_particles: 1500,
            min_particles: 450,
            prune_below: 1.0e-3,
            merge_gate: [3.0, 5.0],
            report_threshold: 0.5,
            quant_step: 0.05,
        }
    }

    /// The same filter with the Doppler-only measurement model (the baseline).
    pub fn doppler_only(mut self) -> Self {
        self.model = PointModel::DopplerOnly;
        self
    }
}

impl Validate for CbmemberConfig {
    fn validate(&self) -> Result<()> {
        self.geometry.validate()?;
        self.spread.validate()?;
        let pos = |v: f32| v.is_finite() && v > 0.0;
        let nonneg = |v: f32| v.is_finite() && v >= 0.0;
        let prob = |v: f32| v.is_finite() && (0.0..=1.0).contains(&v);
        if !pos(self.noise_var) {
            return Err(Error::InvalidConfig("noise_var"));
        }
        if !pos(self.gain) {
            return Err(Error::InvalidConfig("gain"));
        }
        if !pos(self.dt) {
            return Err(Error::InvalidConfig("dt"));
        }
        if let Likelihood::Blocked { bins } = self.likelihood {
            if bins == 0 || !self.geometry.n_velocity.is_multiple_of(bins) {
                return Err(Error::InvalidConfig("likelihood.bins"));
            }
        }
        let p = &self.process;
        if ![p.velocity, p.rho, p.blade_speed, p.omega]
            .iter()
            .all(|&v| nonneg(v))
            || !prob(p.blade_move)
        {
            return Err(Error::InvalidConfig("process"));
        }
        if !(self.p_survival > 0.0 && self.p_survival <= 1.0) {
            return Err(Error::InvalidConfig("p_survival"));
        }
        let b = &self.birth;
        if !(b.existence > 0.0 && b.existence < 1.0) {
            return Err(Error::InvalidConfig("birth.existence"));
        }
        if b.particles == 0 {
            return Err(Error::InvalidConfig("birth.particles"));
        }
        for m in [b.range, b.velocity, b.rho] {
            if !m[0].is_finite() || !nonneg(m[1]) {
                return Err(Error::InvalidConfig("birth mean / std"));
            }
        }
        if let Some([lo, hi]) = b.rho_db {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi && hi <= 300.0) {
                return Err(Error::InvalidConfig("birth.rho_db (lo <= hi <= 300)"));
            }
        }
        for u in [b.blade_speed, b.omega, b.theta] {
            if !(u[0].is_finite() && u[1].is_finite() && u[0] <= u[1]) {
                return Err(Error::InvalidConfig("birth uniform range"));
            }
        }
        if self.blades == 0 || self.blades as usize > MAX_BLADES {
            return Err(Error::InvalidConfig("blades"));
        }
        if self.min_particles == 0 || self.max_particles < self.min_particles {
            return Err(Error::InvalidConfig("min_particles / max_particles"));
        }
        if !(self.prune_below >= 0.0 && self.prune_below < 1.0) {
            return Err(Error::InvalidConfig("prune_below"));
        }
        if !self.merge_gate.iter().all(|&v| nonneg(v)) {
            return Err(Error::InvalidConfig("merge_gate"));
        }
        if !(self.report_threshold > 0.0 && self.report_threshold < 1.0) {
            return Err(Error::InvalidConfig("report_threshold"));
        }
        if !pos(self.quant_step) {
            return Err(Error::InvalidConfig("quant_step"));
        }
        Ok(())
    }
}

/// Per-frame summary.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CbmemberReport {
    /// Live components after the step.
    pub components: usize,
    /// Components reported (existence above the threshold).
    pub reported: usize,
    /// Particles updated this frame (all components, births included).
    pub particles: usize,
    /// A birth component was added (false: every slot held a stronger component).
    pub birth: bool,
    /// Components dropped (pruned, or whose likelihoods all underflowed).
    pub pruned: usize,
    /// Components merged into another.
    pub merged: usize,
    /// Largest existence after the update.
    pub max_existence: f32,
}

/// One component's estimate (eq. 25).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Estimate {
    /// Stable id, given at birth.
    pub id: u32,
    /// Frames since birth (1 on the birth frame).
    pub age: u32,
    /// Existence probability.
    pub existence: f32,
    /// `[r, v, rho, V, omega, theta, B]`.
    pub state: [f32; DIM],
    /// Particles after resampling.
    pub particles: usize,
}

/// One Bernoulli component: existence and `PARTICLES` particles.
#[derive(Debug, Clone)]
struct Component<const PARTICLES: usize> {
    live: bool,
    r: f32,
    n: usize,
    id: u32,
    age: u32,
    est: [f32; DIM],
    x: [[f32; DIM]; PARTICLES],
    w: [f32; PARTICLES],
}

/// The firmware's filter: 4 components of up to 1000 particles, 256 x 32 block sums.
pub type CbmemberTbdM4<F = [f32]> = CbmemberTbd<4, 1000, 8192, F>;
/// The host's filter: 4 components of up to 1500 particles, 256 x 32 block sums.
pub type CbmemberTbdHost<F = [f32]> = CbmemberTbd<4, 1500, 8192, F>;
/// The golden case's filter: 3 components of 96 particles, 256 block sums.
pub type CbmemberTbdSmall<F = [f32]> = CbmemberTbd<3, 96, 256, F>;
/// The soak run's filter: 4 components of 100 particles, 128 block sums.
pub type CbmemberTbdSoak<F = [f32]> = CbmemberTbd<4, 100, 128, F>;

/// The filter with capacities: `COMPONENTS` Bernoulli components, `PARTICLES` particles
/// per component, `BLOCK_SUMS` block sums (`n_range * n_velocity / bins` for the blocked likelihood; unused by
/// the exact one), frame type `F` (`[f32]` power map `|y|^2`, `[Complex32]`, or `[u8]`
/// quantised).
///
/// Memory: about `C (32 P + 48) + 6 P + 4 S + 9 KB` bytes with `C = COMPONENTS`,
/// `P = PARTICLES`, `S = BLOCK_SUMS` (e.g. 170 KB at `C = 4`, `P = 1000`, `S = 8192`). Build large instances in a `Box` or a `static` from
/// [`CbmemberTbd::new_unconfigured`] and set up by [`Detector::configure`].
#[derive(Debug)]
pub struct CbmemberTbd<
    const COMPONENTS: usize,
    const PARTICLES: usize,
    const BLOCK_SUMS: usize,
    F: ?Sized = [f32],
> {
    cfg: CbmemberConfig,
    comps: [Component<PARTICLES>; COMPONENTS],
    lw: [f32; PARTICLES],
    anc: [u16; PARTICLES],
    blocks: [f32; BLOCK_SUMS],
    h: [f32; MAX_VELOCITY_BINS],
    p: [f32; 2 * MAX_VELOCITY_BINS],
    kernel: Kernel,
    dq: Dequant,
    c0: f32,
    rng: Rng,
    next_id: u32,
    frames: u32,
    reported: [u16; COMPONENTS],
    n_reported: usize,
    /// Range of the previous frame's profile peak ([`BirthPlacement::RangePeak`]).
    birth_peak: f32,
    has_peak: bool,
    _frame: PhantomData<fn(&F)>,
}

// By hand: a derive would ask `F: Clone` of the (unsized) frame type.
impl<const COMPONENTS: usize, const PARTICLES: usize, const BLOCK_SUMS: usize, F: ?Sized> Clone
    for CbmemberTbd<COMPONENTS, PARTICLES, BLOCK_SUMS, F>
{
    fn clone(&self) -> Self {
        Self {
            cfg: self.cfg,
            comps: self.comps.clone(),
            lw: self.lw,
            anc: self.anc,
            blocks: self.blocks,
            h: self.h,
            p: self.p,
            kernel: self.kernel,
            dq: self.dq,
            c0: self.c0,
            rng: self.rng.clone(),
            next_id: self.next_id,
            frames: self.frames,
            reported: self.reported,
            n_reported: self.n_reported,
            birth_peak: self.birth_peak,
            has_peak: self.has_peak,
            _frame: PhantomData,
        }
    }
}

/// Likelihood context of one frame.
struct Lr<'a, F: ?Sized> {
    map: &'a F,
    blocks: Option<BlockMap<'a>>,
    g: RdGeometry,
    kernel: Kernel,
    dq: Dequant,
    model: PointModel,
    c0: f32,
}

impl<F: ?Sized + PowerMap> Lr<'_, F> {
    #[inline]
    fn log_lr(&self, x: &[f32; DIM], h: &mut [f32], p: &mut [f32]) -> f32 {
        let mut vels = [0f32; MAX_POINTS];
        let n = point_velocities(
            self.model,
            x[idx::V],
            x[idx::SPREAD],
            x[idx::THETA],
            x[idx::BLADES] as u32,
            &mut vels,
        );
        let amp = peak_snr(self.c0, x[idx::RHO], x[idx::R]);
        let vels = vels.get(..n).unwrap_or(&[]);
        match &self.blocks {
            Some(bm) => log_lr_blocked(bm, &self.g, &self.kernel, amp, x[idx::R], vels, h, p),
            None => log_lr_exact(
                self.map,
                &self.dq,
                &self.g,
                &self.kernel,
                amp,
                x[idx::R],
                vels,
                h,
            ),
        }
    }
}

const TWO_PI: f32 = 2.0 * math::PI;

#[inline]
fn wrap_angle(t: f32) -> f32 {
    let w = t - TWO_PI * math::floor(t / TWO_PI);
    if (0.0..TWO_PI).contains(&w) {
        w
    } else {
        0.0
    }
}

impl<
        const COMPONENTS: usize,
        const PARTICLES: usize,
        const BLOCK_SUMS: usize,
        F: ?Sized + PowerMap,
    > CbmemberTbd<COMPONENTS, PARTICLES, BLOCK_SUMS, F>
{
    /// The unconfigured filter (a compile-time constant, [`Detector::UNCONFIGURED`]):
    /// every call but [`Detector::configure`] returns a typed error or nothing until a
    /// configuration succeeds. For a `static` or a `Box`.
    pub const fn new_unconfigured() -> Self {
        <Self as Detector>::UNCONFIGURED
    }

    /// A configured filter built by value (small capacities; use
    /// [`new_unconfigured`](Self::new_unconfigured) in a `Box` or a `static` with
    /// [`Detector::configure`] for large ones).
    pub fn new(cfg: CbmemberConfig, seed: u64) -> Result<Self> {
        Self::check(&cfg)?;
        let comp = Component {
            live: false,
            r: 0.0,
            n: 0,
            id: 0,
            age: 0,
            est: [0.0; DIM],
            x: [[0.0; DIM]; PARTICLES],
            w: [0.0; PARTICLES],
        };
        let mut f = Self {
            cfg,
            comps: core::array::from_fn(|_| comp.clone()),
            lw: [0.0; PARTICLES],
            anc: [0; PARTICLES],
            blocks: [0.0; BLOCK_SUMS],
            h: [0.0; MAX_VELOCITY_BINS],
            p: [0.0; 2 * MAX_VELOCITY_BINS],
            kernel: Kernel::default(),
            dq: Dequant::new(1.0, 1.0),
            c0: 0.0,
            rng: Rng::seed_from_u64(seed),
            next_id: 1,
            frames: 0,
            reported: [0; COMPONENTS],
            n_reported: 0,
            birth_peak: 0.0,
            has_peak: false,
            _frame: PhantomData,
        };
        f.configure(&cfg, seed)?;
        Ok(f)
    }

    /// Checks `cfg` against the capacities (`COMPONENTS, PARTICLES >= 1`,
    /// `PARTICLES <= 65 536`, `L_max <= PARTICLES`, birth particles `<= PARTICLES`, block
    /// sums `<= BLOCK_SUMS`).
    fn check(cfg: &CbmemberConfig) -> Result<()> {
        cfg.validate()?;
        if COMPONENTS == 0 || PARTICLES == 0 || COMPONENTS > u16::MAX as usize {
            return Err(Error::InvalidConfig("capacities"));
        }
        if PARTICLES > 1 << 16 {
            return Err(Error::Capacity {
                capacity: 1 << 16,
                requested: PARTICLES,
            });
        }
        for n in [cfg.max_particles, cfg.birth.particles] {
            if n > PARTICLES {
                return Err(Error::Capacity {
                    capacity: PARTICLES,
                    requested: n,
                });
            }
        }
        if let Likelihood::Blocked { bins } = cfg.likelihood {
            let need = cfg.geometry.n_range * (cfg.geometry.n_velocity / bins.max(1));
            if need > BLOCK_SUMS {
                return Err(Error::Capacity {
                    capacity: BLOCK_SUMS,
                    requested: need,
                });
            }
        }
        Ok(())
    }

    /// Estimates of the live components (slot order), reported or not.
    pub fn estimates(&self) -> impl Iterator<Item = Estimate> + '_ {
        self.comps.iter().filter(|c| c.live).map(|c| Estimate {
            id: c.id,
            age: c.age,
            existence: c.r,
            state: c.est,
            particles: c.n,
        })
    }

    /// Estimate of reported component `i` (the order of [`Detector::detection`]).
    pub fn reported(&self, i: usize) -> Option<Estimate> {
        let slot = *self.reported.get(..self.n_reported)?.get(i)? as usize;
        let c = self.comps.get(slot)?;
        Some(Estimate {
            id: c.id,
            age: c.age,
            existence: c.r,
            state: c.est,
            particles: c.n,
        })
    }

    /// Particles and weights of live component `k` (slot order of [`Self::estimates`]).
    pub fn particles(&self, k: usize) -> Option<(&[[f32; DIM]], &[f32])> {
        let c = self.comps.iter().filter(|c| c.live).nth(k)?;
        Some((c.x.get(..c.n)?, c.w.get(..c.n)?))
    }

    /// Frames processed since the last reset.
    pub fn frames(&self) -> u32 {
        self.frames
    }

    /// Predicts one particle through eq. 15-16.
    #[inline]
    fn propagate(cfg: &CbmemberConfig, x: &mut [f32; DIM], rng: &mut Rng) {
        let e = cfg.dt;
        let pn = &cfg.process;
        let n1 = pn.velocity * rng.normal();
        let n2 = pn.rho * rng.normal();
        let n3 = pn.blade_speed * rng.normal();
        let n4 = pn.omega * rng.normal();
        let half = 0.5 * e * e;
        x[idx::R] += e * x[idx::V] + half * n1;
        x[idx::V] += e * n1;
        x[idx::RHO] = (x[idx::RHO] + n2).abs();
        x[idx::SPREAD] = (x[idx::SPREAD] + n3).abs();
        x[idx::THETA] = wrap_angle(x[idx::THETA] + e * x[idx::OMEGA] + half * n4);
        x[idx::OMEGA] += e * n4;
        if cfg.estimate_blades && pn.blade_move > 0.0 && rng.bernoulli(pn.blade_move) {
            let b = x[idx::BLADES] as u32;
            let up = rng.bernoulli(0.5);
            let nb = match (up, b) {
                (true, b) if b < MAX_BLADES as u32 => b + 1,
                (true, _) => b - 1,
                (false, b) if b > 1 => b - 1,
                (false, _) => b + 1,
            };
            x[idx::BLADES] = nb as f32;
        }
    }

    /// One particle from the birth density (`frame`: index of the frame being processed).
    fn birth_particle(
        cfg: &CbmemberConfig,
        frame: u32,
        peak: Option<f32>,
        rng: &mut Rng,
    ) -> [f32; DIM] {
        let b = &cfg.birth;
        let blades = if cfg.estimate_blades {
            1 + rng.below(MAX_BLADES as u32)
        } else {
            cfg.blades
        };
        let (r, v) = match peak {
            Some(p) => {
                let g = &cfg.geometry;
                let r = rng.gaussian(p, b.range[1]);
                let v0 = g.velocity_start;
                let v = rng.uniform_range(v0, v0 + g.n_velocity as f32 * g.velocity_bin);
                // The peak is the previous frame's: move it on by the particle's velocity.
                (r + v * cfg.dt, v)
            }
            None => (
                rng.gaussian(b.range[0], b.range[1]),
                rng.gaussian(b.velocity[0], b.velocity[1]),
            ),
        };
        let rho = match b.rho_db {
            Some([lo, hi]) => math::powf(10.0, rng.uniform_range(lo, hi) / 10.0),
            None => rng.gaussian(b.rho[0], b.rho[1]).abs(),
        };
        let spread = rng.uniform_range(b.blade_speed[0], b.blade_speed[1]);
        let omega = rng.uniform_range(b.omega[0], b.omega[1]);
        let mut theta = rng.uniform_range(b.theta[0], b.theta[1]);
        if b.phase_from_frame0 {
            theta += omega * cfg.dt * frame as f32;
        }
        [r, v, rho, spread, omega, wrap_angle(theta), blades as f32]
    }

    /// The slot a birth goes to: a free one, else the weakest component's if its
    /// existence is below the birth's.
    fn birth_slot(comps: &[Component<PARTICLES>], existence: f32) -> Option<usize> {
        if let Some(k) = comps.iter().position(|c| !c.live) {
            return Some(k);
        }
        let mut best: Option<(usize, f32)> = None;
        for (k, c) in comps.iter().enumerate() {
            if best.is_none_or(|(_, r)| c.r < r) {
                best = Some((k, c.r));
            }
        }
        match best {
            Some((k, r)) if r < existence => Some(k),
            _ => None,
        }
    }

    /// One frame (see the module doc).
    fn step_map(&mut self, map: &F) -> Result<CbmemberReport> {
        let g = self.cfg.geometry;
        if map.pixel_count() != g.len() {
            return Err(Error::LengthMismatch {
                expected: g.len(),
                got: map.pixel_count(),
            });
        }
        // Input checks (and the per-frame block sums) before any state change.
        let blocks = match self.cfg.likelihood {
            Likelihood::Blocked { bins } => {
                Some(BlockMap::build(map, &self.dq, &g, bins, &mut self.blocks)?)
            }
            Likelihood::Exact => {
                map.check()?;
                None
            }
        };
        let cfg = self.cfg;
        let lr = Lr {
            map,
            blocks,
            g,
            kernel: self.kernel,
            dq: self.dq,
            model: cfg.model,
            c0: self.c0,
        };
        let mut rep = CbmemberReport::default();

        // 1. Predict.
        let chain = ExistenceMarkov::new(0.0, 1.0 - cfg.p_survival)?;
        for c in self.comps.iter_mut().filter(|c| c.live) {
            c.r = chain.predict(c.r);
            for x in c.x.iter_mut().take(c.n) {
                Self::propagate(&cfg, x, &mut self.rng);
            }
        }

        // 2. Birth.
        let peak = match cfg.birth.placement {
            BirthPlacement::RangePeak if self.has_peak => Some(self.birth_peak),
            _ => None,
        };
        if let Some(k) = Self::birth_slot(&self.comps, cfg.birth.existence) {
            let id = self.next_id;
            self.next_id = self.next_id.wrapping_add(1).max(1);
            if let Some(c) = self.comps.get_mut(k) {
                let n = cfg.birth.particles.min(PARTICLES);
                for x in c.x.iter_mut().take(n) {
                    *x = Self::birth_particle(&cfg, self.frames, peak, &mut self.rng);
                }
                let w = 1.0 / n.max(1) as f32;
                c.w.iter_mut().take(n).for_each(|v| *v = w);
                c.n = n;
                c.r = cfg.birth.existence;
                c.id = id;
                c.age = 0;
                c.live = true;
                rep.birth = true;
            }
        }

        // 3. Update, 4. estimate, 5. resample.
        for c in self.comps.iter_mut().filter(|c| c.live) {
            let n = c.n.min(PARTICLES);
            rep.particles += n;
            let (Some(x), Some(w), Some(lw)) =
                (c.x.get(..n), c.w.get_mut(..n), self.lw.get_mut(..n))
            else {
                c.live = false;
                continue;
            };
            // Weights are uniform before every update (births and resampling make them
            // so): ln rho = LSE_j(ln g_j) - ln n.
            for (l, xj) in lw.iter_mut().zip(x) {
                let v = lr.log_lr(xj, &mut self.h, &mut self.p);
                *l = if v.is_nan() { f32::NEG_INFINITY } else { v };
            }
            let ln_rho = match math::normalize_log_weights(lw, w) {
                Ok(v) => v - math::ln(n as f32),
                Err(_) => {
                    // Every likelihood underflowed (or was not finite): the component dies.
                    c.live = false;
                    rep.pruned += 1;
                    continue;
                }
            };
            c.r = updated_existence(c.r, ln_rho);
            c.est = estimate(x, w, false);
            if !c.est.iter().all(|v| v.is_finite()) {
                // The particles left the range of f32 (a configuration at the edge of
                // it, e.g. a huge frame interval): the component dies (no NaN reported).
                c.live = false;
                rep.pruned += 1;
                continue;
            }
            c.age = c.age.saturating_add(1);
            // Resample to L = clamp(round(r L_max), L_min, L_max).
            let l = (math::round(c.r * cfg.max_particles as f32) as usize)
                .max(cfg.min_particles)
                .min(cfg.max_particles)
                .min(PARTICLES);
            let Some(anc) = self.anc.get_mut(..l) else {
                continue;
            };
            if resample(Scheme::Systematic, w, anc, &mut self.rng).is_ok()
                && gather_resized_in_place(&mut c.x, n, anc).is_ok()
            {
                c.n = l;
                let wl = 1.0 / l.max(1) as f32;
                c.w.iter_mut().take(l).for_each(|v| *v = wl);
            } else {
                // Weights too degenerate to resample: keep the particles as they are.
                let wn = 1.0 / n.max(1) as f32;
                c.w.iter_mut().take(n).for_each(|v| *v = wn);
            }
        }

        // 6. Prune and merge.
        for c in self.comps.iter_mut().filter(|c| c.live) {
            if c.r.is_nan() || c.r < cfg.prune_below || c.n == 0 {
                c.live = false;
                rep.pruned += 1;
            }
        }
        let [gr, gv] = cfg.merge_gate;
        if gr > 0.0 || gv > 0.0 {
            for a in 0..COMPONENTS {
                for b in (a + 1)..COMPONENTS {
                    let (Some(ca), Some(cb)) = (self.comps.get(a), self.comps.get(b)) else {
                        continue;
                    };
                    if !(ca.live && cb.live) {
                        continue;
                    }
                    let close = (ca.est[idx::R] - cb.est[idx::R]).abs() <= gr
                        && (ca.est[idx::V] - cb.est[idx::V]).abs() <= gv;
                    if !close {
                        continue;
                    }
                    // Keep the stronger (the older on a tie).
                    let drop = if ca.r > cb.r || (ca.r == cb.r && ca.id <= cb.id) {
                        b
                    } else {
                        a
                    };
                    if let Some(c) = self.comps.get_mut(drop) {
                        c.live = false;
                        rep.merged += 1;
                    }
                }
            }
        }

        // 7. Report.
        self.n_reported = 0;
        for k in 0..COMPONENTS {
            let Some(c) = self.comps.get_mut(k) else {
                continue;
            };
            if !c.live {
                continue;
            }
            rep.components += 1;
            rep.max_existence = rep.max_existence.max(c.r);
            if c.r > cfg.report_threshold {
                // The circular mean of theta, for the reported components only.
                let n = c.n.min(PARTICLES);
                if let (Some(x), Some(w)) = (c.x.get(..n), c.w.get(..n)) {
                    c.est[idx::THETA] = estimate(x, w, true)[idx::THETA];
                }
                if let Some(s) = self.reported.get_mut(self.n_reported) {
                    *s = k as u16;
                    self.n_reported += 1;
                }
            }
        }
        rep.reported = self.n_reported;
        if cfg.birth.placement == BirthPlacement::RangePeak {
            self.choose_birth_peak(map);
        }
        self.frames = self.frames.saturating_add(1);
        Ok(rep)
    }

    /// [`BirthPlacement::RangePeak`]: the range of the largest `sum_{|k| <= w} S_(i+k)`,
    /// `S_i` the row sums of `map`, `w = round(zeta_r / range_bin)` (at most 32 rows), over
    /// the rows farther than `KAPPA zeta_r` from every reported component. Cost:
    /// `(2 w + 1)` passes over the map.
    fn choose_birth_peak(&mut self, map: &F) {
        let g = self.cfg.geometry;
        let zr = self.cfg.spread.zeta_r;
        let w = math::round(zr / g.range_bin).clamp(0.0, 32.0) as usize;
        let gate = KAPPA * zr;
        let mut best: Option<(usize, f32)> = None;
        for i in 0..g.n_range {
            let rc = g.range_centre(i);
            let taken = self
                .reported
                .get(..self.n_reported)
                .unwrap_or(&[])
                .iter()
                .filter_map(|&k| self.comps.get(k as usize))
                .any(|c| (c.est[idx::R] - rc).abs() <= gate);
            if taken {
                continue;
            }
            let mut t = 0.0f32;
            for row in i.saturating_sub(w)..(i + w + 1).min(g.n_range) {
                map.for_each(&self.dq, row * g.n_velocity, g.n_velocity, |_, v| t += v);
            }
            if t.is_finite() && best.is_none_or(|(_, b)| t > b) {
                best = Some((i, t));
            }
        }
        match best {
            Some((i, _)) => {
                self.birth_peak = g.range_centre(i);
                self.has_peak = true;
            }
            None => self.has_peak = false,
        }
    }
}

/// `r = r_P rho / (1 - r_P + r_P rho)` (eq. 13 of Algorithm 1) from `ln rho`, as
/// `sigmoid(ln r_P - ln(1 - r_P) + ln rho)`; in `[0, 1]`, never NaN.
pub fn updated_existence(r_pred: f32, ln_rho: f32) -> f32 {
    let rp = r_pred.clamp(0.0, 1.0);
    if rp >= 1.0 {
        return 1.0;
    }
    if rp <= 0.0 || ln_rho.is_nan() {
        return 0.0;
    }
    let logit = math::ln(rp) - math::ln1p(-rp) + ln_rho;
    let r = if logit > 0.0 {
        1.0 / (1.0 + math::exp(-logit))
    } else {
        let e = math::exp(logit);
        e / (1.0 + e)
    };
    if r.is_nan() {
        0.0
    } else {
        r.clamp(0.0, 1.0)
    }
}

/// Weighted mean state (eq. 25) of normalised weights; `theta` by its circular mean when
/// `circular` (else left 0).
fn estimate(x: &[[f32; DIM]], w: &[f32], circular: bool) -> [f32; DIM] {
    let mut acc = [0f32; DIM];
    let (mut s, mut co) = (0f32, 0f32);
    for (xj, &wj) in x.iter().zip(w) {
        for (a, &v) in acc.iter_mut().zip(xj.iter()) {
            *a += wj * v;
        }
        if circular {
            s += wj * math::sin(xj[idx::THETA]);
            co += wj * math::cos(xj[idx::THETA]);
        }
    }
    acc[idx::THETA] = if circular {
        wrap_angle(math::atan2(s, co))
    } else {
        0.0
    };
    acc
}

impl<
        const COMPONENTS: usize,
        const PARTICLES: usize,
        const BLOCK_SUMS: usize,
        F: ?Sized + PowerMap,
    > Detector for CbmemberTbd<COMPONENTS, PARTICLES, BLOCK_SUMS, F>
{
    type Frame = F;
    type Config = CbmemberConfig;
    type Report = CbmemberReport;
    const STATE: &'static [&'static str] = &[
        "range_m",
        "velocity_m_per_s",
        "rho",
        "blade_speed_m_per_s",
        "omega_rad_per_s",
        "theta_rad",
    ];
    const SCORE: ScoreKind = ScoreKind::Existence;
    unconfigured_is_zero!();

    /// Validates `cfg` against the capacities and restarts in place from `seed`; works on
    /// an all-zero value (a `static` in `.bss`). On error `self` is unchanged.
    fn configure(&mut self, cfg: &CbmemberConfig, seed: u64) -> Result<()> {
        Self::check(cfg)?;
        self.cfg = *cfg;
        let bins = match cfg.likelihood {
            Likelihood::Blocked { bins } => bins,
            Likelihood::Exact => 1,
        };
        self.kernel = Kernel::new(&cfg.geometry, &cfg.spread, bins);
        self.dq = Dequant::new(cfg.noise_var, cfg.quant_step);
        self.c0 = cfg.gain * 0.5 / cfg.noise_var;
        self.reset(seed);
        Ok(())
    }

    fn config(&self) -> &CbmemberConfig {
        &self.cfg
    }

    /// Drops every component and reseeds (same configuration).
    fn reset(&mut self, seed: u64) {
        for c in self.comps.iter_mut() {
            c.live = false;
            c.n = 0;
            c.r = 0.0;
        }
        self.n_reported = 0;
        self.next_id = 1;
        self.frames = 0;
        self.has_peak = false;
        self.rng = Rng::seed_from_u64(seed);
    }

    fn step(&mut self, map: &F) -> Result<CbmemberReport> {
        self.step_map(map)
    }

    fn detection_count(&self) -> usize {
        self.n_reported
    }

    /// Reported component `i`: state `[r, v, rho, V, omega, theta]`, score = existence,
    /// track = (stable id, age in frames).
    fn detection(&self, i: usize) -> Option<Detection> {
        let e = self.reported(i)?;
        Some(Detection::new(
            e.state.get(..6).unwrap_or(&[]),
            e.existence,
            Some(TrackInfo {
                id: e.id,
                len: e.age,
            }),
        ))
    }
}
