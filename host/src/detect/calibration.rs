//! A calibration file (`cal.json`, written by `faint calibrate`) and its use by
//! `faint detect --calibration`: per-frame thresholds on a detector's own score at a
//! stated false-alarm probability.
//!
//! The thresholds hold for one detector, one configuration (the file keeps it and
//! `faint detect` refuses another) and runs of at most `run_frames` frames from the
//! detector's start: the law of most scores depends on the frame index (the existence
//! filters' early frames, PF-LRT's cumulative log-LR, the DP merit), so each frame index
//! `k` has its own threshold `t_k`. Frame `k >= burn_in` declares a detection when its
//! score is **strictly greater** than `t_k`; frames before the burn-in declare none.

use std::path::Path;

use anyhow::{bail, ensure, Context, Result};
use serde::{Deserialize, Serialize};

/// Version of the `cal.json` format this build reads and writes.
pub const FORMAT: u32 = 1;

/// Where the noise-only runs came from.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Source {
    /// A noise-only (or clutter-only) recording, cut into runs of `run_frames` frames.
    Recording {
        /// The file.
        file: String,
        /// Its frames.
        frames: usize,
    },
    /// Noise-only runs simulated from a model estimated on a file that may hold targets.
    Model {
        /// The file the model was estimated from.
        file: String,
        /// Its frames.
        frames: usize,
        /// The model, with its estimated parameters.
        model: NoiseModel,
    },
}

/// A target-free model of an input kind, estimated robustly (medians) from a file that
/// may hold targets; `faint calibrate --from-input` simulates its noise-only runs from it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "kebab-case", deny_unknown_fields)]
pub enum NoiseModel {
    /// Doppler frames: white complex Gaussian time samples, then the configuration's
    /// window and an `m`-point DFT. `bin_variance = median |z|^2 / ln 2` (the median of an
    /// exponential of mean `s` is `s ln 2`); time-sample variance
    /// `bin_variance / sum_n w_n^2`.
    WindowedComplexGaussian {
        /// Noise variance of one bin, `E |z_b|^2`.
        bin_variance: f64,
        /// The window of the configuration.
        window: faint_core::model::doppler::Window,
    },
    /// Power cubes and maps: independent exponential cells (the power of complex Gaussian
    /// noise), `mean = median / ln 2` over every cell of every frame.
    Exponential {
        /// Mean cell power.
        mean: f64,
    },
    /// Images: independent Gaussian pixels, `mean = median`, `std = 1.4826 MAD`.
    Gaussian {
        /// Mean pixel value.
        mean: f64,
        /// Standard deviation.
        std: f64,
    },
    /// Plot lists: a Poisson number of clutter plots per scan (mean = the median count
    /// per scan), uniform over the configuration's area, amplitudes drawn from the file's.
    PoissonClutter {
        /// Mean plots per scan.
        plots_per_scan: f64,
        /// `[x_min, x_max, y_min, y_max]` (m).
        area: [f32; 4],
        /// Amplitudes the draws come from.
        amplitudes: usize,
    },
}

/// The threshold of one frame index.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameThreshold {
    /// Frame index from the detector's start (0-based).
    pub frame: usize,
    /// `t_k` (a score, so `f32`: it reads back bit for bit); `None` is minus infinity:
    /// the noise runs reported nothing at this frame often enough to matter, so every
    /// detection counts.
    pub value: Option<f32>,
    /// Lower end of the distribution-free 95 % interval of the `(1 - pfa)` quantile.
    pub ci_low: Option<f32>,
    /// Upper end of that interval.
    pub ci_high: Option<f32>,
    /// Noise runs that reported any detection at this frame (before thresholding).
    pub reported: usize,
    /// Noise runs whose score exceeds `value` (strictly): the rate the threshold achieved
    /// on its own noise is `exceedances / runs`. It is `floor(runs pfa)` for a continuous
    /// score; a discrete score (a count, a merit on a grid) ties at the threshold and
    /// achieves less, which this field states (absent in files of older builds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exceedances: Option<usize>,
}

/// A calibration: thresholds of one detector and configuration at a false-alarm
/// probability.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// [`FORMAT`].
    pub format: u32,
    /// The binary that wrote it (`faint --version`).
    pub faint_version: String,
    /// Detector name (`faint detect --list`).
    pub detector: String,
    /// What the score is (`existence`, `log_lr`, `count`, `mass`, `merit`).
    pub score: String,
    /// False-alarm probability per frame: the probability that one frame `k >= burn_in`
    /// of a target-free run yields a detection.
    pub pfa: f64,
    /// Frames from the start that declare nothing.
    pub burn_in: usize,
    /// Frames of each noise run; also the longest input the thresholds cover.
    pub run_frames: usize,
    /// Noise runs behind each threshold.
    pub runs: usize,
    /// Where the runs came from.
    pub source: Source,
    /// Seed of the detector's random streams (run `r` uses `derive_seed(seed, r)`).
    pub seed: u64,
    /// The configuration file (JSON) the thresholds hold for.
    pub config: serde_json::Value,
    /// One threshold per frame index `burn_in..run_frames`.
    pub thresholds: Vec<FrameThreshold>,
}

