//! Observation and motion model of the sky-wave OTHR scenario (Lu, Wang, Zhang 2017, §3).
//!
//! State `x = [fd, fda, A]`: Doppler (Hz), Doppler rate (Hz/s), amplitude.
//!
//! ```text
//! x_k = F x_{k-1} + G v_{k-1},  F = [[1, dT, 0], [0, 1, 0], [0, 0, 1]],
//!                               G = [[dT^2/2, 0], [dT, 0], [0, dT]]         (eq. 16)
//! z_k = DFT_W(A_k exp(j 2 pi fd_k n ts) + wbar_k),  n = 0..m-1               (eq. 17)
//! ```
//!
//! # The observation `h_k(x)` without an FFT per particle
//! With `z_b = sum_n w_n s_n exp(-j 2 pi b n / m)` and `nu = fd ts` (cycles per sample),
//! the target's response in bin `b` is `h_b = A W(nu - b/m)`, where
//! `W(theta) = sum_n w_n exp(j 2 pi theta n)` is the window's DTFT. Writing
//! `fd ts m = b0 + delta` (`b0` the nearest bin, `|delta| <= 1/2`), bin `b0 + j` sees
//! `A W((delta - j)/m)`. The model keeps a table of `W(u/m)` for
//! `u in [-(J + 1/2), J + 1/2]`, [`TABLE_STEPS`] points per bin, computed once in `f64`,
//! and evaluates only the `2J + 1` bins around the peak ([`SPAN`] = 5, `J = 2`) by linear
//! interpolation (all five bins share one interpolation fraction). A particle's cost then
//! needs only
//!
//! ```text
//! ||z - h||^2 = ||z||^2 - 2 Re <z, h> + ||h||^2,   <z, h> = sum_b conj(z_b) h_b
//! ```
//!
//! over those five bins ([`DopplerModel::project`]). With an unknown phase per frame
//! ([`Phase::Unknown`], `A e^{j phi}` in eq. 17) the cost is the minimum over `phi`,
//! `||z||^2 - 2 |<z, h>| + ||h||^2`, and the Gaussian likelihood ratio its average,
//! `ln I0(2 |<z, h>| / s2) - ||h||^2 / s2` ([`Projection`]).
//!
//! Within one frame the five-bin sums of a table row are linear in the interpolation
//! fraction `f`:
//! `<z, h> / A = sum_j conj(z_j) a_j + f sum_j conj(z_j) d_j` (`a_j`, `d_j` the row's
//! points and slopes) and `||h||^2 / A^2 = H0 + f (H1 + f H2)` (per row, computed once in
//! `f64`), so [`DopplerModel::project_cached`] keeps the two complex sums per (first bin,
//! row) in a [`ProjectionCache`] filled on first use in each frame.
//!
//! # Approximation error (stated bound, checked by `tests/crpf_model.rs`)
//! Two sources: (1) the window's energy outside the five bins nearest the peak (the
//! symmetric 32-point Hamming window's side lobes summed over the other 27 bins; worst
//! when the target sits half-way between bins and one of the two bins 2.5 bins away is
//! left out), and (2) the linear interpolation of the table (step 1/128 bin, the phase
//! of `W` turns by about pi per bin, so the chord error is about
//! `(pi/128)^2 / 8 = 8e-5` of the value). Against the exact windowed DFT over all `m`
//! bins computed in `f64`, the relative error `||h_approx - h_exact|| / ||h_exact||` is
//! below [`RESPONSE_ERROR_BOUND`] = 3e-2 for every Doppler in the band (Hamming, `m = 32`;
//! measured maximum 2.65e-2, i.e. at most 7e-4 = -31 dB of the target's energy is left
//! out); the test scans 20 000 Doppler values. In a cost this is a bias of at most
//! `2 ||z|| ||h|| 3e-2` on `||z - h||^2`.

mod cache;
mod motion;
mod response;
mod whiten;

pub use cache::ProjectionCache;
pub use motion::{Motion, PriorBox};
pub use response::{
    dtft, DopplerModel, Phase, Projection, Window, HALF_SPAN, MAX_BINS, RESPONSE_ERROR_BOUND, SPAN,
    TABLE_STEPS,
};
pub use whiten::{unwindow, Likelihood, Whitener, MIN_WINDOW_COEFFICIENT};

