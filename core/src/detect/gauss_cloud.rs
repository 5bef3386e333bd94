//! The particle cloud the three Gaussian comparators share (PF-TBD, JOTT, PF-LRT): what
//! differs between them (existence handling, the statistic) stays in their own modules.
//!
//! ```text
//! reset:     x_i ~ draw(prior)                             (per detector: E_0, U(I_x0))
//! predict:   x_i <- move(x_i)   (per detector: F x + G v of eq. 16, births from U(I_x0))
//! weigh:     ln w_i = (2 Re<z,h(x_i)> - ||h(x_i)||^2) / s2   if x_i holds a target,
//!                   (phase unknown: ln I0(2 |<z,h(x_i)>| / s2) - ||h(x_i)||^2 / s2)
//!            ln w_i = 0                                       otherwise
//! normalise: w_i = exp(ln w_i - LSE),  LSE = ln sum_i exp(ln w_i)   (log domain)
//! estimate:  sum_i w_i x_i / sum_i w_i over the particles holding a target (band wrap)
//! resample:  systematic, then gather in place
//! ```
//! Noise model: independent complex Gaussian bins of variance `s2` ([`GaussConfig`]), or
//! with [`Likelihood::Window`] the window's correlated bins: each frame whitened first
//! (`z' = F W^-1 F^-1 z`, [`Whitener`]), the rectangular window's response `h'` and the
//! per-bin variance `m s2 / sum w^2` in the formulas above.

use crate::detect::Validate;
use crate::math;
use crate::model::doppler::{
    check_frame, CheckedModel, DopplerReport, Likelihood, Model, ModelConfig, Motion, Phase,
    Whitener, Window,
};
use crate::particles::{gather_in_place, resample, Scheme};
use crate::rng::Rng;
use crate::{Complex32, Error, Result};

/// How PF-TBD and JOTT propose their births; the target law (the predicted density) is
/// the same for both, only the importance proposal differs. PF-LRT has no births and
/// ignores it.
///
/// ```text
/// Exact:          JOTT: each particle a birth with probability rho = Pb (1 - q) / q_{k|k-1};
///                 PF-TBD: each absent particle born with probability Pb (eq. 9 chain)
/// FixedShare(s):  B = round(s N) clamped to 1..=N-1 birth particles from U(I_x0) every
///                 frame in systematically spread slots, the other N - B persisting,
///                 importance weights carrying the masses (see the two detectors)
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "kebab-case")
)]
pub enum BirthProposal {
    // The firmware's zero-initialised statics hold an all-zero `GaussConfig` until
    // `configure` installs a validated one; the const evaluator accepts it (the build
    // fails if an all-zero value is not a valid enum value).
    /// Births sampled in their exact proportion (the preset; bit-identical to the
    /// detectors before the option existed).
    #[default]
    Exact,
    /// A fixed share `s` of the particles, `0 < s < 1`, proposed as births every frame
    /// (needs `N >= 2`); `B = round(s N)` clamped to `1..=N-1`.
    FixedShare(f32),
}

impl BirthProposal {
    /// `B` for `N` particles: `None` for [`Exact`](Self::Exact). Errors
    /// ([`Error::InvalidConfig`]): a share that is not finite or not in `(0, 1)`, or
    /// `N < 2` with a fixed share.
    pub fn birth_count<const N: usize>(&self) -> Result<Option<u32>> {
        match *self {
            BirthProposal::Exact => Ok(None),
            BirthProposal::FixedShare(s) => {
                if !(s.is_finite() && s > 0.0 && s < 1.0) {
                    return Err(Error::InvalidConfig(
                        "birth proposal share must be finite and in (0, 1)",
                    ));
                }
                let n = match u32::try_from(N) {
                    Ok(n) if (2..=1 << 31).contains(&n) => n,
                    _ => {
                        return Err(Error::InvalidConfig(
                            "fixed-share birth proposal needs 2 <= N <= 2^31 particles",
                        ))
                    }
                };
                // s N in (0, N): the saturating conversion lands in 0..=N.
                let b = math::round(s * N as f32) as u32;
                Ok(Some(b.clamp(1, n - 1)))
            }
        }
    }
}

