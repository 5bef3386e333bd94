//! `faint reproduce phd` (alias `psophd`): Pei et al. 2019 (PSO-PHD-TBD), Fig. 3-5 and Tables 2-4.
//!
//! Per SNR and Monte Carlo run, one truth and one sequence of 40 power cubes of the
//! `six-targets` preset; the three algorithms (PHD-TBD, PSO-PHD-TBD with K-means,
//! PSO-PHD-TBD with DBSCAN) run on the same cubes. Per frame: mean and standard
//! deviation over runs of the estimated count `N_hat` (Fig. 3-4, Table 2 = mean over
//! frames of the std), mean OSPA on positions with `c = 50 m`, `p = 2` (Fig. 5, Table 3),
//! and the filter's wall time per run (Table 4, cube simulation excluded).

#![allow(clippy::needless_range_loop)]

use faint_core::detect::Detector;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use faint_core::rng::Rng;
use serde::Serialize;

use crate::cli;
use crate::io::{self, plot::Series};
use crate::montecarlo::run_trials;
use crate::scenario::phd::{HostFilter, SixTargets, Variant};
use crate::stats::ospa::ospa;

/// Command-line arguments.
#[derive(clap::Args, Debug, Clone)]
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
}

/// What [`Args::effective`] settles: SNRs, runs, algorithms and the scene at each SNR.
struct Plan {
    snrs: Vec<f64>,
    runs: usize,
    variants: Vec<Variant>,
}