use crate::{Complex32, Error, Result};

/// Validates a frame: `m` bins ([`Error::LengthMismatch`]; `m = 0`, e.g. an
/// unconfigured detector's, is [`Error::InvalidConfig`]), all finite
/// ([`Error::NonFinite`]), with a finite energy ([`Error::Overflow`]). Returns `||z||^2`.
pub fn check_frame(z: &[Complex32], m: usize) -> Result<f32> {
    if z.len() != m || m == 0 {
        return Err(if m == 0 {
            Error::InvalidConfig("bins per frame = 0")
        } else {
            Error::LengthMismatch {
                expected: m,
                got: z.len(),
            }
        });
    }
    let mut zz = 0.0f32;
    for c in z {
        if !(c.re.is_finite() && c.im.is_finite()) {
            return Err(Error::NonFinite);
        }
        zz += c.re * c.re + c.im * c.im;
    }
    if !zz.is_finite() {
        return Err(Error::Overflow);
    }
    Ok(zz)
}

/// Per-bin noise variance estimated from frames, `s2 = sum_k ||z_k||^2 / (K m)` (what the
/// Gaussian comparators assume when the statistics are "unknown"; the paper estimates it
/// from all K frames). Errors: [`Error::Empty`] for no frames, the errors of
/// [`check_frame`], [`Error::Overflow`] if the frames' total energy overflows, and
/// [`Error::InvalidConfig`] if the estimate is zero (all-zero frames).
pub fn estimate_noise_variance<'a>(
    frames: impl IntoIterator<Item = &'a [Complex32]>,
    m: usize,
) -> Result<f32> {
    let mut total = 0.0f32;
    let mut k = 0usize;
    for z in frames {
        total += check_frame(z, m)?;
        k += 1;
    }
    if k == 0 {
        return Err(Error::Empty);
    }
    if !total.is_finite() {
        return Err(Error::Overflow);
    }
    let v = total / (k * m) as f32;
    if !(v.is_finite() && v > 0.0) {
        return Err(Error::InvalidConfig("noise variance estimate is zero"));
    }
    Ok(v)
}

/// The state-space model every OTHR detector shares (observation, motion, existence
/// chain, birth box). Built once from its values by [`ModelConfig::build`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct ModelConfig {
    /// Bins per frame `m`.
    pub bins: usize,
    /// Sample interval `ts` (s).
    pub ts: f32,
    /// DFT window.
    pub window: Window,
    /// Birth box `I_x0`.
    pub prior: PriorBox,
    /// Process noise: std of `v1` (Hz/s^2).
    pub accel_std: f32,
    /// Process noise: std of `v2` (1/s).
    pub amp_std: f32,
    /// `Pb = P(E_k = 1 | E_{k-1} = 0)` (eq. 9).
    pub birth: f32,
    /// `Pd = P(E_k = 0 | E_{k-1} = 1)` (eq. 9).
    pub death: f32,
    /// `P(E_0 = 1)` of the initial particles (and the initial existence of JOTT).
    pub initial_existence: f32,
    /// The target's phase at each frame's start ([`Phase`]): `zero` (eq. 17, the paper
    /// and the presets) or `unknown` (CRPF-TBD's cost minimised over it, the Gaussian
    /// comparators' likelihood ratio averaged over it). Absent in a configuration file
    /// means `zero`, the model files written before the option existed were run with
    /// (`faint detect --print-config` writes `unknown`, its default).
    #[cfg_attr(feature = "serde", serde(default))]
    pub phase: Phase,
}

