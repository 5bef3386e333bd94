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
//! `Pd = sum_{x >= gamma} P1(x)`. This is the "paper" variant ([`CellModel`]), kept for
//! the Fig. 2-4 curves.
//!
//! ## Compound cell law (extension, [`CompoundModel`]; sets `gamma_1` by default)
//! Measured (README "Why the model and simulation differ"): the paper's `P0` is far too
//! light in its tail (simulated / model cell tail up to 1.7e4 at lambda 164-237) because
//! eq. 22-26 let another track add at most one hit to a cell and spread crossings
//! uniformly (`m0 / N_rho`), while in the DMHT several near-parallel clutter chains stack
//! in one cell and cells on long chords collect more. The compound law describes a DMHT
//! cell directly:
//!
//! 1. Chains. The effective clutter plots form `N_ch` chains per period (a chain = plots
//!    of consecutive scans, gated, kept by censoring), of length `j` with law `q(j)`.
//!    A chain is taken straight, direction `phi` uniform, position uniform in the area
//!    (square of side `S`, area `A = S^2`), step `s` between its plots distributed as
//!    the distance of a point uniform in the gate disk: `s = g sqrt(u)`, `u ~ U(0,1)`.
//! 2. Cell. Cell `(rho, theta)` is the strip `rho <= x cos(theta) + y sin(theta) <
//!    rho + drho` (DMHT grid centred on the area, `rho_max = S / sqrt(2)`,
//!    `drho = 2 rho_max / N_rho`); its part in the area has length `c = chord(rho, theta)`.
//!    A chain with angle `psi` to the cell's line has its plots at normal offsets
//!    `u0 + i d`, `d = s |sin(psi)|`, `i < j`; the offset `u0` of a uniformly placed chain
//!    has density `c / A` per unit length near the strip. The plots in the strip are the
//!    consecutive indices with `0 <= u0 + i d < drho`; let `mu_k(j, d)` be the measure of
//!    the `u0` for which there are exactly `k >= 1` of them ([`lattice_measure`];
//!    `sum_k k mu_k = j drho`). So the chains putting `k` plots (in `k` consecutive scans)
//!    into the cell are Poisson with mean
//!    `Lambda_k(c) = c / A * N_ch * sum_j q(j) E_{psi, s}[mu_k(j, s |sin psi|)]`:
//!    `k = j` (the whole chain) when the chain is within about `drho / L` rad of the cell's
//!    direction (the "butterfly" of cells around every chain), `k = 1` when it crosses.
//!    Their first scan is uniform over `0..=N-k`.
//!    Targets (`N_t > 0`) are straight tracks of `N` plots with step `v T_scan`,
//!    `v ~ U(0, V_max)`; each adds `k` hits to the cell with probability
//!    `c / A E_{psi, v}[mu_k(N, v T_scan |sin psi|)]`, of which only `k < M` count (a cell
//!    holding `M` or more plots of one target follows that target: a detection or a
//!    duplicate, not a false alarm). The `N_t` targets are independent and added one by
//!    one to the clutter count: with `v` of the `N` scans covered, each of a target's `k`
//!    scans is new with probability `(N - v) / N`; missed target plots (`1 - Pd0`) are
//!    ignored (slightly conservative).
//! 3. Count. Binary integration counts the scans covered by at least one contribution:
//!    a discrete Boolean model, whose law is exact by a DP over scans ([`coverage_pmf`];
//!    state: scans still covered by the intervals started so far, and the count). The
//!    `M`-run rule does not enter here: censoring has already removed every plot that is
//!    not in a gated `M`-chain, and the DMHT counts all effective plots (this is what the
//!    detector thresholds).
//! 4. Grid. Cells are grouped by chord (96 bins); eq. 28 over the cells' own tails:
//!    `Pfa = 1 - prod_cells (1 - Pfa_cell(c))` (measured adequate: eq. 28 on the simulated
//!    cell tail gives the simulated grid Pfa within ~1.6x).
//!
//! Chain population ([`ChainSource`]): `PaperNc` takes `N_ch = N_c` and
//! `q(j) = P^0(j) / P^0(m > 0)` (eq. 14-21). Measured, this gives 0.40 / 2.93 / 9.5 / 24.4
//! / 52.8 effective clutter plots per scan at lambda 80 / 164 / 237 / 316 / 398 against
//! 0.57 / 4.6 / 13.0 / 29.0 / 53.9 simulated (eq. 15-17 put `mu = L0 Pfa0` plots on a
//! strip of length `L0`, while an MSHT strip is a chord, 4-5x longer on average, and a plot
//! is kept if its chain shares a cell at any of the `N_theta` angles), and the law is then
//! optimistic by about one count at lambda 164-316. `Censoring` (default) counts the
//! chains from the censoring rule ([`censoring_chains`]): with `G = lambda pi g^2 / A` the
//! mean number of plots of a scan in the gate of a given point (edge losses aside),
//! the gated `M`-chains starting in a scan number `T = lambda G^(M-1) c3`, where `c3` is the
//! probability that `M` gated points (each uniform in the gate disk of the previous one;
//! for `M = 3`: two points around a middle one) share one MSHT cell at some angle; a
//! chain extends by one scan with probability `e = 1 - exp(-G c_ext)` (`c_ext`: a new
//! gated point keeps the last `M` in one cell); chains start at the first window or
//! where no extension came: `N_ch = T (1 + (N - M)(1 - e))`, and
//! `q(j) = (1 - e) e^(j - M)` (`j < N`, the rest at `N`). `c3`, `c_ext` are geometric
//! constants computed by a fixed-seed Monte Carlo (40 000 draws) on the exact MSHT grid.
//! Measured: 0.60 / 5.0 / 14.8 / 34.3 / 66.7 effective plots per scan (sim above): a chain
//! that branches (two plots of one scan in chains through the same pair) is counted as
//! two, so the law over-counts at high lambda and is conservative there.

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

