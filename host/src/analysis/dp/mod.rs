//! The merit-distribution analysis of DP-TBD (Wang, Zhang 2016, §3, eq. 18-28; after
//! Johnston, Krishnamurthy 2002): the law of the best merit ending at a pixel, along noise
//! and along the target, frame by frame, for the first-order DP (Barniv, Arnold) and the
//! second-order DP; thresholds `V_T` at a per-track false-alarm rate and `P_D` versus
//! the number of frames.
//!
//! The `q` candidates of each max are treated as independent (the paper's assumption,
//! `F_max = F^q`, eq. 20); [`montecarlo`] measures what that costs against the detectors
//! themselves. Each pixel is `z ~ N(mu, sigma^2)` (`mu = a` on the target pixel, 0
//! elsewhere), quantised as the detectors quantise it, `round(z / h)`.
//!
//! ```text
//! first order (eq. 18-22), noise and target:
//!   X_1 = Z,        X_k = Z + max_{q_B} X_{k-1}                  (F_k = F_Z * F_{k-1}^q_B)
//!   T_1 = Z_a,      T_k = Z_a + max(T_{k-1}, max_{q_B - 1} X_{k-1})
//! second order (eq. 23-26), per pair state d = t - t' in R_B, candidates e in R_I with
//! d - e in R_B, g(e) the transition term:
//!   (Y_k(d): the stored max part J_k of state d, at the pixel t' = t - d; its candidates
//!   all sit at t' and share its z)
//!   Y_2(d) = Z,     Y_k(d) = Z + max_e [Y_{k-1}(d - e) + g(e)]
//!   pixel merit     P_k = Z + max_d Y_k(d)                         (the z of t is shared)
//!   target, moving by d* per frame (e = 0 on the true pair):
//!   A_2 = Z_a,      A_k = Z_a + max(A_{k-1} + g(0), max_{e != 0} [Y_{k-1}(d* - e) + g(e)])
//!   P^T_k = Z_a + max(A_k, max_{d != d*} Y_k(d))
//! threshold and detection (eq. 27-28):
//!   V_T(n) = min { v : P(P_n >= v) <= P_FA },   P_D(n) = P(P^T_n >= V_T(n))
//! ```
//!
//! The laws live on the lattice `h = lsb / refine`. At `refine = 1` the lattice is the
//! detector's own (its merits are integers of `lsb`), so the only approximation left is
//! independence; a finer lattice (`refine > 1`) approaches the unquantised merit, and the
//! difference between the two is the quantisation's effect on `P_D` (reported by
//! `faint reproduce dp`). The transition term on a refined lattice is the detector's
//! integer table times `refine`.

pub mod law;
pub mod montecarlo;

use anyhow::{bail, Result};
use faint_core::detect::dp::{transition_table, DpConfig, Method};
use faint_core::detect::Validate;

pub use law::Law;

/// One analysis: a method, its window and the target's displacement per frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setup {
    /// `Arnold` (first order) or `SecondOrder`; Pulford's gate is not analysed.
    pub method: Method,
    /// `q_B`: 9 (3x3) or 25 (5x5).
    pub qb: usize,
    /// Target displacement per frame `d*` (pixels, inside `R_B`).
    pub step: (i32, i32),
    /// Lattice refinement: `h = lsb / refine` (1: the detector's own lattice).
    pub refine: u32,
}

/// The analysis of one [`Setup`] over `n = 1..=frames`.
#[derive(Debug, Clone, PartialEq)]
pub struct Curves {
    /// `V_T(n)` (intensity, the detectors' merit units), entry `n - 1`.
    pub threshold: Vec<f64>,
    /// The achieved per-track false-alarm rate `P(P_n >= V_T(n))` (`<= P_FA`).
    pub pfa: Vec<f64>,
    /// `P_D(n)` for the amplitude asked for (empty if none).
    pub pd: Vec<f64>,
    /// Mean noise merit `E[P_n]` (intensity).
    pub noise_mean: Vec<f64>,
}