impl ModelConfig {
    /// The OTHR preset of the spec: `m = 32`, `ts = 0.02 s`, Hamming window, Doppler band
    /// `[-25, 25)` Hz, `fda in [-0.5, 0.5]` Hz/s, amplitude box `[0.05, 1.5]` (unit time-domain
    /// noise variance: SNR about -13 dB to +17 dB by eq. 18), `v1` std 0.2 Hz/s^2, `v2` std
    /// 0.02 1/s, `Pb = Pd = 0.05`, `P(E_0 = 1) = 0.05`, zero phase (eq. 17).
    pub fn othr() -> Self {
        Self {
            bins: 32,
            ts: 0.02,
            window: Window::Hamming,
            prior: PriorBox {
                fd: (-25.0, 25.0),
                fda: (-0.5, 0.5),
                amp: (0.05, 1.5),
            },
            accel_std: 0.2,
            amp_std: 0.02,
            birth: 0.05,
            death: 0.05,
            initial_existence: 0.05,
            phase: Phase::Zero,
        }
    }

    /// Validates and builds the model.
    pub fn build(&self) -> Result<Model> {
        self.build_reusing(None)
    }

    /// [`ModelConfig::build`], reusing the response table of `old` when it was built for
    /// the same bins, sample interval and window ([`DopplerModel::new_reusing`]; same
    /// result, without the table's cost).
    pub fn build_reusing(&self, old: Option<&DopplerModel>) -> Result<Model> {
        let checked = self.check()?;
        let obs = match old {
            Some(old) => DopplerModel::new_reusing(self.bins, self.ts, self.window, old)?,
            None => DopplerModel::new(self.bins, self.ts, self.window)?,
        };
        Ok(checked.with_table(obs))
    }

    /// [`ModelConfig::build`] in place: `model` takes this configuration, its response
    /// table rebuilt in place ([`DopplerModel::build_into`]) unless it already holds the
    /// one for these bins, sample interval and window; no model is built on the stack.
    /// On error `model` is unchanged.
    pub fn build_into(&self, model: &mut Model) -> Result<()> {
        self.check()?.write_into(model);
        Ok(())
    }

    /// Every error of [`ModelConfig::build`], without building the response table;
    /// returns the model's other parts.
    pub(crate) fn check(&self) -> Result<CheckedModel> {
        self.prior.validate()?;
        if !(0.0..=1.0).contains(&self.initial_existence) {
            return Err(Error::InvalidConfig("initial existence probability"));
        }
        DopplerModel::check(self.bins, self.ts)?;
        let motion = Motion {
            dt: response::frame_time(self.bins, self.ts),
            accel_std: self.accel_std,
            amp_std: self.amp_std,
            band: response::band(self.ts),
        };
        motion.validate()?;
        let (lo, hi) = motion.band;
        let w = motion.band_width();
        // Doppler is periodic in the band: a birth outside it is one of its aliases.
        if !(self.prior.fd.0 >= lo && self.prior.fd.1 <= hi) {
            return Err(Error::InvalidConfig("prior box Doppler (inside the band)"));
        }
        // A Doppler rate that moves more than one band width per frame is an alias too.
        let fda_max = w / motion.dt;
        if !(self.prior.fda.0 >= -fda_max && self.prior.fda.1 <= fda_max) {
            return Err(Error::InvalidConfig(
                "prior box Doppler rate (|fda| <= W / dT)",
            ));
        }
        if self.prior.amp.1 > max_amplitude(self.bins) {
            return Err(Error::InvalidConfig(
                "prior box amplitude (at most 1e18 / m)",
            ));
        }
        // One frame's process noise (std) at most the whole band / the largest amplitude.
        if !(motion.dt * motion.dt * self.accel_std <= w
            && motion.dt * self.amp_std <= max_amplitude(self.bins))
        {
            return Err(Error::InvalidConfig(
                "process noise std (one frame within range)",
            ));
        }
        let chain = crate::existence::ExistenceMarkov::new(self.birth, self.death)?;
        Ok(CheckedModel {
            cfg: *self,
            motion,
            chain,
        })
    }
}

/// A validated [`ModelConfig`]: every part of its [`Model`] but the response table
/// (small; the table is built by value or in place).
#[derive(Debug, Clone, Copy)]
pub(crate) struct CheckedModel {
    cfg: ModelConfig,
    /// The motion model (its frame time and band are the table's).
    pub(crate) motion: Motion,
    chain: crate::existence::ExistenceMarkov,
}

