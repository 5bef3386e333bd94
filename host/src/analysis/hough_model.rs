//! Analytic detection model of MHT-TBD (paper 003, §4), plus the binomial model of the
//! classic Hough TBD used to set its threshold.
//!
//! ## Cell value (eq. 11)
//! After censoring, a Hough cell's value over `N` scans is `m_s = X + (M-1) I`, with `X`
//! the number of overlapping `M`-runs and `I` the number of run clusters of length `>= M`
//! in its binary hit sequence: this is the number of scans that belong to a run of at
//! least `M` consecutive hits (a cluster of length `L >= M` holds `L - M + 1` overlapping
//! runs, and `L - M + 1 + M - 1 = L`). Its law for an i.i.d. Bernoulli(`p`) sequence is
//! computed exactly by dynamic programming over `(current run length capped at M, value)`
//! instead of the garbled closed forms of eq. 12-13 ([`run_value_pmf`]); it is tested
//! against brute-force enumeration and simulated sequences (`tests/mht_model.rs`).
//!
//! ## Hit probabilities (eq. 15-19), re-derived
//! Lengths are in resolution cells (the seed mixes metres and per-cell probabilities):
//! `L0 = V_max T_scan N / (2 res)` cells on the average track, `Pfa0 = lambda / A`, and the
//! number `l` of clutter plots on such a line in one scan is Poisson with mean
//! `mu = L0 Pfa0` (eq. 15). Two points uniform on `[0, L0]` are farther apart than the gate
//! `g = V_max T_scan / res = 2 L0 / N` with probability `q1 = (1 - g / L0)^2 = (1 - 2/N)^2`
//! (eq. 16). With `l1`, `l2` plots in consecutive scans, all `l1 l2` pairs fail the gate
//! with probability (pairs taken independent, as the paper does) `q1^(l1 l2)`, so
//! `P(some pair passes) = 1 - sum_{l1,l2} q1^(l1 l2) p(l1) p(l2)
//!                      = 1 - sum_l p(l) exp(mu (q1^l - 1))`
//! (the inner sum is a Poisson generating function; the seed's one-line closed form is
//! not this and is not used). Eq. 17 conditions on the cell being hit in the scan:
//! `p_ch = P(some pair passes) / (1 - p(0))`.
//! For a target's cell, the scan is a miss only if the target plot is missed (`1 - Pd0`)
//! and no clutter plot lies within the gate of the line segment, a length
//! `L0 (1 - sqrt(q1)) = g` of line: `p_dh = 1 - (1 - Pd0) exp(-mu (1 - sqrt(q1)))`
//! (eq. 19 with the sign of the exponent fixed: the seed's `exp(-mu (sqrt(q1) - 1))` is
//! larger than 1).
//!
//! ## Cross-track correction (eq. 20-26) and decision (eq. 27-29)
//! `N_c = ceil(N_rho N_theta P^0(m > 0))` clutter tracks survive censoring; `m0`, `m1`
//! are the means of `P^0`, `P^1` given `m > 0`; `Sigma1 = N_c + N_t - 1`;
//! `p0 = m0/N_rho (N_c - 1)/Sigma1 + m1/N_rho N_t/Sigma1`,
//! `p1 = m0/N_rho N_c/Sigma1 + m1/N_rho (N_t - 1)/Sigma1`;
//! `P0 = P^0 * Binomial(Sigma1, p0)`, `P1 = P^1 * Binomial(Sigma1, p1)` (convolution;
//! the mass above `N` is folded into `N` since binary integration caps a cell at `N`).
//! Cell `Pfa = sum_{x >= gamma} P0(x)`, grid `Pfa = 1 - (1 - Pfa_cell)^(N_rho N_theta)`,
//! `Pd = sum_{x >= gamma} P1(x)`.

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

/// Binomial(`n`, `p`) pmf.
pub fn binomial_pmf(n: usize, p: f64) -> Vec<f64> {
    let mut out = vec![0.0; n + 1];
    if p <= 0.0 {
        out[0] = 1.0;
        return out;
    }
    if p >= 1.0 {
        out[n] = 1.0;
        return out;
    }
    let (lp, lq) = (p.ln(), (1.0 - p).ln());
    let mut lc = 0.0f64; // ln C(n, k)
    for (k, o) in out.iter_mut().enumerate() {
        if k > 0 {
            lc += ((n - k + 1) as f64).ln() - (k as f64).ln();
        }
        *o = (lc + k as f64 * lp + (n - k) as f64 * lq).exp();
    }
    out
}

/// `P(X >= gamma)` of a pmf.
pub fn tail(pmf: &[f64], gamma: usize) -> f64 {
    pmf.iter().skip(gamma).sum::<f64>().min(1.0)
}

/// Model parameters (the seed's Fig. 2-4 set is [`ModelParams::paper`]).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct ModelParams {
    /// Resolution cells in the area `A`.
    pub a_cells: f64,
    /// Scans `N`.
    pub n: usize,
    /// Window `M`.
    pub m: usize,
    /// Target plot detection probability `Pd0`.
    pub pd0: f64,
    /// Targets `N_t`.
    pub n_targets: usize,
    /// Gate `V_max T_scan` in resolution cells.
    pub gate_cells: f64,
    /// `N_rho`.
    pub n_rho: usize,
    /// `N_theta`.
    pub n_theta: usize,
    /// Clutter plots per scan `lambda = A Pfa0`.
    pub lambda: f64,
}

impl ModelParams {
    /// Paper §4: `A = 4e4`, `N = 30`, `M = 3`, `Pd0 = 0.85`, `N_t = 5`,
    /// `V_max T_scan = 100 m` with 30 m cells, `256 x 180` grid.
    pub fn paper(lambda: f64) -> Self {
        Self {
            a_cells: 4e4,
            n: 30,
            m: 3,
            pd0: 0.85,
            n_targets: 5,
            gate_cells: 100.0 / 30.0,
            n_rho: 256,
            n_theta: 180,
            lambda,
        }
    }

    /// `L0 = g N / 2` (cells).
    pub fn l0(&self) -> f64 {
        self.gate_cells * self.n as f64 / 2.0
    }
    /// `mu = L0 Pfa0`.
    pub fn mu(&self) -> f64 {
        self.l0() * self.lambda / self.a_cells
    }
    /// `q1 = (1 - g/L0)^2`.
    pub fn q1(&self) -> f64 {
        (1.0 - self.gate_cells / self.l0()).max(0.0).powi(2)
    }
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

/// Length of the line `x cos(th) + y sin(th) = rho` inside the square `[-h, h]^2`.
pub fn chord(rho: f64, th: f64, h: f64) -> f64 {
    let (c, s) = (th.cos(), th.sin());
    let (px, py) = (rho * c, rho * s);
    let (dx, dy) = (-s, c);
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for (p, d) in [(px, dx), (py, dy)] {
        if d.abs() < 1e-12 {
            if p.abs() > h {
                return 0.0;
            }
        } else {
            let (a, b) = ((-h - p) / d, (h - p) / d);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t1 - t0).max(0.0)
}

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
