//! CRPF-TBD: the cost-reference particle filter with an existence variable
//! (Lu, Wang, Zhang, Acta Electronica Sinica 45(6), 2017, §2.1-§2.2).
//!
//! Each particle carries `(x, E, C)`. No noise statistics are used anywhere: particles
//! are weighted by a monotone function of a cost.
//!
//! ```text
//! costs (eq. 11):   E = 1: C = lambda Cbar + ||z_k - h_k(x)||^p,  E = 0: C = lambda Cbar + ||z_k||^p
//! risks:            the same expression on the predicted particle
//! weights (eq. 4):  mu(R_i) = R_i^-q / sum_j R_j^-q
//!         (eq. 5):  mu(R_i) ∝ (R_i - min_j R_j + gamma)^-q
//! existence (eq. 9): Pb = P(E_k=1|E_{k-1}=0), Pd = P(E_k=0|E_{k-1}=1)
//! gate (eq. 10):    r = |<m_k, m_k^i>| / (||m_k|| ||m_k^i||),  m_k = [z_k, z_{k-1}],
//!                   m_k^i = [h_k(x_k^i), h_{k-1}(x_{k-1}^parent)];  r < r_th => E = 0, x = 0
//! existence (eq. 12): P_E^k = (1/N) sum_i E_k^i
//! phase unknown (ModelConfig::phase):
//!   cost:  ||z - h||^2 -> ||z||^2 - 2 |<z,h>| + ||h||^2   (minimised over the phase)
//!   gate:  r = (|<z_k,h_k>| + |<z_{k-1},h_{k-1}>|) / (||m_k|| ||m_k^i||)
//!          (maximised over the two frames' phases)
//! estimates (eq. 8): mean-cost sum_i x_i mu(C_i), min-cost x_argmin C  (over E = 1)
//! ```
//!
//! Steps per frame `k`: (2) predict every particle's existence by `Pi`, continuing ->
//! `F x`, born -> `U(I_x0)`, absent -> 0, and compute its risk; (3) resample the frame
//! `k-1` particles with `mu(R)` (systematic), keeping each copy's parent values; (4) draw
//! the existence again by `Pi`, jitter continuing particles `x ~ N(F xbar, Sigma)`, draw
//! births from `U(I_x0)`, apply the gate; (5) `P_E^k`.
//!
//! Implementation notes:
//! - The existence draws of eq. 9 for `E_{k-1} = 0` particles are made by geometric
//!   skipping ([`BirthGaps`]): in each pass the number of absent particles before the next
//!   birth is drawn once (exactly geometric with parameter `Pb`), so an absent particle
//!   that stays absent costs no draw. Present particles draw their death as before.
//! - All weights are computed in the log domain: `ln mu_i = -q ln R_i` (eq. 4) with
//!   `ln R_i = (p/2) ln ||.||^2` (or `logaddexp(ln lambda + ln Cbar, ...)`), then the
//!   maximum is subtracted before `exp`, so nothing overflows `f32` even with `p = 8`.
//!   When `lambda = 0`, eq. 4 is used and `q p / 2` is a whole number, the same
//!   normalised weights are computed without `ln`/`exp` as `(min ||.||^2 / ||.||^2)^(q p/2)`
//!   (the log-domain normalisation in closed form: the best particle gets weight 1).
//!   On that path each particle keeps its squared residual `d2 = C^(2/p)` instead of
//!   `ln C`, and the mean-cost estimate uses the same ratios `(d2_min / d2_i)^(q p/2)`,
//!   so a frame needs no `ln` or `exp` at all.
//! - The gate compares `|<m_k, m_k^i>|^2 >= r_th^2 ||m_k||^2 ||m_k^i||^2` (no square root;
//!   the quotient form is kept as a fallback if a product overflows `f32`).
//! - Continuing particles (risk and update) project through a per-frame
//!   [`ProjectionCache`]: `<z, h> = amp (A + frac D)` with `A`, `D` the five-bin sums of
//!   the table row's points and slopes against the frame, computed once per frame and
//!   (first bin, row), and `||h||^2 = amp^2 (H0 + frac (H1 + frac H2))` (see
//!   [`DopplerModel::project_cached`](crate::model::doppler::DopplerModel::project_cached));
//!   the same sums up to rounding (relative difference below 4e-6, test `crpf_model`).
//!   BirthGaps, spread over the band, project directly.
//! - `Sigma = diag(jitter_std^2)` (empirical, [`CrpfConfig::jitter_std`]).
//! - The parent's `<z_{k-1}, h_{k-1}>` and `||h_{k-1}||^2` needed by the gate were
//!   computed for its own cost one frame earlier; each particle stores them, so the gate
//!   costs no extra projection. A particle with `E = 0` has `x = 0`, hence `h = 0`. Before
//!   the first frame `z_0 = 0`.
//! - All-zero frame (documented recovery): squared norms are floored at
//!   `f32::MIN_POSITIVE`, so costs stay finite; the gate sees `||m_k|| = 0` only if both
//!   frames are zero, and then rejects (`r = 0`).
//! - `P(E_0 = 1)` is [`ModelConfig::initial_existence`](crate::model::doppler::ModelConfig).
//!
//! Memory: `N * 29` bytes of particles (28 B state, 1 B existence flag) plus `N * 12`
//! bytes of weights and ancestors and a 33 KB fixed part, the response table (11.7 KB)
//! and the projection cache (20 KB) (about 279 KB at `PARTICLES = 6000`): build
//! large instances in a `Box`, or zeroed in a `static` and set up by
//! [`Detector::configure`].

