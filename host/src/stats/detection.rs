//! Detection statistics: thresholds for a wanted false-alarm probability, detection
//! rates with exact binomial confidence intervals, Pd-versus-SNR crossings and ROC points.
//!
//! Convention everywhere: a trial declares a detection when its test statistic is
//! **strictly greater** than the threshold.

use anyhow::{bail, ensure, Result};
use serde::Serialize;
use statrs::distribution::{Beta, Binomial, ContinuousCDF, DiscreteCDF};

/// Confidence level of every interval in this module.
pub const CONFIDENCE: f64 = 0.95;

/// A detection threshold set from H0 (no-target) statistics.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Threshold {
    /// Decide H1 when the statistic is `> value`.
    pub value: f64,
    /// Wanted false-alarm probability.
    pub pfa: f64,
    /// Number of H0 statistics it was set from.
    pub n: usize,
    /// Lower end of the distribution-free 95 % confidence interval of the
    /// `(1 - pfa)` quantile (an order statistic).
    pub ci_low: f64,
    /// Upper end of that interval.
    pub ci_high: f64,
}

/// Sets the threshold for a false-alarm probability `pfa` from H0 statistics.
///
/// The threshold is the order statistic `x_(r)`, `r = ceil(n (1 - pfa))` (1-based), so at
/// most `n pfa` of the H0 values exceed it. Its confidence interval is distribution-free:
/// the number of H0 values below the true quantile is Binomial(n, 1 - pfa), so
/// `[x_(l), x_(u)]` with `l`, `u` its 2.5 % and 97.5 % quantiles (+1) covers the true
/// quantile with probability >= 95 %.
///
/// Errors: empty input, NaN in it, `pfa` outside `(0, 1)`, or fewer than `1 / pfa` values
/// (the quantile would not be resolved).
pub fn threshold_at_pfa(h0: &[f64], pfa: f64) -> Result<Threshold> {
    ensure!(
        pfa > 0.0 && pfa < 1.0,
        "false-alarm probability must lie in (0, 1), got {pfa}"
    );
    ensure!(!h0.is_empty(), "no H0 statistics to set a threshold from");
    ensure!(h0.iter().all(|x| !x.is_nan()), "H0 statistics contain NaN");
    let n = h0.len();
    ensure!(
        (n as f64) * pfa >= 1.0,
        "{n} H0 trials cannot resolve Pfa = {pfa}: need at least {}",
        (1.0 / pfa).ceil()
    );
    let mut s = h0.to_vec();
    s.sort_by(f64::total_cmp);
    let r = ((n as f64) * (1.0 - pfa)).ceil() as usize;
    let r = r.clamp(1, n);
    let value = s[r - 1];
    let bin = Binomial::new(1.0 - pfa, n as u64)?;
    let alpha = 1.0 - CONFIDENCE;
    let l = bin.inverse_cdf(alpha / 2.0) as usize;
    let u = bin.inverse_cdf(1.0 - alpha / 2.0) as usize + 1;
    Ok(Threshold {
        value,
        pfa,
        n,
        ci_low: s[l.clamp(1, n) - 1],
        ci_high: s[u.clamp(1, n) - 1],
    })
}

/// A binomial proportion with its Clopper-Pearson (exact) 95 % interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Proportion {
    /// Successes.
    pub k: usize,
    /// Trials.
    pub n: usize,
    /// `k / n` (0 when `n == 0`).
    pub p: f64,
    /// Lower end of the interval.
    pub lo: f64,
    /// Upper end of the interval.
    pub hi: f64,
}

