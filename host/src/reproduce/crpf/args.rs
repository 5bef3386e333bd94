//! Command line of `faint reproduce crpf`: the clap [`Args`], the `--quick` preset, the
//! checks that reject a bad combination before any run, and the SNR grid parser.

use std::path::PathBuf;

use anyhow::{ensure, Context, Result};

use super::evaluation::{ComparatorModel, Likelihood, VarSource};
use crate::scenario::crpf::{Noise, Othr};
use faint_core::model::doppler::Window;

/// Analysis window of the scene and every detector's model (`--window`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum SceneWindow {
    /// Symmetric Hamming (the preset; neighbouring bins correlated).
    #[default]
    Hamming,
    /// Rectangular (independent bins).
    Rectangular,
}

impl From<SceneWindow> for Window {
    fn from(w: SceneWindow) -> Self {
        match w {
            SceneWindow::Hamming => Window::Hamming,
            SceneWindow::Rectangular => Window::Rectangular,
        }
    }
}

/// Command-line arguments of `faint reproduce crpf`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Particles per detector (1000, 2000, 4000, 6000; 100, 250, 500 for quick runs).
    #[arg(long, default_value_t = 1000)]
    pub particles: usize,
    /// H1 runs per SNR point.
    #[arg(long, default_value_t = 1000)]
    pub trials: usize,
    /// H0 runs for the thresholds (half set the threshold, half check it; all of them
    /// set the threshold used for Pd).
    #[arg(long, default_value_t = 20_000)]
    pub h0_trials: usize,
    /// Target false-alarm probability.
    #[arg(long, default_value_t = 0.001)]
    pub pfa: f64,
    /// Background noise.
    #[arg(long, value_enum, default_value_t = Noise::Gaussian)]
    pub noise: Noise,
    /// SNR grid `a:b:step` in dB (eq. 18).
    #[arg(long, default_value = "-2:14:2")]
    pub snr_db: String,
    /// Output directory.
    #[arg(long, default_value = "out/crpf")]
    pub out: PathBuf,
    /// Master seed.
    #[arg(long, default_value_t = 2017)]
    pub seed: u64,
    /// Run the r_th and lambda sweeps of Fig. 5 (CRPF only, Gaussian noise, SNR 5 dB).
    #[arg(long)]
    pub sweeps: bool,
    /// H0 runs per sweep configuration.
    #[arg(long, default_value_t = 4000)]
    pub sweep_h0_trials: usize,
    /// H1 runs per sweep configuration.
    #[arg(long, default_value_t = 500)]
    pub sweep_trials: usize,
    /// Per-bin noise variance of the Gaussian comparators: estimated from the run's
    /// frames (`run`, the preset) or the scene's true value (`true`).
    #[arg(long, value_enum, default_value_t = VarSource::Run)]
    pub comparator_var: VarSource,
    /// Likelihood of the Gaussian comparators: independent bins (the preset) or the
    /// window's bin covariance taken into account (`window`: frames whitened, see
    /// `faint_core::model::doppler::unwindow`).
    #[arg(long, value_enum, default_value_t = Likelihood::Independent)]
    pub comparator_likelihood: Likelihood,
    /// Analysis window of the scene and of every detector's model.
    #[arg(long, value_enum, default_value_t = SceneWindow::Hamming)]
    pub window: SceneWindow,
    /// Small preset for CI: N = 100, 60 H1 runs per point, 400 H0 runs, Pfa 0.05,
    /// SNR 0:16:4, sweeps with 200 + 40 runs.
    #[arg(long)]
    pub quick: bool,
}

impl Args {
    /// The arguments with the `--quick` preset applied.
    pub(super) fn effective(&self) -> Args {
        let mut a = self.clone();
        if a.quick {
            a.particles = 100;
            a.trials = 60;
            a.h0_trials = 400;
            a.pfa = 0.05;
            a.snr_db = "0:16:4".into();
            a.sweeps = true;
            a.sweep_h0_trials = 200;
            a.sweep_trials = 40;
        }
        a
    }

    /// The comparators' noise model for scene `sc`.
    pub fn comparator_model(&self, sc: &Othr) -> ComparatorModel {
        ComparatorModel {
            var: self.comparator_var,
            likelihood: self.comparator_likelihood,
            time_var: sc.noise_var,
        }
    }

    /// Output sub-directory: `<noise>_n<N>`, with `_var-true`, `_lik-window`, `_rect`
    /// for the non-preset comparator variance, likelihood and window.
    pub fn tag(&self) -> String {
        let mut t = format!("{:?}_n{}", self.noise, self.particles).to_lowercase();
        if self.comparator_var == VarSource::True {
            t += "_var-true";
        }
        if self.comparator_likelihood == Likelihood::Window {
            t += "_lik-window";
        }
        if self.window == SceneWindow::Rectangular {
            t += "_rect";
        }
        t
    }

    /// Checks every argument before any work is done (so a bad combination fails at
    /// once, not after the H0 runs): `--pfa` in `(0, 1)`; a supported `--particles`; at
    /// least one H1 trial; enough `--h0-trials` that the calibration's halves resolve
    /// `--pfa` (each half must hold at least `1 / pfa` runs); a valid `--snr-db` grid;
    /// with `--sweeps`, more than 10 sweep H0 runs and at least one sweep H1 run.
    pub fn validate(&self) -> Result<()> {
        let a = self.effective();
        ensure!(
            a.pfa > 0.0 && a.pfa < 1.0,
            "--pfa must lie in (0, 1), got {}",
            a.pfa
        );
        ensure!(
            PARTICLES.contains(&a.particles),
            "--particles {} is not supported (use {:?})",
            a.particles,
            PARTICLES
        );
        ensure!(a.trials >= 1, "--trials must be at least 1");
        let need = 2 * (1.0 / a.pfa).ceil() as usize;
        ensure!(
            a.h0_trials >= need,
            "--h0-trials {} cannot resolve --pfa {}: the threshold is checked on an \
             independent half of the H0 runs, so each half needs at least {} runs \
             (use --h0-trials {} or more)",
            a.h0_trials,
            a.pfa,
            need / 2,
            need
        );
        parse_grid(&a.snr_db)?;
        if a.sweeps {
            ensure!(
                a.sweep_h0_trials > 10,
                "--sweep-h0-trials must be more than 10 (the sweeps' Pfa is at least \
                 10 / sweep-h0-trials), got {}",
                a.sweep_h0_trials
            );
            ensure!(a.sweep_trials >= 1, "--sweep-trials must be at least 1");
        }
        Ok(())
    }
}

/// Particle counts `faint reproduce crpf` is compiled for (see [`run_stats`](super::run_stats)).
pub const PARTICLES: [usize; 7] = [100, 250, 500, 1000, 2000, 4000, 6000];

/// Parses `a:b:step` into the grid `a, a + step, ..., <= b`.
pub fn parse_grid(s: &str) -> Result<Vec<f64>> {
    let p: Vec<f64> = s
        .split(':')
        .map(|x| x.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .with_context(|| format!("SNR grid '{s}' is not a:b:step"))?;
    ensure!(p.len() == 3, "SNR grid '{s}' is not a:b:step");
    let (a, b, st) = (p[0], p[1], p[2]);
    ensure!(
        st > 0.0 && b >= a,
        "SNR grid '{s}' needs step > 0 and b >= a"
    );
    let n = ((b - a) / st + 1e-9).floor() as usize + 1;
    ensure!(n <= 1000, "SNR grid '{s}' has too many points");
    Ok((0..n).map(|i| a + i as f64 * st).collect())
}