use crate::detect::interface::unconfigured_is_zero;
use crate::detect::{Detection, Detector, ScoreKind, Validate};
use crate::existence::{BirthGaps, ExistenceDraw};
use crate::math::{self, KahanSum};
use crate::model::doppler::{
    check_frame, finite_estimate, DopplerReport, Model, ModelConfig, Motion, Phase,
    ProjectionCache, DOPPLER_STATE, MAX_BINS,
};
use crate::particles::{gather_flagged, resample, systematic_with_sum, FlaggedState, Scheme};
use crate::rng::Rng;
use crate::{Complex32, Error, Result};

/// Resampling weight function `phi(R)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum Weighting {
    /// `phi(R) = R^-q` (eq. 4, the paper's choice).
    Power,
    /// `phi(R) = (R - min R + gamma)^-q`, `0 < gamma < 1` (eq. 5).
    Shifted {
        /// `gamma`.
        gamma: f32,
    },
}

/// Runtime values of CRPF-TBD.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct CrpfConfig {
    /// The shared OTHR model (observation, motion, existence chain, birth box). CRPF-TBD
    /// uses its motion `F` but not its process-noise levels.
    pub model: ModelConfig,
    /// Cost exponent `p` (paper: 8).
    pub p: f32,
    /// Weight exponent `q` (paper: "a positive integer", value not given; default 1).
    pub q: f32,
    /// Forgetting factor `lambda in [0, 1]` (paper: 0).
    pub lambda: f32,
    /// Weight function (paper: eq. 4).
    pub weighting: Weighting,
    /// Correlation gate threshold `r_th` (paper: 0.2).
    pub r_th: f32,
    /// Jitter standard deviations of `Sigma = diag(std^2)` for `[fd, fda, A]`
    /// (empirical; default `[0.1 Hz, 0.1 Hz/s, 0.02]`).
    pub jitter_std: [f32; 3],
}

impl CrpfConfig {
    /// The paper's values on the OTHR preset: `p = 8`, `q = 1`, `lambda = 0`, eq. 4,
    /// `r_th = 0.2`.
    pub fn othr() -> Self {
        Self {
            model: ModelConfig::othr(),
            p: 8.0,
            q: 1.0,
            lambda: 0.0,
            weighting: Weighting::Power,
            r_th: 0.2,
            jitter_std: [0.1, 0.1, 0.02],
        }
    }

    /// Checks every value and builds the model.
    pub(crate) fn build(&self) -> Result<Model> {
        self.check()?;
        self.model.build()
    }

    /// Checks every value and writes the model into `model` in place
    /// ([`ModelConfig::build_into`](crate::model::doppler::ModelConfig::build_into)); on
    /// error `model` is unchanged.
    pub(crate) fn build_into(&self, model: &mut Model) -> Result<()> {
        self.check()?;
        self.model.build_into(model)
    }

    /// Every error of [`CrpfConfig::build`], without building the response table.
    fn check(&self) -> Result<()> {
        if !(self.p.is_finite() && self.p > 0.0) {
            return Err(Error::InvalidConfig("cost exponent p"));
        }
        if !(self.q.is_finite() && self.q > 0.0) {
            return Err(Error::InvalidConfig("weight exponent q"));
        }
        if !(0.0..=1.0).contains(&self.lambda) {
            return Err(Error::InvalidConfig("forgetting factor lambda"));
        }
        if let Weighting::Shifted { gamma } = self.weighting {
            if !(gamma > 0.0 && gamma < 1.0) {
                return Err(Error::InvalidConfig("gamma of eq. 5"));
            }
        }
        if !(0.0..=1.0).contains(&self.r_th) {
            return Err(Error::InvalidConfig("correlation threshold r_th"));
        }
        let motion = self.model.check()?.motion;
        // At most one band width, one alias-free Doppler rate and the largest amplitude.
        let w = motion.band_width();
        let limits = [
            w,
            w / motion.dt,
            crate::model::doppler::max_amplitude(self.model.bins),
        ];
        if self
            .jitter_std
            .iter()
            .zip(limits)
            .any(|(s, l)| !(s.is_finite() && *s >= 0.0 && *s <= l))
        {
            return Err(Error::InvalidConfig(
                "jitter std (at most W, W / dT, 1e18 / m)",
            ));
        }
        Ok(())
    }
}

impl Validate for CrpfConfig {
    fn validate(&self) -> Result<()> {
        self.check()
    }
}

