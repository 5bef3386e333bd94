//! `faint reproduce crpf`: CRPF-TBD against PF-TBD, JOTT and PF-LRT on the `othr`
//! scenario (Lu, Wang, Zhang 2017, Fig. 1, 2, 4, 5).
//!
//! Every trial simulates one run of K = 32 frames and feeds the same frames to the four
//! detectors (each with its own random stream), giving five test statistics: CRPF-max
//! (`zeta_K`), CRPF-mean, PF-mean, JOTT-mean (`D_K`) and PF-LRT (`ln L_K`). Thresholds
//! come from the H0 runs; an independent half of the H0 runs checks the false-alarm
//! rate of the threshold set on the other half (calibration). The Gaussian comparators
//! use the per-bin noise variance estimated from the run's K frames.

use std::path::PathBuf;

use anyhow::{bail, ensure, Context, Result};
use faint_core::detect::bernoulli::BernoulliTbd;
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::detect::Detector;
use faint_core::model::doppler::{estimate_noise_variance, DopplerReport};
use faint_core::rng::{derive_seed, Rng};
use faint_core::statistic::{d_k, zeta_k};
use faint_core::Complex32;
use serde::Serialize;

use crate::io::{self, plot};
use crate::montecarlo::run_trials;
use crate::scenario::crpf::{Noise, Othr, Run};
use crate::stats::detection::{
    detection_rate, snr_at_pd, threshold_at_pfa, PdPoint, Proportion, Threshold,
};

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
    /// Small preset for CI: N = 100, 60 H1 runs per point, 400 H0 runs, Pfa 0.05,
    /// SNR 0:16:4, sweeps with 200 + 40 runs.
    #[arg(long)]
    pub quick: bool,
}