impl Args {
    /// The SNRs, runs and algorithms after the `--quick` defaults, with every argument
    /// checked.
    fn effective(&self) -> Result<Plan> {
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
    fn scene(&self, snr: f64) -> SixTargets {
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

    /// Checks every argument (one-line errors naming the argument) before any run.
    pub fn validate(&self) -> Result<()> {
        let plan = self.effective()?;
        // The filter's own validation, once per SNR, before any run.
        for &snr in &plan.snrs {
            let sc = self.scene(snr);
            for &v in &plan.variants {
                HostFilter::new(sc.config(v), 0)
                    .map_err(|e| anyhow::anyhow!("the options give an invalid filter: {e}"))?;
            }
        }
        Ok(())
    }
}

/// The paper's numbers: (Table 2 PHD-TBD, Table 2 PSO, Table 3 x3, Table 4 PHD, PSO-DBSCAN).
const PAPER: [(f64, [f64; 7]); 3] = [
    (9.0, [0.59, 0.47, 14.68, 9.43, 3.47, 12.49, 22.19]),
    (7.0, [1.00, 0.74, 15.79, 11.55, 4.88, 12.76, 25.73]),
    (5.0, [1.25, 0.93, 17.75, 15.60, 8.52, 12.85, 28.26]),
];

/// One run of one variant.
#[derive(Debug, Clone)]
struct RunResult {
    /// `N_hat` per frame.
    counts: Vec<usize>,
    ospa: Vec<f64>,
    seconds: f64,
}

/// Per-frame row of the CSV.
#[derive(Debug, Serialize)]
struct FrameRow {
    snr_db: f64,
    variant: &'static str,
    frame: usize,
    true_count: usize,
    mean_count: f64,
    std_count: f64,
    /// Mean over runs of `|N_hat - N_true|`.
    mean_abs_count_error: f64,
    mean_ospa: f64,
}

/// Summary row.
#[derive(Debug, Serialize)]
struct SummaryRow {
    snr_db: f64,
    variant: &'static str,
    runs: usize,
    mean_std_count: f64,
    mean_ospa_m: f64,
    /// Mean over frames and runs of `|N_hat - N_true|`.
    mean_abs_count_error: f64,
    /// Frames where every target is alive (the most true targets; frames 17-29 of the
    /// preset, all six alive): mean `N_hat` and mean OSPA.
    all_alive_mean_count: f64,
    /// See [`SummaryRow::all_alive_mean_count`].
    all_alive_mean_ospa_m: f64,
    seconds_per_run: f64,
    ms_per_frame: f64,
}

fn one_run(sc: &SixTargets, variants: &[Variant], seed_rng: &mut Rng) -> Result<Vec<RunResult>> {
    let mut truth_rng = seed_rng.fork(1);
    let mut cube_rng = seed_rng.fork(2);
    let truth = sc.truth(&mut truth_rng);
    let mut filters = Vec::new();
    for &v in variants {
        // Each algorithm's filter seed depends on the algorithm only (the paper's three
        // keep the seeds of earlier runs whatever `--variants` selects).
        let i = Variant::EVERY.iter().position(|&x| x == v).unwrap_or(0);
        let seed = seed_rng.fork(10 + i as u64).next_u64();
        filters.push(crate::instances::boxed::<HostFilter>(&sc.config(v), seed)?);
    }
    let mut res = vec![
        RunResult {
            counts: Vec::new(),
            ospa: Vec::new(),
            seconds: 0.0,
        };
        variants.len()
    ];
    let mut cube = Vec::new();
    let (c, p) = sc.ospa;
    for frame in &truth {
        sc.cube(frame, &mut cube_rng, &mut cube);
        let tr: Vec<[f64; 2]> = frame.iter().map(|t| [t.state[0], t.state[2]]).collect();
        for (f, r) in filters.iter_mut().zip(res.iter_mut()) {
            let t0 = Instant::now();
            let rep = f.step(&cube).map_err(|e| anyhow::anyhow!("{e}"))?;
            r.seconds += t0.elapsed().as_secs_f64();
            let est: Vec<[f64; 2]> = f
                .estimates()
                .iter()
                .map(|e| [e.state[0] as f64, e.state[2] as f64])
                .collect();
            r.counts.push(rep.n_hat);
            r.ospa.push(ospa(&est, &tr, c, p).distance);
        }
    }
    Ok(res)
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    let var = v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / n;
    (m, var.sqrt())
}

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
        let all: Vec<Result<Vec<RunResult>>> =
            run_trials(seed, runs, &label, |_, rng| one_run(&sc, &variants, rng));
        let all: Vec<Vec<RunResult>> = all.into_iter().collect::<Result<_>>()?;
        let truth_counts: Vec<usize> = (1..=sc.frames)
            .map(|k| {
                sc.targets
                    .iter()
                    .filter(|t| t.appear <= k && k <= t.disappear)
                    .count()
            })
            .collect();
        let mut count_series = vec![Series {
            name: "truth".into(),
            points: truth_counts
                .iter()
                .enumerate()
                .map(|(k, &n)| ((k + 1) as f64, n as f64))
                .collect(),
        }];
        let mut std_series = Vec::new();
        let mut ospa_series = Vec::new();
        let most = truth_counts.iter().copied().max().unwrap_or(0);
        for (vi, v) in variants.iter().enumerate() {
            let mut stds = Vec::new();
            let mut ospas = Vec::new();
            let mut errors = Vec::new();
            let (mut alive_count, mut alive_ospa, mut alive_frames) = (0.0, 0.0, 0usize);
            let mut cs = Vec::new();
            let mut ss = Vec::new();
            let mut os = Vec::new();
            for k in 0..sc.frames {
                let counts: Vec<f64> = all.iter().map(|r| r[vi].counts[k] as f64).collect();
                let o: Vec<f64> = all.iter().map(|r| r[vi].ospa[k]).collect();
                let (mc, sdc) = mean_std(&counts);
                let (mo, _) = mean_std(&o);
                let err: Vec<f64> = counts
                    .iter()
                    .map(|&c| (c - truth_counts[k] as f64).abs())
                    .collect();
                let (me, _) = mean_std(&err);
                if truth_counts[k] == most {
                    alive_count += mc;
                    alive_ospa += mo;
                    alive_frames += 1;
                }
                stds.push(sdc);
                ospas.push(mo);
                errors.push(me);
                cs.push(((k + 1) as f64, mc));
                ss.push(((k + 1) as f64, sdc));
                os.push(((k + 1) as f64, mo));
                frames_csv.push(FrameRow {
                    snr_db: snr,
                    variant: v.name(),
                    frame: k + 1,
                    true_count: truth_counts[k],
                    mean_count: mc,
                    std_count: sdc,
                    mean_abs_count_error: me,
                    mean_ospa: mo,
                });
            }
            let secs: Vec<f64> = all.iter().map(|r| r[vi].seconds).collect();
            let (ms, _) = mean_std(&secs);
            summary.push(SummaryRow {
                snr_db: snr,
                variant: v.name(),
                runs,
                mean_std_count: mean_std(&stds).0,
                mean_ospa_m: mean_std(&ospas).0,
                mean_abs_count_error: mean_std(&errors).0,
                all_alive_mean_count: alive_count / alive_frames.max(1) as f64,
                all_alive_mean_ospa_m: alive_ospa / alive_frames.max(1) as f64,
                seconds_per_run: ms,
                ms_per_frame: 1e3 * ms / sc.frames as f64,
            });
            count_series.push(Series {
                name: v.name().into(),
                points: cs,
            });
            std_series.push(Series {
                name: v.name().into(),
                points: ss,
            });
            ospa_series.push(Series {
                name: v.name().into(),
                points: os,
            });
        }
        let d = &args.out;
        io::plot::line_chart(
            d.join(format!("count_{snr}db.svg")),
            &format!("Mean estimated target count, {snr} dB, {runs} runs (Fig. 3)"),
            "frame",
            "count",
            &count_series,
        )?;
        io::plot::line_chart(
            d.join(format!("count_std_{snr}db.svg")),
            &format!("Std of the estimated count, {snr} dB, {runs} runs (Fig. 4)"),
            "frame",
            "std",
            &std_series,
        )?;
        io::plot::line_chart(
            d.join(format!("ospa_{snr}db.svg")),
            &format!("Mean OSPA (c = 50 m, p = 2), {snr} dB, {runs} runs (Fig. 5)"),
            "frame",
            "OSPA (m)",
            &ospa_series,
        )?;
        // Write what we have after every SNR (long runs can be inspected early).
        io::write_csv(d.join("frames.csv"), &frames_csv)?;
        io::write_csv(d.join("summary.csv"), &summary)?;
        io::write_text(d.join("table.md"), &table(&summary))?;
    }
    let md = table(&summary);
    println!("{md}");
    Ok(())
}