/// The state of one CRPF-TBD particle; its existence flag `E` lives in a separate array
/// ([`CrpfTbd`] keeps structure-of-arrays flags), so that an absent particle costs one
/// byte to move. When `lambda = 0` every `E = 0` particle has `x = 0`, `h = 0` and the
/// same cost, so its `Particle` is never read and is left stale (not written at all).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Particle {
    x: [f32; 3],
    /// `ln C` (`-inf` for `C = 0`); on the ln-free path (`int_exponent`), the squared
    /// residual `d2 = C^(2/p)` instead (0 before the first frame).
    log_c: f32,
    /// `<z, h(x)>` at the particle's own frame (0 if `E = 0`).
    zh: Complex32,
    /// `||h(x)||^2` at the particle's own frame (0 if `E = 0`).
    hh: f32,
}

impl FlaggedState for Particle {
    /// Field by field (a whole-struct copy inside one slice compiles to a `memmove` call
    /// per particle on the M4); the parent cost only when `lambda > 0` (`all`), the only
    /// case that reads it.
    #[inline(always)]
    fn copy_from(&mut self, s: &Self, all: bool) {
        self.x[0] = s.x[0];
        self.x[1] = s.x[1];
        self.x[2] = s.x[2];
        if all {
            self.log_c = s.log_c;
        }
        self.zh.re = s.zh.re;
        self.zh.im = s.zh.im;
        self.hh = s.hh;
    }
}

/// `ln C` of a squared residual `d2`, with forgetting of the parent cost (eq. 11).
#[inline]
fn log_cost(cfg: &CrpfConfig, d2: f32, parent_log_c: f32, ln_lambda: f32) -> f32 {
    let c = 0.5 * cfg.p * math::ln(d2);
    if cfg.lambda > 0.0 {
        math::log_add_exp(ln_lambda + parent_log_c, c)
    } else {
        c
    }
}

/// `x^n` for a small whole `n >= 1` by repeated squaring.
#[inline]
fn powi(x: f32, mut n: u32) -> f32 {
    // The usual exponents unrolled (same products, same rounding as the loop).
    match n {
        1 => return x,
        2 => return x * x,
        4 => {
            let x2 = x * x;
            return x2 * x2;
        }
        _ => {}
    }
    let mut acc = 1.0f32;
    let mut b = x;
    while n > 0 {
        if n & 1 == 1 {
            acc *= b;
        }
        b *= b;
        n >>= 1;
    }
    acc
}

/// `q p / 2` when the ln-free weight path applies (`lambda = 0`, eq. 4, whole `q p / 2`
/// in `1..=32`).
fn int_exponent(cfg: &CrpfConfig) -> Option<u32> {
    let e = cfg.q * cfg.p * 0.5;
    if cfg.lambda == 0.0
        && cfg.weighting == Weighting::Power
        && (1.0..=32.0).contains(&e)
        && math::round(e) == e
    {
        Some(e as u32)
    } else {
        None
    }
}

/// Eq. 9 for a particle that is not an absent one staying absent: present at `k - 1`
/// (`e`), one draw decides survival; absent with its birth gap run out, it is born and
/// the next gap is drawn into `left`.
#[inline(always)]
fn predicted_existence(
    draw: &ExistenceDraw,
    births: &BirthGaps,
    e: bool,
    rng: &mut Rng,
    left: &mut u32,
) -> bool {
    if e {
        draw.next(true, rng)
    } else {
        let (r, g) = births.gap(rng.clone());
        *rng = r;
        *left = g;
        true
    }
}

/// What step (4) needs for one particle that exists after the existence draw.
struct UpdateCtx<'a> {
    model: &'a Model,
    cfg: &'a CrpfConfig,
    z: &'a [Complex32],
    zz: f32,
    /// `||m_k||^2 = ||z_k||^2 + ||z_{k-1}||^2`.
    norm_m2: f32,
    r_th2: f32,
    ln_free: bool,
    ln_lambda: f32,
    zz_floor: f32,
    draw: &'a ExistenceDraw,
    births: &'a BirthGaps,
}

/// Step (4) over all particles, from birth gap `left`. Flags and states zipped: no index
/// bounds check. As in `risk_pass`, the loop handles only an absent particle that stays
/// absent; the rest is out of line. `KEEP` (`lambda > 0`, a constant so that the loop
/// tests no flag): absent particles get their state written. `U`: the phase is unknown
/// ([`Phase::Unknown`]; a constant, so the zero-phase path is the code it always was).
#[inline(always)]
fn update_loop<const KEEP: bool, const U: bool>(
    ctx: &UpdateCtx<'_>,
    st: &mut UpdateState<'_>,
    exists: &mut [bool],
    parts: &mut [Particle],
    mut left: u32,
) {
    for (i, (flag, slot)) in exists.iter_mut().zip(parts.iter_mut()).enumerate() {
        if !*flag && left > 0 {
            left -= 1;
            if KEEP {
                ctx.absent(slot);
            }
            continue;
        }
        left = ctx.other::<U>(st, flag, slot, i, left);
    }
}

/// What the update loop accumulates out of line.
struct UpdateState<'a> {
    rng: Rng,
    /// Present particles so far; their indices are in `anc[..count]`.
    count: usize,
    /// Smallest cost of a present particle and its index.
    best: f32,
    arg: Option<usize>,
    anc: &'a mut [u32],
    cache: &'a mut ProjectionCache,
}

