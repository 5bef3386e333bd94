//! Threshold model of the classic Hough TBD (Carlson, Evans, Wilson 1994): a cell's count
//! is binomial over the scans with the probability that a clutter plot falls in its strip;
//! [`classic_gamma`] is the smallest threshold whose whole-grid Pfa meets the target.

use super::{binomial_pmf, chord};

/// Classic Hough TBD clutter model: cell `(r, a)` of an `n_rho x n_theta` grid centred on
/// a square area of side `side` (m) is hit in a scan when at least one of the Poisson
/// (`lambda`) uniform plots falls in its strip (`chord x drho`), so its count is
/// `Binomial(N, 1 - exp(-lambda chord drho / side^2))`. Returns the whole-grid Pfa at each
/// `gamma in 0..=n` (cells assumed independent).
pub fn classic_pfa_grid(
    side: f64,
    n_rho: usize,
    n_theta: usize,
    n: usize,
    lambda: f64,
) -> Vec<f64> {
    let h = side / 2.0;
    let rho_max = h * 2f64.sqrt();
    let drho = 2.0 * rho_max / n_rho as f64;
    // log of P(no false alarm) per gamma
    let mut log_ok = vec![0.0f64; n + 1];
    for a in 0..n_theta {
        let th = a as f64 * std::f64::consts::PI / n_theta as f64;
        for r in 0..n_rho {
            let rho = -rho_max + (r as f64 + 0.5) * drho;
            let len = chord(rho, th, h);
            if len <= 0.0 {
                continue;
            }
            let p = -(-lambda * len * drho / (side * side)).exp_m1();
            let pmf = binomial_pmf(n, p);
            let mut t = 0.0;
            for g in (0..=n).rev() {
                t += pmf[g];
                log_ok[g] += (-t.min(1.0)).ln_1p();
            }
        }
    }
    log_ok.iter().map(|l| -l.exp_m1()).collect()
}

/// Smallest classic threshold with grid `Pfa <= pfa` (`n + 1` if none).
pub fn classic_gamma(
    side: f64,
    n_rho: usize,
    n_theta: usize,
    n: usize,
    lambda: f64,
    pfa: f64,
) -> usize {
    let g = classic_pfa_grid(side, n_rho, n_theta, n, lambda);
    (1..=n).find(|&k| g[k] <= pfa).unwrap_or(n + 1)
}