/// Which per-cell clutter law sets `gamma_1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum, serde::Serialize)]
pub enum Variant {
    /// Eq. 20-26 as published ([`CellModel`]): the Fig. 2-4 curves.
    Paper,
    /// The per-cell compound law ([`CompoundModel`], extension): holds the wanted Pfa.
    #[default]
    Compound,
}

/// Measure (over the chain's offset `u0`, same unit as `w`) of the placements where
/// exactly `k >= 1` of the `j` points `u0 + i d` (`i < j`) fall in `[0, w)`; added to
/// `out[k]`. `sum_k k out[k] = j w`.
pub fn lattice_measure(j: usize, d: f64, w: f64, out: &mut [f64]) {
    if j == 0 || w <= 0.0 {
        return;
    }
    if d <= 1e-12 {
        out[j] += w;
        return;
    }
    let mut bp: Vec<f64> = (0..j)
        .flat_map(|i| [-(i as f64) * d, w - i as f64 * d])
        .collect();
    bp.sort_by(f64::total_cmp);
    for ab in bp.windows(2) {
        let (a, b) = (ab[0], ab[1]);
        if b <= a {
            continue;
        }
        let mid = 0.5 * (a + b);
        let k = (0..j)
            .filter(|&i| {
                let u = mid + i as f64 * d;
                (0.0..w).contains(&u)
            })
            .count();
        if k > 0 {
            out[k] += b - a;
        }
    }
}