/// Runtime values shared by the Gaussian comparators (PF-TBD, JOTT, PF-LRT).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct GaussConfig {
    /// The shared OTHR model; the process noise is used as given.
    pub model: ModelConfig,
    /// Per-bin complex noise variance `s2 = E|w_b|^2` (> 0).
    pub noise_var: f32,
    /// Birth proposal of PF-TBD and JOTT (ignored by PF-LRT); absent in serialised
    /// configurations means [`BirthProposal::Exact`].
    #[cfg_attr(feature = "serde", serde(default))]
    pub birth: BirthProposal,
    /// The bins' noise model ([`Likelihood`]): `independent` (Lu, Wang, Zhang 2017; the
    /// presets) or `window` (the window's bin covariance, exact for windowed frames;
    /// `faint detect`'s default). Absent in serialised configurations means
    /// `independent`, the model of every file written before the option existed.
    #[cfg_attr(feature = "serde", serde(default))]
    pub likelihood: Likelihood,
}

impl GaussConfig {
    /// OTHR preset with a given noise variance (exact birth proposal).
    pub fn othr(noise_var: f32) -> Self {
        Self {
            model: ModelConfig::othr(),
            noise_var,
            birth: BirthProposal::Exact,
            likelihood: Likelihood::Independent,
        }
    }

    /// Whether frames are whitened: [`Likelihood::Window`] with a window that is not
    /// rectangular (for the rectangular window the two likelihoods coincide).
    pub fn whitens(&self) -> bool {
        self.likelihood == Likelihood::Window && self.model.window != Window::Rectangular
    }

    /// The model the particles are weighed with: the configured one, with the
    /// rectangular window's response when frames are whitened.
    fn weighing_model(&self) -> ModelConfig {
        let mut m = self.model;
        if self.whitens() {
            m.window = Window::Rectangular;
        }
        m
    }

    /// `1 / s2` of the bins the particles are weighed against: `1 / noise_var`, or for
    /// whitened frames `sum w^2 / (m noise_var)` (`noise_var` is the windowed bins'
    /// variance `s2t sum w^2`, a whitened bin's is `m s2t`). Errors
    /// ([`Error::InvalidConfig`]) as [`check_variance`], or an inverse that is not finite
    /// and positive.
    fn weighing_inv_var(&self, v: f32) -> Result<f32> {
        let inv = check_variance(v)?;
        if !self.whitens() {
            return Ok(inv);
        }
        let m = self.model.bins.max(1);
        let r = (f64::from(inv) * self.model.window.energy(m) / m as f64) as f32;
        if r.is_finite() && r > 0.0 {
            Ok(r)
        } else {
            Err(Error::InvalidConfig(
                "noise variance must be finite and > 0",
            ))
        }
    }

    /// Checks the variance and builds the model.
    pub(crate) fn build(&self) -> Result<Model> {
        check_variance(self.noise_var)?;
        self.weighing_model().build()
    }

    /// What every Gaussian comparator's `new` / `configure` checks: `N > 0`, a valid
    /// birth proposal for `N`, the weighing model's values (its table is not built) and
    /// the weighing `1 / s2`. Returns the checked model and `1 / s2`.
    pub(crate) fn prepare<const N: usize>(&self) -> Result<(CheckedModel, f32)> {
        if N == 0 {
            return Err(Error::InvalidConfig("particle count N = 0"));
        }
        self.birth.birth_count::<N>()?;
        check_variance(self.noise_var)?;
        let model = self.weighing_model().check()?;
        Ok((model, self.weighing_inv_var(self.noise_var)?))
    }
}

impl Validate for GaussConfig {
    fn validate(&self) -> Result<()> {
        check_variance(self.noise_var)?;
        self.weighing_model().check()?;
        self.weighing_inv_var(self.noise_var)?;
        Whitener::check(self.likelihood, self.model.window, self.model.bins)
    }
}

/// `1 / v` for a finite variance `v > 0` whose inverse is finite.
fn check_variance(v: f32) -> Result<f32> {
    if v.is_finite() && v > 0.0 && (1.0 / v).is_finite() {
        Ok(1.0 / v)
    } else {
        Err(Error::InvalidConfig(
            "noise variance must be finite and > 0",
        ))
    }
}

