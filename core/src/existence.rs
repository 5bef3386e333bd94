//! Two-state Markov chain of target existence, shared by the existence-carrying filters
//! (CRPF-TBD, PF-TBD, Bernoulli/JOTT).
//!
//! ```text
//! Pi = [[1 - Pb, Pb    ],     row: E_{k-1} = 0
//!       [Pd,     1 - Pd]]     row: E_{k-1} = 1
//! ```
//! `Pb = P(E_k = 1 | E_{k-1} = 0)` (birth), `Pd = P(E_k = 0 | E_{k-1} = 1)` (death).

use crate::rng::Rng;
use crate::{Error, Result};

/// The existence transition matrix, given by its birth and death probabilities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExistenceMarkov {
    birth: f32,
    death: f32,
}

/// What happened to one particle's existence flag in a transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transition {
    /// `E_{k-1} = 1`, `E_k = 1`: the target continues.
    Continuing,
    /// `E_{k-1} = 0`, `E_k = 1`: a target is born.
    Born,
    /// `E_{k-1} = 1`, `E_k = 0`: the target dies.
    Died,
    /// `E_{k-1} = 0`, `E_k = 0`: still no target.
    Absent,
}

impl Transition {
    /// Whether the target exists after the transition.
    pub fn exists(self) -> bool {
        matches!(self, Transition::Continuing | Transition::Born)
    }
}

impl ExistenceMarkov {
    /// Builds the chain; both probabilities must lie in `[0, 1]`.
    pub fn new(birth: f32, death: f32) -> Result<Self> {
        if !(0.0..=1.0).contains(&birth) {
            return Err(Error::InvalidConfig("existence birth probability"));
        }
        if !(0.0..=1.0).contains(&death) {
            return Err(Error::InvalidConfig("existence death probability"));
        }
        Ok(Self { birth, death })
    }

    /// `Pb`.
    pub fn birth(&self) -> f32 {
        self.birth
    }

    /// `Pd`.
    pub fn death(&self) -> f32 {
        self.death
    }

    /// Samples `E_k` given `E_{k-1}` (one uniform draw).
    pub fn sample(&self, existed: bool, rng: &mut Rng) -> Transition {
        let u = rng.uniform();
        match existed {
            true if u < self.death => Transition::Died,
            true => Transition::Continuing,
            false if u < self.birth => Transition::Born,
            false => Transition::Absent,
        }
    }

    /// Predicted existence probability:
    /// `q_{k|k-1} = Pb (1 - q) + (1 - Pd) q`.
    pub fn predict(&self, q: f32) -> f32 {
        let q = q.clamp(0.0, 1.0);
        (self.birth * (1.0 - q) + (1.0 - self.death) * q).clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_out_of_range() {
        assert!(ExistenceMarkov::new(-0.1, 0.5).is_err());
        assert!(ExistenceMarkov::new(0.1, 1.5).is_err());
        assert!(ExistenceMarkov::new(f32::NAN, 0.5).is_err());
    }

    #[test]
    fn sampled_frequencies_match_matrix() {
        // 200 000 draws: the binomial standard deviation of a frequency near 0.05 is
        // sqrt(0.05*0.95/2e5) = 4.9e-4, so 0.003 is more than 6 sigma.
        let m = ExistenceMarkov::new(0.05, 0.1).unwrap();
        let mut rng = Rng::seed_from_u64(7);
        let n = 200_000;
        let born = (0..n)
            .filter(|_| m.sample(false, &mut rng).exists())
            .count();
        let died = (0..n)
            .filter(|_| !m.sample(true, &mut rng).exists())
            .count();
        assert!((born as f32 / n as f32 - 0.05).abs() < 0.003);
        assert!((died as f32 / n as f32 - 0.1).abs() < 0.003);
        assert!((m.predict(0.5) - (0.05 * 0.5 + 0.9 * 0.5)).abs() < 1e-6);
    }
}