fn radius(qb: usize) -> Result<i32> {
    match qb {
        9 => Ok(1),
        25 => Ok(2),
        _ => bail!("q_B must be 9 or 25, got {qb}"),
    }
}

/// Runs the analysis for `setup` with the detector configuration `cfg` (its `lsb`,
/// `sigma` and transition term), false-alarm rate `pfa` per noise track, and, if
/// `amplitude` is given, the target laws and `P_D`.
pub fn analyse(
    cfg: &DpConfig,
    setup: &Setup,
    frames: usize,
    pfa: f64,
    amplitude: Option<f64>,
) -> Result<Curves> {
    cfg.validate().map_err(|e| anyhow::anyhow!("{e}"))?;
    let r = radius(setup.qb)?;
    if !(pfa > 0.0 && pfa < 1.0) {
        bail!("pfa must be in (0, 1), got {pfa}");
    }
    if frames == 0 {
        bail!("frames must be at least 1");
    }
    if setup.refine == 0 || setup.refine > 64 {
        bail!("refine must be in 1..=64, got {}", setup.refine);
    }
    let (sx, sy) = setup.step;
    if sx.abs() > r || sy.abs() > r {
        bail!(
            "the target step ({sx}, {sy}) is outside the {}-pixel window",
            setup.qb
        );
    }
    if !matches!(setup.method, Method::Arnold | Method::SecondOrder) {
        bail!(
            "the analysis covers arnold and second_order, not {}",
            setup.method.name()
        );
    }
    let h = f64::from(cfg.lsb) / f64::from(setup.refine);
    let sigma = f64::from(cfg.sigma);
    let z = Law::quantised_normal(0.0, sigma, h);
    let za = amplitude.map(|a| Law::quantised_normal(a, sigma, h));
    let g: Vec<i64> = transition_table(cfg)
        .iter()
        .map(|&v| i64::from(v) * i64::from(setup.refine))
        .collect();
    let mut out = Curves {
        threshold: Vec::with_capacity(frames),
        pfa: Vec::with_capacity(frames),
        pd: Vec::with_capacity(frames),
        noise_mean: Vec::with_capacity(frames),
    };
    let mut record = |noise: &Law, target: Option<&Law>| {
        let (v, p) = noise.upper_quantile(pfa);
        out.threshold.push(v as f64 * h);
        out.pfa.push(p);
        out.noise_mean.push(noise.mean() * h);
        if let Some(t) = target {
            out.pd.push(t.survival(v).min(1.0));
        }
    };
    match setup.method {
        Method::SecondOrder => {
            second_order(&z, za.as_ref(), &g, r, setup.step, frames, &mut record)
        }
        _ => first_order(&z, za.as_ref(), setup.qb, frames, &mut record),
    }
    Ok(out)
}

/// `V_T(n)`, `n = 1..=frames`, on the detector's lattice (`refine = 1`) at per-track
/// false-alarm rate `pfa`, for `cfg.method` (`Arnold` or `SecondOrder`; `Pulford` gets
/// Arnold's, its gate only removes candidates) with window `qb`; intensity units, as
/// `DpTrack::merit` reports them (each value is an exact multiple of `lsb`).
pub fn track_thresholds(cfg: &DpConfig, qb: usize, frames: usize, pfa: f64) -> Result<Vec<f32>> {
    let method = match cfg.method {
        Method::Pulford => Method::Arnold,
        m => m,
    };
    let setup = Setup {
        method,
        qb,
        step: (0, 0),
        refine: 1,
    };
    let c = analyse(cfg, &setup, frames, pfa, None)?;
    Ok(c.threshold.iter().map(|&v| v as f32).collect())
}

