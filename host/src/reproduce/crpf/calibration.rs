//! Thresholds of `faint reproduce crpf` at the wanted Pfa, from the H0 runs: one per
//! compared statistic from all the runs (used for Pd), the check of the threshold set on
//! one half of the runs against the false-alarm rate of the other half ([`calibration`]),
//! and the thresholds of the max statistics quoted with Fig. 1.

use anyhow::Result;
use serde::Serialize;

use super::args::Settings;
use super::evaluation::{Stats, METHODS};
use crate::simulate::crpf::Noise;
use crate::stats::detection::{detection_rate, threshold_at_pfa, Proportion, Threshold};

/// Calibration check of one statistic (`calibration.csv`).
#[derive(Debug, Serialize)]
pub(super) struct CalRow {
    pub(super) noise: Noise,
    pub(super) particles: usize,
    pub(super) method: &'static str,
    pub(super) pfa: f64,
    pub(super) threshold_half_a: f64,
    pub(super) false_alarms_half_b: usize,
    pub(super) n_half_b: usize,
    pub(super) pfa_half_b: f64,
    pub(super) lo: f64,
    pub(super) hi: f64,
    pub(super) inside: bool,
    pub(super) threshold_all: f64,
    pub(super) threshold_ci_low: f64,
    pub(super) threshold_ci_high: f64,
}

/// The thresholds of one run configuration.
#[derive(Debug)]
pub(super) struct Thresholds {
    /// Thresholds of the five compared statistics ([`METHODS`] order), from all H0 runs.
    pub(super) values: [f64; 5],
    /// Calibration check of each compared statistic (`calibration.csv`).
    pub(super) rows: Vec<CalRow>,
    /// Threshold of PF-max (Fig. 1).
    pub(super) pf_max: f64,
    /// Threshold of JOTT-max (Fig. 1).
    pub(super) jott_max: f64,
}

/// Whether the false-alarm rate of half B at the threshold of half A is compatible with
/// the target (the target lies in the Clopper-Pearson interval of the observed rate).
pub fn calibration(h0: &[f64], pfa: f64) -> Result<(Threshold, Proportion)> {
    let half = h0.len() / 2;
    let t = threshold_at_pfa(&h0[..half], pfa)?;
    let p = detection_rate(&h0[half..], t.value);
    Ok((t, p))
}

/// Thresholds at `a.pfa` from the H0 statistics `h0`, with the calibration check of each
/// compared statistic.
pub(super) fn thresholds(a: &Settings, h0: &[Stats]) -> Result<Thresholds> {
    let mut thresholds = [0.0f64; 5];
    let mut cal_rows = Vec::new();
    for (m, name) in METHODS.iter().enumerate() {
        let v: Vec<f64> = h0.iter().map(|s| s.values()[m]).collect();
        let t = threshold_at_pfa(&v, a.pfa)?;
        thresholds[m] = t.value;
        let (ta, pb) = calibration(&v, a.pfa)?;
        cal_rows.push(CalRow {
            noise: a.noise,
            particles: a.particles,
            method: name,
            pfa: a.pfa,
            threshold_half_a: ta.value,
            false_alarms_half_b: pb.k,
            n_half_b: pb.n,
            pfa_half_b: pb.p,
            lo: pb.lo,
            hi: pb.hi,
            inside: pb.lo <= a.pfa && a.pfa <= pb.hi,
            threshold_all: t.value,
            threshold_ci_low: t.ci_low,
            threshold_ci_high: t.ci_high,
        });
    }
    let col = |f: fn(&Stats) -> f64| h0.iter().map(f).collect::<Vec<f64>>();
    let pf_max_t = threshold_at_pfa(&col(|s| s.pf_max), a.pfa)?.value;
    let jott_max_t = threshold_at_pfa(&col(|s| s.jott_max), a.pfa)?.value;
    Ok(Thresholds {
        values: thresholds,
        rows: cal_rows,
        pf_max: pf_max_t,
        jott_max: jott_max_t,
    })
}
