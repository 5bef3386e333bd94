//! SVG charts of `faint reproduce phd` at one SNR: the mean estimated count against the
//! truth (Fig. 3), its standard deviation (Fig. 4) and the mean OSPA (Fig. 5) per frame.

use std::path::Path;

use anyhow::Result;

use super::cubes::Cubes;
use super::evaluation::FrameRow;
use crate::io::{self, chart::Series};
use crate::simulate::phd::Variant;

/// The three charts of one SNR from its per-frame rows `frames` (every variant's, in
/// `variants` order) and the true count per frame.
pub(super) fn charts(
    d: &Path,
    snr: f64,
    runs: usize,
    cubes: Cubes,
    variants: &[Variant],
    truth_counts: &[usize],
    frames: &[FrameRow],
) -> Result<()> {
    let mut count_series = vec![Series {
        name: "truth".into(),
        points: truth_counts
            .iter()
            .enumerate()
            .map(|(k, &n)| ((k + 1) as f64, n as f64))
            .collect(),
    }];
    let mut std_series = Vec::new();
    let mut ospa_series = Vec::new();
    for v in variants {
        let rows = || frames.iter().filter(|r| r.variant == v.name());
        let series = |f: fn(&FrameRow) -> f64| Series {
            name: v.name().into(),
            points: rows().map(|r| (r.frame as f64, f(r))).collect(),
        };
        count_series.push(series(|r| r.mean_count));
        std_series.push(series(|r| r.std_count));
        ospa_series.push(series(|r| r.mean_ospa));
    }
    io::chart::line_chart(
        d.join(format!("count_{snr}db.svg")),
        &format!(
            "Mean estimated target count, {snr} dB, {runs} runs{} (Fig. 3)",
            cubes.label()
        ),
        "frame",
        "count",
        &count_series,
    )?;
    io::chart::line_chart(
        d.join(format!("count_std_{snr}db.svg")),
        &format!(
            "Std of the estimated count, {snr} dB, {runs} runs{} (Fig. 4)",
            cubes.label()
        ),
        "frame",
        "std",
        &std_series,
    )?;
    io::chart::line_chart(
        d.join(format!("ospa_{snr}db.svg")),
        &format!(
            "Mean OSPA (c = 50 m, p = 2), {snr} dB, {runs} runs{} (Fig. 5)",
            cubes.label()
        ),
        "frame",
        "OSPA (m)",
        &ospa_series,
    )
}