impl UpdateCtx<'_> {
    /// An absent particle that stays absent when `lambda > 0`: `E = 0`, `x = 0`, `h = 0`,
    /// `C = lambda Cbar + ||z||^p`.
    #[cold]
    #[inline(never)]
    fn absent(&self, slot: &mut Particle) {
        *slot = Particle {
            x: [0.0; 3],
            log_c: log_cost(self.cfg, self.zz_floor, slot.log_c, self.ln_lambda),
            zh: Complex32::new(0.0, 0.0),
            hh: 0.0,
        };
    }

    /// Step (4) for particle `i` when it is present at `k - 1` (`*flag`), or absent with
    /// its birth gap run out (`left = 0`): the existence draw, then
    /// [`update_present`](Self::update_present) or [`absent`](Self::absent). Returns the
    /// new gap.
    #[inline(never)]
    fn other<const U: bool>(
        &self,
        st: &mut UpdateState<'_>,
        flag: &mut bool,
        slot: &mut Particle,
        i: usize,
        mut left: u32,
    ) -> u32 {
        let e = *flag;
        let mut rng = st.rng.clone();
        let present = predicted_existence(self.draw, self.births, e, &mut rng, &mut left);
        if present {
            let (r, log_c) = self.update_present::<U>(slot, e, rng, st.cache);
            rng = r;
            if let Some(log_c) = log_c {
                st.rng = rng;
                *flag = true;
                st.count += 1;
                if let Some(s) = st.anc.get_mut(st.count - 1) {
                    *s = i as u32;
                }
                if log_c < st.best {
                    st.best = log_c;
                    st.arg = Some(i);
                }
                return left;
            }
        }
        st.rng = rng;
        *flag = false;
        if self.cfg.lambda > 0.0 {
            self.absent(slot);
        }
        left
    }
    /// Step (4) for a particle with `E_k = 1`: jitter `x ~ N(F xbar, Sigma)` if it
    /// continues (`existed`), a birth from `U(I_x0)` otherwise, then the gate (eq. 10)
    /// and the cost. On a pass writes the new state into `slot` and returns its cost;
    /// on a rejection leaves `slot` untouched. Inlined into the out-of-line
    /// [`other`](Self::other) (one call layer per present particle, not two).
    #[inline(always)]
    fn update_present<const U: bool>(
        &self,
        slot: &mut Particle,
        existed: bool,
        mut rng: Rng,
        cache: &mut ProjectionCache,
    ) -> (Rng, Option<f32>) {
        let par = *slot;
        let motion = &self.model.motion;
        let js = self.cfg.jitter_std;
        let (x, par_zh, par_hh) = if existed {
            let xp = motion.predict(par.x);
            let a = xp[2] + js[2] * rng.normal();
            (
                [
                    motion.wrap(xp[0] + js[0] * rng.normal()),
                    xp[1] + js[1] * rng.normal(),
                    if a < 0.0 { -a } else { a },
                ],
                par.zh,
                par.hh,
            )
        } else {
            // Born: the parent had E = 0, so its zh, hh are 0.
            (
                self.model.prior.sample(&mut rng),
                Complex32::new(0.0, 0.0),
                0.0,
            )
        };
        let pr = if existed {
            self.model
                .obs
                .project_cached::<true>(cache, self.z, x[0], x[2])
        } else {
            self.model.obs.project(self.z, x[0], x[2])
        };
        // Gate (eq. 10). r >= r_th  <=>  |<m, m^i>|^2 >= r_th^2 ||m||^2 ||m^i||^2 (no sqrt).
        // Unknown phase: |<m, m^i>| maximised over the two frames' phases,
        // |<z_k, h_k>| + |<z_{k-1}, h_{k-1}>|.
        let r_th = self.cfg.r_th;
        let num2 = if U {
            let n = math::hypot(pr.zh.re, pr.zh.im) + math::hypot(par_zh.re, par_zh.im);
            n * n
        } else {
            (pr.zh + par_zh).norm_sqr()
        };
        let den2 = self.norm_m2 * (pr.hh + par_hh);
        let pass = if den2.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
            r_th <= 0.0 // r = 0
        } else if num2.is_finite() && den2.is_finite() {
            num2 >= self.r_th2 * den2
        } else {
            let num = if U {
                math::hypot(pr.zh.re, pr.zh.im) + math::hypot(par_zh.re, par_zh.im)
            } else {
                (pr.zh + par_zh).norm()
            };
            num / math::sqrt(den2) >= r_th
        };
        if !pass {
            return (rng, None);
        }
        let d2 = if U {
            pr.residual_norm2_unknown_phase(self.zz)
        } else {
            pr.residual_norm2(self.zz)
        };
        let log_c = if self.ln_free {
            d2
        } else {
            log_cost(self.cfg, d2, par.log_c, self.ln_lambda)
        };
        *slot = Particle {
            x,
            log_c,
            zh: pr.zh,
            hh: pr.hh,
        };
        (rng, Some(log_c))
    }
}

