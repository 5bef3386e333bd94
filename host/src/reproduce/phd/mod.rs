//! `faint reproduce phd` (alias `psophd`): Pei et al. 2019 (PSO-PHD-TBD), Fig. 3-5 and Tables 2-4.
//!
//! Per SNR and Monte Carlo run, one truth and one sequence of 40 power cubes of the
//! `six-targets` preset; the three algorithms (PHD-TBD, PSO-PHD-TBD with K-means,
//! PSO-PHD-TBD with DBSCAN) run on the same cubes. Per frame: mean and standard
//! deviation over runs of the estimated count `N_hat` (Fig. 3-4, Table 2 = mean over
//! frames of the std), mean OSPA on positions with `c = 50 m`, `p = 2` (Fig. 5, Table 3),
//! and the filter's wall time per run (Table 4, cube simulation excluded).
//!
//! `--cubes physics` renders the same truth with the physics simulator of power cubes
//! (sinc response, random phase per frame; `cubes.rs`) instead of the filter's model.
//!
//! The code is split by role: [`Args`] and its checks in `args.rs`, the runs and their
//! statistics in `evaluation.rs`, the SVG charts in `charts.rs` and the Markdown table
//! against the paper in `summary.rs`; [`run`] chains them, one SNR after the other.

mod args;
mod charts;
mod cubes;
mod evaluation;
mod summary;

use std::path::Path;

use anyhow::Result;

use crate::cli;
use crate::io;
use crate::shard::{self, Batch, Merged, Run, Shard};
use args::Plan;
use evaluation::RunResult;

pub use args::Args;
pub use cubes::{physics, render, Cubes};

/// The command name in shard files.
pub const COMMAND: &str = "reproduce phd";

/// The batches of the run: the runs of each SNR, in `--snr-db` order.
fn keys(plan: &Plan) -> Vec<String> {
    (0..plan.snrs.len()).map(|j| format!("snr {j}")).collect()
}

/// The runs of every SNR that `shard` holds (all of them for `None`); the runs of SNR
/// `s` draw from the streams of `seed ^ (1000 s)`.
fn collect(args: &Args, plan: &Plan, shard: Option<Shard>) -> Result<Vec<Batch<Vec<RunResult>>>> {
    plan.snrs
        .iter()
        .zip(keys(plan))
        .map(|(&snr, key)| {
            let sc = args.scene(snr);
            let filters: Vec<_> = plan
                .variants
                .iter()
                .map(|&v| (v, args.config(&sc, v)))
                .collect();
            let seed = args.seed ^ (snr * 1000.0) as u64;
            Batch::run(key, plan.runs, shard, |range| {
                evaluation::runs(
                    &sc,
                    args.cubes,
                    &filters,
                    range,
                    seed,
                    &format!("phd {snr} dB{}", args.cubes.label()),
                )
            })
        })
        .collect()
}

/// The outputs of the run from the runs of every SNR (in [`keys`] order).
fn analyse(args: &Args, plan: &Plan, all: Vec<Vec<Vec<RunResult>>>) -> Result<()> {
    cli::out_dir(&args.out)?;
    let mut frames_csv = Vec::new();
    let mut summary = Vec::new();
    let d = &args.out;
    for (&snr, all) in plan.snrs.iter().zip(&all) {
        let sc = args.scene(snr);
        let (frames, rows) = evaluation::statistics(&sc, snr, &plan.variants, all);
        let truth = evaluation::truth_counts(&sc);
        charts::charts(
            d,
            snr,
            plan.runs,
            args.cubes,
            &plan.variants,
            &truth,
            &frames,
        )?;
        frames_csv.extend(frames);
        summary.extend(rows);
    }
    io::write_csv(d.join("frames.csv"), &frames_csv)?;
    io::write_csv(d.join("summary.csv"), &summary)?;
    let md = summary::table(&summary, args.cubes);
    io::write_text(d.join("table.md"), &md)?;
    println!("{md}");
    Ok(())
}

/// Runs the reproduction: the whole run, or with `--shard` (or a scheduler's array) one
/// shard's runs, written to `<out>/shards/` for `faint merge`.
pub fn run(args: &Args) -> Result<()> {
    args.validate()?;
    let plan = args.effective()?;
    let shard = args.shard.resolve()?;
    cli::out_dir(&args.out)?;
    let t0 = std::time::Instant::now();
    let batches = collect(args, &plan, shard)?;
    match shard {
        None => analyse(
            args,
            &plan,
            batches.into_iter().map(|b| b.results).collect(),
        ),
        Some(s) => shard::finish(
            &args.out.join("shards"),
            &Run::new(COMMAND, args)?,
            s,
            t0,
            &batches,
        )
        .map(|_| ()),
    }
}

/// `faint merge` of `reproduce phd` shards: the outputs of the unsharded run, written
/// where it writes them (under `out` if given, else the run's `--out`).
pub fn merge(m: &Merged, out: Option<&Path>) -> Result<()> {
    let mut args: Args = m.run.args()?;
    if let Some(o) = out {
        args.out = o.to_path_buf();
    }
    let plan = args.effective()?;
    analyse(&args, &plan, m.results(&keys(&plan))?)
}
