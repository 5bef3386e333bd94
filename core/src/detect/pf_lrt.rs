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
//! Noise assumed complex Gaussian, independent bins, variance `s2`; with
//! [`Phase::Unknown`](crate::model::doppler::Phase) `LR_i` is averaged over a uniform
//! phase per frame, `ln I0(2 |<z_k,h_i>| / s2) - ||h_i||^2 / s2` (Rician). The report's
//! `log_lr` is `ln L_k`; its `existence` is the per-frame evidence
//! `1 / (1 + exp(-l_k))` of this frame's increment `l_k`.

use super::gauss_cloud::{gauss_detector, GaussianCloud};
use crate::math;
use crate::model::doppler::DopplerReport;
use crate::{Complex32, Result};

/// PF-LRT with 1000 particles (the firmware's comparators, the host's default).
pub type PfLrt1000 = PfLrt<1000>;
/// PF-LRT with 6000 particles (the paper's count; the host's largest).
pub type PfLrt6000 = PfLrt<6000>;

/// PF-LRT with `PARTICLES` particles.
#[derive(Debug, Clone)]
pub struct PfLrt<const PARTICLES: usize> {
    cloud: GaussianCloud<[f32; 3], PARTICLES>,
    log_lr: f32,
}

gauss_detector!(
    PfLrt { log_lr: 0.0 },
    "Validates `cfg`; particles from `U(I_x0)`.",
    crate::detect::ScoreKind::LogLikelihoodRatio
);

impl<const PARTICLES: usize> PfLrt<PARTICLES> {
    /// `ln L_k` so far.
    pub fn log_likelihood_ratio(&self) -> f32 {
        self.log_lr
    }
}

impl<const PARTICLES: usize> PfLrt<PARTICLES> {
    /// One frame (the `Detector::step` of this detector).
    fn advance(&mut self, z: &[Complex32]) -> Result<DopplerReport> {
        let first = self.cloud.frame() == 0;
        self.cloud.predict_and_weigh(z, |x, m, rng| {
            if !first {
                *x = m.motion.propagate(*x, rng);
            }
        })?;
        let inc = match self.cloud.normalise() {
            Some(lse) => lse - math::ln(PARTICLES as f32),
            None => 0.0,
        };
        // Saturates at +-f32::MAX (a long run with a tiny noise variance reaches it).
        self.log_lr = (self.log_lr + inc).clamp(-f32::MAX, f32::MAX);
        let evidence = if inc < -80.0 {
            0.0
        } else {
            1.0 / (1.0 + math::exp(-inc))
        };
        Ok(self.cloud.finish(evidence, self.log_lr))
    }

    /// Restarts from frame 0 (the `Detector::reset` of this detector).
    fn restart(&mut self, seed: u64) {
        self.log_lr = 0.0;
        self.cloud.reset(seed, |m, rng| m.prior.sample(rng));
    }
}
