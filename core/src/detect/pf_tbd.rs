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
//! Births are proposed as the config's [`BirthProposal`] says. `Exact` (the preset) is
//! the chain above: every absent particle born with probability `Pb`. `FixedShare(s)`
//! proposes the same predicted law with a fixed set of birth particles, the importance
//! device of the Bernoulli particle filter (Ristic, Vo, Vo, Farina 2013) applied to the
//! existence-flag particles of Ristic, Arulampalam, Gordon 2004 (cf. the separate birth
//! and continuing particle sets of Rutten, Gordon, Maskell 2005). With `n0` of the `N`
//! (resampled) particles absent, the predicted law is a birth part of mass
//! `beta = Pb n0 / N` (`E = 1`, `x ~ U(I_x0)`) and a non-birth part (absent particles
//! staying absent with probability `1 - Pb`, present ones continuing or dying as in
//! eq. 9). `B` birth slots (see `GaussianCloud::predict_and_weigh_split`) draw from the
//! birth part, the other `N - B` slots (a systematic subsample of the particles) from the
//! non-birth part, and the prior weights correct for the proposal:
//! ```text
//! birth slot:                       E = 1, x ~ U(I_x0),       v = beta / B
//! persisting slot, E_{k-1} = 0:     E = 0,                    v = (1 - Pb) / (N - B)
//! persisting slot, E_{k-1} = 1:     E ~ (continue 1 - Pd, die Pd) as eq. 9, v = 1 / (N - B)
//! w_i ∝ v_i l(z_k | x_i)/l(z_k | H0)
//! ```
//! Noise model assumed: independent complex Gaussian bins of variance `s2` (given, or
//! estimated from the K frames with
//! [`estimate_noise_variance`](crate::model::doppler::estimate_noise_variance)). Weights
//! are normalised in the log domain. With
//! [`Phase::Unknown`](crate::model::doppler::Phase) the likelihood ratio is averaged over
//! a uniform phase per frame: `ln LR = ln I0(2 |<z,h>| / s2) - ||h||^2 / s2` (Rician).

use super::gauss_cloud::{gauss_detector, log_mass, CloudParticle, GaussianCloud};
use crate::existence::Transition;
use crate::math;
use crate::model::doppler::DopplerReport;
use crate::{Complex32, Result};

pub use super::gauss_cloud::{BirthProposal, GaussConfig};

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

/// PF-TBD with 1000 particles (the firmware's comparators, the host's default).
pub type PfTbd1000 = PfTbd<1000>;
/// PF-TBD with 6000 particles (the paper's count; the host's largest).
pub type PfTbd6000 = PfTbd<6000>;

/// PF-TBD with `PARTICLES` particles.
#[derive(Debug, Clone)]
pub struct PfTbd<const PARTICLES: usize> {
    cloud: GaussianCloud<Particle, PARTICLES>,
}

gauss_detector!(
    PfTbd {},
    "Validates `cfg` and draws the initial particles (`E_0 ~ Bernoulli`, `x ~ U(I_x0)`).",
    crate::detect::ScoreKind::Existence
);

impl<const PARTICLES: usize> PfTbd<PARTICLES> {
    /// One frame (the `Detector::step` of this detector).
    fn advance(&mut self, z: &[Complex32]) -> Result<DopplerReport> {
        // Validated at configuration: `None` is the exact proposal.
        match self.cloud.config().birth.birth_count::<PARTICLES>() {
            Ok(Some(b)) => self.advance_fixed_share(z, b)?,
            _ => self
                .cloud
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
                })?,
        }
        let _ = self.cloud.normalise();
        let pe = self.cloud.target_mass();
        Ok(self.cloud.finish(pe.clamp(0.0, 1.0), 0.0))
    }

    /// The fixed-share prediction and weights (module docs) with `b` birth slots,
    /// `1 <= b < N`.
    fn advance_fixed_share(&mut self, z: &[Complex32], b: u32) -> Result<()> {
        let chain = self.cloud.model().chain;
        let pb = chain.birth();
        let n0 = self.cloud.absent_count();
        let beta = pb * (n0 as f32 / PARTICLES as f32);
        let ln_rest = math::ln((PARTICLES as u32 - b) as f32);
        // beta = 0 (no absent particle, or Pb = 0): the births carry no weight; Pb = 1:
        // the absent particles staying absent carry none. Some slot is always finite:
        // a persisting present particle, or (all absent) a birth when Pb > 0, or an
        // absent one when Pb < 1.
        let lv_born = log_mass(beta) - math::ln(b as f32);
        let lv_absent = log_mass(1.0 - pb) - ln_rest;
        let lv_present = -ln_rest;
        self.cloud
            .predict_and_weigh_split(z, b, |pt, birth, m, rng| {
                if birth {
                    pt.x = m.prior.sample(rng);
                    pt.e = true;
                    lv_born
                } else if !pt.e {
                    pt.x = [0.0; 3];
                    lv_absent
                } else {
                    if rng.bernoulli(m.chain.death()) {
                        pt.x = [0.0; 3];
                        pt.e = false;
                    } else {
                        pt.x = m.motion.propagate(pt.x, rng);
                    }
                    lv_present
                }
            })
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