/// `k` successes in `n` trials, with the Clopper-Pearson interval
/// `[B(a/2; k, n-k+1), B(1-a/2; k+1, n-k)]` (`B` the beta quantile, `a = 0.05`).
/// `n == 0` gives `p = 0` and the uninformative interval `[0, 1]`.
pub fn proportion(k: usize, n: usize) -> Proportion {
    let k = k.min(n);
    if n == 0 {
        return Proportion {
            k,
            n,
            p: 0.0,
            lo: 0.0,
            hi: 1.0,
        };
    }
    let alpha = 1.0 - CONFIDENCE;
    let (kf, nf) = (k as f64, n as f64);
    let lo = if k == 0 {
        0.0
    } else {
        Beta::new(kf, nf - kf + 1.0)
            .map(|b| b.inverse_cdf(alpha / 2.0))
            .unwrap_or(0.0)
    };
    let hi = if k == n {
        1.0
    } else {
        Beta::new(kf + 1.0, nf - kf)
            .map(|b| b.inverse_cdf(1.0 - alpha / 2.0))
            .unwrap_or(1.0)
    };
    Proportion {
        k,
        n,
        p: kf / nf,
        lo,
        hi,
    }
}

/// Fraction of `stats` strictly above `threshold` (NaN counts as no detection).
pub fn detection_rate(stats: &[f64], threshold: f64) -> Proportion {
    let k = stats.iter().filter(|&&s| s > threshold).count();
    proportion(k, stats.len())
}

/// The `x` at which a curve first crosses `y = level` upwards, by linear interpolation
/// between the two bracketing points. `points` must be sorted by `x`. `None` when the
/// curve never reaches `level`, or already starts at or above it (not bracketed).
pub fn crossing(points: &[(f64, f64)], level: f64) -> Option<f64> {
    let first = points.first()?;
    if first.1 >= level {
        return None;
    }
    for w in points.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if y0 < level && y1 >= level {
            if y1 == y0 {
                return Some(x1);
            }
            return Some(x0 + (level - y0) * (x1 - x0) / (y1 - y0));
        }
    }
    None
}

/// One point of a Pd-versus-SNR curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PdPoint {
    /// SNR in dB.
    pub snr_db: f64,
    /// Detection rate at that SNR.
    pub pd: Proportion,
}

/// The SNR at which a Pd curve reaches a level, with an interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SnrAtPd {
    /// Crossing of the Pd estimates.
    pub snr_db: Option<f64>,
    /// Crossing of the upper confidence limits (the curve could reach the level this
    /// early).
    pub lo_db: Option<f64>,
    /// Crossing of the lower confidence limits (it reaches the level by here).
    pub hi_db: Option<f64>,
}

/// SNR at which a Pd curve crosses `level`; the interval comes from the crossings of the
/// pointwise Clopper-Pearson bounds (a conservative band, not a joint interval).
pub fn snr_at_pd(curve: &[PdPoint], level: f64) -> SnrAtPd {
    let pts = |f: fn(&Proportion) -> f64| -> Vec<(f64, f64)> {
        curve.iter().map(|c| (c.snr_db, f(&c.pd))).collect()
    };
    SnrAtPd {
        snr_db: crossing(&pts(|p| p.p), level),
        lo_db: crossing(&pts(|p| p.hi), level),
        hi_db: crossing(&pts(|p| p.lo), level),
    }
}