impl CheckedModel {
    /// The model with `obs`, the table built for the configuration's bins, sample
    /// interval and window.
    fn with_table(self, obs: DopplerModel) -> Model {
        Model {
            obs,
            motion: self.motion,
            chain: self.chain,
            prior: self.cfg.prior,
            initial_existence: self.cfg.initial_existence,
            phase: self.cfg.phase,
        }
    }

    /// Writes the model into `model` in place (cannot fail: the configuration is
    /// checked); the table is rebuilt only if `model` holds another one.
    pub(crate) fn write_into(self, model: &mut Model) {
        let c = &self.cfg;
        if !model.obs.is_built_for(c.bins, c.ts, c.window) {
            model.obs.fill(c.bins, c.ts, c.window);
        }
        model.motion = self.motion;
        model.chain = self.chain;
        model.prior = c.prior;
        model.initial_existence = c.initial_existence;
        model.phase = c.phase;
    }
}

/// Largest amplitude of the prior box for `m` bins: `||h||^2 <= A^2 (sum w)^2 SPAN` with
/// `sum w <= m`, and a cost `||z - h||^2` adds a few such terms, so `A <= 1e18 / m` keeps
/// every cost below `f32::MAX` (`(1e18)^2 * 5 * 4 = 2e37`).
pub fn max_amplitude(m: usize) -> f32 {
    1e18 / m.max(1) as f32
}

/// A built [`ModelConfig`].
#[derive(Debug, Clone)]
pub struct Model {
    /// Observation model `h_k(x)`.
    pub obs: DopplerModel,
    /// Motion model (eq. 16).
    pub motion: Motion,
    /// Existence chain (eq. 9).
    pub chain: crate::existence::ExistenceMarkov,
    /// Birth box.
    pub prior: PriorBox,
    /// `P(E_0 = 1)`.
    pub initial_existence: f32,
    /// The phase model of the cost / likelihood ratio.
    pub phase: Phase,
}

/// What every Doppler-frame detector (CRPF-TBD, PF-TBD, JOTT, PF-LRT) reports per frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DopplerReport {
    /// 1-based frame number.
    pub frame: u32,
    /// Existence probability of this frame (`P_E^k` for CRPF-TBD and PF-TBD, `q_k` for
    /// JOTT; for PF-LRT the per-frame evidence `1 / (1 + exp(-l_k))`, `l_k` this frame's
    /// log likelihood-ratio increment).
    pub existence: f32,
    /// Cumulative log likelihood ratio `ln p(Z_k|H1)/p(Z_k|H0)` (PF-LRT; 0 for the others).
    pub log_lr: f32,
    /// State estimate `[fd, fda, A]` (mean-cost for CRPF-TBD, posterior mean otherwise);
    /// `None` when no particle carries a target.
    pub estimate: Option<[f32; 3]>,
    /// Min-cost estimate (CRPF-TBD only, eq. 8).
    pub min_cost_estimate: Option<[f32; 3]>,
}

/// An estimate with every component finite, else `None`: the last guard of every
/// Doppler-frame detector's report (a particle cloud that reached the edge of `f32`
/// reports no estimate for that frame rather than a NaN).
#[inline]
pub(crate) fn finite_estimate(e: Option<[f32; 3]>) -> Option<[f32; 3]> {
    e.filter(|x| x.iter().all(|v| v.is_finite()))
}

/// Names of the Doppler-frame state `[fd, fda, A]` ([`Detector::STATE`](crate::detect::Detector::STATE)).
pub const DOPPLER_STATE: &[&str] = &["fd_hz", "fda_hz_per_s", "amplitude"];

impl DopplerReport {
    /// The report as a [`Detection`](crate::detect::Detection): the estimate, scored by
    /// `existence` or by the cumulative `log_lr`; `None` without an estimate.
    pub fn detection(&self, score: crate::detect::ScoreKind) -> Option<crate::detect::Detection> {
        let x = self.estimate?;
        let s = match score {
            crate::detect::ScoreKind::LogLikelihoodRatio => self.log_lr,
            _ => self.existence,
        };
        Some(crate::detect::Detection::new(&x, s, None))
    }
}
