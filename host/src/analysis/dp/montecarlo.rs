//! Monte Carlo check of the merit analysis against the detectors themselves.
//!
//! Frames of `N(0, sigma^2)` noise (plus, for targets, amplitude `a` in the pixel of a
//! target moving by `d*` pixels per frame from a pixel centre, the analysis's motion)
//! are run through a [`DpTrack`] detector; after `n` frames a pixel's merit is compared
//! with `V_T(n)`:
//!
//! ```text
//! noise:  rate(n) = mean over images of the share of interior pixels with merit >= V_T(n)
//! target: P_D(n)  = share of targets whose pixel at frame n has merit >= V_T(n)
//! ```
//!
//! Only pixels whose backward cone (radius `R (n - 1)`, `R` the window radius) stays in
//! the image count, so no window is clipped, as in the analysis. Neighbouring pixels'
//! tracks share frames, so the noise interval is computed from the per-image shares
//! (images are independent), not from a binomial over pixels. Targets are laid out so
//! that no target's cone reaches another's track.

use crate::montecarlo::run_trials;
use anyhow::{bail, Result};
use faint_core::detect::dp::{DpConfig, DpTrack, Method};
use faint_core::dp_tbd;
use faint_core::rng::{derive_seed, Rng};
use std::collections::BTreeMap;

/// A Monte Carlo rate with its standard error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rate {
    /// The estimate.
    pub rate: f64,
    /// Its standard error.
    pub se: f64,
    /// Pixel tracks (noise) or targets counted.
    pub samples: usize,
}

fn noise_frame(rng: &mut Rng, sigma: f32, out: &mut [f32]) {
    for v in out.iter_mut() {
        *v = sigma * rng.normal();
    }
}

/// One frame of the noise check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoisePoint {
    /// Share of interior pixel tracks with merit `>= V_T(n)` (the per-track `P_FA`).
    pub exceed: Rate,
    /// Mean correlation of horizontally adjacent pixels' merits (what the independence
    /// assumption sets to 0 for the candidates of a max).
    pub neighbour_corr: f64,
    /// The threshold calibrated on these tracks: the smallest merit `v` (a multiple of
    /// `lsb`) with share `>= v` at most the asked rate.
    pub calibrated: f32,
}

/// Per-frame noise exceedance over `images` independent runs of `frames =
/// thresholds.len()` frames; `make` builds an unconfigured detector, `r` is its window
/// radius, `pfa` the rate of the calibrated threshold.
pub fn noise_check<D, F>(
    make: F,
    cfg: &DpConfig,
    r: usize,
    thresholds: &[f32],
    pfa: f64,
    images: usize,
    seed: u64,
) -> Result<Vec<NoisePoint>>
where
    D: DpTrack,
    F: Fn() -> Box<D> + Sync,
{
    let m = D::SIDE;
    let n = thresholds.len();
    if images < 2 || n == 0 || 2 * r * (n - 1) >= m {
        bail!("noise check: {images} images of {n} frames do not fit an {m} x {m} image");
    }
    let lsb = f64::from(cfg.lsb);
    type PerImage = Vec<(f64, usize, f64, BTreeMap<i64, u64>)>;
    let runs: Vec<Result<PerImage>> = crate::montecarlo::pool().install(|| {
        run_trials(seed, images, "DP noise check", |_, rng| {
            let mut det = make();
            det.configure(cfg, 0).map_err(|e| anyhow::anyhow!("{e}"))?;
            let mut z = vec![0f32; m * m];
            let mut out = Vec::with_capacity(n);
            for (k, &vt) in thresholds.iter().enumerate() {
                noise_frame(rng, cfg.sigma, &mut z);
                det.step(&z).map_err(|e| anyhow::anyhow!("{e}"))?;
                let margin = r * k;
                let (mut hit, mut all) = (0usize, 0usize);
                let mut hist = BTreeMap::new();
                let mut pairs = Vec::new();
                for y in margin..m - margin {
                    let mut prev: Option<f64> = None;
                    for x in margin..m - margin {
                        let v = det.merit(x, y).unwrap_or(f32::MIN);
                        all += 1;
                        if v >= vt {
                            hit += 1;
                        }
                        *hist.entry((f64::from(v) / lsb).round() as i64).or_insert(0) += 1;
                        if let Some(p) = prev {
                            pairs.push((p, f64::from(v)));
                        }
                        prev = Some(f64::from(v));
                    }
                }
                out.push((hit as f64 / all as f64, all, correlation(&pairs), hist));
            }
            Ok(out)
        })
    });
    let runs: Vec<PerImage> = runs.into_iter().collect::<Result<_>>()?;
    Ok((0..n)
        .map(|k| {
            let v: Vec<f64> = runs.iter().map(|s| s[k].0).collect();
            let (mean, se) = mean_se(&v);
            let samples: usize = runs.iter().map(|s| s[k].1).sum();
            let corr = runs.iter().map(|s| s[k].2).sum::<f64>() / images as f64;
            let mut hist: BTreeMap<i64, u64> = BTreeMap::new();
            for s in &runs {
                for (&b, &c) in &s[k].3 {
                    *hist.entry(b).or_insert(0) += c;
                }
            }
            NoisePoint {
                exceed: Rate {
                    rate: mean,
                    se,
                    samples,
                },
                neighbour_corr: corr,
                calibrated: (upper_quantile(&hist, samples, pfa) as f64 * lsb) as f32,
            }
        })
        .collect())
}

