//! PF-TBD: particle filter with an existence variable and likelihood-ratio weights
//! (Ristic, Arulampalam, Gordon, *Beyond the Kalman Filter*, 2004, ch. 11), the
//! comparator "PF-mean" of Lu, Wang, Zhang 2017.
//!
//! ```text
//! predict:  E_k ~ Pi(E_{k-1})  (eq. 9); continuing: x_k = F x + G v; born: x_k ~ U(I_x0)
//! weight:   w_i ∝ l(z_k | x_i)/l(z_k | H0) = exp((2 Re<z,h> - ||h||^2) / s2)  if E_i = 1,
//!           w_i ∝ 1  if E_i = 0
//! existence: P_E^k = sum_i w_i E_i;  estimate sum_i w_i E_i x_i / P_E^k; resample.
//! ```
//! Noise model assumed: independent complex Gaussian bins of variance `s2` (given, or
//! estimated from the K frames with
//! [`estimate_noise_variance`](crate::model::doppler::estimate_noise_variance)). Weights
//! are normalised in the log domain.

use crate::existence::Transition;
use crate::math;
use crate::model::doppler::{check_frame, FrameDetector, Model, ModelConfig, TbdReport};
use crate::particles::{gather_in_place, resample, Scheme};
use crate::rng::Rng;
use crate::{Complex32, Error, Result};

/// Runtime values shared by the Gaussian comparators (PF-TBD, JOTT, PF-LRT).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GaussConfig {
    /// The shared OTHR model; the process noise is used as given.
    pub model: ModelConfig,
    /// Per-bin complex noise variance `s2 = E|w_b|^2` (> 0).
    pub noise_var: f32,
}

impl GaussConfig {
    /// OTHR preset with a given noise variance.
    pub fn othr(noise_var: f32) -> Self {
        Self {
            model: ModelConfig::othr(),
            noise_var,
        }
    }

    /// Checks the variance; builds the model.
    pub fn validate(&self) -> Result<Model> {
        check_variance(self.noise_var)?;
        self.model.build()
    }

    /// What every Gaussian comparator's `new` / `reconfigure` needs: `N > 0`, the built
    /// model and `1 / s2`.
    pub(crate) fn prepare<const N: usize>(&self) -> Result<(Model, f32)> {
        if N == 0 {
            return Err(Error::InvalidConfig("particle count N = 0"));
        }
        let model = self.validate()?;
        Ok((model, 1.0 / self.noise_var))
    }
}

pub(crate) fn check_variance(v: f32) -> Result<f32> {
    if v.is_finite() && v > 0.0 && (1.0 / v).is_finite() {
        Ok(1.0 / v)
    } else {
        Err(Error::InvalidConfig(
            "noise variance must be finite and > 0",
        ))
    }
}

/// Weighted mean of states with Doppler averaged around a reference (band wrap).
pub(crate) fn weighted_mean(
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
    let width = model.motion.band.1 - model.motion.band.0;
    let mut s = 0.0f32;
    let mut acc = [0.0f32; 3];
    for (x, w) in xs {
        let mut d = x[0] - reference;
        if d > 0.5 * width {
            d -= width;
        } else if d < -0.5 * width {
            d += width;
        }
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

#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Particle {
    x: [f32; 3],
    e: bool,
}

/// PF-TBD with `N` particles.
#[derive(Debug, Clone)]
pub struct PfTbd<const N: usize> {
    cfg: GaussConfig,
    model: Model,
    inv_var: f32,
    parts: [Particle; N],
    log_w: [f32; N],
    w: [f32; N],
    anc: [u32; N],
    rng: Rng,
    frame: u32,
}

impl<const N: usize> PfTbd<N> {
    /// Re-validates `cfg` and restarts in place from `seed` (as [`new`](Self::new) would),
    /// without building a detector by value: how one that lives in a `static` (e.g. the
    /// firmware's zero-initialised ones) is set up. On error `self` is unchanged.
    pub fn reconfigure(&mut self, cfg: GaussConfig, seed: u64) -> Result<()> {
        let (model, inv_var) = cfg.prepare::<N>()?;
        self.cfg = cfg;
        self.model = model;
        self.inv_var = inv_var;
        self.reset(seed);
        Ok(())
    }

    /// Validates `cfg` and draws the initial particles (`E_0 ~ Bernoulli`, `x ~ U(I_x0)`).
    pub fn new(cfg: GaussConfig, seed: u64) -> Result<Self> {
        let (model, inv_var) = cfg.prepare::<N>()?;
        let mut s = Self {
            cfg,
            model,
            inv_var,
            parts: [Particle::default(); N],
            log_w: [0.0; N],
            w: [0.0; N],
            anc: [0; N],
            rng: Rng::seed_from_u64(seed),
            frame: 0,
        };
        s.reset(seed);
        Ok(s)
    }

    /// Sets the assumed per-bin noise variance (e.g. estimated from the K frames).
    pub fn set_noise_variance(&mut self, v: f32) -> Result<()> {
        self.inv_var = check_variance(v)?;
        self.cfg.noise_var = v;
        Ok(())
    }

    fn step_inner(&mut self, z: &[Complex32]) -> Result<TbdReport> {
        check_frame(z, self.model.obs.bins())?;
        let m = &self.model;
        for (pt, lw) in self.parts.iter_mut().zip(self.log_w.iter_mut()) {
            match m.chain.sample(pt.e, &mut self.rng) {
                Transition::Continuing => pt.x = m.motion.propagate(pt.x, &mut self.rng),
                Transition::Born => {
                    pt.x = m.prior.sample(&mut self.rng);
                    pt.e = true;
                }
                _ => {
                    pt.x = [0.0; 3];
                    pt.e = false;
                }
            }
            *lw = if pt.e {
                m.obs.project_re(z, pt.x[0], pt.x[2]).log_lr(self.inv_var)
            } else {
                0.0
            };
        }
        // Log weights are finite (finite frame, finite variance), so this cannot fail;
        // uniform weights are the documented fallback.
        if math::normalize_log_weights(&self.log_w, &mut self.w).is_err() {
            self.w = [1.0 / N as f32; N];
        }
        let mut pe = 0.0f32;
        for (p, &w) in self.parts.iter().zip(self.w.iter()) {
            if p.e {
                pe += w;
            }
        }
        let est = weighted_mean(
            m,
            self.parts
                .iter()
                .zip(self.w.iter())
                .filter(|(p, _)| p.e)
                .map(|(p, &w)| (p.x, w)),
        );
        if resample(Scheme::Systematic, &self.w, &mut self.anc, &mut self.rng).is_ok() {
            let _ = gather_in_place(&mut self.parts, &self.anc);
        }
        self.frame += 1;
        Ok(TbdReport {
            frame: self.frame,
            existence: pe.clamp(0.0, 1.0),
            log_lr: 0.0,
            estimate: est,
            min_cost_estimate: None,
        })
    }
}

impl<const N: usize> FrameDetector for PfTbd<N> {
    /// One frame; errors as [`check_frame`] (state untouched).
    fn step(&mut self, frame: &[Complex32]) -> Result<TbdReport> {
        self.step_inner(frame)
    }

    fn reset(&mut self, seed: u64) {
        self.rng = Rng::seed_from_u64(seed);
        let p0 = self.model.initial_existence;
        for pt in self.parts.iter_mut() {
            let e = self.rng.bernoulli(p0);
            pt.e = e;
            pt.x = if e {
                self.model.prior.sample(&mut self.rng)
            } else {
                [0.0; 3]
            };
        }
        self.frame = 0;
    }
}
