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

use std::path::Path;

use anyhow::Result;
use serde::{Deserialize, Serialize};

use crate::shard::{self, Batch, Merged, Run, Shard};
use crate::simulate::mht::SeaClutter;
use args::Sizes;
use calibration::{CalibRow, Gammas};

pub use args::{Args, CalibRule, GammaFrom, ModelChoice};
pub use calibration::{
    calibrate, false_track_counts, false_track_counts_at, model_params, pilot_floor,
    pilot_floor_at, proportion_ci, thresholds, thresholds_with, FalseTrackCounts, GridModel,
    PILOT_PERIODS,
};
pub use detectors::{detectors, detectors_with, MhtAt};
pub use evaluation::{evaluate_trial, target_plots_in, track_targets, TrialStats, MATCH_TOL};
pub use stages::{attribute, stage3_fates, Fate, Loss, StageReport};

/// The command name in shard files.
pub const COMMAND: &str = "reproduce mht";

/// What the run fixes before its trials: the thresholds of every lambda and the
/// calibration rows behind them (`--gamma-from sim`). Every shard computes them in full
/// (the trials need `gamma_1`), so they are identical in every shard file.
#[derive(Debug, Serialize, Deserialize)]
struct Meta {
    gammas: Vec<Gammas>,
    calib_csv: Vec<CalibRow>,
}

fn fixed_inputs(args: &Args, sizes: &Sizes) -> Meta {
    let mut calib_csv = Vec::new();
    let gammas = args
        .lambda
        .iter()
        .enumerate()
        .map(|(li, &lambda)| {
            calibration::gammas(args, sizes, li, &SeaClutter::paper(lambda), &mut calib_csv)
        })
        .collect();
    Meta { gammas, calib_csv }
}

/// The batches of the run, in order: per lambda its scoring trials, then its
/// clutter-only trials.
fn keys(args: &Args) -> Vec<String> {
    (0..args.lambda.len())
        .flat_map(|li| [format!("lambda {li}"), format!("lambda {li} null")])
        .collect()
}

/// The trials of every batch that `shard` holds (all of them for `None`).
fn collect(
    args: &Args,
    sizes: &Sizes,
    meta: &Meta,
    shard: Option<Shard>,
) -> Result<Vec<Batch<TrialStats>>> {
    let mut out = Vec::new();
    let mut names = keys(args).into_iter();
    for (li, (&lambda, th)) in args.lambda.iter().zip(&meta.gammas).enumerate() {
        let sc = SeaClutter::paper(lambda);
        for (null, n) in [(false, sizes.trials), (true, sizes.null_trials)] {
            let key = names.next().unwrap_or_default();
            out.push(Batch::run(key, n, shard, |range| {
                evaluation::trials(args, li, &sc, th, null, range)
            })?);
        }
    }
    Ok(out)
}

/// The outputs of the run from the trials of every batch (in [`keys`] order).
fn analyse(args: &Args, sizes: &Sizes, meta: &Meta, runs: Vec<Vec<TrialStats>>) -> Result<()> {
    crate::cli::out_dir(&args.out)?;
    let model_md = outputs::model_figures(&args.out)?;
    let mut summaries = Vec::new();
    let mut null_rows = Vec::new();
    let mut runs = runs.into_iter();
    for (&lambda, th) in args.lambda.iter().zip(&meta.gammas) {
        let sc = SeaClutter::paper(lambda);
        let (res, nres) = (
            runs.next().unwrap_or_default(),
            runs.next().unwrap_or_default(),
        );
        outputs::trials_csv(&args.out, lambda, &res)?;
        summaries.push(evaluation::summarise(
            args,
            sizes,
            &sc,
            th,
            &res,
            &nres,
            &mut null_rows,
        ));
    }
    outputs::tables(&args.out, &summaries, &null_rows, &meta.calib_csv)?;
    outputs::monte_carlo_figures(args, &summaries, &null_rows)?;
    let md = outputs::summary_md(args, sizes, &summaries, &model_md)?;
    println!("{md}");
    Ok(())
}

/// `faint reproduce mht`: the whole run, or with `--shard` (or a scheduler's array) one
/// shard's trials, written to `<out>/shards/` for `faint merge`. The thresholds (and
/// with `--gamma-from sim` their calibration) are computed by every shard; the scoring
/// and clutter-only trials are sharded.
pub fn run(args: &Args) -> Result<()> {
    let sizes = args.validate()?;
    let shard = args.shard.resolve()?;
    crate::cli::out_dir(&args.out)?;
    let t0 = std::time::Instant::now();
    let meta = fixed_inputs(args, &sizes);
    let batches = collect(args, &sizes, &meta, shard)?;
    match shard {
        None => analyse(
            args,
            &sizes,
            &meta,
            batches.into_iter().map(|b| b.results).collect(),
        ),
        Some(s) => {
            let run = Run::new(COMMAND, args)?.with_meta(&meta)?;
            shard::finish(&args.out.join("shards"), &run, s, t0, &batches).map(|_| ())
        }
    }
}

/// `faint merge` of `reproduce mht` shards: the outputs of the unsharded run, written
/// where it writes them (under `out` if given, else the run's `--out`).
pub fn merge(m: &Merged, out: Option<&Path>) -> Result<()> {
    let mut args: Args = m.run.args()?;
    if let Some(o) = out {
        args.out = o.to_path_buf();
    }
    let sizes = args.validate()?;
    let meta: Meta = m.run.meta()?;
    analyse(&args, &sizes, &meta, m.results(&keys(&args))?)
}