/// The smallest bin `v` with `count(>= v) <= alpha total`.
fn upper_quantile(hist: &BTreeMap<i64, u64>, total: usize, alpha: f64) -> i64 {
    let allowed = (alpha * total as f64).floor() as u64;
    let mut above = 0u64;
    let mut last = hist.keys().next_back().map_or(0, |&b| b + 1);
    for (&b, &c) in hist.iter().rev() {
        if above + c > allowed {
            return last;
        }
        above += c;
        last = b;
    }
    last
}

fn correlation(pairs: &[(f64, f64)]) -> f64 {
    let n = pairs.len() as f64;
    if n < 2.0 {
        return 0.0;
    }
    let (ma, mb) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), (x, y)| (a + x / n, b + y / n));
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in pairs {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa > 0.0 && sbb > 0.0 {
        sab / (saa * sbb).sqrt()
    } else {
        0.0
    }
}

fn mean_se(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let mean = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

/// Start pixels of the targets of one image: trajectories `p0 + k d*`, `k < frames`,
/// inside the cone margin, and no target's cone reaching another's track.
pub fn target_starts(m: usize, r: usize, step: (i32, i32), frames: usize) -> Vec<(usize, usize)> {
    let margin = (r * (frames - 1)) as i64;
    let (sx, sy) = (i64::from(step.0), i64::from(step.1));
    let span = |s: i64| s.abs() * (frames as i64 - 1);
    // Chebyshev distance between two tracks > R (n - 1) on one axis
    let gap_x = span(sx) + margin + 1;
    let gap_y = span(sy) + margin + 1;
    let m = m as i64;
    let range = |s: i64| -> (i64, i64) {
        // p0 + k s inside [margin, m - 1 - margin] for k in 0..frames
        let lo = margin - (s * (frames as i64 - 1)).min(0);
        let hi = m - 1 - margin - (s * (frames as i64 - 1)).max(0);
        (lo, hi)
    };
    let (xl, xh) = range(sx);
    let (yl, yh) = range(sy);
    let mut out = Vec::new();
    let mut y = yl;
    while y <= yh {
        let mut x = xl;
        while x <= xh {
            out.push((x as usize, y as usize));
            x += gap_x;
        }
        y += gap_y;
    }
    out
}

/// Per-frame detection rates of targets of amplitude `amp` moving by `step` pixels per
/// frame over `images` independent runs (each holding [`target_starts`] targets), at each
/// of the threshold sequences `thresholds` (all of one length: the frames), on the same
/// runs.
#[allow(clippy::too_many_arguments)]
pub fn target_rates<D, F>(
    make: F,
    cfg: &DpConfig,
    r: usize,
    step: (i32, i32),
    amp: f32,
    thresholds: &[&[f32]],
    images: usize,
    seed: u64,
) -> Result<Vec<Vec<Rate>>>
where
    D: DpTrack,
    F: Fn() -> Box<D> + Sync,
{
    let m = D::SIDE;
    let n = thresholds.first().map_or(0, |t| t.len());
    if thresholds.iter().any(|t| t.len() != n) {
        bail!("target check: threshold sequences of different lengths");
    }
    let starts = target_starts(m, r, step, n.max(1));
    if starts.is_empty() || n == 0 || images == 0 {
        bail!("target check: no target track of {n} frames fits an {m} x {m} image");
    }
    // hits[image][frame][threshold set]
    let hits: Vec<Result<Vec<Vec<usize>>>> = crate::montecarlo::pool().install(|| {
        run_trials(seed, images, "DP target check", |_, rng| {
            let mut det = make();
            det.configure(cfg, 0).map_err(|e| anyhow::anyhow!("{e}"))?;
            let mut z = vec![0f32; m * m];
            let mut out = Vec::with_capacity(n);
            for k in 0..n {
                noise_frame(rng, cfg.sigma, &mut z);
                let pos = |&(x, y): &(usize, usize)| {
                    let px = x as i64 + i64::from(step.0) * k as i64;
                    let py = y as i64 + i64::from(step.1) * k as i64;
                    (px as usize, py as usize)
                };
                for s in &starts {
                    let (x, y) = pos(s);
                    if let Some(v) = z.get_mut(y * m + x) {
                        *v += amp;
                    }
                }
                det.step(&z).map_err(|e| anyhow::anyhow!("{e}"))?;
                let merits: Vec<Option<f32>> = starts
                    .iter()
                    .map(|s| {
                        let (x, y) = pos(s);
                        det.merit(x, y)
                    })
                    .collect();
                out.push(
                    thresholds
                        .iter()
                        .map(|t| {
                            merits
                                .iter()
                                .filter(|v| v.is_some_and(|v| v >= t[k]))
                                .count()
                        })
                        .collect(),
                );
            }
            Ok(out)
        })
    });
    let hits: Vec<Vec<Vec<usize>>> = hits.into_iter().collect::<Result<_>>()?;
    let total = images * starts.len();
    Ok((0..thresholds.len())
        .map(|j| {
            (0..n)
                .map(|k| {
                    let h: usize = hits.iter().map(|v| v[k][j]).sum();
                    let p = h as f64 / total as f64;
                    Rate {
                        rate: p,
                        se: (p * (1.0 - p) / total as f64).sqrt(),
                        samples: total,
                    }
                })
                .collect()
        })
        .collect())
}

/// Side of the noise check's images (room for the cones of long tracks).
pub const NOISE_SIDE: usize = 256;
/// Side of the target check's images.
pub const TARGET_SIDE: usize = 128;

type A9n = dp_tbd!(Arnold, NOISE_SIDE, 9, 2);
type A25n = dp_tbd!(Arnold, NOISE_SIDE, 25, 2);
type S9n = dp_tbd!(SecondOrder, NOISE_SIDE, 9, 3);
type S25n = dp_tbd!(SecondOrder, NOISE_SIDE, 25, 3);
type A9t = dp_tbd!(Arnold, TARGET_SIDE, 9, 2);
type A25t = dp_tbd!(Arnold, TARGET_SIDE, 25, 2);
type S9t = dp_tbd!(SecondOrder, TARGET_SIDE, 9, 3);
type S25t = dp_tbd!(SecondOrder, TARGET_SIDE, 25, 3);

/// The detectors' side of one analysis [`Setup`](super::Setup): the noise check on
/// [`NOISE_SIDE`]-pixel images, then the targets at the analytic and at the calibrated
/// thresholds on [`TARGET_SIDE`]-pixel images.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// Noise check per frame.
    pub noise: Vec<NoisePoint>,
    /// `P_D` per frame at the analytic thresholds.
    pub pd_analytic_vt: Vec<Rate>,
    /// `P_D` per frame at the thresholds calibrated on the noise check.
    pub pd_calibrated_vt: Vec<Rate>,
}

