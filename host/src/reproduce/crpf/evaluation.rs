//! Monte Carlo evaluation of `faint reproduce crpf`: the test statistics of one run
//! through the four detectors ([`run_stats`], [`run_detector`]), batches of runs
//! ([`batch`]), Pd versus SNR at the calibrated thresholds, the SNR at a given Pd and the
//! Fig. 5 parameter sweeps.

use anyhow::{bail, Result};
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::jott::JottTbd;
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::detect::Detector;
use faint_core::model::doppler::{
    estimate_noise_variance, DopplerReport, Likelihood as CoreLikelihood, Whitener, Window,
};
use faint_core::rng::{derive_seed, Rng};
use faint_core::statistic::{d_k, zeta_k};
use faint_core::Complex32;
use serde::{Deserialize, Serialize};

use super::args::Settings;
use super::comparators::{ComparatorModel, Comparators, Likelihood, VarSource};
use crate::instances::boxed;
use crate::montecarlo::run_trial_range;
use crate::simulate::crpf::{Noise, Othr, Run};
use crate::stats::detection::{detection_rate, snr_at_pd, threshold_at_pfa, PdPoint};

/// Names of the five test statistics, in [`Stats::values`] order.
pub const METHODS: [&str; 5] = ["CRPF-max", "CRPF-mean", "PF-mean", "JOTT-mean", "PF-LRT"];

/// Test statistics of one run.
#[derive(Debug, Clone, Copy, Serialize, Deserialize, Default)]
pub struct Stats {
    /// `zeta_K` of CRPF-TBD.
    pub crpf_max: f64,
    /// `D_K` of CRPF-TBD.
    pub crpf_mean: f64,
    /// `D_K` of PF-TBD.
    pub pf_mean: f64,
    /// `D_K` of JOTT.
    pub jott_mean: f64,
    /// `ln L_K` of PF-LRT.
    pub pf_lrt: f64,
    /// `zeta_K` of PF-TBD (Fig. 1).
    pub pf_max: f64,
    /// `zeta_K` of JOTT (Fig. 1).
    pub jott_max: f64,
    /// Mean |Doppler error| (Hz) of CRPF-TBD's mean-cost estimate over frames 14..=26
    /// where it exists (NaN if never, or under H0).
    pub crpf_fd_err: f64,
}

impl Stats {
    /// The five compared statistics, in [`METHODS`] order.
    pub fn values(&self) -> [f64; 5] {
        [
            self.crpf_max,
            self.crpf_mean,
            self.pf_mean,
            self.jott_mean,
            self.pf_lrt,
        ]
    }
}

/// The comparators' configuration for one run under `cm` (`model`: CRPF-TBD's, whose
/// window is the scene's analysis window). The window-aware likelihood whitens the frames
/// in the detectors' step (`GaussConfig::likelihood`); the variance is always that of the
/// windowed bins.
fn comparator_config(
    run: &Run,
    model: faint_core::model::doppler::ModelConfig,
    cm: &ComparatorModel,
) -> Result<GaussConfig> {
    let m = run.frames.first().map_or(0, Vec::len);
    let noise_var = match cm.var {
        VarSource::Run => match cm.likelihood {
            Likelihood::Independent => {
                estimate_noise_variance(run.frames.iter().map(|f| f.as_slice()), m)?
            }
            Likelihood::Window => whitened_run_variance(run, model.window, m)?,
        },
        VarSource::True => (cm.time_var * model.window.energy(m)) as f32,
    };
    Ok(GaussConfig {
        model,
        noise_var,
        birth: cm.birth,
        likelihood: match cm.likelihood {
            Likelihood::Independent => CoreLikelihood::Independent,
            Likelihood::Window => CoreLikelihood::Window,
        },
    })
}

/// The run's noise variance estimated on the frames the window-aware likelihood weighs:
/// `sum_k ||z'_k||^2 / (K m)` of the whitened frames (`Whitener`), returned in the
/// windowed bins' units (times `sum w^2 / m`), as `GaussConfig::noise_var` takes it.
/// Under heavy-tailed noise this differs from the windowed frames' estimate (a large
/// sample near the window's edge counts fully in the whitened frame, little in the
/// windowed one); under Gaussian noise both estimate the same value.
fn whitened_run_variance(run: &Run, window: Window, m: usize) -> Result<f32> {
    let mut wh = Whitener::inactive();
    wh.configure(CoreLikelihood::Window, window, m)?;
    let mut white = Vec::with_capacity(run.frames.len());
    for f in &run.frames {
        white.push(wh.apply(f)?.to_vec());
    }
    let v = estimate_noise_variance(white.iter().map(|f| f.as_slice()), m)?;
    Ok((f64::from(v) * window.energy(m) / m as f64) as f32)
}

