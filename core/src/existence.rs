//! Two-state Markov chain of target existence, shared by the existence-carrying filters
//! (CRPF-TBD, PF-TBD, Bernoulli/JOTT).
//!
//! ```text
//! Pi = [[1 - Pb, Pb    ],     row: E_{k-1} = 0
//!       [Pd,     1 - Pd]]     row: E_{k-1} = 1
//! ```
//! `Pb = P(E_k = 1 | E_{k-1} = 0)` (birth), `Pd = P(E_k = 0 | E_{k-1} = 1)` (death).
//!
//! Fast exact samplers of the chain for particle loops: [`ExistenceDraw`] (one `u32` per
//! transition, bit-identical to [`ExistenceMarkov::sample`]) and [`BirthGaps`] (births
//! among absent particles by geometric skipping).

use crate::math;
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

/// The existence draw of eq. 9 in integers, bit-identical to
/// [`ExistenceMarkov::sample`]: that draws
/// `u = (x >> 8) 2^-24` from one `u32` `x` and compares `u < p`; `p 2^24` is exact in
/// `f32`, so `u < p` is `(x >> 8) < ceil(p 2^24)` for the whole number `x >> 8`.
#[derive(Debug, Clone, Copy)]
pub struct ExistenceDraw {
    /// `[ceil(Pb 2^24), ceil(Pd 2^24)]`, indexed by `E_{k-1}`.
    thr: [u32; 2],
}

impl ExistenceDraw {
    /// The thresholds of `chain`.
    pub fn new(chain: &ExistenceMarkov) -> Self {
        // p in [0, 1] (validated by the chain), so p 2^24 in [0, 2^24] is exact.
        let ceil = |p: f32| {
            let t = p * 16_777_216.0;
            let f = t as u32;
            if (f as f32) < t {
                f + 1
            } else {
                f
            }
        };
        Self {
            thr: [ceil(chain.birth()), ceil(chain.death())],
        }
    }

    /// `E_k` given `E_{k-1} = existed`, from one draw: the flag flips (birth or death)
    /// when the draw falls below the row's threshold.
    #[inline(always)]
    pub fn next(&self, existed: bool, rng: &mut Rng) -> bool {
        let u = rng.next_u32() >> 8;
        let thr = self.thr[existed as usize];
        existed != (u < thr)
    }
}

/// The births of eq. 9 among absent particles, drawn by geometric skipping: in one pass
/// over the particles every `E_{k-1} = 0` particle is born independently with
/// probability `Pb`, so the number of absent particles that stay absent before the next
/// birth is geometric, `P(G >= g) = (1 - Pb)^g`, and one draw of `G` per birth replaces
/// one draw per absent particle (CRPF-TBD's births, Lu, Wang, Zhang 2017, eq. 9). [`gap`](Self::gap) draws `G` by inversion of its
/// distribution function on one `u32`: `G = g` for `T_{g-1} <= u < T_g`,
/// `T_g = 2^32 (1 - (1 - Pb)^(g+1))` (a table of 32 entries, binary search); a draw
/// beyond the table (probability `(1 - Pb)^32`, 0.19 for `Pb = 0.05`) adds 32 and draws
/// again, which is exact because the geometric law is memoryless. When `(1 - Pb)^32 > 1/2`
/// (`Pb` below about 0.021) the table would loop too often, and
/// `G = floor(ln U / ln(1 - Pb))` (`U` uniform on `(0, 1]`, 24 bits) is used instead. The
/// same law as one draw per particle, up to the rounding of `T_g` (`f32`, relative
/// error below `1e-5`) or the 2^-24 resolution of `U`.
#[derive(Debug, Clone, Copy)]
pub struct BirthGaps {
    /// `T_g`, `g = 0..32`.
    thr: [u32; 32],
    /// `1 / ln(1 - Pb)` for the logarithmic fallback.
    scale: f32,
    mode: GapMode,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum GapMode {
    /// `Pb = 0`: no absent particle is ever born.
    Never,
    /// `Pb = 1`: every absent particle is born.
    Always,
    Table,
    Log,
}

impl BirthGaps {
    /// The gap sampler of `chain`'s birth probability.
    pub fn new(chain: &ExistenceMarkov) -> Self {
        let pb = chain.birth();
        let q = 1.0 - pb;
        let mut thr = [0u32; 32];
        let mut tail = 1.0f32;
        for t in thr.iter_mut() {
            tail *= q;
            // P(G <= g) 2^32, saturating at u32::MAX.
            *t = ((1.0 - tail) * 4_294_967_296.0) as u32;
        }
        let mode = if pb <= 0.0 {
            GapMode::Never
        } else if pb >= 1.0 {
            GapMode::Always
        } else if tail > 0.5 {
            GapMode::Log
        } else {
            GapMode::Table
        };
        Self {
            thr,
            scale: 1.0 / math::ln1p(-pb),
            mode,
        }
    }