/// ROC points `(pfa, pd)` for every threshold between distinct observed values, from
/// `(1, 1)` down to `(0, 0)`, sorted by increasing `pfa`.
pub fn roc(h0: &[f64], h1: &[f64]) -> Result<Vec<(f64, f64)>> {
    if h0.is_empty() || h1.is_empty() {
        bail!("ROC needs H0 and H1 statistics");
    }
    ensure!(
        h0.iter().chain(h1).all(|x| !x.is_nan()),
        "ROC statistics contain NaN"
    );
    let mut t: Vec<f64> = h0.iter().chain(h1).copied().collect();
    t.sort_by(f64::total_cmp);
    t.dedup();
    let mut a = h0.to_vec();
    let mut b = h1.to_vec();
    a.sort_by(f64::total_cmp);
    b.sort_by(f64::total_cmp);
    let above = |s: &[f64], th: f64| s.len() - s.partition_point(|&x| x <= th);
    let mut pts = vec![(1.0, 1.0)];
    for &th in &t {
        pts.push((
            above(&a, th) as f64 / a.len() as f64,
            above(&b, th) as f64 / b.len() as f64,
        ));
    }
    pts.sort_by(|p, q| p.0.total_cmp(&q.0).then(p.1.total_cmp(&q.1)));
    pts.dedup();
    Ok(pts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use faint_core::rng::Rng;

    #[test]
    fn threshold_order_statistic() {
        let h0: Vec<f64> = (1..=1000).map(|i| i as f64).collect();
        let t = threshold_at_pfa(&h0, 0.01).unwrap();
        assert_eq!(t.value, 990.0);
        assert_eq!(detection_rate(&h0, t.value).k, 10);
        assert!(t.ci_low < t.value && t.value < t.ci_high);
        assert!(threshold_at_pfa(&h0, 0.0001).is_err());
        assert!(threshold_at_pfa(&h0, 1.5).is_err());
        assert!(threshold_at_pfa(&[f64::NAN; 200], 0.1).is_err());
    }

    #[test]
    fn clopper_pearson_reference_values() {
        // Reference: k = 5, n = 20 -> [0.0866, 0.4910] (Clopper & Pearson 1934, as
        // tabulated by e.g. R's binom.test(5, 20)).
        let p = proportion(5, 20);
        assert!((p.lo - 0.086_571_5).abs() < 1e-5, "{}", p.lo);
        assert!((p.hi - 0.491_046_1).abs() < 1e-5, "{}", p.hi);
        let z = proportion(0, 10);
        assert_eq!(z.lo, 0.0);
        assert!((z.hi - 0.308_502_2).abs() < 1e-5);
        assert_eq!(proportion(0, 0).hi, 1.0);
    }

    #[test]
    fn calibration_on_independent_batch() {
        // A threshold at Pfa = 0.05 set on 20 000 uniform H0 draws, applied to another
        // 20 000: the false-alarm count must lie in the 95 % Clopper-Pearson interval
        // around the target (with a fixed seed this is a deterministic check; the
        // threshold's own sampling error, sd ~ sqrt(pfa(1-pfa)/n) = 0.0015, is well
        // inside the interval half-width of ~0.003 at n = 20 000).
        let mut rng = Rng::seed_from_u64(11);
        let a: Vec<f64> = (0..20_000).map(|_| rng.uniform() as f64).collect();
        let b: Vec<f64> = (0..20_000).map(|_| rng.uniform() as f64).collect();
        let t = threshold_at_pfa(&a, 0.05).unwrap();
        let fa = detection_rate(&b, t.value);
        let band = proportion(1000, 20_000);
        assert!(fa.p > band.lo && fa.p < band.hi, "{fa:?} {band:?}");
    }

    #[test]
    fn crossing_interpolates() {
        let c = [(0.0, 0.1), (2.0, 0.3), (4.0, 0.7), (6.0, 0.95)];
        assert!((crossing(&c, 0.5).unwrap() - 3.0).abs() < 1e-12);
        assert_eq!(crossing(&c, 0.99), None);
        assert_eq!(crossing(&c, 0.05), None);
        let curve: Vec<PdPoint> = [(0.0, 10), (2.0, 50), (4.0, 90)]
            .iter()
            .map(|&(s, k)| PdPoint {
                snr_db: s,
                pd: proportion(k, 100),
            })
            .collect();
        let s = snr_at_pd(&curve, 0.5);
        assert!((s.snr_db.unwrap() - 2.0).abs() < 1e-9);
        assert!(s.lo_db.unwrap() < 2.0 && s.hi_db.unwrap() > 2.0);
    }

    #[test]
    fn roc_endpoints_and_monotone() {
        let h0 = [0.1, 0.2, 0.3, 0.4];
        let h1 = [0.35, 0.5, 0.6, 0.7];
        let r = roc(&h0, &h1).unwrap();
        assert_eq!(r.first(), Some(&(0.0, 0.0)));
        assert_eq!(r.last(), Some(&(1.0, 1.0)));
        assert!(r.windows(2).all(|w| w[0].0 <= w[1].0 && w[0].1 <= w[1].1));
        assert!(r.contains(&(0.0, 0.75)));
    }
}
