//! Command line of `faint reproduce mht`: the clap [`Args`], its value enums
//! ([`ModelChoice`], [`GammaFrom`], [`CalibRule`]), the checks run before any trial and
//! the run sizes with the `--quick` preset applied.

use std::path::PathBuf;

use serde::{Deserialize, Serialize};

use crate::cli;
use crate::instances::mht::{PLOTS, REPRODUCE_PLOTS, REPRODUCE_TRACKS, TRACKS};
use crate::shard::ShardArg;
use crate::stats::detection::proportion;

/// Command-line arguments (shard files keep them, without `--shard`).
#[derive(clap::Args, Debug, Clone, Serialize, Deserialize)]
pub struct Args {
    /// Clutter plots per scan, each in (0, 2000] (repeatable).
    #[arg(long = "lambda", num_args = 1.., default_values_t = vec![80.0, 164.0, 237.0, 316.0, 398.0])]
    pub lambda: Vec<f32>,
    /// Trials per lambda (with targets), 1 to 1000000 [default: 2000; --quick: 20].
    #[arg(long)]
    pub trials: Option<usize>,
    /// Clutter-only trials per lambda for the model-threshold check, 1 to 1000000
    /// [default: 500; --quick: 20].
    #[arg(long)]
    pub null_trials: Option<usize>,
    /// Wanted whole-grid Pfa for the thresholds, in (0, 1).
    #[arg(long, default_value_t = 1e-4)]
    pub pfa: f64,
    /// Master seed.
    #[arg(long, default_value_t = 2022)]
    pub seed: u64,
    /// Output folder.
    #[arg(long, default_value = "out/mht")]
    pub out: PathBuf,
    /// Use this `gamma_1` (1 to 255) for every lambda instead of the model's (e.g. the
    /// paper's 22).
    #[arg(long)]
    pub gamma1: Option<u8>,
    /// CI size: 20 trials, 20 null trials, 200 calibration and 200 check periods;
    /// never overrides a value given.
    #[arg(long)]
    pub quick: bool,
    /// Per-cell clutter law that sets `gamma_1`: `paper` (eq. 20-26 as published) or
    /// `compound` (chain-stacking law, the default: holds the wanted Pfa in simulation);
    /// `compound-nc` is the compound law with the paper's `N_c` chains (for comparison).
    #[arg(long, value_enum, default_value_t = ModelChoice::Compound)]
    pub model: ModelChoice,
    /// Where `gamma_1` comes from: `model` (the `--model` law's grid Pfa) or `sim`
    /// (clutter-only simulation: the smallest `gamma_1` whose rate of periods with a
    /// confirmed track meets `--pfa` by `--calib-rule`, see [`calibrate`](super::calibrate)).
    #[arg(long, value_enum, default_value_t = GammaFrom::Model)]
    pub gamma_from: GammaFrom,
    /// Clutter-only periods per lambda for `--gamma-from sim`, 1 to 1000000
    /// [default: 20000; --quick: 200].
    #[arg(long)]
    pub calib_periods: Option<usize>,
    /// Independent clutter-only periods per lambda that check the calibrated `gamma_1`,
    /// 0 (no check) to 1000000 [default: 10000; --quick: 200].
    #[arg(long)]
    pub calib_check: Option<usize>,
    /// Calibration rule: `point` (estimated rate `k / T <= pfa`) or `upper` (the
    /// Clopper-Pearson 95 % interval's upper end `<= pfa`; needs `T >~ 3.7 / pfa`).
    #[arg(long, value_enum, default_value_t = CalibRule::Point)]
    pub calib_rule: CalibRule,
    /// Smallest candidate `gamma_1` of the calibration (candidates below it are not
    /// simulated; a result at this floor is flagged), 1 to 255.
    #[arg(long, default_value_t = 3)]
    pub calib_min_gamma: u8,
    /// MHT-TBD's plot capacity per scan: 640 (the host's) or 512 (the STM32H743's, the
    /// firmware's `MhtTbd<512, 30, 256, 180, 32>`); plots, gated pairs and chains beyond
    /// it are skipped and counted. Also the calibration's detector.
    #[arg(long, default_value_t = PLOTS)]
    #[serde(default = "host_plots")]
    pub plots: usize,
    /// MHT-TBD's track capacity: 32 (the host's and the firmware's) or 16 (a smaller
    /// store, which costs Pd); peaks beyond it are dropped weakest first and counted.
    /// Also the calibration's detector.
    #[arg(long, default_value_t = TRACKS)]
    #[serde(default = "host_tracks")]
    pub tracks: usize,
    /// One shard of the trials (`--shard I/N`, see `faint merge`).
    #[command(flatten)]
    #[serde(skip)]
    pub shard: ShardArg,
}

