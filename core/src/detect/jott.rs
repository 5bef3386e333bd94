//! JOTT / Bernoulli particle filter (Mahler 2007; Ristic, Vo, Vo, Farina 2013) for
//! track-before-detect, the comparator "JOTT-mean" of Lu, Wang, Zhang 2017.
//!
//! ```text
//! q_{k|k-1} = Pb (1 - q_{k-1}) + Ps q_{k-1},   Ps = 1 - Pd
//! predicted density: mixture of persisting F x + G v (mass Ps q) and births U(I_x0)
//!                    (mass Pb (1 - q)), proposed as the config's `BirthProposal` says:
//!   Exact:         each particle a birth with probability rho = Pb (1 - q_{k-1}) / q_{k|k-1},
//!                  prior weights v_i = 1/N
//!   FixedShare(s): B birth particles from U(I_x0) beside N - B persisting ones (Ristic,
//!                  Vo, Vo, Farina 2013, sec. "particle filter implementation"), prior weights
//!                  v_i = Pb (1 - q_{k-1}) / (B q_{k|k-1})       (births)
//!                  v_i = Ps q_{k-1} / ((N - B) q_{k|k-1})       (persisting, Ps = 1 - Pd)
//!   (frame 1 draws every particle from U(I_x0) with v_i = 1/N under both)
//! I_k = sum_i v_i exp((2 Re<z,h_i> - ||h_i||^2) / s2)        (likelihood-ratio integral)
//! q_k = q_{k|k-1} I_k / (1 - q_{k|k-1} + q_{k|k-1} I_k)
//!     = 1 / (1 + exp(ln(1 - q_{k|k-1}) - ln q_{k|k-1} - ln I_k))   (log domain)
//! w_i ∝ v_i LR_i, estimate sum w_i x_i, resample N.
//! ```
//! Noise assumed complex Gaussian, independent bins, variance `s2` (see
//! [`GaussConfig`](super::pf_tbd::GaussConfig)). With
//! [`Phase::Unknown`](crate::model::doppler::Phase) `LR_i` is averaged over a uniform
//! phase per frame: `ln LR_i = ln I0(2 |<z,h_i>| / s2) - ||h_i||^2 / s2` (Rician).

use super::gauss_cloud::{gauss_detector, log_mass, GaussianCloud};
use crate::math;
use crate::model::doppler::DopplerReport;
use crate::{Complex32, Result};

/// JOTT with 1000 particles (the firmware's comparators, the host's default).
pub type JottTbd1000 = JottTbd<1000>;
/// JOTT with 6000 particles (the paper's count; the host's largest).
pub type JottTbd6000 = JottTbd<6000>;

/// JOTT (Bernoulli) filter with `PARTICLES` particles.
#[derive(Debug, Clone)]
pub struct JottTbd<const PARTICLES: usize> {
    cloud: GaussianCloud<[f32; 3], PARTICLES>,
    q: f32,
}

gauss_detector!(
    JottTbd { q: 0.0 },
    "Validates `cfg`; `q_0 = initial_existence`, particles from `U(I_x0)`.",
    crate::detect::ScoreKind::Existence
);

impl<const PARTICLES: usize> JottTbd<PARTICLES> {
    /// One frame (the `Detector::step` of this detector).
    fn advance(&mut self, z: &[Complex32]) -> Result<DopplerReport> {
        let chain = &self.cloud.model().chain;
        let q_pred = chain.predict(self.q);
        let born_mass = chain.birth() * (1.0 - self.q);
        let rho = if q_pred > 0.0 {
            (born_mass / q_pred).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let first = self.cloud.frame() == 0;
        // Validated at configuration: `None` is the exact proposal.
        let fixed = match self.cloud.config().birth.birth_count::<PARTICLES>() {
            Ok(Some(b)) if !first => Some(b),
            _ => None,
        };
        if let Some(b) = fixed {
            // ln v of a birth and of a persisting particle, normalised by their total
            // (q_pred up to rounding). A zero mass gives -inf (those particles carry no
            // weight); both zero (q_pred = 0, q stays 0 below): uniform.
            let persist_mass = (1.0 - chain.death()) * self.q;
            let total = born_mass + persist_mass;
            let (lv_born, lv_persist) = if total > 0.0 {
                let ln_t = math::ln(total);
                (
                    log_mass(born_mass) - math::ln(b as f32) - ln_t,
                    log_mass(persist_mass) - math::ln((PARTICLES as u32 - b) as f32) - ln_t,
                )
            } else {
                (0.0, 0.0)
            };
            self.cloud
                .predict_and_weigh_split(z, b, |x, birth, m, rng| {
                    if birth {
                        *x = m.prior.sample(rng);
                        lv_born
                    } else {
                        *x = m.motion.propagate(*x, rng);
                        lv_persist
                    }
                })?;
        } else {
            self.cloud.predict_and_weigh(z, |x, m, rng| {
                *x = if first || rng.bernoulli(rho) {
                    m.prior.sample(rng)
                } else {
                    m.motion.propagate(*x, rng)
                };
            })?;
        }
        // ln I_k = LSE(ln v + ln LR): minus ln N for the exact proposal (v = 1/N), the
        // prior weights are in the log weights for the fixed share. Finite for a finite
        // frame.
        let ln_v = if fixed.is_some() {
            0.0
        } else {
            math::ln(PARTICLES as f32)
        };
        let q = match self.cloud.normalise() {
            Some(lse) => {
                let ln_i = lse - ln_v;
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
            None => q_pred,
        };
        self.q = q.clamp(0.0, 1.0);
        Ok(self.cloud.finish(self.q, 0.0))
    }

    /// Restarts from frame 0 (the `Detector::reset` of this detector).
    fn restart(&mut self, seed: u64) {
        self.q = self.cloud.model().initial_existence;
        self.cloud.reset(seed, |m, rng| m.prior.sample(rng));
    }
}
