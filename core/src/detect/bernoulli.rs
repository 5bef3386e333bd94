//! JOTT / Bernoulli particle filter (Mahler 2007; Ristic, Vo, Vo, Farina 2013) for
//! track-before-detect, the comparator "JOTT-mean" of Lu, Wang, Zhang 2017.
//!
//! ```text
//! q_{k|k-1} = Pb (1 - q_{k-1}) + Ps q_{k-1},   Ps = 1 - Pd
//! predicted density: mixture of persisting F x + G v (mass Ps q) and births U(I_x0)
//!                    (mass Pb (1 - q)); here sampled directly: each particle is a birth
//!                    with probability rho = Pb (1 - q_{k-1}) / q_{k|k-1}
//! I_k = (1/N) sum_i exp((2 Re<z,h_i> - ||h_i||^2) / s2)      (likelihood-ratio integral)
//! q_k = q_{k|k-1} I_k / (1 - q_{k|k-1} + q_{k|k-1} I_k)
//!     = 1 / (1 + exp(ln(1 - q_{k|k-1}) - ln q_{k|k-1} - ln I_k))   (log domain)
//! w_i ∝ LR_i, estimate sum w_i x_i, resample N.
//! ```
//! Noise assumed complex Gaussian, independent bins, variance `s2` (see
//! [`GaussConfig`](super::pf_tbd::GaussConfig)).

use super::pf_tbd::{check_variance, weighted_mean, GaussConfig};
use crate::math;
use crate::model::doppler::{check_frame, FrameDetector, Model, TbdReport};
use crate::particles::{gather_in_place, resample, Scheme};
use crate::rng::Rng;
use crate::{Complex32, Result};

/// Bernoulli (JOTT) filter with `N` particles.
#[derive(Debug, Clone)]
pub struct BernoulliTbd<const N: usize> {
    cfg: GaussConfig,
    model: Model,
    inv_var: f32,
    q: f32,
    xs: [[f32; 3]; N],
    log_w: [f32; N],
    w: [f32; N],
    anc: [u32; N],
    rng: Rng,
    frame: u32,
}

impl<const N: usize> BernoulliTbd<N> {
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

    /// Validates `cfg`; `q_0 = initial_existence`, particles from `U(I_x0)`.
    pub fn new(cfg: GaussConfig, seed: u64) -> Result<Self> {
        let (model, inv_var) = cfg.prepare::<N>()?;
        let mut s = Self {
            cfg,
            model,
            inv_var,
            q: 0.0,
            xs: [[0.0; 3]; N],
            log_w: [0.0; N],
            w: [0.0; N],
            anc: [0; N],
            rng: Rng::seed_from_u64(seed),
            frame: 0,
        };
        s.reset(seed);
        Ok(s)
    }

    /// Sets the assumed per-bin noise variance.
    pub fn set_noise_variance(&mut self, v: f32) -> Result<()> {
        self.inv_var = check_variance(v)?;
        self.cfg.noise_var = v;
        Ok(())
    }

    fn step_inner(&mut self, z: &[Complex32]) -> Result<TbdReport> {
        check_frame(z, self.model.obs.bins())?;
        let m = &self.model;
        let q_pred = m.chain.predict(self.q);
        let born_mass = m.chain.birth() * (1.0 - self.q);
        let rho = if q_pred > 0.0 {
            (born_mass / q_pred).clamp(0.0, 1.0)
        } else {
            1.0
        };
        for (x, lw) in self.xs.iter_mut().zip(self.log_w.iter_mut()) {
            *x = if self.frame == 0 || self.rng.bernoulli(rho) {
                m.prior.sample(&mut self.rng)
            } else {
                m.motion.propagate(*x, &mut self.rng)
            };
            *lw = m.obs.project_re(z, x[0], x[2]).log_lr(self.inv_var);
        }
        // ln I_k = LSE(ln LR) - ln N; finite for a finite frame.
        let lse = math::normalize_log_weights(&self.log_w, &mut self.w);
        let q = match lse {
            Ok(l) => {
                let ln_i = l - math::ln(N as f32);
                if q_pred <= 0.0 {
                    0.0
                } else if q_pred >= 1.0 {
                    1.0
                } else {
                    let t = math::ln(1.0 - q_pred) - math::ln(q_pred) - ln_i;
                    if t > 80.0 {
                        0.0
                    } else {
                        1.0 / (1.0 + math::exp(t))
                    }
                }
            }
            Err(_) => {
                self.w = [1.0 / N as f32; N];
                q_pred
            }
        };
        self.q = q.clamp(0.0, 1.0);
        let est = weighted_mean(m, self.xs.iter().zip(self.w.iter()).map(|(x, &w)| (*x, w)));
        if resample(Scheme::Systematic, &self.w, &mut self.anc, &mut self.rng).is_ok() {
            let _ = gather_in_place(&mut self.xs, &self.anc);
        }
        self.frame += 1;
        Ok(TbdReport {
            frame: self.frame,
            existence: self.q,
            log_lr: 0.0,
            estimate: est,
            min_cost_estimate: None,
        })
    }
}

impl<const N: usize> FrameDetector for BernoulliTbd<N> {
    /// One frame; errors as [`check_frame`] (state untouched).
    fn step(&mut self, frame: &[Complex32]) -> Result<TbdReport> {
        self.step_inner(frame)
    }

    fn reset(&mut self, seed: u64) {
        self.rng = Rng::seed_from_u64(seed);
        self.q = self.model.initial_existence;
        for x in self.xs.iter_mut() {
            *x = self.model.prior.sample(&mut self.rng);
        }
        self.frame = 0;
    }
}