/// Step (2) for a particle with `E_k = 1` in the prediction: `||z - h(x)||^2` of `F x`
/// (`existed`) or of a birth from `U(I_x0)`. Inlined into the out-of-line
/// [`RiskCtx::other`].
#[inline(always)]
fn risk_present<const U: bool>(
    model: &Model,
    z: &[Complex32],
    zz: f32,
    x: &[f32; 3],
    existed: bool,
    mut rng: Rng,
    cache: &mut ProjectionCache,
) -> (Rng, f32) {
    let xp = if existed {
        model.motion.predict(*x)
    } else {
        model.prior.sample(&mut rng)
    };
    // BirthGaps land anywhere in the band: projected directly (a cache entry would be used
    // once).
    // Unknown phase (`U`): the cost needs |<z, h>|, the full projection.
    let pr = match (existed, U) {
        (true, false) => model.obs.project_cached::<false>(cache, z, xp[0], xp[2]),
        (true, true) => model.obs.project_cached::<true>(cache, z, xp[0], xp[2]),
        (false, false) => model.obs.project_re(z, xp[0], xp[2]),
        (false, true) => model.obs.project(z, xp[0], xp[2]),
    };
    let d2 = if U {
        pr.residual_norm2_unknown_phase(zz)
    } else {
        pr.residual_norm2(zz)
    };
    (rng, d2)
}

/// Step (2): the existence draw and the squared residual `||z - h||^2` of every
/// predicted particle into `out` (`||z||^2`, floored, for `E = 0`); returns the smallest.
/// Its own function so that the loop over mostly absent particles keeps the generator
/// and its pointers in registers.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn risk_pass<const U: bool>(
    model: &Model,
    z: &[Complex32],
    zz: f32,
    exists: &[bool],
    parts: &[Particle],
    out: &mut [f32],
    rng_out: &mut Rng,
    births: &BirthGaps,
    cache: &mut ProjectionCache,
) -> f32 {
    let zz_floor = zz.max(f32::MIN_POSITIVE);
    let draw_table = ExistenceDraw::new(&model.chain);
    // Through an opaque reference the two thresholds are read from memory by one
    // indexed load per particle, instead of being held in two (spilled) registers and
    // selected.
    let draw = core::hint::black_box(&draw_table);
    let (rng, mut left) = births.gap(rng_out.clone());
    let ctx = RiskCtx {
        model,
        z,
        zz,
        zz_floor,
        draw,
        births,
    };
    let mut st = RiskState {
        rng,
        dmin: f32::INFINITY,
        n_present: 0,
        cache,
    };
    let n = exists.len().min(out.len()).min(parts.len());
    // The loop itself handles only the common case, an absent particle that stays absent
    // (geometric skipping: one decrement, no draw); everything else is out of line with
    // the generator in memory, so the loop keeps three pointers, the counters and
    // `||z||^2` in registers.
    for ((&e, o), p) in exists.iter().zip(out.iter_mut()).zip(parts.iter()) {
        if !e && left > 0 {
            left -= 1;
            *o = zz_floor;
            continue;
        }
        let (l, v) = ctx.other::<U>(&mut st, e, &p.x, left);
        left = l;
        *o = v;
    }
    let mut dmin = st.dmin;
    if st.n_present < n && zz_floor < dmin {
        dmin = zz_floor;
    }
    *rng_out = st.rng;
    dmin
}

/// What the risk pass needs for a particle that is present at `k - 1` or is born.
struct RiskCtx<'a> {
    model: &'a Model,
    z: &'a [Complex32],
    zz: f32,
    zz_floor: f32,
    draw: &'a ExistenceDraw,
    births: &'a BirthGaps,
}

/// What the risk pass accumulates out of line.
struct RiskState<'a> {
    rng: Rng,
    dmin: f32,
    n_present: usize,
    cache: &'a mut ProjectionCache,
}

impl RiskCtx<'_> {
    /// A particle present at `k - 1` (`e`), or an absent one whose birth gap ran out
    /// (`left = 0`): its predicted existence, its residual (`||z||^2` floored if absent)
    /// and the new gap.
    #[inline(never)]
    fn other<const U: bool>(
        &self,
        st: &mut RiskState<'_>,
        e: bool,
        x: &[f32; 3],
        mut left: u32,
    ) -> (u32, f32) {
        let mut rng = st.rng.clone();
        let present = predicted_existence(self.draw, self.births, e, &mut rng, &mut left);
        let v = if present {
            let (r, d2) = risk_present::<U>(self.model, self.z, self.zz, x, e, rng, st.cache);
            rng = r;
            st.n_present += 1;
            // Not f32::min: that is a call to fminf on the M4 (no VMINNM); d2 is never
            // NaN.
            if d2 < st.dmin {
                st.dmin = d2;
            }
            d2
        } else {
            self.zz_floor
        };
        st.rng = rng;
        (left, v)
    }
}

/// CRPF-TBD with 1000 particles (the firmware's instruction table, the host's default).
pub type CrpfTbd1000 = CrpfTbd<1000>;
/// CRPF-TBD with 6000 particles (the paper's count; the host's largest).
pub type CrpfTbd6000 = CrpfTbd<6000>;

