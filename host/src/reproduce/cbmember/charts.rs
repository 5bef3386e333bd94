//! SVG charts of `faint reproduce cbmember`: Fig. 7-11, the ablations and the
//! target-free false alarms, from the curve points.

use std::path::Path;

use anyhow::Result;

use super::evaluation::{runs_per_point, Row};
use crate::io::{self, chart::Series};

pub(super) fn series(
    rows: &[Row],
    set: &str,
    name: &str,
    label: &str,
    f: fn(&Row) -> f64,
) -> Series {
    Series {
        name: label.to_string(),
        points: rows
            .iter()
            .filter(|r| r.set == set && r.curve == name)
            .map(|r| (r.snr_db, f(r)))
            .collect(),
    }
}

pub(super) fn charts(d: &Path, rows: &[Row], fig11: &[usize]) -> Result<()> {
    let pd = |r: &Row| r.pd;
    let n = |set: &str| runs_per_point(rows, set);
    let runs = n("base");
    let has = |set: &str| rows.iter().any(|r| r.set == set);
    if has("base") {
        io::chart::line_chart(
            d.join("fig7_pd.svg"),
            &format!("Fig. 7: Pd vs SNR, {runs} runs per point"),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(
                    rows,
                    "base",
                    "joint 1500",
                    "joint (Doppler + micro-Doppler)",
                    pd,
                ),
                series(rows, "base", "Doppler-only 1500", "Doppler-only", pd),
            ],
        )?;
        io::chart::line_chart(
            d.join("fig8_ospa.svg"),
            &format!("Fig. 8: mean OSPA (range m, velocity m/s; c = 5, p = 2), {runs} runs"),
            "SNR (dB, eq. 19)",
            "mean OSPA",
            &[
                series(rows, "base", "joint 1500", "joint", |r| r.ospa),
                series(rows, "base", "Doppler-only 1500", "Doppler-only", |r| {
                    r.ospa
                }),
                series(rows, "base", "joint 1500", "joint, after burn-in", |r| {
                    r.ospa_after_burn_in
                }),
            ],
        )?;
        let mut s: Vec<Series> = fig11
            .iter()
            .map(|&p| {
                series(
                    rows,
                    "base",
                    &format!("joint {p}"),
                    &format!("joint {p}"),
                    pd,
                )
            })
            .collect();
        s.push(series(
            rows,
            "base",
            "Doppler-only 1500",
            "Doppler-only 1500",
            pd,
        ));
        io::chart::line_chart(
            d.join("fig11_particles.svg"),
            &format!("Fig. 11: Pd vs SNR by particle count, {runs} runs"),
            "SNR (dB, eq. 19)",
            "Pd",
            &s,
        )?;
    }
    if has("blades 3") {
        io::chart::line_chart(
            d.join("fig9_blades.svg"),
            &format!(
                "Fig. 9: Pd vs SNR by blade count (joint 1500), {} runs (B = 2: {runs})",
                n("blades 3")
            ),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(rows, "base", "joint 1500", "B = 2", pd),
                series(rows, "blades 3", "joint 1500", "B = 3", pd),
                series(rows, "blades 4", "joint 1500", "B = 4", pd),
            ],
        )?;
    }
    if has("omega 0.04 pi") {
        io::chart::line_chart(
            d.join("fig10_omega.svg"),
            &format!(
                "Fig. 10: Pd vs SNR by rotor rate (joint 1500), {} runs (0.06 pi: {runs})",
                n("omega 0.04 pi")
            ),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(rows, "omega 0.04 pi", "joint 1500", "omega = 0.04 pi", pd),
                series(rows, "base", "joint 1500", "omega = 0.06 pi", pd),
                series(rows, "omega 0.08 pi", "joint 1500", "omega = 0.08 pi", pd),
            ],
        )?;
    }
    if has("ablation") {
        io::chart::line_chart(
            d.join("ablation_pd.svg"),
            &format!(
                "Ablations: B estimated, u8 map (joint 1500), {} runs (base: {runs})",
                n("ablation")
            ),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(rows, "base", "joint 1500", "joint (f32 map, B known)", pd),
                series(
                    rows,
                    "ablation",
                    "joint 1500 B estimated",
                    "B estimated",
                    pd,
                ),
                series(rows, "ablation", "joint 1500 u8 map", "u8 map", pd),
                series(rows, "base", "Doppler-only 1500", "Doppler-only", pd),
            ],
        )?;
    }
    if has("known") {
        io::chart::line_chart(
            d.join("known_pd.svg"),
            &format!(
                "Micro-Doppler known (the paper's assumption): Pd, {} runs (base: {runs})",
                n("known")
            ),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(
                    rows,
                    "known",
                    "joint 1500 micro-Doppler known",
                    "joint, V / omega / theta known",
                    pd,
                ),
                series(
                    rows,
                    "base",
                    "joint 1500",
                    "joint, V / omega / theta estimated",
                    pd,
                ),
                series(rows, "base", "Doppler-only 1500", "Doppler-only", pd),
            ],
        )?;
    }
    if has("merge") {
        io::chart::line_chart(
            d.join("merge_ospa.svg"),
            &format!("Merge gate: mean OSPA, {} runs (base: {runs})", n("merge")),
            "SNR (dB, eq. 19)",
            "mean OSPA",
            &[
                series(
                    rows,
                    "base",
                    "joint 1500",
                    "joint, gate [3 m, 5 m/s] (preset)",
                    |r| r.ospa,
                ),
                series(
                    rows,
                    "merge",
                    "joint 1500 merge gate 2 m 0.5 mps",
                    "joint, gate [2 m, 0.5 m/s]",
                    |r| r.ospa,
                ),
                series(
                    rows,
                    "base",
                    "Doppler-only 1500",
                    "Doppler-only, gate [3 m, 5 m/s] (preset)",
                    |r| r.ospa,
                ),
                series(
                    rows,
                    "merge",
                    "Doppler-only 1500 merge gate 2 m 0.5 mps",
                    "Doppler-only, gate [2 m, 0.5 m/s]",
                    |r| r.ospa,
                ),
            ],
        )?;
    }
    if has("physical") {
        let names: Vec<String> = rows
            .iter()
            .filter(|r| r.set == "physical")
            .map(|r| r.curve.clone())
            .fold(Vec::new(), |mut v, n| {
                if !v.contains(&n) {
                    v.push(n);
                }
                v
            });
        let s: Vec<Series> = names
            .iter()
            .map(|n| series(rows, "physical", n, n, pd))
            .collect();
        io::chart::line_chart(
            d.join("physical_pd.svg"),
            &format!(
                "Physical generator (eq. 11 + FFT): Pd vs SNR, {} runs",
                n("physical")
            ),
            "SNR (dB, peak pixel, eq. 19)",
            "Pd",
            &s,
        )?;
    }
    if has("target-free") {
        io::chart::line_chart(
            d.join("false_alarms.svg"),
            &format!(
                "Target-free runs: reported components per frame, {} runs",
                n("target-free")
            ),
            "filter gain set for SNR (dB)",
            "false alarms per frame",
            &[
                series(rows, "target-free", "joint 1500", "joint", |r| {
                    r.reported_per_frame
                }),
                series(
                    rows,
                    "target-free",
                    "Doppler-only 1500",
                    "Doppler-only",
                    |r| r.reported_per_frame,
                ),
            ],
        )?;
    }
    Ok(())
}
