//! Fig. 5 of Wang, Zhang 2016: `P_D` versus the number of frames `n` from the merit
//! analysis (§3) for the first-order DP and the second-order DP at `q_B = 9` and 25
//! (`q_I = 9`), beside Monte Carlo runs of the detectors themselves.
//!
//! Per setup (target at 1 px/frame, step `(1, 0)`, amplitude `snr * sigma`, design
//! amplitude the same): the analytic `V_T(n)` at `P_FA` per noise track on the detectors'
//! lattice and on a 4x finer one (the quantisation's effect), `P_D(n)`; then the noise
//! check (share of noise pixel tracks above `V_T(n)`, neighbour correlation, the
//! threshold calibrated on those tracks) and the target check at the analytic and at the
//! calibrated thresholds (see `analysis::dp::montecarlo`). Outputs `fig5.csv`,
//! `fig5.svg` (P_D), `fig5_pfa.svg` (P_FA) and the Markdown section returned.

use std::path::Path;

use anyhow::{ensure, Result};
use faint_core::detect::dp::{DpConfig, Method};
use serde::Serialize;

use crate::analysis::dp::montecarlo::{self, NOISE_SIDE, TARGET_SIDE};
use crate::analysis::dp::{analyse, Setup};
use crate::io::{self, chart::Series};

/// What Fig. 5 runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fig5Options {
    /// `SNR = a / sigma` of the target (the paper does not state it: 2.0).
    pub snr: f32,
    /// Noise pixel tracks at the last frame, at least (whole images of the noise check).
    pub noise_tracks: usize,
    /// Targets per setup, at least (whole images of the target check).
    pub target_tracks: usize,
    /// Frames `n = 1..=frames`.
    pub frames: usize,
    /// False-alarm rate per noise track.
    pub pfa: f64,
    /// Master seed.
    pub seed: u64,
}

#[derive(Debug, Clone, Serialize)]
struct Row {
    method: &'static str,
    qb: usize,
    n: usize,
    vt: f64,
    pfa_analytic: f64,
    pd_analytic: f64,
    pd_analytic_fine_lattice: f64,
    pfa_mc: f64,
    pfa_mc_se: f64,
    noise_tracks: usize,
    neighbour_corr: f64,
    vt_calibrated: f32,
    pd_mc_at_vt: f64,
    pd_mc_at_vt_se: f64,
    pd_mc_at_calibrated_vt: f64,
    pd_mc_at_calibrated_vt_se: f64,
    targets: usize,
}

fn label(m: Method) -> &'static str {
    match m {
        Method::SecondOrder => "second-order",
        _ => "Arnold",
    }
}

/// Runs Fig. 5 into `out` and returns its Markdown section.
pub fn run(opts: &Fig5Options, out: &Path) -> Result<String> {
    ensure!(opts.frames >= 2, "Fig. 5 needs at least 2 frames");
    ensure!(
        opts.snr.is_finite() && opts.snr > 0.0,
        "Fig. 5: --snr must be positive"
    );
    let mut rows = Vec::new();
    let mut pd_series = Vec::new();
    let mut pfa_series = Vec::new();
    for qb in [9usize, 25] {
        let r = if qb == 9 { 1 } else { 2 };
        for method in [Method::Arnold, Method::SecondOrder] {
            let mut cfg = DpConfig::dim_point(method, 1);
            let amp = opts.snr * cfg.sigma;
            cfg.a_design = amp;
            let s = |refine| Setup {
                method,
                qb,
                step: (1, 0),
                refine,
            };
            let c = analyse(&cfg, &s(1), opts.frames, opts.pfa, Some(f64::from(amp)))?;
            let fine = analyse(&cfg, &s(4), opts.frames, opts.pfa, Some(f64::from(amp)))?;
            let vt: Vec<f32> = c.threshold.iter().map(|&v| v as f32).collect();
            let side = NOISE_SIDE - 2 * r * (opts.frames - 1);
            let noise_images = opts.noise_tracks.div_ceil(side * side).max(2);
            let per_image = montecarlo::target_starts(TARGET_SIDE, r, (1, 0), opts.frames).len();
            ensure!(
                per_image > 0,
                "Fig. 5: {} frames do not fit the target images",
                opts.frames
            );
            let target_images = opts.target_tracks.div_ceil(per_image).max(1);
            let mc = montecarlo::check(
                &cfg,
                &s(1),
                amp,
                &vt,
                opts.pfa,
                noise_images,
                target_images,
                faint_core::rng::derive_seed(opts.seed, qb as u64 * 4 + method as u64),
            )?;
            let name = format!("{} q_B={qb}", label(method));
            pd_series.push(Series {
                name: format!("{name} analysis"),
                points: (0..opts.frames)
                    .map(|k| ((k + 1) as f64, c.pd[k]))
                    .collect(),
            });
            pd_series.push(Series {
                name: format!("{name} detector"),
                points: (0..opts.frames)
                    .map(|k| ((k + 1) as f64, mc.pd_analytic_vt[k].rate))
                    .collect(),
            });
            pfa_series.push(Series {
                name: format!("{name} detector"),
                points: (0..opts.frames)
                    .map(|k| ((k + 1) as f64, mc.noise[k].exceed.rate))
                    .collect(),
            });
            for k in 0..opts.frames {
                rows.push(Row {
                    method: method.name(),
                    qb,
                    n: k + 1,
                    vt: c.threshold[k],
                    pfa_analytic: c.pfa[k],
                    pd_analytic: c.pd[k],
                    pd_analytic_fine_lattice: fine.pd[k],
                    pfa_mc: mc.noise[k].exceed.rate,
                    pfa_mc_se: mc.noise[k].exceed.se,
                    noise_tracks: mc.noise[k].exceed.samples,
                    neighbour_corr: mc.noise[k].neighbour_corr,
                    vt_calibrated: mc.noise[k].calibrated,
                    pd_mc_at_vt: mc.pd_analytic_vt[k].rate,
                    pd_mc_at_vt_se: mc.pd_analytic_vt[k].se,
                    pd_mc_at_calibrated_vt: mc.pd_calibrated_vt[k].rate,
                    pd_mc_at_calibrated_vt_se: mc.pd_calibrated_vt[k].se,
                    targets: mc.pd_analytic_vt[k].samples,
                });
            }
        }
    }
    io::write_csv(out.join("fig5.csv"), &rows)?;
    let title = format!("Fig. 5: P_D vs frames, SNR {}, P_FA {}", opts.snr, opts.pfa);
    io::chart::line_chart(out.join("fig5.svg"), &title, "frames n", "P_D", &pd_series)?;
    io::chart::line_chart_log_y(
        out.join("fig5_pfa.svg"),
        "Fig. 5: noise-track P_FA at the analytic V_T",
        "frames n",
        "P_FA",
        &pfa_series,
    )?;
    Ok(summary(opts, &rows))
}