fn first_order(
    z: &Law,
    za: Option<&Law>,
    qb: usize,
    frames: usize,
    record: &mut dyn FnMut(&Law, Option<&Law>),
) {
    let mut x = z.clone();
    let mut t = za.cloned();
    record(&x, t.as_ref());
    for _ in 2..=frames {
        let others = x.max_pow(qb - 1);
        if let (Some(tp), Some(za)) = (t.as_mut(), za) {
            let best = Law::max_of(&[(tp, 0), (&others, 0)]).unwrap_or_else(|| tp.clone());
            *tp = za.plus(&best);
        }
        // max of q_B = max(one, q_B - 1 others)
        let all = Law::max_of(&[(&x, 0), (&others, 0)]).unwrap_or_else(|| x.clone());
        x = z.plus(&all);
        record(&x, t.as_ref());
    }
}

/// The candidates `e` (index `(ey + 1) 3 + (ex + 1)`) of state `d` with `d - e` in `R_B`,
/// and the predecessor state index of each.
fn candidates(d: (i32, i32), r: i32) -> Vec<(usize, usize)> {
    let n = 2 * r + 1;
    let mut c = Vec::with_capacity(9);
    for ei in 0..9i32 {
        let (ex, ey) = (ei % 3 - 1, ei / 3 - 1);
        let (px, py) = (d.0 - ex, d.1 - ey);
        if px.abs() <= r && py.abs() <= r {
            c.push((ei as usize, ((py + r) * n + (px + r)) as usize));
        }
    }
    c
}

fn second_order(
    z: &Law,
    za: Option<&Law>,
    g: &[i64],
    r: i32,
    step: (i32, i32),
    frames: usize,
    record: &mut dyn FnMut(&Law, Option<&Law>),
) {
    let n = 2 * r + 1;
    let states: Vec<(i32, i32)> = (0..n * n).map(|s| (s % n - r, s / n - r)).collect();
    let star = ((step.1 + r) * n + (step.0 + r)) as usize;
    let cands: Vec<Vec<(usize, usize)>> = states.iter().map(|&d| candidates(d, r)).collect();
    // frame 1: the pixel merit is the pixel itself
    record(z, za);
    if frames < 2 {
        return;
    }
    // frame 2: Y_2(d) = Z for every d, A_2 = Z_a
    let mut y: Vec<Law> = vec![z.clone(); states.len()];
    let mut a = za.cloned();
    let pixel = |y: &[Law], skip: Option<usize>| -> Option<Law> {
        let terms: Vec<(&Law, i64)> = y
            .iter()
            .enumerate()
            .filter(|(i, _)| Some(*i) != skip)
            .map(|(_, l)| (l, 0))
            .collect();
        Law::max_of(&terms)
    };
    let record_frame = |y: &[Law], a: Option<&Law>, record: &mut dyn FnMut(&Law, Option<&Law>)| {
        let noise = pixel(y, None).map(|m| z.plus(&m));
        let target = match (a, za) {
            (Some(a), Some(za)) => {
                let best = match pixel(y, Some(star)) {
                    Some(o) => Law::max_of(&[(a, 0), (&o, 0)]),
                    None => Some(a.clone()),
                };
                best.map(|b| za.plus(&b))
            }
            _ => None,
        };
        if let Some(noise) = noise {
            record(&noise, target.as_ref());
        }
    };
    record_frame(&y, a.as_ref(), record);
    for _ in 3..=frames {
        let g0 = g.get(4).copied().unwrap_or(0);
        if let (Some(ap), Some(za)) = (a.as_mut(), za) {
            let others: Vec<(&Law, i64)> = cands[star]
                .iter()
                .filter(|(e, _)| *e != 4)
                .map(|&(e, p)| (&y[p], g[e]))
                .collect();
            let mut terms = others;
            terms.push((ap, g0));
            if let Some(best) = Law::max_of(&terms) {
                *ap = za.plus(&best);
            }
        }
        // the candidates of state d sit at one pixel and share its z
        y = cands
            .iter()
            .map(|c| {
                let terms: Vec<(&Law, i64)> = c.iter().map(|&(e, p)| (&y[p], g[e])).collect();
                let best = Law::max_of(&terms).unwrap_or_else(|| Law::point(0));
                z.plus(&best)
            })
            .collect();
        record_frame(&y, a.as_ref(), record);
    }
}
