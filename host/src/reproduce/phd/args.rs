//! Command line of `faint reproduce phd`: the clap [`Args`], the `--quick` preset, the
//! ablation options applied to the preset scene and the checks run before any run.

use std::path::PathBuf;

use anyhow::Result;

use serde::{Deserialize, Serialize};

use crate::cli;
use crate::instances::phd::HostFilter;
use crate::shard::ShardArg;
use crate::simulate::phd::{SixTargets, Variant};
use faint_core::detect::phd::PhdConfig;

use super::cubes::Cubes;

/// Command-line arguments (shard files keep them, without `--shard`).
#[derive(clap::Args, Debug, Clone, Serialize, Deserialize)]
pub struct Args {
    /// SNRs in dB, each in [-60, 60] (default 9,7,5; --quick 9).
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true)]
    pub snr_db: Option<Vec<f64>>,
    /// Monte Carlo runs per SNR, 1 to 1000000 (paper and default: 100; --quick 2).
    #[arg(long)]
    pub runs: Option<usize>,
    /// Output directory.
    #[arg(long, default_value = "out/phd")]
    pub out: PathBuf,
    /// Master seed.
    #[arg(long, default_value_t = 2019)]
    pub seed: u64,
    /// CI mode: small defaults (2 runs at 9 dB only); never overrides a value given.
    #[arg(long)]
    pub quick: bool,
    /// Two-frame birth velocity (m/s, `pair_max_speed`): a birth particle's tangential
    /// velocity from its displacement to a birth cell of the frame before, when the
    /// speed is at most this, finite and >= 0; 0 (default) = off, `N(0, 40^2)` tangential
    /// velocity.
    #[arg(long, default_value_t = 0.0)]
    pub birth_pair_speed: f64,
    /// At most this many particles move in the swarm per frame (0 = every gated
    /// particle, the setting of the README's earlier tables); default: the preset's 512.
    #[arg(long)]
    pub swarm_cap: Option<usize>,
    /// Algorithms to run, comma-separated: phd-tbd, pso-phd-kmeans, pso-phd-dbscan (the
    /// paper's three, the default) and phd-tbd-dbscan (PHD-TBD with DBSCAN extraction, an
    /// ablation).
    #[arg(long, value_delimiter = ',')]
    pub variants: Option<Vec<String>>,
    /// Ablation: the filter's motion noise `q1` (preset 1), finite and > 0.
    #[arg(long)]
    pub filter_q1: Option<f64>,
    /// Ablation: birth mass per component and frame `Pb` (preset 0.02), in (0, 1).
    #[arg(long)]
    pub birth_mass: Option<f64>,
    /// Ablation: birth particles per frame (preset 1000), 1 to 4096.
    #[arg(long)]
    pub birth_particles: Option<usize>,
    /// Ablation: particles kept per estimated target (preset 1000), 1 to 8192 (the
    /// filter holds 8192 particles in all: more are clamped by the filter).
    #[arg(long)]
    pub particles_per_target: Option<usize>,
    /// Ablation: clutter normalisation `lambda_k` of eq. 20 (preset 1), finite and > 0.
    #[arg(long)]
    pub clutter_lambda: Option<f64>,
    /// Ablation: the filter's intensity scale in dB (default 0): the birth intensities
    /// `U[0.75 P, 1.25 P]` and the intensity floor `0.05 P` times `10^(X/10)`, X in
    /// [-60, 60] (the cubes keep the target power `P` of `--snr-db`).
    #[arg(long, allow_hyphen_values = true)]
    pub filter_intensity_db: Option<f64>,
    /// The cubes: `model` (the preset's, drawn from the filter's own model) or
    /// `physics` (the same targets rendered by the physics simulator: sinc response per
    /// axis, random phase per frame; same SNR, the peak-cell power of a target at a cell
    /// centre over the noise power). The filters are the same.
    #[arg(long, value_enum, default_value_t = Cubes::Model)]
    #[serde(default)]
    pub cubes: Cubes,
    /// One shard of the runs (`--shard I/N`, see `faint merge`).
    #[command(flatten)]
    #[serde(skip)]
    pub shard: ShardArg,
}

/// What [`Args::effective`] settles: SNRs, runs, algorithms and the scene at each SNR.
pub(super) struct Plan {
    pub(super) snrs: Vec<f64>,
    pub(super) runs: usize,
    pub(super) variants: Vec<Variant>,
}

