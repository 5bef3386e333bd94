//! `faint reproduce mht`: Bao et al. 2022 (MHT-TBD) Fig. 2-4 (model), Fig. 10-12
//! (Monte Carlo) and the false-alarm count, for MHT-TBD and the classic Carlson Hough TBD.
//!
//! Scoring (documented choices):
//! - a reported track (MHT: a confirmed track's line; classic: a peak's line) **matches**
//!   target `i` when every noise-free position of the target over the `N` scans lies
//!   within `MATCH_TOL` of the line, or (MHT only, its tracks carry plots) when more than
//!   half of the track's plots are target `i`'s; a target is detected when some track
//!   matches it;
//!   a track matching no target is a **false alarm** (a second track on the same target is
//!   a duplicate, not a false alarm);
//! - plot-loss rate: over detected targets, the target's pre-detection plots missing from
//!   the best matching track (the one holding most of its plots);
//! - wrong-plot rate: over those tracks, the associated plots not made by the target;
//! - clutter density: clutter plots per scan before censoring, and clutter plots marked
//!   effective per scan after it;
//! - model-threshold check: clutter-only trials (no targets) record the largest DMHT count
//!   of the period, so the empirical grid Pfa at every `gamma` is the fraction of trials
//!   whose largest count reaches `gamma`, next to the model's eq. 28.
//!
//! The code is split by role: [`Args`] and its checks in `args.rs`, the thresholds (the
//! models' and the simulation's calibration of `gamma_1`) in `calibration.rs`, the two
//! detectors built for a scene in `detectors.rs`, the trials and their scoring in
//! `evaluation.rs`, and the CSV, SVG and Markdown outputs in `outputs.rs`; [`run`] chains
//! them.

mod args;
mod calibration;
mod detectors;
mod evaluation;
mod outputs;
mod stages;

use crate::simulate::mht::SeaClutter;

pub use args::{Args, CalibRule, GammaFrom, ModelChoice};
pub use calibration::{
    calibrate, false_track_counts, model_params, pilot_floor, proportion_ci, thresholds,
    thresholds_with, FalseTrackCounts, GridModel, PILOT_PERIODS,
};
pub use detectors::detectors;
pub use evaluation::{evaluate_trial, target_plots_in, track_targets, TrialStats, MATCH_TOL};
pub use stages::{attribute, stage3_fates, Fate, Loss, StageReport};

/// Entry point.
pub fn run(args: &Args) -> anyhow::Result<()> {
    let sizes = args.validate()?;
    let mut calib_csv = Vec::new();
    crate::cli::out_dir(&args.out)?;
    let model_md = outputs::model_figures(&args.out)?;
    let mut summaries = Vec::new();
    let mut null_rows = Vec::new();
    for (li, &lambda) in args.lambda.iter().enumerate() {
        let sc = SeaClutter::paper(lambda);
        let th = calibration::gammas(args, &sizes, li, &sc, &mut calib_csv);
        let (res, nres) = evaluation::trials(args, &sizes, li, &sc, &th)?;
        outputs::trials_csv(&args.out, lambda, &res)?;
        summaries.push(evaluation::summarise(
            args,
            &sizes,
            &sc,
            &th,
            &res,
            &nres,
            &mut null_rows,
        ));
    }
    outputs::tables(&args.out, &summaries, &null_rows, &calib_csv)?;
    outputs::monte_carlo_figures(args, &summaries, &null_rows)?;
    let md = outputs::summary_md(args, &sizes, &summaries, &model_md)?;
    println!("{md}");
    Ok(())
}