/// `ln x` for a probability mass `x`: `-inf` for `x <= 0` (or NaN), whatever the `ln`
/// implementation does at 0.
pub(crate) fn log_mass(x: f32) -> f32 {
    if x > 0.0 {
        math::ln(x)
    } else {
        f32::NEG_INFINITY
    }
}

/// A target's log likelihood ratio against the frame under the model's phase:
/// `(2 Re<z,h> - ||h||^2) / s2` (zero phase; `Re <z,h>` only) or the Rician
/// `ln I0(2 |<z,h>| / s2) - ||h||^2 / s2` (unknown phase; the full projection).
/// `U`: the phase is unknown ([`Phase::Unknown`]; a constant of the frame's loop).
#[inline(always)]
fn log_lr_of<const U: bool>(m: &Model, z: &[Complex32], x: [f32; 3], inv_var: f32) -> f32 {
    if U {
        m.obs.project(z, x[0], x[2]).log_lr_unknown_phase(inv_var)
    } else {
        m.obs.project_re(z, x[0], x[2]).log_lr(inv_var)
    }
}

/// Weighted mean of states with Doppler averaged around a reference (band wrap).
fn weighted_mean(
    model: &Model,
    xs: impl Iterator<Item = ([f32; 3], f32)> + Clone,
) -> Option<[f32; 3]> {
    let mut best = -1.0f32;
    let mut reference = 0.0f32;
    for (x, w) in xs.clone() {
        if w > best {
            best = w;
            reference = x[0];
        }
    }
    if best <= 0.0 {
        return None;
    }
    let width = model.motion.band_width();
    let mut s = 0.0f32;
    let mut acc = [0.0f32; 3];
    for (x, w) in xs {
        let d = Motion::wrap_offset(x[0], reference, width);
        acc[0] += w * d;
        acc[1] += w * x[1];
        acc[2] += w * x[2];
        s += w;
    }
    if s > 0.0 {
        Some([
            model.motion.wrap(reference + acc[0] / s),
            acc[1] / s,
            acc[2] / s,
        ])
    } else {
        None
    }
}

/// One particle of a [`GaussianCloud`]: a state `[fd, fda, A]`, possibly tagged "no
/// target" (PF-TBD's `E = 0`).
pub(crate) trait CloudParticle: Copy + Default {
    /// The state if the particle holds a target, `None` if not (log weight 0, left out of
    /// the estimate).
    fn target(&self) -> Option<[f32; 3]>;
}

impl CloudParticle for [f32; 3] {
    #[inline]
    fn target(&self) -> Option<[f32; 3]> {
        Some(*self)
    }
}

/// `N` particles of type `P` with their log weights, weights and ancestors, the model,
/// `1 / s2`, the random stream and the frame count.
///
/// The field order is fixed (`repr(C)`, model and scalars first): the layout moves the
/// firmware's per-particle instruction counts by up to 2 %, and this order keeps all three
/// comparators within 0.5 % of their counts before the cloud was shared.
#[derive(Debug, Clone)]
#[repr(C)]
pub(crate) struct GaussianCloud<P, const N: usize> {
    model: Model,
    inv_var: f32,
    rng: Rng,
    frame: u32,
    cfg: GaussConfig,
    parts: [P; N],
    log_w: [f32; N],
    w: [f32; N],
    anc: [u32; N],
    last: DopplerReport,
    white: Whitener,
}

/// The fields a frame's weighing loop borrows (the frame may borrow the whitener).
struct Weigh<'a, P, const N: usize> {
    model: &'a Model,
    inv_var: f32,
    rng: &'a mut Rng,
    parts: &'a mut [P; N],
    log_w: &'a mut [f32; N],
}

