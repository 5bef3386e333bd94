//! The compound cell law (extension, see the module doc, "Compound cell law" and "Chain
//! population"): clutter chains from the censoring rule or the paper's `N_c`, their
//! contributions to a DMHT cell ([`lattice_measure`]), the covered-scan count
//! ([`coverage_pmf`]) and [`CompoundModel`], the grid Pfa that sets `gamma_1` by default.

use super::run_law::{p_ch, run_value_pmf};
use super::{binomial_pmf, chord, tail, ModelParams};

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
