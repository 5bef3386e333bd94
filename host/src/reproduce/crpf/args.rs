//! Command line of `faint reproduce crpf`: the clap [`Args`], the `--quick` preset, the
//! checks that reject a bad combination before any run, and the SNR grid parser.

use std::path::PathBuf;

use anyhow::{ensure, Result};

use super::comparators::{ComparatorModel, Likelihood, VarSource};
use crate::cli;
use crate::shard::ShardArg;
use crate::simulate::crpf::{Noise, Othr};
use faint_core::detect::pf_tbd::BirthProposal;
use faint_core::model::doppler::{Phase, Window};
use serde::{Deserialize, Serialize};

/// Analysis window of the scene and every detector's model (`--window`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
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

/// Command-line arguments of `faint reproduce crpf`. `--quick` changes the defaults of
/// the arguments not given, never a given value. Shard files keep them as JSON
/// (without `--shard`).
#[derive(clap::Args, Debug, Clone, Serialize, Deserialize)]
pub struct Args {
    /// Particles per detector: 100, 250, 500, 1000, 2000, 4000 or 6000 [default: 1000;
    /// --quick: 100].
    #[arg(long)]
    pub particles: Option<usize>,
    /// H1 runs per SNR point, 1 to 1000000 [default: 1000; --quick: 60].
    #[arg(long)]
    pub trials: Option<usize>,
    /// H0 runs for the thresholds (half set the threshold, half check it; all of them
    /// set the threshold used for Pd), at least 2 / pfa, at most 1000000 [default: 20000;
    /// --quick: 400].
    #[arg(long)]
    pub h0_trials: Option<usize>,
    /// Target false-alarm probability, in (0, 1) [default: 0.001; --quick: 0.05].
    #[arg(long)]
    pub pfa: Option<f64>,
    /// Background noise.
    #[arg(long, value_enum, default_value_t = Noise::Gaussian)]
    pub noise: Noise,
    /// SNR grid `a:b:step` in dB (eq. 18), values in [-60, 60], at most 1000 points
    /// [default: -2:14:2; --quick: 0:16:4].
    #[arg(long, allow_hyphen_values = true)]
    pub snr_db: Option<String>,
    /// Output directory.
    #[arg(long, default_value = "out/crpf")]
    pub out: PathBuf,
    /// Master seed.
    #[arg(long, default_value_t = 2017)]
    pub seed: u64,
    /// Run the r_th and lambda sweeps of Fig. 5 (CRPF only, Gaussian noise, SNR 5 dB;
    /// always on with --quick).
    #[arg(long)]
    pub sweeps: bool,
    /// H0 runs per sweep configuration, 11 to 1000000 [default: 4000; --quick: 200].
    #[arg(long)]
    pub sweep_h0_trials: Option<usize>,
    /// H1 runs per sweep configuration, 1 to 1000000 [default: 500; --quick: 40].
    #[arg(long)]
    pub sweep_trials: Option<usize>,
    /// Per-bin noise variance of the Gaussian comparators: estimated from the run's
    /// frames (`run`, the preset) or the scene's true value (`true`).
    #[arg(long, value_enum, default_value_t = VarSource::Run)]
    pub comparator_var: VarSource,
    /// Likelihood of the Gaussian comparators: independent bins (the preset) or the
    /// window's bin covariance taken into account (`window`: frames whitened in the
    /// detectors' step, `GaussConfig::likelihood`).
    #[arg(long, value_enum, default_value_t = Likelihood::Independent)]
    pub comparator_likelihood: Likelihood,
    /// Analysis window of the scene and of every detector's model.
    #[arg(long, value_enum, default_value_t = SceneWindow::Hamming)]
    pub window: SceneWindow,
    /// The four detectors' phase model (`config.model.phase`): `zero` (eq. 17, the
    /// paper) or `unknown` (the cost minimised, the likelihood averaged over the phase).
    #[arg(long, value_enum, default_value_t = PhaseModel::Zero)]
    pub phase: PhaseModel,
    /// The simulated target's phase at each frame's start: `zero` (eq. 17, the paper)
    /// or `random` (uniform, independent per frame: independent dwells).
    #[arg(long, value_enum, default_value_t = EchoPhase::Zero)]
    pub echo_phase: EchoPhase,
    /// Birth proposal of PF-TBD and JOTT: `exact` (the preset: JOTT births in their exact
    /// proportion, PF-TBD's absent particles born at rate Pb) or `fixed-share:<s>` (a
    /// share s in (0, 1) of the particles proposed as births every frame, importance
    /// weights keeping the same law; faint_core::detect::pf_tbd::BirthProposal).
    #[arg(long, default_value = "exact")]
    pub birth_proposal: String,
    /// Small defaults for CI: N = 100, 60 H1 runs per point, 400 H0 runs, Pfa 0.05,
    /// SNR 0:16:4, sweeps with 200 + 40 runs; never overrides a value given.
    #[arg(long)]
    pub quick: bool,
    /// One shard of the runs (`--shard I/N`, see `faint merge`).
    #[command(flatten)]
    #[serde(skip)]
    pub shard: ShardArg,
}