impl<P: CloudParticle, const N: usize> GaussianCloud<P, N> {
    /// Validates `cfg`; particles are default until [`reset`](Self::reset).
    pub(crate) fn new(cfg: GaussConfig) -> Result<Self> {
        let (_, inv_var) = cfg.prepare::<N>()?;
        let model = cfg.build()?;
        let mut white = Whitener::inactive();
        white.configure(cfg.likelihood, cfg.model.window, cfg.model.bins)?;
        Ok(Self {
            white,
            cfg,
            model,
            inv_var,
            parts: [P::default(); N],
            log_w: [0.0; N],
            w: [0.0; N],
            anc: [0; N],
            rng: Rng::seed_from_u64(0),
            frame: 0,
            last: DopplerReport::default(),
        })
    }

    /// Re-validates `cfg` and installs it; on error `self` is unchanged. The caller
    /// [`reset`](Self::reset)s next.
    pub(crate) fn reconfigure(&mut self, cfg: GaussConfig) -> Result<()> {
        let (model, inv_var) = cfg.prepare::<N>()?;
        // Validates before it writes: on error nothing has changed.
        self.white
            .configure(cfg.likelihood, cfg.model.window, cfg.model.bins)?;
        self.cfg = cfg;
        // In place: the model's table (some 14 KB) is not built on the stack, and is kept
        // when it is already the one for these bins, sample interval and window.
        model.write_into(&mut self.model);
        self.inv_var = inv_var;
        Ok(())
    }

    /// Sets the assumed per-bin noise variance of the (windowed) frames.
    pub(crate) fn set_noise_variance(&mut self, v: f32) -> Result<()> {
        self.inv_var = self.cfg.weighing_inv_var(v)?;
        self.cfg.noise_var = v;
        Ok(())
    }

    /// Reseeds the stream from `seed`, redraws every particle with `draw`, frame 0.
    pub(crate) fn reset(&mut self, seed: u64, mut draw: impl FnMut(&Model, &mut Rng) -> P) {
        self.rng = Rng::seed_from_u64(seed);
        for p in self.parts.iter_mut() {
            *p = draw(&self.model, &mut self.rng);
        }
        self.frame = 0;
        self.last = DopplerReport::default();
    }

    /// The configuration.
    pub(crate) fn config(&self) -> &GaussConfig {
        &self.cfg
    }

    /// The last frame's report.
    pub(crate) fn last(&self) -> &DopplerReport {
        &self.last
    }

    /// The built model.
    pub(crate) fn model(&self) -> &Model {
        &self.model
    }

    /// Frames processed since the last reset.
    pub(crate) fn frame(&self) -> u32 {
        self.frame
    }

    /// Checks the frame ([`check_frame`]; on error nothing changes), then per particle:
    /// `step` moves it, and its log weight becomes the Gaussian log likelihood ratio
    /// `(2 Re<z,h> - ||h||^2) / s2` over the response bins (0 without a target).
    pub(crate) fn predict_and_weigh(
        &mut self,
        z: &[Complex32],
        mut step: impl FnMut(&mut P, &Model, &mut Rng),
    ) -> Result<()> {
        let (z, w) = self.frame_and_loop(z)?;
        // The phase model as a constant of the loop (one copy per model).
        match w.model.phase {
            Phase::Zero => Self::weigh_all::<false>(w, z, &mut step),
            Phase::Unknown => Self::weigh_all::<true>(w, z, &mut step),
        }
        Ok(())
    }

