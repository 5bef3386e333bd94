//! `faint reproduce crpf`: CRPF-TBD against PF-TBD, JOTT and PF-LRT on the `othr`
//! scenario (Lu, Wang, Zhang 2017, Fig. 1, 2, 4, 5).
//!
//! Every trial simulates one run of K = 32 frames and feeds the same frames to the four
//! detectors (each with its own random stream), giving five test statistics: CRPF-max
//! (`zeta_K`), CRPF-mean, PF-mean, JOTT-mean (`D_K`) and PF-LRT (`ln L_K`). Thresholds
//! come from the H0 runs; an independent half of the H0 runs checks the false-alarm
//! rate of the threshold set on the other half (calibration). The Gaussian comparators
//! use the per-bin noise variance estimated from the run's K frames.
//!
//! The code is split by role: [`Args`] and its checks in `args.rs`, the comparators'
//! noise model in `comparators.rs`, the thresholds and their calibration check in
//! `calibration.rs`, the detectors' statistics, Pd versus SNR and the sweeps in
//! `evaluation.rs`, and the CSV, SVG and Markdown outputs in `outputs.rs`; [`run`] chains
//! them.

mod args;
mod calibration;
mod comparators;
mod evaluation;
mod outputs;

use std::path::Path;

use anyhow::Result;
use faint_core::detect::crpf::CrpfConfig;
use faint_core::rng::derive_seed;

use crate::shard::{self, Batch, Merged, Run, Shard};
use crate::simulate::crpf::{Noise, Othr};
use args::Settings;

pub use args::{Args, EchoPhase, PhaseModel, SceneWindow, PARTICLES};
pub use calibration::calibration;
pub use comparators::{ComparatorModel, Comparators, Likelihood, VarSource};
pub use evaluation::{batch, batch_range, run_detector, run_stats, Stats, METHODS};

/// One Monte Carlo batch of the reproduction: its key in shard files, its runs and how
/// they are drawn.
struct Spec {
    key: String,
    label: String,
    noise: Noise,
    snr_db: Option<f64>,
    cfg: CrpfConfig,
    trials: usize,
    master: u64,
    comparators: Comparators,
}

/// The scene and CRPF-TBD configuration of `a`.
fn scene(a: &Settings) -> (Othr, CrpfConfig) {
    let sc = Othr {
        window: a.window.into(),
        random_phase: a.echo_phase == EchoPhase::Random,
        ..Othr::default()
    };
    let mut cfg = CrpfConfig::othr();
    cfg.model.window = sc.window;
    cfg.model.phase = a.phase.into();
    (sc, cfg)
}

/// Every batch of the run, in order: the H0 runs, the H1 runs of each SNR point, then
/// (with the sweeps) each sweep configuration's H0 and H1 runs.
fn specs(a: &Settings, sc: &Othr, cfg: &CrpfConfig) -> Vec<Spec> {
    let cm = Comparators::from(a.comparator_model(sc));
    let mut v = vec![Spec {
        key: "h0".into(),
        label: "crpf H0".into(),
        noise: a.noise,
        snr_db: None,
        cfg: *cfg,
        trials: a.h0_trials,
        master: derive_seed(a.seed, 0),
        comparators: cm,
    }];
    for (j, &snr) in a.grid.iter().enumerate() {
        v.push(Spec {
            key: format!("snr {j}"),
            label: format!("crpf {snr} dB"),
            noise: a.noise,
            snr_db: Some(snr),
            cfg: *cfg,
            trials: a.trials,
            master: derive_seed(a.seed, 100 + j as u64),
            comparators: cm,
        });
    }
    if a.sweeps {
        for (ci, (param, value, c)) in evaluation::sweep_configs(cfg).into_iter().enumerate() {
            let seed = derive_seed(a.seed, 1000 + ci as u64);
            for (h, snr, trials, master) in [
                ("H0", None, a.sweep_h0_trials, seed),
                ("H1", Some(5.0), a.sweep_trials, derive_seed(seed, 1)),
            ] {
                v.push(Spec {
                    key: format!("sweep {ci} {h}"),
                    label: format!("sweep {param}={value:.2} {h}"),
                    noise: Noise::Gaussian,
                    snr_db: snr,
                    cfg: c,
                    trials,
                    master,
                    comparators: false.into(),
                });
            }
        }
    }
    v
}