fn frames_to(rows: &[&Row], pd: f64) -> String {
    rows.iter()
        .find(|r| r.pd_analytic >= pd)
        .map_or_else(|| "> n".into(), |r| r.n.to_string())
}

fn summary(opts: &Fig5Options, rows: &[Row]) -> String {
    let mut s = format!(
        "## Fig. 5: P_D versus frames (merit analysis and detectors)\n\n\
         SNR {}, P_FA {} per noise track, target 1 px/frame; analysis on the detectors' \
         lattice; detector columns: noise tracks on {NOISE_SIDE} x {NOISE_SIDE} images, \
         targets on {TARGET_SIDE} x {TARGET_SIDE} images (seed {}).\n\n",
        opts.snr, opts.pfa, opts.seed
    );
    let pick: Vec<usize> = [1, 2, 3, 5, 10, 15, 20, 30, 40]
        .into_iter()
        .filter(|&n| n <= opts.frames)
        .collect();
    let mut table = Vec::new();
    for r in rows.iter().filter(|r| pick.contains(&r.n)) {
        table.push(vec![
            format!("{} {}", r.method, r.qb),
            r.n.to_string(),
            format!("{:.2}", r.vt),
            format!("{:.4}", r.pfa_analytic),
            format!("{:.4} ± {:.4} ({})", r.pfa_mc, r.pfa_mc_se, r.noise_tracks),
            format!("{:.2}", r.neighbour_corr),
            format!("{:.3}", r.pd_analytic),
            format!("{:.3}", r.pd_analytic_fine_lattice),
            format!(
                "{:.3} ± {:.3} ({})",
                r.pd_mc_at_vt, r.pd_mc_at_vt_se, r.targets
            ),
            format!("{:.2}", r.vt_calibrated),
            format!(
                "{:.3} ± {:.3}",
                r.pd_mc_at_calibrated_vt, r.pd_mc_at_calibrated_vt_se
            ),
        ]);
    }
    s += &io::markdown_table(
        &[
            "method q_B",
            "n",
            "V_T",
            "P_FA analysis",
            "P_FA detector (tracks)",
            "neighbour corr",
            "P_D analysis",
            "P_D analysis, 4x lattice",
            "P_D detector at V_T (targets)",
            "V_T calibrated",
            "P_D detector at calibrated V_T",
        ],
        &table,
    );
    s += "\n\nFrames to reach a P_D (analysis):\n\n";
    let mut t2 = Vec::new();
    for qb in [9usize, 25] {
        for m in ["arnold", "second_order"] {
            let rs: Vec<&Row> = rows
                .iter()
                .filter(|r| r.qb == qb && r.method == m)
                .collect();
            t2.push(vec![
                format!("{m} {qb}"),
                frames_to(&rs, 0.5),
                frames_to(&rs, 0.9),
                format!("{:.3}", rs.last().map_or(0.0, |r| r.pd_analytic)),
            ]);
        }
    }
    s += &io::markdown_table(
        &[
            "method q_B",
            "n at P_D 0.5",
            "n at P_D 0.9",
            "P_D at last n",
        ],
        &t2,
    );
    s.push('\n');
    s
}