    /// Checks the frame ([`check_frame`]), whitens it when the likelihood says so
    /// ([`Whitener::apply`]); returns it with the weighing loop's fields. On error nothing
    /// but the whitener's scratch frame has changed.
    fn frame_and_loop<'a>(
        &'a mut self,
        z: &'a [Complex32],
    ) -> Result<(&'a [Complex32], Weigh<'a, P, N>)> {
        check_frame(z, self.model.obs.bins())?;
        let z = self.white.apply(z)?;
        Ok((
            z,
            Weigh {
                model: &self.model,
                inv_var: self.inv_var,
                rng: &mut self.rng,
                parts: &mut self.parts,
                log_w: &mut self.log_w,
            },
        ))
    }

    /// The loop of [`predict_and_weigh`](Self::predict_and_weigh) for the phase model `U`
    /// (its own function: the detectors' step stays the size it was).
    #[inline(never)]
    fn weigh_all<const U: bool>(
        w: Weigh<'_, P, N>,
        z: &[Complex32],
        step: &mut impl FnMut(&mut P, &Model, &mut Rng),
    ) {
        let m = w.model;
        for (p, lw) in w.parts.iter_mut().zip(w.log_w.iter_mut()) {
            step(p, m, w.rng);
            *lw = match p.target() {
                Some(x) => log_lr_of::<U>(m, z, x, w.inv_var),
                None => 0.0,
            };
        }
    }

    /// [`predict_and_weigh`](Self::predict_and_weigh) for a fixed-share birth proposal:
    /// of the `N` slots exactly `births` (`1..N`, validated by
    /// [`BirthProposal::birth_count`]) are birth slots, spread systematically over the
    /// (resampled, ancestor-sorted) array: with one offset `o` uniform on `0..N`, slot `i`
    /// is a birth slot iff `floor((o + (i+1) B) / N) > floor((o + i B) / N)`, so each slot
    /// is one with probability `B / N` and the other `N - B` are a systematic subsample of
    /// the previous particles. `step(p, birth_slot, m, rng)` moves a particle and returns
    /// its log prior weight `ln v_i`; its log weight becomes
    /// `ln v_i + (2 Re<z,h> - ||h||^2) / s2` (`ln v_i` without a target).
    pub(crate) fn predict_and_weigh_split(
        &mut self,
        z: &[Complex32],
        births: u32,
        mut step: impl FnMut(&mut P, bool, &Model, &mut Rng) -> f32,
    ) -> Result<()> {
        let (z, w) = self.frame_and_loop(z)?;
        match w.model.phase {
            Phase::Zero => Self::weigh_split::<false>(w, z, births, &mut step),
            Phase::Unknown => Self::weigh_split::<true>(w, z, births, &mut step),
        }
        Ok(())
    }

    /// The loop of [`predict_and_weigh_split`](Self::predict_and_weigh_split) for the
    /// phase model `U` (its own function, as `weigh_all`).
    #[inline(never)]
    fn weigh_split<const U: bool>(
        w: Weigh<'_, P, N>,
        z: &[Complex32],
        births: u32,
        step: &mut impl FnMut(&mut P, bool, &Model, &mut Rng) -> f32,
    ) {
        let m = w.model;
        // 2 <= N <= 2^31 and births < N (birth_count): acc + births < 2^32, and acc stays
        // below N after each step.
        let n = N as u32;
        let mut acc = w.rng.below(n);
        for (p, lw) in w.parts.iter_mut().zip(w.log_w.iter_mut()) {
            acc += births;
            let birth_slot = acc >= n;
            if birth_slot {
                acc -= n;
            }
            let prior = step(p, birth_slot, m, w.rng);
            *lw = match p.target() {
                Some(x) => prior + log_lr_of::<U>(m, z, x, w.inv_var),
                None => prior,
            };
        }
    }

    /// Particles without a target.
    pub(crate) fn absent_count(&self) -> usize {
        self.parts.iter().filter(|p| p.target().is_none()).count()
    }

    /// Normalises the log weights; returns `LSE = ln sum_i exp(ln w_i)`. Log weights are
    /// finite (finite frame, finite variance), so this cannot fail; the documented fallback
    /// is uniform weights and `None`.
    pub(crate) fn normalise(&mut self) -> Option<f32> {
        match math::normalize_log_weights(&self.log_w, &mut self.w) {
            Ok(lse) => Some(lse),
            Err(_) => {
                self.w = [1.0 / N as f32; N];
                None
            }
        }
    }

    /// `sum_i w_i` over the particles holding a target.
    pub(crate) fn target_mass(&self) -> f32 {
        let mut mass = 0.0f32;
        for (p, &w) in self.parts.iter().zip(self.w.iter()) {
            if p.target().is_some() {
                mass += w;
            }
        }
        mass
    }

    /// Ends the frame: the weighted-mean estimate, systematic resampling, gather; the
    /// report carries `existence` and `log_lr` as the detector computed them.
    pub(crate) fn finish(&mut self, existence: f32, log_lr: f32) -> DopplerReport {
        let est = weighted_mean(
            &self.model,
            self.parts
                .iter()
                .zip(self.w.iter())
                .filter_map(|(p, &w)| p.target().map(|x| (x, w))),
        );
        if resample(Scheme::Systematic, &self.w, &mut self.anc, &mut self.rng).is_ok() {
            let _ = gather_in_place(&mut self.parts, &self.anc);
        }
        self.frame += 1;
        self.last = DopplerReport {
            frame: self.frame,
            existence,
            log_lr,
            estimate: crate::model::doppler::finite_estimate(est),
            min_cost_estimate: None,
        };
        self.last
    }
}

