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
//! The code is split by role: [`Args`] and its checks in `args.rs`, the thresholds and
//! their calibration check in `calibration.rs`, the detectors' statistics, Pd versus SNR
//! and the sweeps in `evaluation.rs`, and the CSV, SVG and Markdown outputs in
//! `figures.rs`; [`run`] chains them.

mod args;
mod calibration;
mod evaluation;
mod figures;

use anyhow::Result;
use faint_core::detect::crpf::CrpfConfig;
use faint_core::rng::derive_seed;

use crate::scenario::crpf::Othr;

pub use args::{Args, EchoPhase, PhaseModel, SceneWindow, PARTICLES};
pub use calibration::calibration;
pub use evaluation::{
    batch, run_detector, run_stats, ComparatorModel, Comparators, Likelihood, Stats, VarSource,
    METHODS,
};

/// `faint reproduce crpf`.
pub fn run(args: &Args) -> Result<()> {
    let a = args.effective()?;
    let grid = a.grid.clone();
    let sc = Othr {
        window: a.window.into(),
        random_phase: a.echo_phase == EchoPhase::Random,
        ..Othr::default()
    };
    let mut cfg = CrpfConfig::othr();
    cfg.model.window = sc.window;
    cfg.model.phase = a.phase.into();
    let tag = a.tag();
    let dir = a.out.join(&tag);
    crate::cli::out_dir(&dir)?;
    let t0 = std::time::Instant::now();

    // H0: thresholds and calibration.
    let h0 = batch(
        &sc,
        a.noise,
        None,
        a.particles,
        &cfg,
        a.h0_trials,
        derive_seed(a.seed, 0),
        a.comparator_model(&sc),
        "crpf H0",
    )?;
    let th = calibration::thresholds(&a, &h0)?;
    figures::h0(&dir, &a, &h0, &th)?;

    // H1: Pd versus SNR.
    let pd = evaluation::pd_vs_snr(&a, &sc, &cfg, &grid, &th.values)?;
    figures::pd_vs_snr(&dir, &a, &pd)?;

    // Table: SNR at Pd = 0.5 and 0.9.
    let snr_rows = evaluation::snr_at_pd_rows(&a, &pd.curves);
    let md = figures::table(
        &dir,
        &a,
        &snr_rows,
        &th,
        &pd.fd_err,
        t0.elapsed().as_secs_f64(),
    )?;

    if a.sweeps {
        let sw = evaluation::sweeps(&a, &sc, &cfg)?;
        figures::sweeps(&a, &sw)?;
    }
    println!("{md}");
    println!("written to {}", dir.display());
    Ok(())
}
