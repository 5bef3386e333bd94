//! Outputs of `faint reproduce mht`: the model's Fig. 2-4 and its table, the CSV files
//! (trials, summary, clutter-only Pfa, calibration), the Monte Carlo Fig. 10-12 and the
//! grid-Pfa chart, and `summary.md`, the Markdown summary also printed.

use std::path::Path;

use super::args::{Args, GammaFrom, Sizes};
use super::calibration::{proportion_ci, CalibRow};
use super::evaluation::{NullRow, Summary, TrialStats};
use crate::analysis::mht::{CellModel, ModelParams};
use crate::io::chart::{self, Series};
use crate::io::write_csv;

/// A chart of `(name, points)` series, on a logarithmic y axis if `log_y`; nothing is
/// drawn when no point can be shown (e.g. every rate 0 on the log axis).
fn line_chart(
    path: &Path,
    title: &str,
    xl: &str,
    yl: &str,
    series: &[(String, Vec<(f64, f64)>)],
    log_y: bool,
) -> anyhow::Result<()> {
    let shown = |p: &(f64, f64)| p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0);
    if !series.iter().any(|s| s.1.iter().any(shown)) {
        return Ok(());
    }
    let series: Vec<Series> = series
        .iter()
        .map(|(name, points)| Series {
            name: name.clone(),
            points: points.clone(),
        })
        .collect();
    if log_y {
        chart::line_chart_log_y(path, title, xl, yl, &series)
    } else {
        chart::line_chart(path, title, xl, yl, &series)
    }
}

/// Model curves row.
#[derive(Debug, serde::Serialize)]
struct ModelRow {
    figure: &'static str,
    lambda: f64,
    n: usize,
    m: usize,
    detector: &'static str,
    gamma: usize,
    pfa_grid: f64,
    pd: f64,
}

/// Fig. 2-4 of the model (SVG and `model_curves.csv`); returns the Markdown table of the
/// model at the paper's parameters.
pub(super) fn model_figures(out: &Path) -> anyhow::Result<String> {
    let mut rows = Vec::new();
    let mut fig2 = Vec::new();
    let mut fig3 = Vec::new();
    for lambda in [100.0, 300.0] {
        let cm = CellModel::new(ModelParams::paper(lambda));
        let mut c2 = Vec::new();
        let mut c3 = Vec::new();
        for g in 1..=30 {
            let (pf, pd) = (cm.pfa_grid(g), cm.pd(g));
            rows.push(ModelRow {
                figure: "fig2-3",
                lambda,
                n: 30,
                m: 3,
                detector: "mht",
                gamma: g,
                pfa_grid: pf,
                pd,
            });
            c2.push((g as f64, pf));
            if pf > 1e-12 {
                c3.push((pf.log10(), pd));
            }
        }
        fig2.push((format!("lambda={lambda}"), c2));
        fig3.push((format!("lambda={lambda}"), c3));
    }
    line_chart(
        &out.join("fig2_pfa_vs_gamma.svg"),
        "Fig. 2: MHT-TBD grid Pfa vs gamma_1 (model, N=30, M=3)",
        "gamma_1",
        "Pfa",
        &fig2,
        true,
    )?;
    line_chart(
        &out.join("fig3_pd_vs_pfa.svg"),
        "Fig. 3: MHT-TBD Pd vs Pfa (model, N=30, M=3)",
        "log10 Pfa",
        "Pd",
        &fig3,
        false,
    )?;
    let mut fig4 = Vec::new();
    for (n, lambda) in [(20usize, 100.0), (20, 300.0), (30, 300.0)] {
        for m in [3usize, 4, 7] {
            let mut mp = ModelParams::paper(lambda);
            mp.n = n;
            mp.m = m;
            let cm = CellModel::new(mp);
            let mut c = Vec::new();
            for g in 1..=n {
                let (pf, pd) = (cm.pfa_grid(g), cm.pd(g));
                rows.push(ModelRow {
                    figure: "fig4",
                    lambda,
                    n,
                    m,
                    detector: "mht",
                    gamma: g,
                    pfa_grid: pf,
                    pd,
                });
                if pf > 1e-12 {
                    c.push((pf.log10(), pd));
                }
            }
            fig4.push((format!("N={n} lambda={lambda} M={m}"), c));
        }
        let mut mp = ModelParams::paper(lambda);
        mp.n = n;
        let cm = CellModel::optimal(mp);
        let mut c = Vec::new();
        for g in 1..=n {
            let (pf, pd) = (cm.pfa_grid(g), cm.pd(g));
            rows.push(ModelRow {
                figure: "fig4",
                lambda,
                n,
                m: 1,
                detector: "optimal",
                gamma: g,
                pfa_grid: pf,
                pd,
            });
            if pf > 1e-12 {
                c.push((pf.log10(), pd));
            }
        }
        fig4.push((format!("N={n} lambda={lambda} optimal"), c));
    }
    line_chart(
        &out.join("fig4_pd_vs_pfa_n_m.svg"),
        "Fig. 4: Pd vs Pfa for N, lambda, M (model) and the optimal detector",
        "log10 Pfa",
        "Pd",
        &fig4,
        false,
    )?;
    write_csv(out.join("model_curves.csv"), &rows)?;
    let mut s = String::from("| lambda | p_ch | p_dh | N_c | gamma_1 (Pfa<=1e-4) | model Pd |\n|---|---|---|---|---|---|\n");
    for lambda in [80.0, 100.0, 164.0, 237.0, 300.0, 316.0, 398.0] {
        let cm = CellModel::new(ModelParams::paper(lambda));
        let g = cm.gamma_for_pfa(1e-4);
        s += &format!(
            "| {lambda} | {:.4} | {:.4} | {} | {} | {:.4} |\n",
            cm.p_ch,
            cm.p_dh,
            cm.n_c,
            g,
            cm.pd(g)
        );
    }
    Ok(s)
}