/// The detectors' phase model (`--phase`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum PhaseModel {
    /// Zero at each frame's start (eq. 17; the presets).
    #[default]
    Zero,
    /// Unknown, independent per frame.
    Unknown,
}

impl From<PhaseModel> for Phase {
    fn from(p: PhaseModel) -> Self {
        match p {
            PhaseModel::Zero => Phase::Zero,
            PhaseModel::Unknown => Phase::Unknown,
        }
    }
}

/// The simulated echo's phase (`--echo-phase`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum EchoPhase {
    /// Zero at each frame's start (eq. 17; the paper's scene).
    #[default]
    Zero,
    /// Uniform, independent per frame.
    Random,
}

/// The arguments after the `--quick` defaults, checked.
#[derive(Debug, Clone)]
pub(super) struct Settings {
    pub(super) particles: usize,
    pub(super) trials: usize,
    pub(super) h0_trials: usize,
    pub(super) pfa: f64,
    pub(super) noise: Noise,
    pub(super) snr_db: String,
    pub(super) grid: Vec<f64>,
    pub(super) out: PathBuf,
    pub(super) seed: u64,
    pub(super) sweeps: bool,
    pub(super) sweep_h0_trials: usize,
    pub(super) sweep_trials: usize,
    pub(super) comparator_var: VarSource,
    pub(super) comparator_likelihood: Likelihood,
    pub(super) window: SceneWindow,
    pub(super) phase: PhaseModel,
    pub(super) echo_phase: EchoPhase,
    pub(super) birth: BirthProposal,
}