    /// Absent particles that stay absent before the next birth (`u32::MAX`: never);
    /// takes and returns the stream by value (it stays in registers).
    #[inline(never)]
    pub fn gap(&self, mut rng: Rng) -> (Rng, u32) {
        match self.mode {
            GapMode::Table => {
                let last = self.thr[31];
                let mut base = 0u32;
                loop {
                    let u = rng.next_u32();
                    if u < last {
                        let g = self.thr.partition_point(|&t| t <= u) as u32;
                        return (rng, base.saturating_add(g));
                    }
                    base = base.saturating_add(32);
                }
            }
            GapMode::Log => {
                // ln U <= 0 and scale < 0: a non-negative product (saturating conversion).
                let g = (math::ln(rng.uniform_open0()) * self.scale) as u32;
                (rng, g)
            }
            GapMode::Never => (rng, u32::MAX),
            GapMode::Always => (rng, 0),
        }
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

    #[test]
    fn birth_gaps_are_geometric() {
        // Births by geometric skipping against the law of one Bernoulli(Pb) draw per
        // absent particle: over 400 000 absent particles the birth rate and the law of
        // the gap (P(G = 0) = Pb, P(G >= 20) = (1 - Pb)^20) must match within 5 binomial
        // standard deviations (sd of the rate 3.4e-4 at Pb = 0.05), i.e. an error of
        // 1.7e-3 in the rate fails.
        // 0.01 takes the logarithmic path, 0.05 and 0.3 the table.
        for pb in [0.01f32, 0.05, 0.3] {
            let chain = ExistenceMarkov::new(pb, 0.05).unwrap();
            let b = BirthGaps::new(&chain);
            let mut rng = Rng::seed_from_u64(3);
            let (mut births, mut absent) = (0u64, 0u64);
            let (mut zero, mut long, mut gaps) = (0u64, 0u64, 0u64);
            while absent < 400_000 {
                let (r, g) = b.gap(rng);
                rng = r;
                gaps += 1;
                zero += (g == 0) as u64;
                long += (g >= 20) as u64;
                absent += g as u64 + 1;
                births += 1;
            }
            let p = pb as f64;
            let check = |got: f64, want: f64, n: u64| {
                let sd = (want * (1.0 - want) / n as f64).sqrt();
                assert!((got - want).abs() < 5.0 * sd, "pb {pb}: {got} vs {want}");
            };
            check(births as f64 / absent as f64, p, absent);
            check(zero as f64 / gaps as f64, p, gaps);
            check(long as f64 / gaps as f64, (1.0 - p).powi(20), gaps);
        }
        // Pb = 0: never born; Pb = 1: always born.
        let never = BirthGaps::new(&ExistenceMarkov::new(0.0, 0.05).unwrap());
        assert_eq!(never.gap(Rng::seed_from_u64(1)).1, u32::MAX);
        let always = BirthGaps::new(&ExistenceMarkov::new(1.0, 0.05).unwrap());
        let mut rng = Rng::seed_from_u64(1);
        for _ in 0..1000 {
            let (r, g) = always.gap(rng);
            rng = r;
            assert_eq!(g, 0);
        }
    }
}
