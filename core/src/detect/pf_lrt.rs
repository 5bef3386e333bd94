//! PF-LRT: particle-filter likelihood-ratio test (Boers and Driessen, IEEE SPL 10(10),
//! 2003), the comparator "PF-LRT" of Lu, Wang, Zhang 2017.
//!
//! A bootstrap particle filter runs under H1 (target present in every frame); the
//! likelihood ratio of the frames is estimated from the predictive particles:
//!
//! ```text
//! p(z_k | Z_{k-1}, H1) / p(z_k | H0) ≈ (1/N) sum_i exp((2 Re<z_k,h_i> - ||h_i||^2) / s2)
//! ln L_K = sum_k ln[(1/N) sum_i LR_i^k]          (accumulated in the log domain)
//! ```
//! Noise assumed complex Gaussian, independent bins, variance `s2`. The report's
//! `log_lr` is `ln L_k`; its `existence` is the per-frame evidence
//! `1 / (1 + exp(-l_k))` of this frame's increment `l_k`.

use super::pf_tbd::{check_variance, weighted_mean, GaussConfig};
use crate::math;
use crate::model::doppler::{check_frame, FrameDetector, Model, TbdReport};
use crate::particles::{gather_in_place, resample, Scheme};
use crate::rng::Rng;
use crate::{Complex32, Result};

/// PF-LRT with `N` particles.
#[derive(Debug, Clone)]
pub struct PfLrt<const N: usize> {
    cfg: GaussConfig,
    model: Model,
    inv_var: f32,
    log_lr: f32,
    xs: [[f32; 3]; N],
    log_w: [f32; N],
    w: [f32; N],
    anc: [u32; N],
    rng: Rng,
    frame: u32,
}

impl<const N: usize> PfLrt<N> {
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

    /// Validates `cfg`; particles from `U(I_x0)`.
    pub fn new(cfg: GaussConfig, seed: u64) -> Result<Self> {
        let (model, inv_var) = cfg.prepare::<N>()?;
        let mut s = Self {
            cfg,
            model,
            inv_var,
            log_lr: 0.0,
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

    /// `ln L_k` so far.
    pub fn log_likelihood_ratio(&self) -> f32 {
        self.log_lr
    }

    fn step_inner(&mut self, z: &[Complex32]) -> Result<TbdReport> {
        check_frame(z, self.model.obs.bins())?;
        let m = &self.model;
        let first = self.frame == 0;
        for (x, lw) in self.xs.iter_mut().zip(self.log_w.iter_mut()) {
            if !first {
                *x = m.motion.propagate(*x, &mut self.rng);
            }
            *lw = m.obs.project_re(z, x[0], x[2]).log_lr(self.inv_var);
        }
        let inc = match math::normalize_log_weights(&self.log_w, &mut self.w) {
            Ok(l) => l - math::ln(N as f32),
            Err(_) => {
                self.w = [1.0 / N as f32; N];
                0.0
            }
        };
        self.log_lr += inc;
        let est = weighted_mean(m, self.xs.iter().zip(self.w.iter()).map(|(x, &w)| (*x, w)));
        if resample(Scheme::Systematic, &self.w, &mut self.anc, &mut self.rng).is_ok() {
            let _ = gather_in_place(&mut self.xs, &self.anc);
        }
        self.frame += 1;
        let evidence = if inc < -80.0 {
            0.0
        } else {
            1.0 / (1.0 + math::exp(-inc))
        };
        Ok(TbdReport {
            frame: self.frame,
            existence: evidence,
            log_lr: self.log_lr,
            estimate: est,
            min_cost_estimate: None,
        })
    }
}

impl<const N: usize> FrameDetector for PfLrt<N> {
    /// One frame; errors as [`check_frame`] (state untouched).
    fn step(&mut self, frame: &[Complex32]) -> Result<TbdReport> {
        self.step_inner(frame)
    }

    fn reset(&mut self, seed: u64) {
        self.rng = Rng::seed_from_u64(seed);
        self.log_lr = 0.0;
        for x in self.xs.iter_mut() {
            *x = self.model.prior.sample(&mut self.rng);
        }
        self.frame = 0;
    }
}