/// Runs a detector over a run's frames; returns the per-frame reports.
pub fn run_detector<D: Detector<Frame = [Complex32], Report = DopplerReport> + ?Sized>(
    det: &mut D,
    run: &Run,
) -> Result<Vec<DopplerReport>> {
    let mut out = Vec::with_capacity(run.frames.len());
    faint_core::detect::run(det, run.frames.iter().map(|z| z.as_slice()), |_, _, r| {
        out.push(*r)
    })
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(out)
}

fn doppler_error(reports: &[DopplerReport], run: &Run, band: f64) -> f64 {
    let mut s = 0.0;
    let mut n = 0usize;
    for (r, t) in reports.iter().zip(&run.truth).skip(13) {
        if let (Some(e), Some(t)) = (r.estimate, t) {
            let mut d = e[0] as f64 - t[0];
            d -= band * (d / band).round();
            s += d.abs();
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

fn stats_of<const N: usize>(
    run: &Run,
    crpf_cfg: &CrpfConfig,
    seed: u64,
    comparators: Comparators,
) -> Result<Stats> {
    let mut crpf = boxed::<CrpfTbd<N>>(crpf_cfg, derive_seed(seed, 1))?;
    let rc = run_detector(crpf.as_mut(), run)?;
    let pe: Vec<f32> = rc.iter().map(|r| r.existence).collect();
    let mut st = Stats {
        crpf_max: zeta_k(&pe)? as f64,
        crpf_mean: d_k(&pe)? as f64,
        crpf_fd_err: doppler_error(&rc, run, 50.0),
        ..Stats::default()
    };
    let Some(cm) = comparators.0 else {
        return Ok(st);
    };
    let g = comparator_config(run, crpf_cfg.model, &cm)?;
    let mut pf = boxed::<PfTbd<N>>(&g, derive_seed(seed, 2))?;
    let rp: Vec<f32> = run_detector(pf.as_mut(), run)?
        .iter()
        .map(|r| r.existence)
        .collect();
    drop(pf);
    let mut jott = boxed::<JottTbd<N>>(&g, derive_seed(seed, 3))?;
    let rj: Vec<f32> = run_detector(jott.as_mut(), run)?
        .iter()
        .map(|r| r.existence)
        .collect();
    drop(jott);
    let mut lrt = boxed::<PfLrt<N>>(&g, derive_seed(seed, 4))?;
    let rl = run_detector(lrt.as_mut(), run)?;
    st.pf_mean = d_k(&rp)? as f64;
    st.pf_max = zeta_k(&rp)? as f64;
    st.jott_mean = d_k(&rj)? as f64;
    st.jott_max = zeta_k(&rj)? as f64;
    st.pf_lrt = rl.last().map(|r| r.log_lr as f64).unwrap_or(0.0);
    Ok(st)
}

/// Statistics of one run with `particles` particles (dispatch to the const generic).
pub fn run_stats(
    particles: usize,
    run: &Run,
    crpf_cfg: &CrpfConfig,
    seed: u64,
    comparators: impl Into<Comparators>,
) -> Result<Stats> {
    let comparators = comparators.into();
    match particles {
        100 => stats_of::<100>(run, crpf_cfg, seed, comparators),
        250 => stats_of::<250>(run, crpf_cfg, seed, comparators),
        500 => stats_of::<500>(run, crpf_cfg, seed, comparators),
        1000 => stats_of::<1000>(run, crpf_cfg, seed, comparators),
        2000 => stats_of::<2000>(run, crpf_cfg, seed, comparators),
        4000 => stats_of::<4000>(run, crpf_cfg, seed, comparators),
        6000 => stats_of::<6000>(run, crpf_cfg, seed, comparators),
        n => bail!("unsupported particle count {n} (use 100, 250, 500, 1000, 2000, 4000, 6000)"),
    }
}

/// Runs `trials` Monte Carlo runs at `snr_db` (None = H0).
#[allow(clippy::too_many_arguments)]
pub fn batch(
    scenario: &Othr,
    noise: Noise,
    snr_db: Option<f64>,
    particles: usize,
    crpf_cfg: &CrpfConfig,
    trials: usize,
    master: u64,
    comparators: impl Into<Comparators>,
    label: &str,
) -> Result<Vec<Stats>> {
    batch_range(
        scenario,
        noise,
        snr_db,
        particles,
        crpf_cfg,
        0..trials,
        master,
        comparators,
        label,
    )
}

/// [`batch`] for the runs `range` only (one shard): run `i` is the run `i` of the whole
/// batch.
#[allow(clippy::too_many_arguments)]
pub fn batch_range(
    scenario: &Othr,
    noise: Noise,
    snr_db: Option<f64>,
    particles: usize,
    crpf_cfg: &CrpfConfig,
    range: std::ops::Range<usize>,
    master: u64,
    comparators: impl Into<Comparators>,
    label: &str,
) -> Result<Vec<Stats>> {
    let comparators = comparators.into();
    run_trial_range(master, range, label, |i, rng: &mut Rng| {
        let run = scenario.simulate(snr_db, noise, rng);
        run_stats(
            particles,
            &run,
            crpf_cfg,
            derive_seed(master ^ 0x5eed, i as u64),
            comparators,
        )
    })
    .into_iter()
    .collect()
}

/// Pd of one statistic at one SNR (`pd_vs_snr.csv`).
#[derive(Debug, Serialize)]
pub(super) struct PdRow {
    noise: Noise,
    particles: usize,
    method: &'static str,
    snr_db: f64,
    threshold: f64,
    k: usize,
    n: usize,
    pd: f64,
    lo: f64,
    hi: f64,
}

/// SNR of one statistic at one Pd level (`snr_at_pd.csv`).
#[derive(Debug, Serialize)]
pub(super) struct SnrRow {
    pub(super) noise: Noise,
    pub(super) particles: usize,
    pub(super) method: &'static str,
    pub(super) level: f64,
    pub(super) snr_db: Option<f64>,
    pub(super) lo_db: Option<f64>,
    pub(super) hi_db: Option<f64>,
    pub(super) delta_vs_crpf_max_db: Option<f64>,
}

/// Pd of one statistic at one sweep configuration (`fig5_sweeps.csv`).
#[derive(Debug, Serialize)]
pub(super) struct SweepRow {
    parameter: &'static str,
    value: f64,
    method: &'static str,
    pfa: f64,
    threshold: f64,
    pd: f64,
    lo: f64,
    hi: f64,
}

/// Pd versus SNR of the compared statistics.
#[derive(Debug)]
pub(super) struct PdCurves {
    /// One row per SNR point and statistic (`pd_vs_snr.csv`).
    pub(super) rows: Vec<PdRow>,
    /// Pd curve of each compared statistic ([`METHODS`] order).
    pub(super) curves: Vec<Vec<PdPoint>>,
    /// Per SNR point: (SNR, median over runs of CRPF-TBD's mean |Doppler error|, runs
    /// with an estimate).
    pub(super) fd_err: Vec<(f64, f64, usize)>,
}

/// Pd at every SNR of `grid` from its H1 runs (`h1[j]` at `grid[j]`), each statistic
/// against its threshold in `thresholds`.
pub(super) fn pd_vs_snr(
    a: &Settings,
    grid: &[f64],
    h1_runs: &[Vec<Stats>],
    thresholds: &[f64; 5],
) -> Result<PdCurves> {
    let mut rows = Vec::new();
    let mut curves: Vec<Vec<PdPoint>> = vec![Vec::new(); 5];
    let mut fd_err = Vec::new();
    for (&snr, h1) in grid.iter().zip(h1_runs) {
        for (m, name) in METHODS.iter().enumerate() {
            let v: Vec<f64> = h1.iter().map(|s| s.values()[m]).collect();
            let p = detection_rate(&v, thresholds[m]);
            curves[m].push(PdPoint { snr_db: snr, pd: p });
            rows.push(PdRow {
                noise: a.noise,
                particles: a.particles,
                method: name,
                snr_db: snr,
                threshold: thresholds[m],
                k: p.k,
                n: p.n,
                pd: p.p,
                lo: p.lo,
                hi: p.hi,
            });
        }
        let mut e: Vec<f64> = h1
            .iter()
            .map(|s| s.crpf_fd_err)
            .filter(|x| x.is_finite())
            .collect();
        e.sort_by(f64::total_cmp);
        fd_err.push((
            snr,
            e.get(e.len() / 2).copied().unwrap_or(f64::NAN),
            e.len(),
        ));
    }
    Ok(PdCurves {
        rows,
        curves,
        fd_err,
    })
}

/// SNR at Pd = 0.5 and 0.9 of each compared statistic, and its difference to CRPF-max.
pub(super) fn snr_at_pd_rows(a: &Settings, curves: &[Vec<PdPoint>]) -> Vec<SnrRow> {
    let mut snr_rows = Vec::new();
    for level in [0.5, 0.9] {
        let reference = snr_at_pd(&curves[0], level).snr_db;
        for (m, name) in METHODS.iter().enumerate() {
            let s = snr_at_pd(&curves[m], level);
            let delta = match (s.snr_db, reference) {
                (Some(x), Some(r)) => Some(x - r),
                _ => None,
            };
            snr_rows.push(SnrRow {
                noise: a.noise,
                particles: a.particles,
                method: name,
                level,
                snr_db: s.snr_db,
                lo_db: s.lo_db,
                hi_db: s.hi_db,
                delta_vs_crpf_max_db: delta,
            });
        }
    }
    snr_rows
}

/// Fig. 5 sweeps: Pd of CRPF-max and CRPF-mean at 5 dB per `r_th` and `lambda`.
#[derive(Debug)]
pub(super) struct Sweeps {
    /// The Pfa of the sweeps' thresholds (`--pfa`, at least 10 / sweep-h0-trials).
    pub(super) pfa: f64,
    /// One row per configuration and statistic (`fig5_sweeps.csv`).
    pub(super) rows: Vec<SweepRow>,
    /// `(value, Pd)` curves: CRPF-max and CRPF-mean over `r_th`, then over `lambda`.
    pub(super) series: Vec<Vec<(f64, f64)>>,
}

/// The Fig. 5 sweep configurations: `(parameter, value, config)`, `r_th` then `lambda`.
pub(super) fn sweep_configs(base: &CrpfConfig) -> Vec<(&'static str, f64, CrpfConfig)> {
    (0..=8)
        .map(|i| {
            let r = 0.05 * i as f64;
            (
                "r_th",
                r,
                CrpfConfig {
                    r_th: r as f32,
                    ..*base
                },
            )
        })
        .chain((0..=5).map(|i| {
            let l = 0.2 * i as f64;
            (
                "lambda",
                l,
                CrpfConfig {
                    lambda: l as f32,
                    ..*base
                },
            )
        }))
        .collect()
}

/// Fig. 5: Pd of CRPF-max and CRPF-mean at 5 dB (Gaussian) over `r_th` and `lambda`,
/// from the H0 and H1 runs `runs[ci]` of each configuration of [`sweep_configs`].
pub(super) fn sweeps(
    a: &Settings,
    base: &CrpfConfig,
    runs: &[(Vec<Stats>, Vec<Stats>)],
) -> Result<Sweeps> {
    let pfa = a.pfa.max(10.0 / a.sweep_h0_trials as f64);
    let mut rows = Vec::new();
    let mut series = vec![Vec::new(); 4];
    let configs = sweep_configs(base);
    for ((param, value, _), (h0, h1)) in configs.iter().zip(runs) {
        for (mi, (method, f)) in [
            ("CRPF-max", (|s: &Stats| s.crpf_max) as fn(&Stats) -> f64),
            ("CRPF-mean", |s: &Stats| s.crpf_mean),
        ]
        .into_iter()
        .enumerate()
        {
            let t = threshold_at_pfa(&h0.iter().map(f).collect::<Vec<_>>(), pfa)?;
            let p = detection_rate(&h1.iter().map(f).collect::<Vec<_>>(), t.value);
            let si = if *param == "r_th" { mi } else { 2 + mi };
            series[si].push((*value, p.p));
            rows.push(SweepRow {
                parameter: param,
                value: *value,
                method,
                pfa,
                threshold: t.value,
                pd: p.p,
                lo: p.lo,
                hi: p.hi,
            });
        }
    }
    Ok(Sweeps { pfa, rows, series })
}