/// Runs the [`Check`] of `setup` (`Arnold` or `SecondOrder`, `q_B` 9 or 25) against the
/// analytic thresholds `vt` (one per frame): `noise_images` noise runs and
/// `target_images` target runs of amplitude `amp`.
#[allow(clippy::too_many_arguments)]
pub fn check(
    cfg: &DpConfig,
    setup: &super::Setup,
    amp: f32,
    vt: &[f32],
    pfa: f64,
    noise_images: usize,
    target_images: usize,
    seed: u64,
) -> Result<Check> {
    macro_rules! run {
        ($n:ty, $t:ty, $r:expr) => {{
            let noise = noise_check(
                || Box::new(<$n>::new_unconfigured()),
                cfg,
                $r,
                vt,
                pfa,
                noise_images,
                derive_seed(seed, 1),
            )?;
            let cal: Vec<f32> = noise.iter().map(|p| p.calibrated).collect();
            let mut pd = target_rates(
                || Box::new(<$t>::new_unconfigured()),
                cfg,
                $r,
                setup.step,
                amp,
                &[vt, &cal],
                target_images,
                derive_seed(seed, 2),
            )?
            .into_iter();
            Check {
                pd_analytic_vt: pd.next().unwrap_or_default(),
                pd_calibrated_vt: pd.next().unwrap_or_default(),
                noise,
            }
        }};
    }
    Ok(match (setup.method, setup.qb) {
        (Method::Arnold, 9) => run!(A9n, A9t, 1),
        (Method::Arnold, 25) => run!(A25n, A25t, 2),
        (Method::SecondOrder, 9) => run!(S9n, S9t, 1),
        (Method::SecondOrder, 25) => run!(S25n, S25t, 2),
        (m, q) => bail!("no Monte Carlo check for {} with q_B = {q}", m.name()),
    })
}
