//! Probability laws on an integer lattice: the merit laws of the DP analysis.
//!
//! A [`Law`] is the pmf of an integer random variable `X` (a merit in lattice steps)
//! over `lo..lo + pmf.len()`. The operations are the three the DP recursion needs:
//!
//! ```text
//! sum of independent laws:      p_{X+Y}(v) = sum_u p_X(u) p_Y(v - u)
//! max of independent laws:      P(max_i (X_i + g_i) >= v) = 1 - prod_i (1 - S_i(v - g_i))
//!                               computed as -expm1(sum_i ln1p(-S_i(v - g_i)))
//! survival:                     S(v) = P(X >= v)
//! ```
//!
//! The max is computed from survival functions in the log domain so that the upper
//! tail (where thresholds at small false-alarm rates live) keeps its relative
//! precision. Mass below [`TRIM`] at either end is dropped after each operation.

/// Mass dropped at each end of a law after an operation (the truncation error of one
/// operation is at most `2 TRIM` in total variation).
pub const TRIM: f64 = 1e-17;

/// A law on the integer lattice: `pmf[i] = P(X = lo + i)`.
#[derive(Debug, Clone, PartialEq)]
pub struct Law {
    lo: i64,
    pmf: Vec<f64>,
}

/// `P(N(0, 1) >= x)`, accurate in both tails.
fn normal_sf(x: f64) -> f64 {
    0.5 * statrs::function::erf::erfc(x / core::f64::consts::SQRT_2)
}

impl Law {
    /// The law of `round(z / h)` for `z ~ N(mean, sigma^2)` (`sigma > 0`, `h > 0`), over
    /// `mean / h +- 10 sigma / h` (the mass beyond is below `1e-23`).
    pub fn quantised_normal(mean: f64, sigma: f64, h: f64) -> Law {
        let c = mean / h;
        let w = (10.0 * sigma / h).ceil();
        let lo = (c - w).floor() as i64;
        let hi = (c + w).ceil() as i64;
        // P(round(z/h) = m) = P((m - 1/2) h <= z < (m + 1/2) h); from the tail on each
        // side of the mean so that neither tail cancels
        let sf = |m: i64| normal_sf(((m as f64 - 0.5) * h - mean) / sigma);
        let cdf = |m: i64| normal_sf((mean - (m as f64 - 0.5) * h) / sigma);
        let pmf = (lo..=hi)
            .map(|m| {
                if (m as f64) * h >= mean {
                    (sf(m) - sf(m + 1)).max(0.0)
                } else {
                    (cdf(m + 1) - cdf(m)).max(0.0)
                }
            })
            .collect();
        Law { lo, pmf }.trimmed()
    }

    /// A point mass at `v`.
    pub fn point(v: i64) -> Law {
        Law {
            lo: v,
            pmf: vec![1.0],
        }
    }

    /// Lowest lattice value held.
    pub fn lo(&self) -> i64 {
        self.lo
    }

    /// Highest lattice value held.
    pub fn hi(&self) -> i64 {
        self.lo + self.pmf.len() as i64 - 1
    }

    /// `P(X = v)`.
    pub fn pmf(&self, v: i64) -> f64 {
        if v < self.lo {
            return 0.0;
        }
        self.pmf.get((v - self.lo) as usize).copied().unwrap_or(0.0)
    }

    /// Total mass held (1 up to the trimmed tails).
    pub fn mass(&self) -> f64 {
        self.pmf.iter().sum()
    }

    /// Mean (lattice units).
    pub fn mean(&self) -> f64 {
        let m: f64 = self.mass();
        self.pmf
            .iter()
            .enumerate()
            .map(|(i, p)| (self.lo + i as i64) as f64 * p)
            .sum::<f64>()
            / m
    }

    /// The survival function on `lo..=hi + 1`: `s[i] = P(X >= lo + i)` (summed from the
    /// top, so the upper tail is exact to rounding).
    fn survival_table(&self) -> Vec<f64> {
        let mut s = vec![0.0; self.pmf.len() + 1];
        let mut acc = 0.0;
        for i in (0..self.pmf.len()).rev() {
            acc += self.pmf[i];
            s[i] = acc;
        }
        s
    }

    /// `P(X >= v)`.
    pub fn survival(&self, v: i64) -> f64 {
        if v <= self.lo {
            return self.mass();
        }
        let i = (v - self.lo) as usize;
        self.pmf.get(i..).map_or(0.0, |t| t.iter().sum())
    }

    /// The smallest lattice value `v` with `P(X >= v) <= alpha`, and that probability:
    /// a threshold `V_T` at false-alarm rate `alpha` (the achieved rate is at most
    /// `alpha`: the lattice is discrete).
    pub fn upper_quantile(&self, alpha: f64) -> (i64, f64) {
        let s = self.survival_table();
        for (i, &p) in s.iter().enumerate() {
            if p <= alpha {
                return (self.lo + i as i64, p);
            }
        }
        (self.hi() + 1, 0.0)
    }

    /// The law shifted by `g` lattice steps (`X + g`).
    pub fn shifted(&self, g: i64) -> Law {
        Law {
            lo: self.lo + g,
            pmf: self.pmf.clone(),
        }
    }

