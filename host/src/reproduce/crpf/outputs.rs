//! Outputs of `faint reproduce crpf`: the CSV files of the H0 statistics, calibration,
//! Pd versus SNR, SNR at Pd and sweeps; the SVG figures (Fig. 1 histograms, Fig. 2 / 4
//! Pd versus SNR, Fig. 5 sweeps); and `table.md`, the Markdown summary also printed.

use std::path::Path;

use anyhow::Result;

use super::args::Settings;
use super::calibration::Thresholds;
use super::evaluation::{PdCurves, SnrRow, Stats, Sweeps, METHODS};
use crate::io::{self, chart};
use crate::simulate::crpf::Noise;

/// H0 outputs: `h0_stats.csv`, `calibration.csv` and Fig. 1 (H0 histograms of the
/// existence statistics).
pub(super) fn h0(dir: &Path, a: &Settings, h0: &[Stats], th: &Thresholds) -> Result<()> {
    io::write_csv(dir.join("h0_stats.csv"), h0)?;
    io::write_csv(dir.join("calibration.csv"), &th.rows)?;
    // Fig. 1: H0 histograms of zeta_K and D_K.
    let col = |f: fn(&Stats) -> f64| h0.iter().map(f).collect::<Vec<f64>>();
    chart::histogram(
        dir.join("fig1_h0_statistics.svg"),
        &format!("H0 existence statistics, N = {}, K = 32", a.particles),
        "statistic",
        &[
            ("CRPF-max".into(), col(|s| s.crpf_max)),
            ("CRPF-mean".into(), col(|s| s.crpf_mean)),
            ("PF-max".into(), col(|s| s.pf_max)),
            ("PF-mean".into(), col(|s| s.pf_mean)),
            ("JOTT-max".into(), col(|s| s.jott_max)),
            ("JOTT-mean".into(), col(|s| s.jott_mean)),
        ],
        50,
    )?;
    Ok(())
}

/// `pd_vs_snr.csv` and the Pd versus SNR figure (Fig. 2 for Gaussian noise, else Fig. 4).
pub(super) fn pd_vs_snr(dir: &Path, a: &Settings, pd: &PdCurves) -> Result<()> {
    io::write_csv(dir.join("pd_vs_snr.csv"), &pd.rows)?;
    let series: Vec<chart::Series> = METHODS
        .iter()
        .zip(&pd.curves)
        .map(|(n, c)| chart::Series {
            name: n.to_string(),
            points: c.iter().map(|p| (p.snr_db, p.pd.p)).collect(),
        })
        .collect();
    let fig = if a.noise == Noise::Gaussian {
        "fig2"
    } else {
        "fig4"
    };
    chart::line_chart(
        dir.join(format!("{fig}_pd_vs_snr.svg")),
        &format!(
            "Pd vs SNR, {:?} noise, N = {}, Pfa = {}",
            a.noise, a.particles, a.pfa
        ),
        "SNR (dB, eq. 18)",
        "Pd",
        &series,
    )?;
    Ok(())
}

/// `snr_at_pd.csv` and `table.md` (SNR at Pd, calibration, Fig. 1 thresholds, CRPF-TBD's
/// Doppler error); returns the Markdown. `elapsed_s` is the run's wall-clock time so far.
pub(super) fn table(
    dir: &Path,
    a: &Settings,
    snr_rows: &[SnrRow],
    th: &Thresholds,
    fd_err: &[(f64, f64, usize)],
    elapsed_s: f64,
) -> Result<String> {
    io::write_csv(dir.join("snr_at_pd.csv"), snr_rows)?;
    let md_rows: Vec<Vec<String>> = snr_rows
        .iter()
        .map(|s| {
            vec![
                format!("{:?}", s.noise),
                s.particles.to_string(),
                s.method.to_string(),
                format!("{}", s.level),
                io::fmt_opt(s.snr_db, 2),
                format!("[{}, {}]", io::fmt_opt(s.lo_db, 2), io::fmt_opt(s.hi_db, 2)),
                io::fmt_opt(s.delta_vs_crpf_max_db, 2),
            ]
        })
        .collect();
    let mut md = format!(
        "# CRPF-TBD reproduction: {:?} noise, N = {}, Pfa = {}\n\n\
         {} H0 runs, {} H1 runs per SNR point, SNR grid {}, seed {}, {:.0} s.\n\n\
         ## SNR (dB, eq. 18) at Pd = 0.5 / 0.9 (interval: crossings of the 95 % \
         Clopper-Pearson band); delta = method minus CRPF-max\n\n",
        a.noise, a.particles, a.pfa, a.h0_trials, a.trials, a.snr_db, a.seed, elapsed_s
    );
    md += &io::markdown_table(
        &[
            "noise", "N", "method", "Pd", "SNR dB", "interval", "delta dB",
        ],
        &md_rows,
    );
    md += "\n\n## Calibration: threshold from H0 half A, false-alarm rate on half B\n\n";
    md += &io::markdown_table(
        &[
            "method",
            "threshold (A)",
            "FA on B",
            "rate",
            "95 % CI",
            "target inside",
        ],
        &th.rows
            .iter()
            .map(|c| {
                vec![
                    c.method.to_string(),
                    format!("{:.4}", c.threshold_half_a),
                    format!("{}/{}", c.false_alarms_half_b, c.n_half_b),
                    format!("{:.5}", c.pfa_half_b),
                    format!("[{:.5}, {:.5}]", c.lo, c.hi),
                    c.inside.to_string(),
                ]
            })
            .collect::<Vec<_>>(),
    );
    md += &format!(
        "\n\nFig. 1: thresholds at Pfa {} of the max statistics: CRPF-max {:.4}, PF-max {:.4}, \
         JOTT-max {:.4}.\n\n## CRPF-TBD Doppler error (median over runs of the mean |error| \
         over frames 14-26, Hz)\n\n",
        a.pfa, th.values[0], th.pf_max, th.jott_max
    );
    md += &io::markdown_table(
        &["SNR dB", "median |fd error| Hz", "runs with an estimate"],
        &fd_err
            .iter()
            .map(|(s, e, n)| vec![format!("{s}"), format!("{e:.3}"), n.to_string()])
            .collect::<Vec<_>>(),
    );
    md.push('\n');
    io::write_text(dir.join("table.md"), &md)?;
    Ok(md)
}

/// Fig. 5 outputs under `sweeps_n<N>/`: `fig5_sweeps.csv`, `fig5_r_th.svg`, `fig5_lambda.svg`.
pub(super) fn sweeps(a: &Settings, sw: &Sweeps) -> Result<()> {
    let dir = a.out.join(format!("sweeps_n{}", a.particles));
    io::write_csv(dir.join("fig5_sweeps.csv"), &sw.rows)?;
    let names = ["CRPF-max", "CRPF-mean"];
    let pfa = sw.pfa;
    for (k, (param, xl)) in [("r_th", "r_th"), ("lambda", "lambda")].iter().enumerate() {
        chart::line_chart(
            dir.join(format!("fig5_{param}.svg")),
            &format!(
                "Pd at 5 dB vs {param} (Gaussian, N = {}, Pfa = {pfa})",
                a.particles
            ),
            xl,
            "Pd",
            &(0..2)
                .map(|mi| chart::Series {
                    name: names[mi].into(),
                    points: sw.series[2 * k + mi].clone(),
                })
                .collect::<Vec<_>>(),
        )?;
    }
    Ok(())
}