/// What every Gaussian comparator shares, written once: the inherent `new` (validate
/// `cfg`, then reset from `seed`) and `set_noise_variance`, and the whole
/// [`Detector`](crate::detect::Detector) impl. `$t` is a `struct $t<const N: usize>` with
/// a field `cloud: GaussianCloud<_, N>` and inherent `advance(&mut self, z)` (one frame)
/// and `restart(&mut self, seed)` (reset); `$field: $init` give its other fields' values
/// before the reset; `$new_doc` is `new`'s doc line; `$score` the detections' score.
macro_rules! gauss_detector {
    ($t:ident { $($field:ident: $init:expr),* }, $new_doc:literal, $score:expr) => {
        impl<const N: usize> $t<N> {
            /// The unconfigured detector (a compile-time constant,
            /// [`Detector::UNCONFIGURED`](crate::detect::Detector::UNCONFIGURED)): every
            /// call but `configure` returns a typed error or nothing until a
            /// configuration succeeds. For a `static` or a `Box`.
            pub const fn new_unconfigured() -> Self {
                <Self as $crate::detect::Detector>::UNCONFIGURED
            }

            #[doc = $new_doc]
            pub fn new(
                cfg: $crate::detect::pf_tbd::GaussConfig,
                seed: u64,
            ) -> $crate::Result<Self> {
                let mut s = Self {
                    cloud: $crate::detect::gauss_cloud::GaussianCloud::new(cfg)?,
                    $($field: $init),*
                };
                s.restart(seed);
                Ok(s)
            }

            /// Sets the assumed per-bin noise variance (e.g. estimated from the K frames).
            pub fn set_noise_variance(&mut self, v: f32) -> $crate::Result<()> {
                self.cloud.set_noise_variance(v)
            }
        }

        impl<const N: usize> $crate::detect::Detector for $t<N> {
            type Frame = [$crate::Complex32];
            type Config = $crate::detect::pf_tbd::GaussConfig;
            type Report = $crate::model::doppler::DopplerReport;
            const STATE: &'static [&'static str] = $crate::model::doppler::DOPPLER_STATE;
            const SCORE: $crate::detect::ScoreKind = $score;
            $crate::detect::interface::unconfigured_is_zero!();

            /// Re-validates `cfg` and restarts in place from `seed` (as `new` would),
            /// without building a detector by value: how one that lives in a `static`
            /// (built by `new_unconfigured`) is set up. On error `self` is unchanged.
            fn configure(
                &mut self,
                cfg: &$crate::detect::pf_tbd::GaussConfig,
                seed: u64,
            ) -> $crate::Result<()> {
                self.cloud.reconfigure(*cfg)?;
                self.restart(seed);
                Ok(())
            }

            fn config(&self) -> &$crate::detect::pf_tbd::GaussConfig {
                self.cloud.config()
            }

            fn reset(&mut self, seed: u64) {
                self.restart(seed);
            }

            /// One frame; errors as
            /// [`check_frame`](crate::model::doppler::check_frame) (state untouched).
            fn step(
                &mut self,
                z: &[$crate::Complex32],
            ) -> $crate::Result<$crate::model::doppler::DopplerReport> {
                self.advance(z)
            }

            /// One detection per frame with an estimate: the posterior-mean
            /// `[fd, fda, A]`.
            fn detection_count(&self) -> usize {
                usize::from(self.cloud.last().estimate.is_some())
            }

            fn detection(&self, i: usize) -> Option<$crate::detect::Detection> {
                if i == 0 {
                    self.cloud.last().detection(Self::SCORE)
                } else {
                    None
                }
            }
        }
    };
}
pub(crate) use gauss_detector;