fn table(summary: &[SummaryRow]) -> String {
    let mut rows = Vec::new();
    for s in summary {
        let paper = PAPER.iter().find(|p| p.0 == s.snr_db).map(|p| p.1);
        let (p_std, p_ospa, p_time) = match (paper, s.variant) {
            (Some(p), "PHD-TBD") => (Some(p[0]), Some(p[2]), Some(p[5])),
            (Some(p), "PSO-PHD-TBD (K-means)") => (Some(p[1]), Some(p[3]), None),
            (Some(p), "PSO-PHD-TBD (DBSCAN)") => (Some(p[1]), Some(p[4]), Some(p[6])),
            _ => (None, None, None),
        };
        rows.push(vec![
            format!("{}", s.snr_db),
            s.variant.to_string(),
            s.runs.to_string(),
            format!("{:.2}", s.mean_std_count),
            io::fmt_opt(p_std, 2),
            format!("{:.2}", s.mean_ospa_m),
            io::fmt_opt(p_ospa, 2),
            format!("{:.2}", s.mean_abs_count_error),
            format!("{:.2}", s.all_alive_mean_count),
            format!("{:.2}", s.all_alive_mean_ospa_m),
            format!("{:.3}", s.seconds_per_run),
            io::fmt_opt(p_time, 2),
        ]);
    }
    io::markdown_table(
        &[
            "SNR (dB)",
            "algorithm",
            "runs",
            "mean std of count (ours)",
            "paper T2",
            "mean OSPA m (ours)",
            "paper T3",
            "mean abs count error",
            "count, all alive",
            "OSPA m, all alive",
            "s per 40-frame run (ours, 1 core)",
            "paper T4 (MATLAB)",
        ],
        &rows,
    )
}