/// Exact law of the number of scans covered by a Poisson process of scan intervals
/// (discrete Boolean model): `nu[t][k]` = mean number of intervals `[t, t + k)` starting at
/// scan `t` (`k` in `1..=n`). Returns `pmf[v]`, `v in 0..=n`.
///
/// DP over scans with state `r` = scans still covered from the current one on (the
/// largest remaining length of the intervals started so far) and `v` = covered scans so
/// far. At scan `t` the longest new interval has `P(K_max <= k) = exp(-sum_{k' > k}
/// nu[t][k'])` (Poisson thinning), `r <- max(r, K_max)`, and the scan is covered iff `r >= 1`.
pub fn coverage_pmf(n: usize, nu: &[Vec<f64>]) -> Vec<f64> {
    // cur[r][v]
    let mut cur = vec![vec![0.0f64; n + 1]; n + 1];
    cur[0][0] = 1.0;
    let mut pk = vec![0.0f64; n + 1];
    for row in nu.iter().take(n) {
        // P(K_max = k), k in 0..=n
        let mut above = 0.0f64; // sum_{k' > k} nu
        let mut g = vec![0.0f64; n + 1];
        for k in (0..=n).rev() {
            g[k] = (-above).exp();
            above += row.get(k).copied().unwrap_or(0.0);
        }
        for k in 0..=n {
            pk[k] = g[k] - if k > 0 { g[k - 1] } else { 0.0 };
        }
        let mut nxt = vec![vec![0.0f64; n + 1]; n + 1];
        for (r, row) in cur.iter().enumerate() {
            for (v, &w) in row.iter().enumerate() {
                if w == 0.0 {
                    continue;
                }
                for (k, p) in pk.iter().enumerate() {
                    if *p == 0.0 {
                        continue;
                    }
                    let r2 = r.max(k);
                    if r2 >= 1 {
                        nxt[r2 - 1][(v + 1).min(n)] += w * p;
                    } else {
                        nxt[0][v] += w * p;
                    }
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

/// Where the compound law takes its clutter chains (count and length law) from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum ChainSource {
    /// The paper's clutter tracks: `N_c` (eq. 21) chains with the run-length law
    /// `P^0(j) / P^0(m > 0)` of eq. 14-17.
    PaperNc,
    /// Chains counted from the censoring rule itself ([`censoring_chains`]).
    Censoring,
}

/// Clutter chains that survive censoring, from the censoring rule (see the module doc,
/// "Chain population"): returns `(chains per period, length law q[j], c3, c_ext)`.
///
/// `c3` = P(two points uniform in the gate disk around a third, all in the area, share
/// one MSHT cell at one of the `N_theta` angles), `c_ext` = P(a fourth point uniform in
/// the gate of the third keeps the last three in one cell, given the first three do);
/// both by a fixed-seed Monte Carlo over the exact geometry (square area, rho bins of
/// `drho = side sqrt(2) / N_rho` from the centre).
pub fn censoring_chains(params: &ModelParams) -> (f64, Vec<f64>, f64, f64) {
    let n = params.n;
    let side = params.a_cells.sqrt();
    let h = side / 2.0;
    let rho_max = h * 2f64.sqrt();
    let drho = 2.0 * rho_max / params.n_rho as f64;
    let g = params.gate_cells;
    let trig: Vec<(f64, f64)> = (0..params.n_theta)
        .map(|a| {
            let th = a as f64 * std::f64::consts::PI / params.n_theta as f64;
            (th.cos(), th.sin())
        })
        .collect();
    let bin = |p: (f64, f64), t: (f64, f64)| ((p.0 * t.0 + p.1 * t.1 + rho_max) / drho).floor();
    let share = |ps: &[(f64, f64)]| {
        trig.iter().any(|&t| {
            let b = bin(ps[0], t);
            ps[1..].iter().all(|&p| bin(p, t) == b)
        })
    };
    let inside = |p: (f64, f64)| p.0.abs() <= h && p.1.abs() <= h;
    let mut rng = faint_core::rng::Rng::seed_from_u64(0x4d48_5443);
    let mut u = || f64::from(rng.uniform());
    const K: usize = 40_000;
    let (mut n3, mut n4) = (0usize, 0usize);
    let disk = |c: (f64, f64), u1: f64, u2: f64| {
        let (r, ph) = (g * u1.sqrt(), std::f64::consts::TAU * u2);
        (c.0 + r * ph.cos(), c.1 + r * ph.sin())
    };
    for _ in 0..K {
        let p2 = (side * (u() - 0.5), side * (u() - 0.5));
        let p1 = disk(p2, u(), u());
        let p3 = disk(p2, u(), u());
        if !(inside(p1) && inside(p3) && share(&[p1, p2, p3])) {
            continue;
        }
        n3 += 1;
        let p4 = disk(p3, u(), u());
        if inside(p4) && share(&[p2, p3, p4]) {
            n4 += 1;
        }
    }
    let c3 = n3 as f64 / K as f64;
    let c_ext = if n3 > 0 { n4 as f64 / n3 as f64 } else { 0.0 };
    let gated = params.lambda * std::f64::consts::PI * g * g / params.a_cells;
    let m = params.m.max(1);
    // gated M-chains starting in one scan (M = 3: lambda^3 (pi g^2 / A)^2 c3)
    let t = params.lambda * gated.powi(m as i32 - 1) * c3;
    let e = -(-gated * c_ext).exp_m1();
    let windows = n.saturating_sub(m) + 1;
    let chains = t * (1.0 + windows.saturating_sub(1) as f64 * (1.0 - e));
    let mut q = vec![0.0f64; n + 1];
    for (j, qj) in q.iter_mut().enumerate().skip(m) {
        *qj = if j < n {
            (1.0 - e) * e.powi((j - m) as i32)
        } else {
            e.powi((n - m) as i32)
        };
    }
    (chains, q, c3, c_ext)
}

/// Law of the count after adding one independent contribution of `k` scans (law `one`,
/// `k < N`) at a uniform position to a count with law `pmf`: with `v` scans covered,
/// each of the `k` is new with probability `(N - v) / N` (union, not sum; the clustering
/// of the covered scans is ignored).
fn add_hits(pmf: &[f64], one: &[f64], n: usize) -> Vec<f64> {
    let mut out = vec![0.0f64; n + 1];
    for (v, pv) in pmf.iter().enumerate() {
        if *pv == 0.0 {
            continue;
        }
        let q = (n - v.min(n)) as f64 / n as f64;
        for (k, pk) in one.iter().enumerate() {
            if *pk == 0.0 {
                continue;
            }
            for (i, b) in binomial_pmf(k, q).iter().enumerate() {
                out[(v + i).min(n)] += pv * pk * b;
            }
        }
    }
    out
}

/// The per-cell compound clutter law (extension replacing eq. 20-26; see the module doc,
/// "Compound cell law").
#[derive(Debug, Clone)]
pub struct CompoundModel {
    /// Parameters.
    pub params: ModelParams,
    /// `p_ch` (eq. 17).
    pub p_ch: f64,
    /// Clutter chains per period (the paper's `N_c`, eq. 21).
    pub chains: f64,
    /// Law of a chain's length `j` (`P^0(j) / P^0(m > 0)`).
    pub chain_len: Vec<f64>,
    /// Strip width `drho` of a DMHT cell (resolution cells).
    pub drho: f64,
    /// Mean number of clutter-chain contributions of `k` scans per period per unit of
    /// chord (`lam[k]`, `k in 1..=N`).
    pub lam: Vec<f64>,
    /// Grid cells grouped by chord: `(number of cells, chord, cell tail P(count >= g))`.
    pub bins: Vec<(f64, f64, Vec<f64>)>,
}

impl CompoundModel {
    /// Evaluate the compound model for `params` (square area of `a_cells` resolution cells,
    /// DMHT grid centred on it with `rho_max` = half its diagonal), chains from `source`.
    pub fn new(params: ModelParams, source: ChainSource) -> Self {
        let n = params.n;
        let pc = p_ch(&params);
        let (chains, chain_len) = match source {
            ChainSource::PaperNc => {
                let raw = run_value_pmf(n, params.m, pc);
                let pos = tail(&raw, 1);
                let cells = (params.n_rho * params.n_theta) as f64;
                let law = raw
                    .iter()
                    .enumerate()
                    .map(|(j, p)| if j == 0 || pos <= 0.0 { 0.0 } else { p / pos })
                    .collect();
                ((cells * pos).ceil(), law)
            }
            ChainSource::Censoring => {
                let (c, q, _, _) = censoring_chains(&params);
                (c, q)
            }
        };
        let side = params.a_cells.sqrt();
        let h = side / 2.0;
        let rho_max = h * 2f64.sqrt();
        let drho = 2.0 * rho_max / params.n_rho as f64;
        // E over direction psi (uniform) and step s (a point uniform in the gate disk:
        // s = g sqrt(u)) of the k-measure of a j-chain, per chain.
        const NPSI: usize = 720;
        const NS: usize = 8;
        let g = params.gate_cells;
        let mut per_chain = vec![0.0f64; n + 1];
        let mut buf = vec![0.0f64; n + 1];
        for (j, q) in chain_len.iter().enumerate() {
            if *q <= 0.0 {
                continue;
            }
            buf.iter_mut().for_each(|b| *b = 0.0);
            for si in 0..NS {
                let s = g * ((si as f64 + 0.5) / NS as f64).sqrt();
                for pi in 0..NPSI {
                    let psi = (pi as f64 + 0.5) / NPSI as f64 * std::f64::consts::FRAC_PI_2;
                    lattice_measure(j, s * psi.sin(), drho, &mut buf);
                }
            }
            let wgt = q / (NS * NPSI) as f64;
            for (o, b) in per_chain.iter_mut().zip(&buf) {
                *o += wgt * b;
            }
        }
        // targets: straight tracks of N scans, step v T_scan with v uniform up to V_max
        // (s = g u); only their contributions of fewer than M scans count (a cell holding
        // M or more plots of one target is on that target: a detection, not a false alarm)
        let mut per_target = vec![0.0f64; n + 1];
        if params.n_targets > 0 {
            buf.iter_mut().for_each(|b| *b = 0.0);
            for si in 0..NS {
                let s = g * (si as f64 + 0.5) / NS as f64;
                for pi in 0..NPSI {
                    let psi = (pi as f64 + 0.5) / NPSI as f64 * std::f64::consts::FRAC_PI_2;
                    lattice_measure(n, s * psi.sin(), drho, &mut buf);
                }
            }
            for k in 1..params.m.max(1).min(n + 1) {
                per_target[k] = buf[k] / (NS * NPSI) as f64;
            }
        }
        let lam: Vec<f64> = per_chain
            .iter()
            .map(|c| chains * c / params.a_cells)
            .collect();
        // group the grid's cells by chord
        const NB: usize = 96;
        let cmax = 2.0 * rho_max;
        let mut cnt = vec![0.0f64; NB];
        let mut csum = vec![0.0f64; NB];
        for a in 0..params.n_theta {
            let th = a as f64 * std::f64::consts::PI / params.n_theta as f64;
            for r in 0..params.n_rho {
                let rho = -rho_max + (r as f64 + 0.5) * drho;
                let c = chord(rho, th, h);
                if c <= 0.0 {
                    continue;
                }
                let b = ((c / cmax * NB as f64) as usize).min(NB - 1);
                cnt[b] += 1.0;
                csum[b] += c;
            }
        }
        let bins = (0..NB)
            .filter(|&b| cnt[b] > 0.0)
            .map(|b| {
                let c = csum[b] / cnt[b];
                let nu: Vec<Vec<f64>> = (0..n)
                    .map(|t| {
                        (0..=n)
                            .map(|k| {
                                if k == 0 || t + k > n {
                                    0.0
                                } else {
                                    lam[k] * c / (n - k + 1) as f64
                                }
                            })
                            .collect()
                    })
                    .collect();
                let mut pmf = coverage_pmf(n, &nu);
                // each target adds k < M hits with probability c / A * per_target[k]
                let mut one = vec![0.0f64; n + 1];
                for (k, t) in per_target.iter().enumerate().skip(1) {
                    one[k] = (t * c / params.a_cells).min(1.0);
                }
                one[0] = (1.0 - one.iter().skip(1).sum::<f64>()).max(0.0);
                for _ in 0..params.n_targets {
                    pmf = add_hits(&pmf, &one, n);
                }
                let tl: Vec<f64> = (0..=n + 1).map(|g| tail(&pmf, g)).collect();
                (cnt[b], c, tl)
            })
            .collect();
        Self {
            params,
            p_ch: pc,
            chains,
            chain_len,
            drho,
            lam,
            bins,
        }
    }

    /// Mean over all `N_rho N_theta` cells of `P(count >= gamma)`.
    pub fn pfa_cell(&self, gamma: usize) -> f64 {
        let cells = (self.params.n_rho * self.params.n_theta) as f64;
        let g = gamma.min(self.params.n + 1);
        self.bins.iter().map(|(k, _, t)| k * t[g]).sum::<f64>() / cells
    }

    /// Whole-grid Pfa by eq. 28 over the cells' own tails:
    /// `1 - prod_cells (1 - Pfa_cell(chord))`.
    pub fn pfa_grid(&self, gamma: usize) -> f64 {
        let g = gamma.min(self.params.n + 1);
        let l: f64 = self
            .bins
            .iter()
            .map(|(k, _, t)| k * (-t[g].min(1.0)).ln_1p())
            .sum();
        -l.exp_m1()
    }

    /// Smallest `gamma` with grid `Pfa <= pfa` (`N + 1` if none).
    pub fn gamma_for_pfa(&self, pfa: f64) -> usize {
        (1..=self.params.n)
            .find(|&g| self.pfa_grid(g) <= pfa)
            .unwrap_or(self.params.n + 1)
    }

    /// Mean effective clutter plots per scan the law assumes (`N_c E[j] / N`).
    pub fn clutter_per_scan(&self) -> f64 {
        let ej: f64 = self
            .chain_len
            .iter()
            .enumerate()
            .map(|(j, q)| j as f64 * q)
            .sum();
        self.chains * ej / self.params.n as f64
    }
}