impl Args {
    fn effective(&self) -> Args {
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

/// Particle counts `faint reproduce crpf` is compiled for (see [`run_stats`]).
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

/// Names of the five test statistics, in [`Stats::values`] order.
pub const METHODS: [&str; 5] = ["CRPF-max", "CRPF-mean", "PF-mean", "JOTT-mean", "PF-LRT"];

/// Test statistics of one run.
#[derive(Debug, Clone, Copy, Serialize, Default)]
pub struct Stats {
    /// `zeta_K` of CRPF-TBD.
    pub crpf_max: f64,
    /// `D_K` of CRPF-TBD.
    pub crpf_mean: f64,
    /// `D_K` of PF-TBD.
    pub pf_mean: f64,
    /// `D_K` of JOTT.
    pub jott_mean: f64,
    /// `ln L_K` of PF-LRT.
    pub pf_lrt: f64,
    /// `zeta_K` of PF-TBD (Fig. 1).
    pub pf_max: f64,
    /// `zeta_K` of JOTT (Fig. 1).
    pub jott_max: f64,
    /// Mean |Doppler error| (Hz) of CRPF-TBD's mean-cost estimate over frames 14..=26
    /// where it exists (NaN if never, or under H0).
    pub crpf_fd_err: f64,
}

impl Stats {
    /// The five compared statistics, in [`METHODS`] order.
    pub fn values(&self) -> [f64; 5] {
        [
            self.crpf_max,
            self.crpf_mean,
            self.pf_mean,
            self.jott_mean,
            self.pf_lrt,
        ]
    }
}

/// Runs a detector over a run's frames; returns the per-frame reports.
pub fn run_detector<D: Detector<Frame = [Complex32], Report = DopplerReport> + ?Sized>(
    det: &mut D,
    run: &Run,
) -> Result<Vec<DopplerReport>> {
    let mut out = Vec::with_capacity(run.frames.len());
    faint_core::detect::run(det, run.frames.iter().map(|z| z.as_slice()), |_, _, r| {
        out.push(*r)
    })
    .map_err(|e| anyhow::anyhow!("{e}"))?;
    Ok(out)
}

fn doppler_error(reports: &[DopplerReport], run: &Run, band: f64) -> f64 {
    let mut s = 0.0;
    let mut n = 0usize;
    for (r, t) in reports.iter().zip(&run.truth).skip(13) {
        if let (Some(e), Some(t)) = (r.estimate, t) {
            let mut d = e[0] as f64 - t[0];
            d -= band * (d / band).round();
            s += d.abs();
            n += 1;
        }
    }
    if n == 0 {
        f64::NAN
    } else {
        s / n as f64
    }
}

fn stats_of<const N: usize>(
    run: &Run,
    crpf_cfg: &CrpfConfig,
    seed: u64,
    comparators: bool,
) -> Result<Stats> {
    let mut crpf = Box::new(CrpfTbd::<N>::new(*crpf_cfg, derive_seed(seed, 1))?);
    let rc = run_detector(crpf.as_mut(), run)?;
    let pe: Vec<f32> = rc.iter().map(|r| r.existence).collect();
    let mut st = Stats {
        crpf_max: zeta_k(&pe)? as f64,
        crpf_mean: d_k(&pe)? as f64,
        crpf_fd_err: doppler_error(&rc, run, 50.0),
        ..Stats::default()
    };
    if !comparators {
        return Ok(st);
    }
    let var = estimate_noise_variance(run.frames.iter().map(|f| f.as_slice()), 32)?;
    let g = GaussConfig {
        model: crpf_cfg.model,
        noise_var: var,
    };
    let mut pf = Box::new(PfTbd::<N>::new(g, derive_seed(seed, 2))?);
    let rp: Vec<f32> = run_detector(pf.as_mut(), run)?
        .iter()
        .map(|r| r.existence)
        .collect();
    drop(pf);
    let mut jott = Box::new(BernoulliTbd::<N>::new(g, derive_seed(seed, 3))?);
    let rj: Vec<f32> = run_detector(jott.as_mut(), run)?
        .iter()
        .map(|r| r.existence)
        .collect();
    drop(jott);
    let mut lrt = Box::new(PfLrt::<N>::new(g, derive_seed(seed, 4))?);
    let rl = run_detector(lrt.as_mut(), run)?;
    st.pf_mean = d_k(&rp)? as f64;
    st.pf_max = zeta_k(&rp)? as f64;
    st.jott_mean = d_k(&rj)? as f64;
    st.jott_max = zeta_k(&rj)? as f64;
    st.pf_lrt = rl.last().map(|r| r.log_lr as f64).unwrap_or(0.0);
    Ok(st)
}

/// Statistics of one run with `particles` particles (dispatch to the const generic).
pub fn run_stats(
    particles: usize,
    run: &Run,
    crpf_cfg: &CrpfConfig,
    seed: u64,
    comparators: bool,
) -> Result<Stats> {
    match particles {
        100 => stats_of::<100>(run, crpf_cfg, seed, comparators),
        250 => stats_of::<250>(run, crpf_cfg, seed, comparators),
        500 => stats_of::<500>(run, crpf_cfg, seed, comparators),
        1000 => stats_of::<1000>(run, crpf_cfg, seed, comparators),
        2000 => stats_of::<2000>(run, crpf_cfg, seed, comparators),
        4000 => stats_of::<4000>(run, crpf_cfg, seed, comparators),
        6000 => stats_of::<6000>(run, crpf_cfg, seed, comparators),
        n => bail!("unsupported particle count {n} (use 100, 250, 500, 1000, 2000, 4000, 6000)"),
    }
}

/// Runs `trials` Monte Carlo runs at `snr_db` (None = H0).
#[allow(clippy::too_many_arguments)]
pub fn batch(
    scenario: &Othr,
    noise: Noise,
    snr_db: Option<f64>,
    particles: usize,
    crpf_cfg: &CrpfConfig,
    trials: usize,
    master: u64,
    comparators: bool,
    label: &str,
) -> Result<Vec<Stats>> {
    run_trials(master, trials, label, |i, rng: &mut Rng| {
        let run = scenario.simulate(snr_db, noise, rng);
        run_stats(
            particles,
            &run,
            crpf_cfg,
            derive_seed(master ^ 0x5eed, i as u64),
            comparators,
        )
    })
    .into_iter()
    .collect()
}

#[derive(Debug, Serialize)]
struct PdRow {
    noise: Noise,
    particles: usize,
    method: &'static str,
    snr_db: f64,
    threshold: f64,
    k: usize,
    n: usize,
    pd: f64,
    lo: f64,
    hi: f64,
}

#[derive(Debug, Serialize)]
struct CalRow {
    noise: Noise,
    particles: usize,
    method: &'static str,
    pfa: f64,
    threshold_half_a: f64,
    false_alarms_half_b: usize,
    n_half_b: usize,
    pfa_half_b: f64,
    lo: f64,
    hi: f64,
    inside: bool,
    threshold_all: f64,
    threshold_ci_low: f64,
    threshold_ci_high: f64,
}

#[derive(Debug, Serialize)]
struct SnrRow {
    noise: Noise,
    particles: usize,
    method: &'static str,
    level: f64,
    snr_db: Option<f64>,
    lo_db: Option<f64>,
    hi_db: Option<f64>,
    delta_vs_crpf_max_db: Option<f64>,
}

#[derive(Debug, Serialize)]
struct SweepRow {
    parameter: &'static str,
    value: f64,
    method: &'static str,
    pfa: f64,
    threshold: f64,
    pd: f64,
    lo: f64,
    hi: f64,
}

/// Whether the false-alarm rate of half B at the threshold of half A is compatible with
/// the target (the target lies in the Clopper-Pearson interval of the observed rate).
pub fn calibration(h0: &[f64], pfa: f64) -> Result<(Threshold, Proportion)> {
    let half = h0.len() / 2;
    let t = threshold_at_pfa(&h0[..half], pfa)?;
    let p = detection_rate(&h0[half..], t.value);
    Ok((t, p))
}

/// `faint reproduce crpf`.
pub fn run(args: &Args) -> Result<()> {
    args.validate()?;
    let a = args.effective();
    let grid = parse_grid(&a.snr_db)?;
    let sc = Othr::default();
    let cfg = CrpfConfig::othr();
    let tag = format!("{:?}_n{}", a.noise, a.particles).to_lowercase();
    let dir = a.out.join(&tag);
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
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
        true,
        "crpf H0",
    )?;
    io::write_csv(dir.join("h0_stats.csv"), &h0)?;
    let mut thresholds = [0.0f64; 5];
    let mut cal_rows = Vec::new();
    for (m, name) in METHODS.iter().enumerate() {
        let v: Vec<f64> = h0.iter().map(|s| s.values()[m]).collect();
        let t = threshold_at_pfa(&v, a.pfa)?;
        thresholds[m] = t.value;
        let (ta, pb) = calibration(&v, a.pfa)?;
        cal_rows.push(CalRow {
            noise: a.noise,
            particles: a.particles,
            method: name,
            pfa: a.pfa,
            threshold_half_a: ta.value,
            false_alarms_half_b: pb.k,
            n_half_b: pb.n,
            pfa_half_b: pb.p,
            lo: pb.lo,
            hi: pb.hi,
            inside: pb.lo <= a.pfa && a.pfa <= pb.hi,
            threshold_all: t.value,
            threshold_ci_low: t.ci_low,
            threshold_ci_high: t.ci_high,
        });
    }
    io::write_csv(dir.join("calibration.csv"), &cal_rows)?;
    // Fig. 1: H0 histograms of zeta_K and D_K.
    let col = |f: fn(&Stats) -> f64| h0.iter().map(f).collect::<Vec<f64>>();
    plot::histogram(
        dir.join("fig1_h0_statistics.svg"),
        &format!("H0 existence statistics, N = {}, K = 32", a.particles),
        "statistic",
        &[
            ("CRPF-max".into(), col(|s| s.crpf_max)),
            ("CRPF-mean".into(), col(|s| s.crpf_mean)),
            ("PF-max".into(), col(|s| s.pf_max)),
            ("PF-mean".into(), col(|s| s.pf_mean)),
            ("JOTT-max".into(), col(|s| s.jott_max)),
            ("JOTT-mean".into(), col(|s| s.jott_mean)),
        ],
        50,
    )?;
    let pf_max_t = threshold_at_pfa(&col(|s| s.pf_max), a.pfa)?.value;
    let jott_max_t = threshold_at_pfa(&col(|s| s.jott_max), a.pfa)?.value;

    // H1: Pd versus SNR.
    let mut rows = Vec::new();
    let mut curves: Vec<Vec<PdPoint>> = vec![Vec::new(); 5];
    let mut fd_err = Vec::new();
    for (j, &snr) in grid.iter().enumerate() {
        let h1 = batch(
            &sc,
            a.noise,
            Some(snr),
            a.particles,
            &cfg,
            a.trials,
            derive_seed(a.seed, 100 + j as u64),
            true,
            &format!("crpf {snr} dB"),
        )?;
        for (m, name) in METHODS.iter().enumerate() {
            let v: Vec<f64> = h1.iter().map(|s| s.values()[m]).collect();
            let p = detection_rate(&v, thresholds[m]);
            curves[m].push(PdPoint { snr_db: snr, pd: p });
            rows.push(PdRow {
                noise: a.noise,
                particles: a.particles,
                method: name,
                snr_db: snr,
                threshold: thresholds[m],
                k: p.k,
                n: p.n,
                pd: p.p,
                lo: p.lo,
                hi: p.hi,
            });
        }
        let mut e: Vec<f64> = h1
            .iter()
            .map(|s| s.crpf_fd_err)
            .filter(|x| x.is_finite())
            .collect();
        e.sort_by(f64::total_cmp);
        fd_err.push((
            snr,
            e.get(e.len() / 2).copied().unwrap_or(f64::NAN),
            e.len(),
        ));
    }
    io::write_csv(dir.join("pd_vs_snr.csv"), &rows)?;
    let series: Vec<plot::Series> = METHODS
        .iter()
        .zip(&curves)
        .map(|(n, c)| plot::Series {
            name: n.to_string(),
            points: c.iter().map(|p| (p.snr_db, p.pd.p)).collect(),
        })
        .collect();
    let fig = if a.noise == Noise::Gaussian {
        "fig2"
    } else {
        "fig4"
    };
    plot::line_chart(
        dir.join(format!("{fig}_pd_vs_snr.svg")),
        &format!(
            "Pd vs SNR, {:?} noise, N = {}, Pfa = {}",
            a.noise, a.particles, a.pfa
        ),
        "SNR (dB, eq. 18)",
        "Pd",
        &series,
    )?;

    // Table: SNR at Pd = 0.5 and 0.9.
    let mut snr_rows = Vec::new();
    let mut md_rows = Vec::new();
    for level in [0.5, 0.9] {
        let reference = snr_at_pd(&curves[0], level).snr_db;
        for (m, name) in METHODS.iter().enumerate() {
            let s = snr_at_pd(&curves[m], level);
            let delta = match (s.snr_db, reference) {
                (Some(x), Some(r)) => Some(x - r),
                _ => None,
            };
            md_rows.push(vec![
                format!("{:?}", a.noise),
                a.particles.to_string(),
                name.to_string(),
                format!("{level}"),
                io::fmt_opt(s.snr_db, 2),
                format!("[{}, {}]", io::fmt_opt(s.lo_db, 2), io::fmt_opt(s.hi_db, 2)),
                io::fmt_opt(delta, 2),
            ]);
            snr_rows.push(SnrRow {
                noise: a.noise,
                particles: a.particles,
                method: name,
                level,
                snr_db: s.snr_db,
                lo_db: s.lo_db,
                hi_db: s.hi_db,
                delta_vs_crpf_max_db: delta,
            });
        }
    }
    io::write_csv(dir.join("snr_at_pd.csv"), &snr_rows)?;
    let mut md = format!(
        "# CRPF-TBD reproduction: {:?} noise, N = {}, Pfa = {}\n\n\
         {} H0 runs, {} H1 runs per SNR point, SNR grid {}, seed {}, {:.0} s.\n\n\
         ## SNR (dB, eq. 18) at Pd = 0.5 / 0.9 (interval: crossings of the 95 % \
         Clopper-Pearson band); delta = method minus CRPF-max\n\n",
        a.noise,
        a.particles,
        a.pfa,
        a.h0_trials,
        a.trials,
        a.snr_db,
        a.seed,
        t0.elapsed().as_secs_f64()
    );
    md += &io::markdown_table(
        &[
            "noise", "N", "method", "Pd", "SNR dB", "interval", "delta dB",
        ],
        &md_rows,
    );
    md += "\n\n## Calibration: threshold from H0 half A, false-alarm rate on half B\n\n";
    md += &io::markdown_table(
        &[
            "method",
            "threshold (A)",
            "FA on B",
            "rate",
            "95 % CI",
            "target inside",
        ],
        &cal_rows
            .iter()
            .map(|c| {
                vec![
                    c.method.to_string(),
                    format!("{:.4}", c.threshold_half_a),
                    format!("{}/{}", c.false_alarms_half_b, c.n_half_b),
                    format!("{:.5}", c.pfa_half_b),
                    format!("[{:.5}, {:.5}]", c.lo, c.hi),
                    c.inside.to_string(),
                ]
            })
            .collect::<Vec<_>>(),
    );
    md += &format!(
        "\n\nFig. 1: thresholds at Pfa {} of the max statistics: CRPF-max {:.4}, PF-max {:.4}, \
         JOTT-max {:.4}.\n\n## CRPF-TBD Doppler error (median over runs of the mean |error| \
         over frames 14-26, Hz)\n\n",
        a.pfa, thresholds[0], pf_max_t, jott_max_t
    );
    md += &io::markdown_table(
        &["SNR dB", "median |fd error| Hz", "runs with an estimate"],
        &fd_err
            .iter()
            .map(|(s, e, n)| vec![format!("{s}"), format!("{e:.3}"), n.to_string()])
            .collect::<Vec<_>>(),
    );
    md.push('\n');
    io::write_text(dir.join("table.md"), &md)?;

    if a.sweeps {
        sweeps(&a, &sc, &cfg)?;
    }
    println!("{md}");
    println!("written to {}", dir.display());
    Ok(())
}

/// Fig. 5: Pd of CRPF-max and CRPF-mean at 5 dB (Gaussian) over `r_th` and `lambda`.
fn sweeps(a: &Args, sc: &Othr, base: &CrpfConfig) -> Result<()> {
    let pfa = a.pfa.max(10.0 / a.sweep_h0_trials as f64);
    let mut rows = Vec::new();
    let mut series = vec![Vec::new(); 4];
    let configs: Vec<(&'static str, f64, CrpfConfig)> = (0..=8)
        .map(|i| {
            let r = 0.05 * i as f64;
            (
                "r_th",
                r,
                CrpfConfig {
                    r_th: r as f32,
                    ..*base
                },
            )
        })
        .chain((0..=5).map(|i| {
            let l = 0.2 * i as f64;
            (
                "lambda",
                l,
                CrpfConfig {
                    lambda: l as f32,
                    ..*base
                },
            )
        }))
        .collect();
    for (ci, (param, value, cfg)) in configs.iter().enumerate() {
        let seed = derive_seed(a.seed, 1000 + ci as u64);
        let h0 = batch(
            sc,
            Noise::Gaussian,
            None,
            a.particles,
            cfg,
            a.sweep_h0_trials,
            seed,
            false,
            &format!("sweep {param}={value:.2} H0"),
        )?;
        let h1 = batch(
            sc,
            Noise::Gaussian,
            Some(5.0),
            a.particles,
            cfg,
            a.sweep_trials,
            derive_seed(seed, 1),
            false,
            &format!("sweep {param}={value:.2} H1"),
        )?;
        for (mi, (method, f)) in [
            ("CRPF-max", (|s: &Stats| s.crpf_max) as fn(&Stats) -> f64),
            ("CRPF-mean", |s: &Stats| s.crpf_mean),
        ]
        .into_iter()
        .enumerate()
        {
            let t = threshold_at_pfa(&h0.iter().map(f).collect::<Vec<_>>(), pfa)?;
            let p = detection_rate(&h1.iter().map(f).collect::<Vec<_>>(), t.value);
            let si = if *param == "r_th" { mi } else { 2 + mi };
            series[si].push((*value, p.p));
            rows.push(SweepRow {
                parameter: param,
                value: *value,
                method,
                pfa,
                threshold: t.value,
                pd: p.p,
                lo: p.lo,
                hi: p.hi,
            });
        }
    }
    let dir = a.out.join(format!("sweeps_n{}", a.particles));
    io::write_csv(dir.join("fig5_sweeps.csv"), &rows)?;
    let names = ["CRPF-max", "CRPF-mean"];
    for (k, (param, xl)) in [("r_th", "r_th"), ("lambda", "lambda")].iter().enumerate() {
        plot::line_chart(
            dir.join(format!("fig5_{param}.svg")),
            &format!(
                "Pd at 5 dB vs {param} (Gaussian, N = {}, Pfa = {pfa})",
                a.particles
            ),
            xl,
            "Pd",
            &(0..2)
                .map(|mi| plot::Series {
                    name: names[mi].into(),
                    points: series[2 * k + mi].clone(),
                })
                .collect::<Vec<_>>(),
        )?;
    }
    Ok(())
}
