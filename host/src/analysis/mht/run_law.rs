//! The paper's cell-value law (eq. 11-29, see the module doc): the run value of a binary
//! hit sequence and its exact law, the clutter and target hit probabilities `p_ch` and
//! `p_dh`, and [`CellModel`], the cross-track correction and decision of eq. 20-29 that
//! draws the Fig. 2-4 curves.

use super::{binomial_pmf, tail, ModelParams};

/// Number of scans of `seq` that belong to a run of at least `m` consecutive hits.
pub fn run_value(seq: &[bool], m: usize) -> usize {
    let mut v = 0;
    let mut run = 0;
    for &h in seq.iter().chain(core::iter::once(&false)) {
        if h {
            run += 1;
        } else {
            if run >= m {
                v += run;
            }
            run = 0;
        }
    }
    v
}

/// Exact law of [`run_value`] for `n` i.i.d. Bernoulli(`p`) scans: `pmf[v]`, `v in 0..=n`.
pub fn run_value_pmf(n: usize, m: usize, p: f64) -> Vec<f64> {
    let m = m.max(1);
    let q = 1.0 - p;
    // state r in 0..=m (m = inside a run already counted)
    let mut cur = vec![vec![0.0f64; n + 1]; m + 1];
    cur[0][0] = 1.0;
    for _ in 0..n {
        let mut nxt = vec![vec![0.0f64; n + 1]; m + 1];
        for r in 0..=m {
            for v in 0..=n {
                let w = cur[r][v];
                if w == 0.0 {
                    continue;
                }
                nxt[0][v] += w * q;
                if r == m {
                    nxt[m][(v + 1).min(n)] += w * p;
                } else if r + 1 == m {
                    nxt[m][(v + m).min(n)] += w * p;
                } else {
                    nxt[r + 1][v] += w * p;
                }
            }
        }
        cur = nxt;
    }
    let mut out = vec![0.0; n + 1];
    for row in &cur {
        for (o, w) in out.iter_mut().zip(row) {
            *o += w;
        }
    }
    out
}

/// The same law by enumerating all `2^n` sequences (small `n` only).
pub fn run_value_pmf_brute(n: usize, m: usize, p: f64) -> Vec<f64> {
    let mut out = vec![0.0; n + 1];
    let mut seq = vec![false; n];
    for bits in 0u64..(1u64 << n) {
        let mut k = 0;
        for (i, s) in seq.iter_mut().enumerate() {
            *s = bits >> i & 1 == 1;
            k += usize::from(*s);
        }
        out[run_value(&seq, m)] += p.powi(k as i32) * (1.0 - p).powi((n - k) as i32);
    }
    out
}

/// Poisson pmf up to where the tail is negligible.
fn poisson_pmf(mu: f64) -> Vec<f64> {
    let kmax = (mu + 12.0 * mu.sqrt() + 30.0).ceil() as usize;
    let mut out = Vec::with_capacity(kmax + 1);
    let mut w = (-mu).exp();
    for k in 0..=kmax {
        if k > 0 {
            w *= mu / k as f64;
        }
        out.push(w);
    }
    out
}

/// Clutter cell hit probability `p_ch` (eq. 17, re-derived, see the module doc).
pub fn p_ch(mp: &ModelParams) -> f64 {
    let mu = mp.mu();
    if mu <= 0.0 {
        return 0.0;
    }
    let q1 = mp.q1();
    let pois = poisson_pmf(mu);
    let none: f64 = pois
        .iter()
        .enumerate()
        .map(|(l, p)| p * (mu * (q1.powi(l as i32) - 1.0)).exp())
        .sum();
    ((1.0 - none) / (1.0 - (-mu).exp())).clamp(0.0, 1.0)
}

/// Target cell hit probability `p_dh` (eq. 19, sign of the exponent fixed).
pub fn p_dh(mp: &ModelParams) -> f64 {
    1.0 - (1.0 - mp.pd0) * (-mp.mu() * (1.0 - mp.q1().sqrt())).exp()
}

/// The model's laws for one parameter set.
#[derive(Debug, Clone)]
pub struct CellModel {
    /// Parameters.
    pub params: ModelParams,
    /// `p_ch`.
    pub p_ch: f64,
    /// `p_dh`.
    pub p_dh: f64,
    /// `P^0`, `P^1`: run-value laws without cross-track correction (eq. 14).
    pub p0_raw: Vec<f64>,
    /// See `p0_raw`.
    pub p1_raw: Vec<f64>,
    /// `N_c` (eq. 21).
    pub n_c: f64,
    /// `p0`, `p1` (eq. 22-23).
    pub p0_cross: f64,
    /// See `p0_cross`.
    pub p1_cross: f64,
    /// `P0`, `P1` (eq. 25-26).
    pub p0: Vec<f64>,
    /// See `p0`.
    pub p1: Vec<f64>,
}

