//! Monte Carlo evaluation of `faint reproduce phd`: one run of the scene through the
//! algorithms, and the per-frame and summary statistics over the runs of one SNR.

use std::time::Instant;

use anyhow::Result;
use faint_core::detect::phd::PhdConfig;
use faint_core::detect::Detector;
use faint_core::rng::Rng;
use serde::Serialize;

use super::cubes::{Cubes, Renderer};
use crate::instances::phd::HostFilter;
use crate::montecarlo::run_trial_range;
use crate::simulate::phd::{SixTargets, Variant};
use crate::stats::ospa::ospa;

/// One run of one variant (`seconds`: the filter's wall time, the one result that is
/// not reproducible bit for bit).
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub(super) struct RunResult {
    /// `N_hat` per frame.
    counts: Vec<usize>,
    ospa: Vec<f64>,
    seconds: f64,
}

/// Per-frame row of the CSV.
#[derive(Debug, Serialize)]
pub(super) struct FrameRow {
    pub(super) snr_db: f64,
    pub(super) variant: &'static str,
    pub(super) frame: usize,
    pub(super) true_count: usize,
    pub(super) mean_count: f64,
    pub(super) std_count: f64,
    /// Mean over runs of `|N_hat - N_true|`.
    pub(super) mean_abs_count_error: f64,
    pub(super) mean_ospa: f64,
}

/// Summary row.
#[derive(Debug, Serialize)]
pub(super) struct SummaryRow {
    pub(super) snr_db: f64,
    pub(super) variant: &'static str,
    pub(super) runs: usize,
    pub(super) mean_std_count: f64,
    pub(super) mean_ospa_m: f64,
    /// Mean over frames and runs of `|N_hat - N_true|`.
    pub(super) mean_abs_count_error: f64,
    /// Frames where every target is alive (the most true targets; frames 17-29 of the
    /// preset, all six alive): mean `N_hat` and mean OSPA.
    pub(super) all_alive_mean_count: f64,
    /// See [`SummaryRow::all_alive_mean_count`].
    pub(super) all_alive_mean_ospa_m: f64,
    pub(super) seconds_per_run: f64,
    pub(super) ms_per_frame: f64,
}

fn one_run(
    sc: &SixTargets,
    render: &Renderer,
    variants: &[(Variant, PhdConfig)],
    seed_rng: &mut Rng,
) -> Result<Vec<RunResult>> {
    let mut truth_rng = seed_rng.fork(1);
    let mut cube_rng = seed_rng.fork(2);
    let truth = sc.truth(&mut truth_rng);
    let mut filters = Vec::new();
    for (v, config) in variants {
        // Each algorithm's filter seed depends on the algorithm only (the paper's three
        // keep the seeds of earlier runs whatever `--variants` selects).
        let i = Variant::EVERY.iter().position(|x| x == v).unwrap_or(0);
        let seed = seed_rng.fork(10 + i as u64).next_u64();
        filters.push(crate::instances::boxed::<HostFilter>(config, seed)?);
    }
    let mut res = vec![
        RunResult {
            counts: Vec::new(),
            ospa: Vec::new(),
            seconds: 0.0,
        };
        variants.len()
    ];
    let mut cube = Vec::new();
    let (c, p) = sc.ospa;
    for frame in &truth {
        render.frame(sc, frame, &mut cube_rng, &mut cube);
        let tr: Vec<[f64; 2]> = frame.iter().map(|t| [t.state[0], t.state[2]]).collect();
        for (f, r) in filters.iter_mut().zip(res.iter_mut()) {
            let t0 = Instant::now();
            let rep = f.step(&cube).map_err(|e| anyhow::anyhow!("{e}"))?;
            r.seconds += t0.elapsed().as_secs_f64();
            let est: Vec<[f64; 2]> = f
                .estimates()
                .iter()
                .map(|e| [e.state[0] as f64, e.state[2] as f64])
                .collect();
            r.counts.push(rep.n_hat);
            r.ospa.push(ospa(&est, &tr, c, p).distance);
        }
    }
    Ok(res)
}

/// The runs `range` of scene `sc` on `cubes` through `variants` and their filters (run `i` on stream `i`
/// of `seed`, whichever range, or shard, runs it; the same truth and cube streams
/// whatever the cubes).
pub(super) fn runs(
    sc: &SixTargets,
    cubes: Cubes,
    variants: &[(Variant, PhdConfig)],
    range: std::ops::Range<usize>,
    seed: u64,
    label: &str,
) -> Result<Vec<Vec<RunResult>>> {
    let render = Renderer::new(cubes, sc);
    let all: Vec<Result<Vec<RunResult>>> = run_trial_range(seed, range, label, |_, rng| {
        one_run(sc, &render, variants, rng)
    });
    all.into_iter().collect()
}

/// The true target count of each frame (1-based frames `1..=sc.frames`).
pub(super) fn truth_counts(sc: &SixTargets) -> Vec<usize> {
    (1..=sc.frames)
        .map(|k| {
            sc.targets
                .iter()
                .filter(|t| t.appear <= k && k <= t.disappear)
                .count()
        })
        .collect()
}

/// The per-frame rows and the summary row of every variant over the runs `all` of
/// scene `sc` at `snr`.
pub(super) fn statistics(
    sc: &SixTargets,
    snr: f64,
    variants: &[Variant],
    all: &[Vec<RunResult>],
) -> (Vec<FrameRow>, Vec<SummaryRow>) {
    let runs = all.len();
    let truth_counts = truth_counts(sc);
    let mut frames_csv = Vec::new();
    let mut summary = Vec::new();
    let most = truth_counts.iter().copied().max().unwrap_or(0);
    for (vi, v) in variants.iter().enumerate() {
        let mut stds = Vec::new();
        let mut ospas = Vec::new();
        let mut errors = Vec::new();
        let (mut alive_count, mut alive_ospa, mut alive_frames) = (0.0, 0.0, 0usize);
        for (k, &truth) in truth_counts.iter().enumerate() {
            let counts: Vec<f64> = all.iter().map(|r| r[vi].counts[k] as f64).collect();
            let o: Vec<f64> = all.iter().map(|r| r[vi].ospa[k]).collect();
            let (mc, sdc) = mean_std(&counts);
            let (mo, _) = mean_std(&o);
            let err: Vec<f64> = counts.iter().map(|&c| (c - truth as f64).abs()).collect();
            let (me, _) = mean_std(&err);
            if truth == most {
                alive_count += mc;
                alive_ospa += mo;
                alive_frames += 1;
            }
            stds.push(sdc);
            ospas.push(mo);
            errors.push(me);
            frames_csv.push(FrameRow {
                snr_db: snr,
                variant: v.name(),
                frame: k + 1,
                true_count: truth,
                mean_count: mc,
                std_count: sdc,
                mean_abs_count_error: me,
                mean_ospa: mo,
            });
        }
        let secs: Vec<f64> = all.iter().map(|r| r[vi].seconds).collect();
        let (ms, _) = mean_std(&secs);
        summary.push(SummaryRow {
            snr_db: snr,
            variant: v.name(),
            runs,
            mean_std_count: mean_std(&stds).0,
            mean_ospa_m: mean_std(&ospas).0,
            mean_abs_count_error: mean_std(&errors).0,
            all_alive_mean_count: alive_count / alive_frames.max(1) as f64,
            all_alive_mean_ospa_m: alive_ospa / alive_frames.max(1) as f64,
            seconds_per_run: ms,
            ms_per_frame: 1e3 * ms / sc.frames as f64,
        });
    }
    (frames_csv, summary)
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n;
    (m, var.sqrt())
}