    /// The law of `X + Y` for independent `X ~ self`, `Y ~ other` (direct convolution).
    pub fn plus(&self, other: &Law) -> Law {
        let (a, b) = if self.pmf.len() <= other.pmf.len() {
            (self, other)
        } else {
            (other, self)
        };
        let mut out = vec![0.0; a.pmf.len() + b.pmf.len() - 1];
        for (i, &pa) in a.pmf.iter().enumerate() {
            if pa == 0.0 {
                continue;
            }
            for (o, &pb) in out[i..].iter_mut().zip(&b.pmf) {
                *o += pa * pb;
            }
        }
        Law {
            lo: a.lo + b.lo,
            pmf: out,
        }
        .trimmed()
    }

    /// The law of `max_i (X_i + g_i)` for independent `X_i ~ terms[i].0`, shifts
    /// `g_i = terms[i].1`; `None` for no terms.
    pub fn max_of(terms: &[(&Law, i64)]) -> Option<Law> {
        let lo = terms.iter().map(|(l, g)| l.lo + g).max()?;
        let hi = terms.iter().map(|(l, g)| l.hi() + g).max()?;
        let tables: Vec<(Vec<f64>, i64)> = terms
            .iter()
            .map(|(l, g)| (l.survival_table(), l.lo + g))
            .collect();
        // S_max(v) = -expm1(sum_i ln1p(-S_i(v))) for v in lo..=hi + 1
        let n = (hi - lo + 2) as usize;
        let mut s = vec![0.0f64; n];
        for (k, sv) in s.iter_mut().enumerate() {
            let v = lo + k as i64;
            let mut acc = 0.0f64;
            for (t, base) in &tables {
                let si = if v <= *base {
                    t.first().copied().unwrap_or(0.0)
                } else {
                    t.get((v - base) as usize).copied().unwrap_or(0.0)
                };
                acc += (-si.min(1.0)).ln_1p();
            }
            *sv = -acc.exp_m1();
        }
        let pmf = s.windows(2).map(|w| (w[0] - w[1]).max(0.0)).collect();
        Some(Law { lo, pmf }.trimmed())
    }

    /// The law of the max of `q` independent copies of `X` (`F_max = F^q`, eq. 20).
    pub fn max_pow(&self, q: usize) -> Law {
        if q <= 1 {
            return self.clone();
        }
        let s = self.survival_table();
        let q = q as f64;
        let ms: Vec<f64> = s
            .iter()
            .map(|&si| -(q * (-si.min(1.0)).ln_1p()).exp_m1())
            .collect();
        let pmf = ms.windows(2).map(|w| (w[0] - w[1]).max(0.0)).collect();
        Law { lo: self.lo, pmf }.trimmed()
    }

    /// Drops the mass below [`TRIM`] at each end (keeps at least one point).
    fn trimmed(mut self) -> Law {
        let mut lo_cut = 0;
        let mut acc = 0.0;
        for (i, &p) in self.pmf.iter().enumerate() {
            acc += p;
            if acc > TRIM {
                lo_cut = i;
                break;
            }
        }
        let mut hi_cut = self.pmf.len();
        acc = 0.0;
        for (i, &p) in self.pmf.iter().enumerate().rev() {
            acc += p;
            if acc > TRIM {
                hi_cut = i + 1;
                break;
            }
        }
        if lo_cut >= hi_cut {
            return self;
        }
        self.pmf.truncate(hi_cut);
        self.pmf.drain(..lo_cut);
        self.lo += lo_cut as i64;
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantised_normal_has_unit_mass_and_the_right_moments() {
        let l = Law::quantised_normal(3.0, 1.5, 1.0 / 16.0);
        assert!((l.mass() - 1.0).abs() < 1e-12);
        // mean of round(z/h) is mean/h exactly for a symmetric law centred on a lattice
        // point (3 = 48 h)
        assert!((l.mean() - 48.0).abs() < 1e-9);
    }

    #[test]
    fn max_and_sum_match_brute_force_on_small_laws() {
        let a = Law {
            lo: -1,
            pmf: vec![0.2, 0.5, 0.3],
        };
        let b = Law {
            lo: 0,
            pmf: vec![0.6, 0.4],
        };
        let s = a.plus(&b);
        let m = Law::max_of(&[(&a, 0), (&b, 1)]).unwrap();
        let mut ps = [0.0; 8];
        let mut pm = [0.0; 8];
        for (i, pa) in a.pmf.iter().enumerate() {
            for (j, pb) in b.pmf.iter().enumerate() {
                let (x, y) = (-1 + i as i64, j as i64);
                ps[(x + y + 4) as usize] += pa * pb;
                pm[(x.max(y + 1) + 4) as usize] += pa * pb;
            }
        }
        for v in -4..4i64 {
            assert!(
                (s.pmf(v) - ps[(v + 4) as usize]).abs() < 1e-15,
                "sum at {v}"
            );
            assert!(
                (m.pmf(v) - pm[(v + 4) as usize]).abs() < 1e-15,
                "max at {v}"
            );
        }
        let p3 = a.max_pow(3);
        let bf: f64 = (0..27)
            .filter(|k| {
                let v = [k % 3, (k / 3) % 3, k / 9]
                    .iter()
                    .map(|&i| -1 + i as i64)
                    .max();
                v == Some(1)
            })
            .map(|k| a.pmf[k % 3] * a.pmf[(k / 3) % 3] * a.pmf[k / 9])
            .sum();
        assert!((p3.pmf(1) - bf).abs() < 1e-15);
        assert_eq!(a.upper_quantile(0.3), (1, 0.3));
        assert_eq!(a.upper_quantile(0.29), (2, 0.0));
    }
}
