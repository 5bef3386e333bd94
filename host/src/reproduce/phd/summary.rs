//! The Markdown table of `faint reproduce phd`: our numbers next to the paper's
//! Tables 2-4.

use super::cubes::Cubes;
use super::evaluation::SummaryRow;
use crate::io;

/// The paper's numbers: (Table 2 PHD-TBD, Table 2 PSO, Table 3 x3, Table 4 PHD, PSO-DBSCAN).
pub(super) const PAPER: [(f64, [f64; 7]); 3] = [
    (9.0, [0.59, 0.47, 14.68, 9.43, 3.47, 12.49, 22.19]),
    (7.0, [1.00, 0.74, 15.79, 11.55, 4.88, 12.76, 25.73]),
    (5.0, [1.25, 0.93, 17.75, 15.60, 8.52, 12.85, 28.26]),
];

/// The table of `summary`; on physics cubes a first line says so (the paper's columns
/// stay: its figures are from its model's cubes).
pub(super) fn table(summary: &[SummaryRow], cubes: Cubes) -> String {
    let mut rows = Vec::new();
    for s in summary {
        let paper = PAPER.iter().find(|p| p.0 == s.snr_db).map(|p| p.1);
        let (p_std, p_ospa, p_time) = match (paper, s.variant) {
            (Some(p), "PHD-TBD") => (Some(p[0]), Some(p[2]), Some(p[5])),
            (Some(p), "PSO-PHD-TBD (K-means)") => (Some(p[1]), Some(p[3]), None),
            (Some(p), "PSO-PHD-TBD (DBSCAN)") => (Some(p[1]), Some(p[4]), Some(p[6])),
            _ => (None, None, None),
        };
        rows.push(vec![
            format!("{}", s.snr_db),
            s.variant.to_string(),
            s.runs.to_string(),
            format!("{:.2}", s.mean_std_count),
            io::fmt_opt(p_std, 2),
            format!("{:.2}", s.mean_ospa_m),
            io::fmt_opt(p_ospa, 2),
            format!("{:.2}", s.mean_abs_count_error),
            format!("{:.2}", s.all_alive_mean_count),
            format!("{:.2}", s.all_alive_mean_ospa_m),
            format!("{:.3}", s.seconds_per_run),
            io::fmt_opt(p_time, 2),
        ]);
    }
    let head = match cubes {
        Cubes::Model => "",
        Cubes::Physics => "Cubes from the physics simulator (sinc response per axis at the sub-cell offset, random phase per frame), not from the filter's model; the paper's columns are from its model's cubes.\n\n",
    };
    let table = io::markdown_table(
        &[
            "SNR (dB)",
            "algorithm",
            "runs",
            "mean std of count (ours)",
            "paper T2",
            "mean OSPA m (ours)",
            "paper T3",
            "mean abs count error",
            "count, all alive",
            "OSPA m, all alive",
            "s per 40-frame run (ours, 1 core)",
            "paper T4 (MATLAB)",
        ],
        &rows,
    );
    format!("{head}{table}")
}