/// CRPF-TBD with `PARTICLES` particles (presets [`CrpfTbd1000`], [`CrpfTbd6000`]).
#[derive(Debug, Clone)]
pub struct CrpfTbd<const PARTICLES: usize> {
    cfg: CrpfConfig,
    model: Model,
    parts: [Particle; PARTICLES],
    /// `E` of each particle.
    exists: [bool; PARTICLES],
    /// Log risks, then log weights; reused as scratch.
    log_w: [f32; PARTICLES],
    w: [f32; PARTICLES],
    anc: [u32; PARTICLES],
    prev: [Complex32; MAX_BINS],
    prev_zz: f32,
    rng: Rng,
    frame: u32,
    /// `q p / 2` when the ln-free weight path applies.
    int_exponent: Option<u32>,
    /// The birth-gap sampler of the model's existence chain.
    births: BirthGaps,
    /// Per-frame projection sums.
    cache: ProjectionCache,
    /// The last frame's report.
    last: DopplerReport,
}

impl<const PARTICLES: usize> CrpfTbd<PARTICLES> {
    /// The unconfigured detector (a compile-time constant, [`Detector::UNCONFIGURED`]):
    /// every call but [`Detector::configure`] returns a typed error or nothing until a
    /// configuration succeeds. For a `static` or a `Box`.
    pub const fn new_unconfigured() -> Self {
        <Self as Detector>::UNCONFIGURED
    }

    /// Validates `cfg` and initialises the particles (step 1) from `seed`.
    pub fn new(cfg: CrpfConfig, seed: u64) -> Result<Self> {
        if PARTICLES == 0 {
            return Err(Error::InvalidConfig("particle count N = 0"));
        }
        if u32::try_from(PARTICLES).is_err() {
            return Err(Error::IndexOutOfRange);
        }
        let model = cfg.build()?;
        let int_exponent = int_exponent(&cfg);
        let births = BirthGaps::new(&model.chain);
        let mut s = Self {
            cfg,
            model,
            parts: [Particle::default(); PARTICLES],
            exists: [false; PARTICLES],
            log_w: [0.0; PARTICLES],
            w: [0.0; PARTICLES],
            anc: [0; PARTICLES],
            prev: [Complex32::new(0.0, 0.0); MAX_BINS],
            prev_zz: 0.0,
            rng: Rng::seed_from_u64(seed),
            frame: 0,
            int_exponent,
            births,
            cache: ProjectionCache::default(),
            last: DopplerReport::default(),
        };
        s.init_from(seed);
        Ok(s)
    }

    fn init_from(&mut self, seed: u64) {
        self.rng = Rng::seed_from_u64(seed);
        self.last = DopplerReport::default();
        self.init();
    }

    /// Frames processed since the last reset.
    pub fn frame(&self) -> u32 {
        self.frame
    }

    /// Step 1: `E_0^i ~ Bernoulli(P(E_0 = 1))`, `x ~ U(I_x0)` where `E = 1`, `C = 0`.
    fn init(&mut self) {
        let p0 = self.model.initial_existence;
        for (pt, flag) in self.parts.iter_mut().zip(self.exists.iter_mut()) {
            let e = self.rng.bernoulli(p0);
            *flag = e;
            *pt = Particle {
                x: if e {
                    self.model.prior.sample(&mut self.rng)
                } else {
                    [0.0; 3]
                },
                log_c: f32::NEG_INFINITY,
                zh: Complex32::new(0.0, 0.0),
                hh: 0.0,
            };
        }
        self.prev = [Complex32::new(0.0, 0.0); MAX_BINS];
        self.prev_zz = 0.0;
        self.frame = 0;
    }

