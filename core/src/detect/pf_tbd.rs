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

use super::gauss_cloud::{gauss_detector, CloudParticle, GaussianCloud};
use crate::existence::Transition;
use crate::model::doppler::DopplerReport;
use crate::{Complex32, Result};

pub use super::gauss_cloud::GaussConfig;

#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct Particle {
    x: [f32; 3],
    e: bool,
}

impl CloudParticle for Particle {
    #[inline]
    fn target(&self) -> Option<[f32; 3]> {
        if self.e {
            Some(self.x)
        } else {
            None
        }
    }
}

/// PF-TBD with `N` particles.
#[derive(Debug, Clone)]
pub struct PfTbd<const N: usize> {
    cloud: GaussianCloud<Particle, N>,
}

gauss_detector!(
    PfTbd {},
    "Validates `cfg` and draws the initial particles (`E_0 ~ Bernoulli`, `x ~ U(I_x0)`).",
    crate::detect::ScoreKind::Existence
);

impl<const N: usize> PfTbd<N> {
    /// One frame (the `Detector::step` of this detector).
    fn advance(&mut self, z: &[Complex32]) -> Result<DopplerReport> {
        self.cloud
            .predict_and_weigh(z, |pt, m, rng| match m.chain.sample(pt.e, rng) {
                Transition::Continuing => pt.x = m.motion.propagate(pt.x, rng),
                Transition::Born => {
                    pt.x = m.prior.sample(rng);
                    pt.e = true;
                }
                _ => {
                    pt.x = [0.0; 3];
                    pt.e = false;
                }
            })?;
        let _ = self.cloud.normalise();
        let pe = self.cloud.target_mass();
        Ok(self.cloud.finish(pe.clamp(0.0, 1.0), 0.0))
    }

    /// Restarts from frame 0 (the `Detector::reset` of this detector).
    fn restart(&mut self, seed: u64) {
        self.cloud.reset(seed, |m, rng| {
            let e = rng.bernoulli(m.initial_existence);
            Particle {
                x: if e { m.prior.sample(rng) } else { [0.0; 3] },
                e,
            }
        });
    }
}
