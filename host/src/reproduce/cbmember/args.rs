//! Command line of `faint reproduce cbmember`: the clap [`Args`], the set names, the
//! `--quick` preset and the checks run before any run.

use std::path::PathBuf;

use anyhow::{ensure, Result};

use serde::{Deserialize, Serialize};

use crate::cli;
use crate::instances::cbmember::MAX_PARTICLES;
use crate::shard::ShardArg;

/// Command-line arguments of `faint reproduce cbmember` (shard files keep them, without
/// `--shard`).
#[derive(clap::Args, Debug, Clone, Serialize, Deserialize)]
pub struct Args {
    /// Monte Carlo runs per SNR point, 1 to 1000000 (default 100; --quick: 2).
    #[arg(long)]
    pub runs: Option<usize>,
    /// SNR grid `a:b:step` in dB, eq. 19 peak-pixel SNR, values in [-60, 60], at most
    /// 1000 points (default -24:-8:2; --quick -14:-10:4).
    #[arg(long, allow_hyphen_values = true)]
    pub snr_db: Option<String>,
    /// SNR grid of the physical-generator ablation, as `--snr-db` (default -4:24:4;
    /// --quick 8:16:8).
    #[arg(long, allow_hyphen_values = true)]
    pub physical_snr_db: Option<String>,
    /// `L_max` values of Fig. 11, each 1 to 1500 (default 700,1000,1500; --quick 700).
    #[arg(long, value_delimiter = ',')]
    pub particles: Option<Vec<usize>>,
    /// Frames of the Table 3 timing run, 1 to 100 (default 100; --quick 10).
    #[arg(long)]
    pub timing_frames: Option<usize>,
    /// Output directory.
    #[arg(long, default_value = "out/cbmember")]
    pub out: PathBuf,
    /// Master seed.
    #[arg(long, default_value_t = 2024)]
    pub seed: u64,
    /// Sets to run (default all): base (Fig. 7, 8, 11), blades (Fig. 9), omega (Fig. 10),
    /// fa (target-free), ablation (B estimated, u8 map), merge (the narrower merge gate
    /// [2 m, 0.5 m/s]), known (micro-Doppler parameters known), physical, timing (Table 3).
    #[arg(long, value_delimiter = ',')]
    pub sets: Option<Vec<String>>,
    /// CI mode: small defaults (2 runs, two SNR points, 700 particles, 10 timing
    /// frames); never overrides a value given on the command line.
    #[arg(long)]
    pub quick: bool,
    /// A `curves.csv` of an earlier run whose sets not run now are merged into this run's
    /// CSV, plots and summary (e.g. the base set at 100 runs, the others at 50).
    #[arg(long)]
    pub previous: Option<PathBuf>,
    /// One shard of the runs (`--shard I/N`, see `faint merge`).
    #[command(flatten)]
    #[serde(skip)]
    pub shard: ShardArg,
}

/// Every set name accepted by `--sets`.
pub const SETS: [&str; 9] = [
    "base", "blades", "omega", "fa", "ablation", "merge", "known", "physical", "timing",
];

/// Arguments after `--quick` defaults.
#[derive(Debug, Clone)]
pub(super) struct Effective {
    pub(super) runs: usize,
    pub(super) snrs: Vec<f64>,
    pub(super) physical_snrs: Vec<f64>,
    pub(super) particles: Vec<usize>,
    pub(super) timing_frames: usize,
    pub(super) sets: Vec<String>,
}

impl Args {
    pub(super) fn effective(&self) -> Result<Effective> {
        let q = self.quick;
        let runs = cli::runs("--runs", self.runs.unwrap_or(if q { 2 } else { 100 }))?;
        let grid = self
            .snr_db
            .clone()
            .unwrap_or_else(|| if q { "-14:-10:4" } else { "-24:-8:2" }.into());
        let snrs = cli::grid("--snr-db", &grid)?;
        for &s in &snrs {
            cli::snr_db("--snr-db", s)?;
        }
        let pgrid = self
            .physical_snr_db
            .clone()
            .unwrap_or_else(|| if q { "8:16:8" } else { "-4:24:4" }.into());
        let physical_snrs = cli::grid("--physical-snr-db", &pgrid)?;
        for &s in &physical_snrs {
            cli::snr_db("--physical-snr-db", s)?;
        }
        let particles = self.particles.clone().unwrap_or_else(|| {
            if q {
                vec![700]
            } else {
                vec![700, 1000, 1500]
            }
        });
        ensure!(
            !particles.is_empty(),
            "--particles needs at least one value"
        );
        for &p in &particles {
            cli::count("--particles", p, 1..=MAX_PARTICLES)?;
        }
        let timing_frames = self.timing_frames.unwrap_or(if q { 10 } else { 100 });
        // The truth leaves the map after 100 frames.
        cli::count("--timing-frames", timing_frames, 1..=100)?;
        let sets = self
            .sets
            .clone()
            .unwrap_or_else(|| SETS.iter().map(|s| s.to_string()).collect());
        for s in &sets {
            ensure!(
                SETS.contains(&s.as_str()),
                "--sets: unknown set '{s}' (known: {})",
                SETS.join(", ")
            );
        }
        Ok(Effective {
            runs,
            snrs,
            physical_snrs,
            particles,
            timing_frames,
            sets,
        })
    }

    /// Checks every argument (one-line errors naming the argument) before any run.
    pub fn validate(&self) -> Result<()> {
        self.effective().map(|_| ())
    }
}