    /// Steps (2)-(3): risks, weights, resampling. Leaves the resampled parents in
    /// `self.parts`.
    fn predict_and_resample(&mut self, z: &[Complex32], zz: f32, ln_lambda: f32) {
        // Squared residual of every predicted particle, and the smallest.
        // The phase model as a constant of the pass (one copy of the loop per model).
        let dmin = match self.model.phase {
            Phase::Zero => risk_pass::<false>(
                &self.model,
                z,
                zz,
                &self.exists,
                &self.parts,
                &mut self.log_w,
                &mut self.rng,
                &self.births,
                &mut self.cache,
            ),
            Phase::Unknown => risk_pass::<true>(
                &self.model,
                z,
                zz,
                &self.exists,
                &self.parts,
                &mut self.log_w,
                &mut self.rng,
                &self.births,
                &mut self.cache,
            ),
        };
        if let Some(n) = self.int_exponent {
            // w_i = (min d2 / d2_i)^(q p / 2): eq. 4 normalised by its largest weight,
            // summed on the way (the compensated sum `resample` would compute).
            let mut sum = KahanSum::new();
            if n == 4 {
                for (w, &d) in self.w.iter_mut().zip(self.log_w.iter()) {
                    let r = dmin / d;
                    let r2 = r * r;
                    *w = r2 * r2;
                    sum.add(*w);
                }
            } else {
                for (w, &d) in self.w.iter_mut().zip(self.log_w.iter()) {
                    *w = powi(dmin / d, n);
                    sum.add(*w);
                }
            }
            // Degenerate weights cannot occur (risks are floored and finite, so every
            // w_i is in [0, 1] and the best is 1); if they did, the particles are kept as
            // they are (identity resampling), as with `resample`'s errors below.
            if systematic_with_sum(
                &self.w,
                sum.value(),
                &mut self.log_w,
                &mut self.anc,
                &mut self.rng,
            ) {
                let all = self.cfg.lambda > 0.0;
                if all {
                    gather_flagged::<Particle, true>(&mut self.parts, &mut self.exists, &self.anc);
                } else {
                    gather_flagged::<Particle, false>(&mut self.parts, &mut self.exists, &self.anc);
                }
            }
            return;
        }
        let ok = {
            // ln R_i, then ln mu_i, all in the log domain.
            for (i, lr) in self.log_w.iter_mut().enumerate() {
                let half = 0.5 * self.cfg.p * math::ln(*lr);
                *lr = if self.cfg.lambda > 0.0 {
                    math::log_add_exp(ln_lambda + self.parts[i].log_c, half)
                } else {
                    half
                };
            }
            let q = self.cfg.q;
            match self.cfg.weighting {
                Weighting::Power => {
                    for lr in self.log_w.iter_mut() {
                        *lr *= -q;
                    }
                }
                Weighting::Shifted { gamma } => {
                    let lmin = self.log_w.iter().fold(f32::INFINITY, |a, &b| a.min(b));
                    let lg = math::ln(gamma);
                    for lr in self.log_w.iter_mut() {
                        // ln(R - Rmin) = ln Rmin + ln(expm1(ln R - ln Rmin))
                        let d = *lr - lmin;
                        let l_diff = if d > 30.0 {
                            lmin + d
                        } else if d > 0.0 {
                            lmin + math::ln(math::exp(d) - 1.0)
                        } else {
                            f32::NEG_INFINITY
                        };
                        *lr = -q * math::log_add_exp(l_diff, lg);
                    }
                }
            }
            math::normalize_log_weights(&self.log_w, &mut self.w).is_ok()
        };
        // Degenerate weights cannot occur (risks are floored and finite); if they did,
        // the particles are kept as they are (identity resampling).
        if ok && resample(Scheme::Systematic, &self.w, &mut self.anc, &mut self.rng).is_ok() {
            let all = self.cfg.lambda > 0.0;
            if all {
                gather_flagged::<Particle, true>(&mut self.parts, &mut self.exists, &self.anc);
            } else {
                gather_flagged::<Particle, false>(&mut self.parts, &mut self.exists, &self.anc);
            }
        }
    }

    fn step_inner(&mut self, z: &[Complex32]) -> Result<DopplerReport> {
        let m = self.model.obs.bins();
        let zz = check_frame(z, m)?;
        self.cache.new_frame();
        let ln_lambda = if self.cfg.lambda > 0.0 {
            math::ln(self.cfg.lambda)
        } else {
            f32::NEG_INFINITY
        };
        self.predict_and_resample(z, zz, ln_lambda);

        // Step (4): update existence, jitter / births, gate, costs.
        let zz_floor = zz.max(f32::MIN_POSITIVE);
        let draw_table = ExistenceDraw::new(&self.model.chain);
        let ctx = UpdateCtx {
            model: &self.model,
            cfg: &self.cfg,
            z,
            zz,
            zz_floor,
            norm_m2: zz + self.prev_zz,
            r_th2: self.cfg.r_th * self.cfg.r_th,
            ln_free: self.int_exponent.is_some(),
            ln_lambda,
            draw: &draw_table,
            births: &self.births,
        };
        // `anc` (free after resampling) collects the indices of the E = 1 particles, so
        // the estimates visit only those; the min-cost one is tracked too.
        let (rng, left) = ctx.births.gap(self.rng.clone());
        let mut st = UpdateState {
            rng,
            count: 0,
            best: f32::INFINITY,
            arg: None,
            anc: &mut self.anc,
            cache: &mut self.cache,
        };
        // With lambda = 0 an absent particle's state is never read again: only its flag
        // is written (and it is already `false`).
        let (keep, unknown) = (self.cfg.lambda > 0.0, self.model.phase == Phase::Unknown);
        let (ex, parts) = (&mut self.exists, &mut self.parts);
        match (keep, unknown) {
            (true, false) => update_loop::<true, false>(&ctx, &mut st, ex, parts, left),
            (false, false) => update_loop::<false, false>(&ctx, &mut st, ex, parts, left),
            (true, true) => update_loop::<true, true>(&ctx, &mut st, ex, parts, left),
            (false, true) => update_loop::<false, true>(&ctx, &mut st, ex, parts, left),
        }
        let (count, best, arg) = (st.count, st.best, st.arg);
        self.rng = st.rng;

        let (mean, min) = self.estimates(count, best, arg);
        // `z` has `m <= MAX_BINS` bins (checked above): the zip copies all of them.
        for (p, &v) in self.prev.iter_mut().zip(z) {
            *p = v;
        }
        self.prev_zz = zz;
        self.frame += 1;
        self.last = DopplerReport {
            frame: self.frame,
            existence: count as f32 / PARTICLES as f32,
            log_lr: 0.0,
            estimate: finite_estimate(mean),
            min_cost_estimate: finite_estimate(min),
        };
        Ok(self.last)
    }