/// `trials_lambda<lambda>.csv`: the scoring trials of one lambda.
pub(super) fn trials_csv(out: &Path, lambda: f32, res: &[TrialStats]) -> anyhow::Result<()> {
    write_csv(out.join(format!("trials_lambda{lambda}.csv")), res)
}

/// `summary.csv`, `null_pfa.csv` and, when `gamma_1` was calibrated, `calib.csv`.
pub(super) fn tables(
    out: &Path,
    summaries: &[Summary],
    null_rows: &[NullRow],
    calib_csv: &[CalibRow],
) -> anyhow::Result<()> {
    write_csv(out.join("summary.csv"), summaries)?;
    write_csv(out.join("null_pfa.csv"), null_rows)?;
    if !calib_csv.is_empty() {
        write_csv(out.join("calib.csv"), calib_csv)?;
    }
    Ok(())
}

/// Fig. 10-12 (clutter density, Pd, plot rates versus lambda) and the clutter-only grid
/// Pfa versus `gamma_1` against the model.
pub(super) fn monte_carlo_figures(
    args: &Args,
    summaries: &[Summary],
    null_rows: &[NullRow],
) -> anyhow::Result<()> {
    // figures 10-12
    let xs = |f: &dyn Fn(&Summary) -> f64| {
        summaries
            .iter()
            .map(|s| (f64::from(s.lambda), f(s)))
            .collect::<Vec<_>>()
    };
    line_chart(
        &args.out.join("fig10_clutter_density.svg"),
        "Fig. 10: clutter plots per scan before/after censoring",
        "lambda",
        "plots per scan",
        &[
            ("before (sim)".into(), xs(&|s| s.clutter_per_scan_before)),
            ("after (sim)".into(), xs(&|s| s.clutter_per_scan_after)),
            (
                "after (model N_c m0 / N)".into(),
                xs(&|s| s.clutter_after_model),
            ),
            (
                "after (compound chains)".into(),
                xs(&|s| s.clutter_after_compound),
            ),
        ],
        true,
    )?;
    line_chart(
        &args.out.join("fig11_pd_vs_lambda.svg"),
        "Fig. 11: track detection probability vs lambda",
        "lambda",
        "Pd",
        &[
            ("MHT-TBD".into(), xs(&|s| s.mht_pd)),
            ("classic Hough TBD".into(), xs(&|s| s.classic_pd)),
        ],
        false,
    )?;
    line_chart(
        &args.out.join("fig12_plot_rates.svg"),
        "Fig. 12: plot-loss and wrong-plot rates (MHT-TBD)",
        "lambda",
        "rate",
        &[
            ("plot loss".into(), xs(&|s| s.plot_loss)),
            ("wrong plot".into(), xs(&|s| s.wrong_plot)),
        ],
        false,
    )?;
    let mut null_series = Vec::new();
    for &lambda in &args.lambda {
        let r: Vec<&NullRow> = null_rows.iter().filter(|r| r.lambda == lambda).collect();
        null_series.push((
            format!("sim lambda={lambda}"),
            r.iter().map(|r| (r.gamma as f64, r.sim_pfa)).collect(),
        ));
        null_series.push((
            format!("model lambda={lambda}"),
            r.iter().map(|r| (r.gamma as f64, r.model_pfa)).collect(),
        ));
    }
    line_chart(
        &args.out.join("null_pfa_vs_gamma.svg"),
        "Grid Pfa vs gamma_1: clutter-only simulation vs model",
        "gamma_1",
        "Pfa",
        &null_series,
        true,
    )?;
    Ok(())
}