impl Args {
    /// The SNRs, runs and algorithms after the `--quick` defaults, with every argument
    /// checked.
    pub(super) fn effective(&self) -> Result<Plan> {
        let q = self.quick;
        let speed = cli::finite("--birth-pair-speed", self.birth_pair_speed)?;
        anyhow::ensure!(
            speed >= 0.0,
            "--birth-pair-speed must be a speed >= 0 m/s, got {speed}"
        );
        let snrs =
            self.snr_db
                .clone()
                .unwrap_or_else(|| if q { vec![9.0] } else { vec![9.0, 7.0, 5.0] });
        anyhow::ensure!(!snrs.is_empty(), "--snr-db needs at least one value");
        for &s in &snrs {
            cli::snr_db("--snr-db", s)?;
        }
        let runs = cli::runs("--runs", self.runs.unwrap_or(if q { 2 } else { 100 }))?;
        let variants = match &self.variants {
            None => Variant::ALL.to_vec(),
            Some(keys) => {
                let mut v = Vec::new();
                for k in keys {
                    let found = Variant::EVERY.iter().find(|x| x.key() == k.trim());
                    let Some(&x) = found else {
                        anyhow::bail!(
                            "--variants: '{k}' is not one of phd-tbd, pso-phd-kmeans, pso-phd-dbscan, phd-tbd-dbscan"
                        );
                    };
                    anyhow::ensure!(!v.contains(&x), "--variants: '{k}' is given twice");
                    v.push(x);
                }
                anyhow::ensure!(!v.is_empty(), "--variants needs at least one algorithm");
                v
            }
        };
        let positive = |name: &str, x: Option<f64>| -> Result<()> {
            if let Some(x) = x {
                cli::finite(name, x)?;
                anyhow::ensure!(x > 0.0, "{name} must be > 0, got {x}");
            }
            Ok(())
        };
        positive("--filter-q1", self.filter_q1)?;
        positive("--clutter-lambda", self.clutter_lambda)?;
        if let Some(x) = self.filter_intensity_db {
            cli::snr_db("--filter-intensity-db", x)?;
        }
        if let Some(p) = self.birth_mass {
            cli::probability("--birth-mass", p)?;
        }
        if let Some(n) = self.birth_particles {
            cli::count("--birth-particles", n, 1..=4096)?;
        }
        if let Some(n) = self.particles_per_target {
            cli::count("--particles-per-target", n, 1..=8192)?;
        }
        Ok(Plan {
            snrs,
            runs,
            variants,
        })
    }

    /// The preset at `snr` with this run's options.
    pub(super) fn scene(&self, snr: f64) -> SixTargets {
        /// `*field = value` when the option was given.
        fn set<T: Copy>(field: &mut T, value: Option<T>) {
            if let Some(v) = value {
                *field = v;
            }
        }
        let mut sc = SixTargets::new(snr);
        sc.birth_pair_max_speed = self.birth_pair_speed;
        set(&mut sc.swarm_cap, self.swarm_cap);
        set(&mut sc.filter_q_motion, self.filter_q1);
        set(&mut sc.p_birth, self.birth_mass);
        set(&mut sc.birth_particles, self.birth_particles);
        set(&mut sc.particles_per_target, self.particles_per_target);
        set(&mut sc.clutter_lambda, self.clutter_lambda);
        sc
    }

    /// The filter of `variant` on scene `sc` with this run's options.
    pub(super) fn config(&self, sc: &SixTargets, variant: Variant) -> PhdConfig {
        let mut c = sc.config(variant);
        if let Some(x) = self.filter_intensity_db {
            let k = 10f64.powf(x / 10.0) as f32;
            c.birth.intensity = c.birth.intensity.map(|i| i * k);
            c.min_intensity *= k;
        }
        c
    }

    /// Checks every argument (one-line errors naming the argument) before any run.
    pub fn validate(&self) -> Result<()> {
        let plan = self.effective()?;
        // The filter's own validation, once per SNR, before any run.
        for &snr in &plan.snrs {
            let sc = self.scene(snr);
            for &v in &plan.variants {
                HostFilter::new(self.config(&sc, v), 0)
                    .map_err(|e| anyhow::anyhow!("the options give an invalid filter: {e}"))?;
            }
        }
        Ok(())
    }
}