    /// Mean-cost and min-cost estimates (eq. 8) over the `E = 1` particles, with
    /// `mu(C) = C^-q / sum C^-q` computed in the log domain.
    ///
    /// `self.anc[..count]` holds the indices of the `E = 1` particles, `best` / `arg` the
    /// smallest `log_c` among them and its index (both found by the update loop).
    fn estimates(
        &self,
        count: usize,
        best: f32,
        arg: Option<usize>,
    ) -> (Option<[f32; 3]>, Option<[f32; 3]>) {
        let (Some(best_x), Some(live)) = (
            arg.and_then(|a| self.parts.get(a)).map(|p| p.x),
            self.anc.get(..count),
        ) else {
            return (None, None);
        };
        // max of -q ln C is at the min cost (on the ln-free path `log_c` holds d2 and
        // mu_i = (d2_min / d2_i)^(q p / 2)).
        let q = self.cfg.q;
        let top = -q * best;
        let n = self.int_exponent;
        // Doppler is averaged relative to the min-cost particle so the wrap at the band
        // edge does not split the mean.
        let ref_fd = best_x[0];
        let width = self.model.motion.band_width();
        // One loop per weight form (the form is not re-tested per particle).
        let (s, acc) = match n {
            Some(4) => self.weighted_sums(live, ref_fd, width, |c| powi(best / c, 4)),
            Some(n) => self.weighted_sums(live, ref_fd, width, |c| powi(best / c, n)),
            None => self.weighted_sums(live, ref_fd, width, |c| math::exp(-q * c - top)),
        };
        // s >= 1 (the min-cost particle contributes exp(0)).
        let mean = [
            self.model.motion.wrap(ref_fd + acc[0] / s),
            acc[1] / s,
            acc[2] / s,
        ];
        (Some(mean), Some(best_x))
    }

    /// `sum_i w_i` and `sum_i w_i [fd_i - ref_fd (wrapped), fda_i, A_i]` over the particles
    /// `live`, `w_i = weight(log_c_i)`.
    #[inline(always)]
    fn weighted_sums(
        &self,
        live: &[u32],
        ref_fd: f32,
        width: f32,
        weight: impl Fn(f32) -> f32,
    ) -> (f32, [f32; 3]) {
        let mut s = 0.0f32;
        let mut acc = [0.0f32; 3];
        for p in live.iter().filter_map(|&i| self.parts.get(i as usize)) {
            let w = weight(p.log_c);
            acc[0] += w * Motion::wrap_offset(p.x[0], ref_fd, width);
            acc[1] += w * p.x[1];
            acc[2] += w * p.x[2];
            s += w;
        }
        (s, acc)
    }
}

impl<const PARTICLES: usize> Detector for CrpfTbd<PARTICLES> {
    type Frame = [Complex32];
    type Config = CrpfConfig;
    type Report = DopplerReport;
    const STATE: &'static [&'static str] = DOPPLER_STATE;
    const SCORE: ScoreKind = ScoreKind::Existence;
    unconfigured_is_zero!();

    /// Re-validates `cfg` and restarts in place from `seed` (as [`CrpfTbd::new`] would),
    /// without building a detector by value: how one that lives in a `static` (built by
    /// [`CrpfTbd::new_unconfigured`]) is set up. On error `self` is unchanged.
    fn configure(&mut self, cfg: &CrpfConfig, seed: u64) -> Result<()> {
        if PARTICLES == 0 {
            return Err(Error::InvalidConfig("particle count N = 0"));
        }
        if u32::try_from(PARTICLES).is_err() {
            return Err(Error::IndexOutOfRange);
        }
        // Checked, then written in place (the model's table is some 14 KB: no copy of it
        // goes through the stack).
        cfg.build_into(&mut self.model)?;
        self.int_exponent = int_exponent(cfg);
        self.births = BirthGaps::new(&self.model.chain);
        self.cfg = *cfg;
        self.init_from(seed);
        Ok(())
    }

    fn config(&self) -> &CrpfConfig {
        &self.cfg
    }

    fn reset(&mut self, seed: u64) {
        self.init_from(seed);
    }

    /// One frame. Errors (state untouched): [`Error::LengthMismatch`] for a frame that is
    /// not `m` bins, [`Error::NonFinite`] for NaN/inf samples.
    fn step(&mut self, frame: &[Complex32]) -> Result<DopplerReport> {
        self.step_inner(frame)
    }

    /// One detection per frame with an estimate: the mean-cost `[fd, fda, A]`, scored by
    /// the existence probability `P_E^k` (eq. 12).
    fn detection_count(&self) -> usize {
        usize::from(self.last.estimate.is_some())
    }

    fn detection(&self, i: usize) -> Option<Detection> {
        if i == 0 {
            self.last.detection(Self::SCORE)
        } else {
            None
        }
    }
}