/// The runs of every batch of `a` that `shard` holds (all of them for `None`).
fn collect(a: &Settings, shard: Option<Shard>) -> Result<Vec<Batch<Stats>>> {
    let (sc, cfg) = scene(a);
    specs(a, &sc, &cfg)
        .into_iter()
        .map(|s| {
            Batch::run(s.key, s.trials, shard, |range| {
                evaluation::batch_range(
                    &sc,
                    s.noise,
                    s.snr_db,
                    a.particles,
                    &s.cfg,
                    range,
                    s.master,
                    s.comparators,
                    &s.label,
                )
            })
        })
        .collect()
}

/// The outputs of the run from every batch's runs (in [`specs`] order); `seconds` gives
/// the run time `table.md` states (for merged shards, the sum of theirs).
fn analyse(a: &Settings, mut runs: Vec<Vec<Stats>>, seconds: impl Fn() -> f64) -> Result<()> {
    let (_, cfg) = scene(a);
    let dir = a.out.join(a.tag());
    crate::cli::out_dir(&dir)?;
    let mut rest = runs.split_off(1);
    let h0 = runs.pop().unwrap_or_default();
    let sweep_runs = rest.split_off(a.grid.len().min(rest.len()));
    let h1 = rest;

    // H0: thresholds and calibration.
    let th = calibration::thresholds(a, &h0)?;
    outputs::h0(&dir, a, &h0, &th)?;

    // H1: Pd versus SNR.
    let pd = evaluation::pd_vs_snr(a, &a.grid, &h1, &th.values)?;
    outputs::pd_vs_snr(&dir, a, &pd)?;

    // Table: SNR at Pd = 0.5 and 0.9.
    let snr_rows = evaluation::snr_at_pd_rows(a, &pd.curves);
    let md = outputs::table(&dir, a, &snr_rows, &th, &pd.fd_err, seconds())?;

    if a.sweeps {
        let mut pairs = Vec::new();
        let mut it = sweep_runs.into_iter();
        while let (Some(h0), Some(h1)) = (it.next(), it.next()) {
            pairs.push((h0, h1));
        }
        let sw = evaluation::sweeps(a, &cfg, &pairs)?;
        outputs::sweeps(a, &sw)?;
    }
    println!("{md}");
    println!("written to {}", dir.display());
    Ok(())
}

/// The command name in shard files.
pub const COMMAND: &str = "reproduce crpf";

/// `faint reproduce crpf`: the whole run, or with `--shard` (or a scheduler's array) one
/// shard's runs, written to `<out>/<tag>/shards/` for `faint merge`.
pub fn run(args: &Args) -> Result<()> {
    let a = args.effective()?;
    let shard = args.shard.resolve()?;
    let t0 = std::time::Instant::now();
    let batches = collect(&a, shard)?;
    match shard {
        None => analyse(&a, batches.into_iter().map(|b| b.results).collect(), || {
            t0.elapsed().as_secs_f64()
        }),
        Some(s) => {
            let dir = a.out.join(a.tag()).join("shards");
            let seconds = t0.elapsed().as_secs_f64();
            let path = shard::write(&dir, &Run::new(COMMAND, args)?, s, seconds, &batches)?;
            let runs: usize = batches.iter().map(|b| b.results.len()).sum();
            println!(
                "shard {s}: {runs} runs in {seconds:.1} s written to {}; merge with `faint merge {}`",
                path.display(),
                dir.display()
            );
            Ok(())
        }
    }
}

/// `faint merge` of `reproduce crpf` shards: the outputs of the unsharded run, written
/// where it writes them (under `out` if given, else the run's `--out`).
pub fn merge(m: &Merged, out: Option<&Path>) -> Result<()> {
    let mut args: Args = m.run.args()?;
    if let Some(o) = out {
        args.out = o.to_path_buf();
    }
    let a = args.effective()?;
    let (sc, cfg) = scene(&a);
    let keys: Vec<String> = specs(&a, &sc, &cfg).into_iter().map(|s| s.key).collect();
    analyse(&a, m.results(&keys)?, || m.seconds)
}
