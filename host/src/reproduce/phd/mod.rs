//! `faint reproduce phd` (alias `psophd`): Pei et al. 2019 (PSO-PHD-TBD), Fig. 3-5 and Tables 2-4.
//!
//! Per SNR and Monte Carlo run, one truth and one sequence of 40 power cubes of the
//! `six-targets` preset; the three algorithms (PHD-TBD, PSO-PHD-TBD with K-means,
//! PSO-PHD-TBD with DBSCAN) run on the same cubes. Per frame: mean and standard
//! deviation over runs of the estimated count `N_hat` (Fig. 3-4, Table 2 = mean over
//! frames of the std), mean OSPA on positions with `c = 50 m`, `p = 2` (Fig. 5, Table 3),
//! and the filter's wall time per run (Table 4, cube simulation excluded).
//!
//! The code is split by role: [`Args`] and its checks in `args.rs`, the runs and their
//! statistics in `evaluation.rs`, the SVG charts in `charts.rs` and the Markdown table
//! against the paper in `summary.rs`; [`run`] chains them, one SNR after the other.

mod args;
mod charts;
mod evaluation;
mod summary;

use anyhow::Result;

use crate::cli;
use crate::io;
use args::Plan;

pub use args::Args;

/// Runs the reproduction.
pub fn run(args: &Args) -> Result<()> {
    args.validate()?;
    let Plan {
        snrs,
        runs,
        variants,
    } = args.effective()?;
    cli::out_dir(&args.out)?;
    let mut frames_csv = Vec::new();
    let mut summary = Vec::new();
    for &snr in &snrs {
        let sc = args.scene(snr);
        let label = format!("phd {snr} dB");
        let seed = args.seed ^ (snr * 1000.0) as u64;
        let all = evaluation::runs(&sc, &variants, runs, seed, &label)?;
        let (frames, rows) = evaluation::statistics(&sc, snr, &variants, &all);
        let d = &args.out;
        let truth = evaluation::truth_counts(&sc);
        charts::charts(d, snr, runs, &variants, &truth, &frames)?;
        frames_csv.extend(frames);
        summary.extend(rows);
        // Write what we have after every SNR (long runs can be inspected early).
        io::write_csv(d.join("frames.csv"), &frames_csv)?;
        io::write_csv(d.join("summary.csv"), &summary)?;
        io::write_text(d.join("table.md"), &summary::table(&summary))?;
    }
    let md = summary::table(&summary);
    println!("{md}");
    Ok(())
}