/// `summary.md`: thresholds, Monte Carlo results, the clutter-only check and the model
/// table `model_md`; returns the Markdown.
pub(super) fn summary_md(
    args: &Args,
    sizes: &Sizes,
    summaries: &[Summary],
    model_md: &str,
) -> anyhow::Result<String> {
    let Sizes {
        trials,
        null_trials,
        calib_periods,
        calib_check,
    } = *sizes;
    let mut md = String::new();
    if args.gamma_from == GammaFrom::Sim {
        md += &format!("Trials per lambda: {trials} with 5 targets, {null_trials} clutter-only; gamma_1 calibrated by simulation: smallest gamma_1 whose clutter-only periods with a confirmed track are <= {} by rule {:?} ({calib_periods} calibration periods, every larger gamma_1 passing too), checked on {calib_check} independent periods.\n\n", args.pfa, args.calib_rule);
        md += "| lambda | gamma_1 (sim) | gamma_1 (model) | calibration: periods with a confirmed track | rate [95% CI] | at floor | check: periods with a confirmed track (tracks) | check rate [95% CI] |\n|---|---|---|---|---|---|---|---|\n";
        for s in summaries {
            let (_, clo, _) = proportion_ci(s.calib_periods_with_track, s.calib_periods);
            md += &format!(
                "| {} | {} | {} | {} / {} | {:.2e} [{:.2e}, {:.2e}] | {} | {} / {} ({}) | {:.2e} [{:.2e}, {:.2e}] |\n",
                s.lambda, s.gamma1, s.gamma1_model, s.calib_periods_with_track, s.calib_periods,
                s.calib_rate, clo, s.calib_rate_hi, s.calib_at_floor,
                s.check_periods_with_track, s.check_periods, s.check_tracks,
                s.check_rate, s.check_rate_lo, s.check_rate_hi
            );
        }
        md += "\n";
    } else {
        md += &format!("Trials per lambda: {trials} with 5 targets, {null_trials} clutter-only; thresholds for grid Pfa <= {} from the {:?} model.\n\n", args.pfa, args.model);
    }
    md += "| lambda | gamma_1 | clutter/scan before | after (sim) | after (paper N_c m0 / N) | after (compound chains) | target plots kept | MHT Pd [95% CI] | MHT false tracks (trials with FA) | plot loss | wrong plot | classic gamma | classic Pd | classic false peaks (trials with FA) |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for s in summaries {
        md += &format!(
            "| {} | {} | {:.1} | {:.2} | {:.2} | {:.2} | {:.3} | {:.3} [{:.3}, {:.3}] | {} ({}) | {:.3} | {:.3} | {} | {:.3} | {} ({}) |\n",
            s.lambda, s.gamma1, s.clutter_per_scan_before, s.clutter_per_scan_after, s.clutter_after_model, s.clutter_after_compound, s.target_plots_kept,
            s.mht_pd, s.mht_pd_lo, s.mht_pd_hi, s.mht_false_tracks, s.mht_trials_with_fa, s.plot_loss, s.wrong_plot,
            s.gamma_classic, s.classic_pd, s.classic_false_peaks, s.classic_trials_with_fa
        );
    }
    md += &format!(
        "\nMHT-TBD capacity: {} plots per scan, {} tracks. Skipped at capacity (plots, gated pairs, chains) over the scoring and clutter-only trials, per lambda: {}; peaks dropped beyond the track capacity: {}.\n",
        args.plots,
        args.tracks,
        summaries.iter().map(|s| s.capacity_skips.to_string()).collect::<Vec<_>>().join(" / "),
        summaries.iter().map(|s| s.peaks_dropped.to_string()).collect::<Vec<_>>().join(" / "),
    );
    md += "\nModel threshold in clutter-only simulation (largest DMHT count >= gamma_1, before track confirmation; and periods with a confirmed track):\n\n| lambda | gamma_1 | sim grid Pfa [95% CI] | model grid Pfa (eq. 28, N_t = 0) | periods with a confirmed false track | classic sim Pfa at its gamma |\n|---|---|---|---|---|---|\n";
    for s in summaries {
        md += &format!(
            "| {} | {} | {:.4} [{:.4}, {:.4}] | {:.2e} | {} / {} | {:.4} |\n",
            s.lambda,
            s.gamma1,
            s.null_pfa_sim,
            s.null_pfa_lo,
            s.null_pfa_hi,
            s.null_pfa_model,
            s.null_confirmed_fa_trials,
            s.null_trials,
            s.classic_null_pfa_sim
        );
    }
    md += "\nModel (paper parameters, Fig. 2-4 set):\n\n";
    md += model_md;
    crate::io::write_text(args.out.join("summary.md"), &md)?;
    Ok(md)
}