fn conv_capped(a: &[f64], b: &[f64], cap: usize) -> Vec<f64> {
    let mut out = vec![0.0; cap + 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[(i + j).min(cap)] += x * y;
        }
    }
    out
}

fn cond_mean(pmf: &[f64]) -> f64 {
    let pos: f64 = pmf.iter().skip(1).sum();
    if pos <= 0.0 {
        return 0.0;
    }
    pmf.iter()
        .enumerate()
        .skip(1)
        .map(|(k, p)| k as f64 * p)
        .sum::<f64>()
        / pos
}

impl CellModel {
    /// Evaluate the model.
    pub fn new(params: ModelParams) -> Self {
        let (pc, pd) = (p_ch(&params), p_dh(&params));
        Self::with_hit_probabilities(params, pc, pd)
    }

    /// The model with given hit probabilities (e.g. the optimal detector's).
    pub fn with_hit_probabilities(params: ModelParams, pc: f64, pd: f64) -> Self {
        let n = params.n;
        let p0_raw = run_value_pmf(n, params.m, pc);
        let p1_raw = run_value_pmf(n, params.m, pd);
        Self::from_raw(params, pc, pd, p0_raw, p1_raw)
    }

    fn from_raw(params: ModelParams, pc: f64, pd: f64, p0_raw: Vec<f64>, p1_raw: Vec<f64>) -> Self {
        let n = params.n;
        let cells = (params.n_rho * params.n_theta) as f64;
        let n_c = (cells * tail(&p0_raw, 1)).ceil();
        let nt = params.n_targets as f64;
        let (m0, m1) = (cond_mean(&p0_raw), cond_mean(&p1_raw));
        let sigma1 = n_c + nt - 1.0;
        let nr = params.n_rho as f64;
        let (p0c, p1c) = if sigma1 > 0.0 {
            (
                (m0 / nr * (n_c - 1.0).max(0.0) / sigma1 + m1 / nr * nt / sigma1).clamp(0.0, 1.0),
                (m0 / nr * n_c / sigma1 + m1 / nr * (nt - 1.0).max(0.0) / sigma1).clamp(0.0, 1.0),
            )
        } else {
            (0.0, 0.0)
        };
        let s1 = sigma1.max(0.0) as usize;
        let p0 = conv_capped(&p0_raw, &binomial_pmf(s1, p0c), n);
        let p1 = conv_capped(&p1_raw, &binomial_pmf(s1, p1c), n);
        Self {
            params,
            p_ch: pc,
            p_dh: pd,
            p0_raw,
            p1_raw,
            n_c,
            p0_cross: p0c,
            p1_cross: p1c,
            p0,
            p1,
        }
    }

    /// Velocity-constrained optimal binary integration (Fig. 4 reference): every gated
    /// hit counts, no run requirement: `Binomial(N, p)` with the same hit probabilities
    /// and the same cross-track correction.
    pub fn optimal(params: ModelParams) -> Self {
        let (pc, pd) = (p_ch(&params), p_dh(&params));
        let b0 = binomial_pmf(params.n, pc);
        let b1 = binomial_pmf(params.n, pd);
        Self::from_raw(params, pc, pd, b0, b1)
    }

    /// Cell false-alarm probability at threshold `gamma` (eq. 27).
    pub fn pfa_cell(&self, gamma: usize) -> f64 {
        tail(&self.p0, gamma)
    }
    /// Whole-grid false-alarm probability (eq. 28).
    pub fn pfa_grid(&self, gamma: usize) -> f64 {
        let c = self.pfa_cell(gamma);
        let cells = (self.params.n_rho * self.params.n_theta) as f64;
        -(cells * (-c).ln_1p()).exp_m1()
    }
    /// Detection probability (eq. 29).
    pub fn pd(&self, gamma: usize) -> f64 {
        tail(&self.p1, gamma)
    }
    /// Smallest `gamma` with grid `Pfa <= pfa` (`N + 1` if none).
    pub fn gamma_for_pfa(&self, pfa: f64) -> usize {
        (1..=self.params.n)
            .find(|&g| self.pfa_grid(g) <= pfa)
            .unwrap_or(self.params.n + 1)
    }
}