impl Calibration {
    /// The false-alarm rate the thresholds achieved on their own noise runs, averaged
    /// over the frame indices (`exceedances / runs`); `None` for files of older builds.
    /// Below `pfa` for a discrete score, whose values tie at the threshold.
    pub fn achieved_pfa(&self) -> Option<f64> {
        let counts: Option<Vec<usize>> = self.thresholds.iter().map(|t| t.exceedances).collect();
        let counts = counts.filter(|c| !c.is_empty() && self.runs > 0)?;
        let total: usize = counts.iter().sum();
        Some(total as f64 / (counts.len() as f64 * self.runs as f64))
    }

    /// How many of the noise runs exceeded frame `k`'s threshold (`None` for a frame
    /// without a threshold or a file of an older build).
    pub fn exceedances_at(&self, k: usize) -> Option<usize> {
        self.thresholds
            .iter()
            .find(|t| t.frame == k)
            .and_then(|t| t.exceedances)
    }

    /// Reads and checks `path`.
    pub fn load(path: &Path) -> Result<Self> {
        let text = std::fs::read_to_string(path)
            .with_context(|| format!("--calibration {}: cannot read", path.display()))?;
        let cal: Calibration = serde_json::from_str(&text)
            .with_context(|| format!("--calibration {}: not a calibration file", path.display()))?;
        ensure!(
            cal.format == FORMAT,
            "--calibration {}: format {} (this build reads format {FORMAT})",
            path.display(),
            cal.format
        );
        ensure!(
            cal.pfa > 0.0 && cal.pfa < 1.0 && cal.burn_in <= cal.run_frames,
            "--calibration {}: inconsistent (pfa {}, burn-in {}, run frames {})",
            path.display(),
            cal.pfa,
            cal.burn_in,
            cal.run_frames
        );
        let want: Vec<usize> = (cal.burn_in..cal.run_frames).collect();
        let have: Vec<usize> = cal.thresholds.iter().map(|t| t.frame).collect();
        ensure!(
            want == have,
            "--calibration {}: thresholds for frames {}..{} expected",
            path.display(),
            cal.burn_in,
            cal.run_frames
        );
        Ok(cal)
    }

    /// Checks that the calibration holds for `detector` run with the configuration
    /// `config` on `frames` frames.
    pub fn check(&self, detector: &str, config: &serde_json::Value, frames: usize) -> Result<()> {
        ensure!(
            self.detector == detector,
            "--calibration: made for {}, not {detector}",
            self.detector
        );
        if &self.config != config {
            bail!(
                "--calibration: made with another configuration of {detector}; calibrate again with this --config"
            );
        }
        ensure!(
            frames <= self.run_frames,
            "--calibration: the input has {frames} frames, the thresholds cover runs of {}; calibrate with --run-frames {frames} or more",
            self.run_frames
        );
        Ok(())
    }

    /// True if a detection of `score` at frame `frame` is declared.
    pub fn declares(&self, frame: usize, score: f32) -> bool {
        match self.threshold(frame) {
            Threshold::BurnIn | Threshold::Beyond => false,
            Threshold::Any => !score.is_nan(),
            Threshold::Above(t) => f64::from(score) > t,
        }
    }

    /// The threshold of frame `frame`.
    pub fn threshold(&self, frame: usize) -> Threshold {
        if frame < self.burn_in {
            return Threshold::BurnIn;
        }
        match self.thresholds.get(frame - self.burn_in) {
            None => Threshold::Beyond,
            Some(t) => match t.value {
                None => Threshold::Any,
                Some(v) => Threshold::Above(f64::from(v)),
            },
        }
    }
}

/// The rule of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Threshold {
    /// Before the burn-in: nothing declared.
    BurnIn,
    /// Past the calibrated run length: nothing declared (`check` refuses such inputs).
    Beyond,
    /// Every detection is declared (the threshold is minus infinity).
    Any,
    /// A detection is declared when its score is greater.
    Above(f64),
}

impl Threshold {
    /// The threshold as a number for a table: `None` before the burn-in and past the end,
    /// minus infinity for [`Threshold::Any`].
    pub fn value(self) -> Option<f64> {
        match self {
            Threshold::BurnIn | Threshold::Beyond => None,
            Threshold::Any => Some(f64::NEG_INFINITY),
            Threshold::Above(t) => Some(t),
        }
    }
}