impl Args {
    /// The arguments with the `--quick` defaults applied, after [`validate`](Self::validate).
    pub(super) fn effective(&self) -> Result<Settings> {
        let q = self.quick;
        let pfa = cli::probability("--pfa", self.pfa.unwrap_or(if q { 0.05 } else { 0.001 }))?;
        let particles = self.particles.unwrap_or(if q { 100 } else { 1000 });
        ensure!(
            PARTICLES.contains(&particles),
            "--particles {particles} is not supported (use {PARTICLES:?})"
        );
        let trials = cli::runs("--trials", self.trials.unwrap_or(if q { 60 } else { 1000 }))?;
        let h0_trials = cli::runs(
            "--h0-trials",
            self.h0_trials.unwrap_or(if q { 400 } else { 20_000 }),
        )?;
        let need = 2 * (1.0 / pfa).ceil() as usize;
        ensure!(
            h0_trials >= need,
            "--h0-trials {h0_trials} cannot resolve --pfa {pfa}: the threshold is checked on an \
             independent half of the H0 runs, so each half needs at least {} runs \
             (use --h0-trials {need} or more)",
            need / 2,
        );
        let snr_db = self
            .snr_db
            .clone()
            .unwrap_or_else(|| if q { "0:16:4" } else { "-2:14:2" }.into());
        let grid = cli::grid("--snr-db", &snr_db)?;
        for &s in &grid {
            cli::snr_db("--snr-db", s)?;
        }
        let sweeps = self.sweeps || q;
        let sweep_h0_trials = cli::count(
            "--sweep-h0-trials",
            self.sweep_h0_trials.unwrap_or(if q { 200 } else { 4000 }),
            11..=cli::MAX_RUNS,
        )?;
        let sweep_trials = cli::runs(
            "--sweep-trials",
            self.sweep_trials.unwrap_or(if q { 40 } else { 500 }),
        )?;
        let birth = birth_proposal(&self.birth_proposal)?;
        Ok(Settings {
            particles,
            trials,
            h0_trials,
            pfa,
            noise: self.noise,
            snr_db,
            grid,
            out: self.out.clone(),
            seed: self.seed,
            sweeps,
            sweep_h0_trials,
            sweep_trials,
            comparator_var: self.comparator_var,
            comparator_likelihood: self.comparator_likelihood,
            window: self.window,
            phase: self.phase,
            echo_phase: self.echo_phase,
            birth,
        })
    }

    /// Checks every argument before any work is done (so a bad combination fails at
    /// once, not after the H0 runs): `--pfa` in `(0, 1)`; a supported `--particles`;
    /// run counts in `1..=1000000`; enough `--h0-trials` that the calibration's halves
    /// resolve `--pfa` (each half must hold at least `1 / pfa` runs); a valid `--snr-db`
    /// grid; more than 10 sweep H0 runs; a `--birth-proposal` of `exact` or
    /// `fixed-share:<s>` with `s` in (0, 1).
    pub fn validate(&self) -> Result<()> {
        self.effective().map(|_| ())
    }
}

impl Settings {
    /// The comparators' noise model for scene `sc`.
    pub(super) fn comparator_model(&self, sc: &Othr) -> ComparatorModel {
        ComparatorModel {
            var: self.comparator_var,
            likelihood: self.comparator_likelihood,
            time_var: sc.noise_var,
            birth: self.birth,
        }
    }

    /// Output sub-directory: `<noise>_n<N>`, with `_var-true`, `_lik-window`, `_rect`,
    /// `_phase-unknown`, `_echo-random`, `_birth-fs<s>` for the non-preset comparator
    /// variance, likelihood, window, phase model, echo phase and birth proposal.
    pub(super) fn tag(&self) -> String {
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
        if self.phase == PhaseModel::Unknown {
            t += "_phase-unknown";
        }
        if self.echo_phase == EchoPhase::Random {
            t += "_echo-random";
        }
        if let BirthProposal::FixedShare(s) = self.birth {
            t += &format!("_birth-fs{s}");
        }
        t
    }
}

/// Particle counts `faint reproduce crpf` is compiled for (see [`run_stats`](super::run_stats)).
pub use crate::instances::doppler::REPRODUCE_PARTICLES as PARTICLES;

/// `--birth-proposal`: `exact` or `fixed-share:<s>`, `s` finite in (0, 1) (the particle
/// count then gives `B = round(s N)`, clamped to `1..=N-1`).
fn birth_proposal(v: &str) -> Result<BirthProposal> {
    if v == "exact" {
        return Ok(BirthProposal::Exact);
    }
    let Some(share) = v.strip_prefix("fixed-share:") else {
        anyhow::bail!("--birth-proposal: '{v}' is neither 'exact' nor 'fixed-share:<s>'");
    };
    let s: f32 = share
        .parse()
        .map_err(|_| anyhow::anyhow!("--birth-proposal: '{v}': '{share}' is not a number"))?;
    ensure!(
        s.is_finite() && s > 0.0 && s < 1.0,
        "--birth-proposal: '{v}': the share must lie in (0, 1)"
    );
    Ok(BirthProposal::FixedShare(s))
}
