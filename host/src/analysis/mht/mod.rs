//! Analytic detection model of MHT-TBD (Bao et al. 2022, §4), plus the binomial model
//! of the classic Hough TBD used to set its threshold.
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
//! Lengths are in resolution cells (not metres mixed with per-cell probabilities):
//! `L0 = V_max T_scan N / (2 res)` cells on the average track, `Pfa0 = lambda / A`, and the
//! number `l` of clutter plots on such a line in one scan is Poisson with mean
//! `mu = L0 Pfa0` (eq. 15). Two points uniform on `[0, L0]` are farther apart than the gate
//! `g = V_max T_scan / res = 2 L0 / N` with probability `q1 = (1 - g / L0)^2 = (1 - 2/N)^2`
//! (eq. 16). With `l1`, `l2` plots in consecutive scans, all `l1 l2` pairs fail the gate
//! with probability (pairs taken independent, as the paper does) `q1^(l1 l2)`, so
//! `P(some pair passes) = 1 - sum_{l1,l2} q1^(l1 l2) p(l1) p(l2)
//!                      = 1 - sum_l p(l) exp(mu (q1^l - 1))`
//! (the inner sum is a Poisson generating function; a one-line closed form given for it
//! is not this and is not used). Eq. 17 conditions on the cell being hit in the scan:
//! `p_ch = P(some pair passes) / (1 - p(0))`.
//! For a target's cell, the scan is a miss only if the target plot is missed (`1 - Pd0`)
//! and no clutter plot lies within the gate of the line segment, a length
//! `L0 (1 - sqrt(q1)) = g` of line: `p_dh = 1 - (1 - Pd0) exp(-mu (1 - sqrt(q1)))`
//! (eq. 19 with the sign of the exponent fixed: `exp(-mu (sqrt(q1) - 1))` as written is
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
//!
//! The code is split by law: the run-length (cell-value) law, the hit probabilities and
//! the paper's cross-track correction ([`CellModel`]) in `run_law.rs`, the compound law
//! ([`CompoundModel`]) in `compound.rs`, the classic detector's binomial model
//! ([`classic_gamma`]) in `classic.rs`; the parameters and helpers they share are here.

mod classic;
mod compound;
mod run_law;

pub use classic::{classic_gamma, classic_pfa_grid};
pub use compound::{censoring_chains, coverage_pmf, lattice_measure, ChainSource, CompoundModel};
pub use run_law::{p_ch, p_dh, run_value, run_value_pmf, run_value_pmf_brute, CellModel};

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

/// Model parameters (the paper's Fig. 2-4 set is [`ModelParams::paper`]).
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

/// The largest binary-integration count of an accumulator's cells: the statistic whose
/// whole-grid law the models give (a period is a false alarm when it reaches `gamma`).
pub fn max_count<const R: usize, const A: usize>(
    acc: &faint_core::detect::mht::Accumulator<R, A>,
) -> u8 {
    let mut m = 0;
    for a in 0..A {
        for r in 0..R {
            m = m.max(acc.count(r, a));
        }
    }
    m
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

/// Which per-cell clutter law sets `gamma_1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum, serde::Serialize)]
pub enum Variant {
    /// Eq. 20-26 as published ([`CellModel`]): the Fig. 2-4 curves.
    Paper,
    /// The per-cell compound law ([`CompoundModel`], extension): holds the wanted Pfa.
    #[default]
    Compound,
}
