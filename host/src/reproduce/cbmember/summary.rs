//! The Markdown summary of `faint reproduce cbmember`: our numbers next to the paper's.

use super::evaluation::{curve, runs_per_point, Row};
use super::paper;
use super::timing::TimingRow;
use crate::io;
use crate::stats::detection::snr_at_pd;

fn fmt_db(x: Option<f64>) -> String {
    io::fmt_opt(x, 2)
}

/// The Markdown summary: our numbers next to the paper's.
pub(super) fn summary(rows: &[Row], timing: &[TimingRow]) -> String {
    let mut s = String::new();
    let n = |set: &str| runs_per_point(rows, set);
    let runs = n("base");
    let at = |set: &str, name: &str, lvl: f64| snr_at_pd(&curve(rows, set, name), lvl);
    if rows.iter().any(|r| r.set == "base") {
        s.push_str(
            "### Sensitivity: SNR at Pd 0.9 (Fig. 7, 9, 10, 11, ablations; runs per point in the table)\n\n",
        );
        let mut t = Vec::new();
        let dop = at("base", "Doppler-only 1500", 0.9);
        let names: Vec<String> = rows
            .iter()
            .filter(|r| {
                r.set == "base"
                    || r.set.starts_with("blades")
                    || r.set.starts_with("omega")
                    || r.set == "ablation"
                    || r.set == "merge"
                    || r.set == "known"
            })
            .map(|r| format!("{}|{}", r.set, r.curve))
            .fold(Vec::new(), |mut v, n| {
                if !v.contains(&n) {
                    v.push(n);
                }
                v
            });
        for key in names {
            let (set, name) = key.split_once('|').unwrap_or(("", ""));
            let x = at(set, name, 0.9);
            let gain = match (dop.snr_db, x.snr_db) {
                (Some(a), Some(b)) => Some(a - b),
                _ => None,
            };
            let band = match (dop.lo_db, dop.hi_db, x.lo_db, x.hi_db) {
                (Some(dl), Some(dh), Some(xl), Some(xh)) => {
                    format!("[{:.2}, {:.2}]", dl - xh, dh - xl)
                }
                _ => "-".into(),
            };
            let paper = if name.starts_with("joint") && (set == "base") {
                format!("{:.1}", paper::GAIN_DB)
            } else {
                "-".into()
            };
            t.push(vec![
                set.to_string(),
                name.to_string(),
                n(set).to_string(),
                fmt_db(x.snr_db),
                format!("[{}, {}]", fmt_db(x.lo_db), fmt_db(x.hi_db)),
                fmt_db(gain),
                band,
                paper,
            ]);
        }
        s.push_str(&io::markdown_table(
            &[
                "set",
                "filter",
                "runs per point",
                "SNR at Pd 0.9 (dB)",
                "band (CP bounds)",
                "gain over Doppler-only (dB)",
                "gain band",
                "paper gain (dB)",
            ],
            &t,
        ));
        s.push('\n');
        // OSPA at the highest SNR.
        let top = rows
            .iter()
            .filter(|r| r.set == "base")
            .map(|r| r.snr_db)
            .fold(f64::NEG_INFINITY, f64::max);
        let mut t = Vec::new();
        for r in rows.iter().filter(|r| {
            (r.set == "base" || r.set == "merge" || r.set == "known") && r.snr_db == top
        }) {
            t.push(vec![
                format!("{} ({})", r.curve, r.set),
                format!("{}", r.snr_db),
                format!("{:.3}", r.pd),
                format!("{:.3}", r.reported_per_frame),
                format!("{:.3} +- {:.3}", r.ospa, r.ospa_se),
                format!("{:.3}", r.ospa_after_burn_in),
                format!("{:.3}", r.rmse_range_m),
                format!("{:.3}", r.rmse_velocity_mps),
                format!("{:.1}", paper::OSPA_SETTLED),
            ]);
        }
        s.push_str(&format!(
            "\n### Estimation at the highest SNR (Fig. 8), {runs} runs\n\n"
        ));
        s.push_str(&io::markdown_table(
            &[
                "filter",
                "SNR (dB)",
                "Pd",
                "reported per frame",
                "mean OSPA, all frames (+- standard error over runs)",
                "mean OSPA, after burn-in",
                "RMSE range (m)",
                "RMSE velocity (m/s)",
                "paper OSPA (units not stated)",
            ],
            &t,
        ));
    }
    let fa: Vec<&Row> = rows.iter().filter(|r| r.set == "target-free").collect();
    if !fa.is_empty() {
        s.push_str(&format!("\n### False alarms per frame, target-free runs ({} runs per point, after burn-in; paper: none given)\n\n", n("target-free")));
        let t: Vec<Vec<String>> = fa
            .iter()
            .map(|r| {
                vec![
                    r.curve.clone(),
                    format!("{}", r.snr_db),
                    r.frames.to_string(),
                    format!("{:.4}", r.reported_per_frame),
                ]
            })
            .collect();
        s.push_str(&io::markdown_table(
            &[
                "filter",
                "gain set for SNR (dB)",
                "frames",
                "false alarms per frame",
            ],
            &t,
        ));
    }
    let ph: Vec<&Row> = rows.iter().filter(|r| r.set == "physical").collect();
    if !ph.is_empty() {
        s.push_str(&format!(
            "\n### Physical generator (eq. 11 + slow-time FFT), {} runs per point\n\n",
            n("physical")
        ));
        let t: Vec<Vec<String>> = ph
            .iter()
            .map(|r| {
                vec![
                    r.curve.clone(),
                    format!("{}", r.snr_db),
                    format!("{:.3} [{:.3}, {:.3}]", r.pd, r.pd_lo, r.pd_hi),
                    format!("{:.3}", r.reported_per_frame),
                    format!("{:.3}", r.ospa),
                ]
            })
            .collect();
        s.push_str(&io::markdown_table(
            &[
                "filter",
                "SNR (dB)",
                "Pd [95 % CP]",
                "reported per frame",
                "mean OSPA",
            ],
            &t,
        ));
    }
    if !timing.is_empty() {
        s.push_str("\n### Table 3: time per frame (CPU time of one host thread, -10 dB, map generation excluded)\n\n");
        let t: Vec<Vec<String>> = timing
            .iter()
            .map(|r| {
                vec![
                    r.algorithm.clone(),
                    r.particles.to_string(),
                    r.frames.to_string(),
                    format!("{:.0}", r.particles_per_frame),
                    format!("{:.3}", r.ms_per_frame),
                    io::fmt_opt(r.paper_s.map(|p| p * 1e3), 0),
                    io::fmt_opt(r.speed_up, 0),
                ]
            })
            .collect();
        s.push_str(&io::markdown_table(
            &[
                "algorithm",
                "L_max",
                "frames",
                "particles updated per frame",
                "ms per frame (ours)",
                "paper ms (MATLAB)",
                "paper / ours",
            ],
            &t,
        ));
    }
    s
}