fn host_plots() -> usize {
    PLOTS
}

fn host_tracks() -> usize {
    TRACKS
}

/// `--gamma-from` values.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum GammaFrom {
    /// The `--model` law.
    #[default]
    Model,
    /// Clutter-only simulation of the confirmed-false-track rate ([`calibrate`](super::calibrate)).
    Sim,
}

/// `--calib-rule` values: how a candidate `gamma_1` passes with `k` of `T` clutter-only
/// periods giving a confirmed track.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum CalibRule {
    /// `k / T <= pfa`.
    #[default]
    Point,
    /// Clopper-Pearson 95 % upper end `<= pfa` (one-sided 97.5 %).
    Upper,
}

impl CalibRule {
    /// Does `k` of `n` periods with a confirmed track pass at the wanted `pfa`?
    pub fn passes(self, k: u64, n: u64, pfa: f64) -> bool {
        match self {
            Self::Point => (k as f64) <= pfa * n as f64,
            Self::Upper => proportion(k as usize, n as usize).hi <= pfa,
        }
    }
}

/// `--model` values.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum ModelChoice {
    /// Eq. 20-26 as published.
    Paper,
    /// Compound law, chains from the censoring rule (default).
    #[default]
    Compound,
    /// Compound law with the paper's `N_c` clutter tracks.
    CompoundNc,
}

/// Run sizes after the `--quick` preset.
#[derive(Debug, Clone, Copy)]
pub(super) struct Sizes {
    /// Trials per lambda (with targets).
    pub(super) trials: usize,
    /// Clutter-only trials per lambda.
    pub(super) null_trials: usize,
    /// Clutter-only calibration periods per lambda (`--gamma-from sim`).
    pub(super) calib_periods: usize,
    /// Independent clutter-only check periods per lambda (`--gamma-from sim`).
    pub(super) calib_check: usize,
}

impl Args {
    /// Checks the arguments before any work is done (and warns when `--calib-rule upper`
    /// cannot reach `--pfa` with the calibration periods); returns the run sizes after
    /// the `--quick` defaults.
    pub(super) fn validate(&self) -> anyhow::Result<Sizes> {
        let args = self;
        let q = args.quick;
        cli::probability("--pfa", args.pfa)?;
        anyhow::ensure!(!args.lambda.is_empty(), "give at least one --lambda");
        for &l in &args.lambda {
            cli::finite("--lambda", l.into())?;
            anyhow::ensure!(
                l > 0.0 && l <= 2000.0,
                "--lambda must lie in (0, 2000] clutter plots per scan, got {l}"
            );
        }
        if let Some(g) = args.gamma1 {
            cli::count("--gamma1", g.into(), 1..=255)?;
        }
        cli::count("--calib-min-gamma", args.calib_min_gamma.into(), 1..=255)?;
        anyhow::ensure!(
            REPRODUCE_PLOTS.contains(&args.plots),
            "--plots must be one of {REPRODUCE_PLOTS:?} (the compiled-in capacities), got {}",
            args.plots
        );
        anyhow::ensure!(
            REPRODUCE_TRACKS.contains(&args.tracks),
            "--tracks must be one of {REPRODUCE_TRACKS:?} (the compiled-in capacities), got {}",
            args.tracks
        );
        anyhow::ensure!(
            !(args.gamma1.is_some() && args.gamma_from == GammaFrom::Sim),
            "--gamma1 and --gamma-from sim exclude each other"
        );
        let sizes = Sizes {
            trials: cli::runs("--trials", args.trials.unwrap_or(if q { 20 } else { 2000 }))?,
            null_trials: cli::runs(
                "--null-trials",
                args.null_trials.unwrap_or(if q { 20 } else { 500 }),
            )?,
            calib_periods: cli::runs(
                "--calib-periods",
                args.calib_periods.unwrap_or(if q { 200 } else { 20_000 }),
            )?,
            calib_check: cli::count(
                "--calib-check",
                args.calib_check.unwrap_or(if q { 200 } else { 10_000 }),
                0..=cli::MAX_RUNS,
            )?,
        };
        let calib_periods = sizes.calib_periods;
        if args.gamma_from == GammaFrom::Sim
            && args.calib_rule == CalibRule::Upper
            && (calib_periods as f64) * args.pfa < 3.7
        {
            eprintln!(
                "warning: --calib-rule upper with {calib_periods} periods cannot reach pfa {} (zero events give an upper bound ~3.7 / T): gamma_1 will be N + 1",
                args.pfa
            );
        }
        Ok(sizes)
    }
}
