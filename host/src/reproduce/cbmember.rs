//! `faint reproduce cbmember`: the rotor-UAV paper (*Weak targets detection and
//! estimation based on joint use of Doppler and micro-Doppler*, Journal of Radars, 2023):
//! CBMeMBer TBD with the joint Doppler / micro-Doppler model against the Doppler-only
//! baseline on the `rotor-uav` preset. Fig. 7 (Pd vs SNR), Fig. 8 (mean OSPA vs SNR),
//! Fig. 9 (blade count 2 / 3 / 4), Fig. 10 (rotor rate), Fig. 11 (particle counts),
//! Table 3 (time per frame), false alarms per frame from target-free runs, and the
//! ablations: the physical map generator (eq. 11 + slow-time FFT; preset filter and one
//! with `zeta_v` matched to the physical peak width), `B` estimated, the quantised `u8` map.
//!
//! Per SNR point and run: one truth and 40 maps; every filter of a set runs on the same
//! maps (set "base": joint at each `--particles` and at 1500, Doppler-only at 1500). Run
//! `i` of SNR point `j` uses `Rng::from_stream(derive_seed(seed, j), i)` in every set
//! (common random numbers across sets), so results are identical for any thread count.
//! Scores (preset): after a 5-frame burn-in a frame is a detection when a reported
//! component (existence > 0.5) is within 3 range bins and 1 m/s of the truth; Pd is over
//! (run, frame) pairs with a Clopper-Pearson 95 % interval (the frames of one run are
//! correlated, so the interval is optimistic); OSPA over (range m, velocity m/s),
//! `c = 5`, `p = 2`, averaged over all 40 frames (as the paper) and after the burn-in.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::{ensure, Context, Result};
use faint_core::detect::cbmember::{CbmemberConfig, Likelihood};
use faint_core::detect::Detector;
use faint_core::model::range_doppler::{quantise, Dequant, PointModel};
use faint_core::rng::{derive_seed, Rng};
use serde::Serialize;

use crate::cli;
use crate::instances::boxed;
use crate::io::{self, plot::Series};
use crate::montecarlo::run_trials;
use crate::scenario::cbmember::{HostFilter, HostFilterU8, MapKind, MapSource, RotorUav};
use crate::stats::detection::{proportion, snr_at_pd, PdPoint, Proportion};
use crate::stats::ospa::ospa;

/// Capacity of the host filter (particles per component).
pub const MAX_PARTICLES: usize = 1500;

/// Command-line arguments of `faint reproduce cbmember`.
#[derive(clap::Args, Debug, Clone)]
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
}

/// Every set name accepted by `--sets`.
pub const SETS: [&str; 9] = [
    "base", "blades", "omega", "fa", "ablation", "merge", "known", "physical", "timing",
];

/// Arguments after `--quick` defaults.
#[derive(Debug, Clone)]
struct Effective {
    runs: usize,
    snrs: Vec<f64>,
    physical_snrs: Vec<f64>,
    particles: Vec<usize>,
    timing_frames: usize,
    sets: Vec<String>,
}

impl Args {
    fn effective(&self) -> Result<Effective> {
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

/// The paper's numbers.
pub mod paper {
    /// Table 3 (MATLAB R2022b, AMD R4750U): seconds per frame, `(algorithm, L_max, s)`.
    pub const TABLE3: [(&str, usize, f64); 4] = [
        ("Doppler-only", 1500, 0.068),
        ("joint", 700, 0.066),
        ("joint", 1000, 0.101),
        ("joint", 1500, 0.143),
    ];
    /// Sensitivity gain of joint over Doppler-only at Pd 0.9-0.92 (dB).
    pub const GAIN_DB: f64 = 2.0;
    /// Mean OSPA level reached from about 0.5 dB (Fig. 8; units not stated).
    pub const OSPA_SETTLED: f64 = 0.1;
}

/// Input kind of a filter.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Input {
    Power,
    Quantised,
}

/// One filter of a set.
#[derive(Debug, Clone)]
struct FilterSpec {
    name: String,
    cfg: CbmemberConfig,
    input: Input,
}

/// Per run and filter.
#[derive(Debug, Clone, Copy, Default)]
struct RunStats {
    hits: usize,
    scored: usize,
    reported: usize,
    ospa_all: f64,
    ospa_burn: f64,
    err_r2: f64,
    err_v2: f64,
    n_err: usize,
}

/// One point of a curve (a CSV row).
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct Row {
    /// Set and curve.
    pub set: String,
    /// Curve name.
    pub curve: String,
    /// SNR (dB).
    pub snr_db: f64,
    /// Runs.
    pub runs: usize,
    /// Scored (run, frame) pairs.
    pub frames: usize,
    /// Detections among them.
    pub hits: usize,
    /// Pd.
    pub pd: f64,
    /// Clopper-Pearson 95 % interval.
    pub pd_lo: f64,
    /// Upper end.
    pub pd_hi: f64,
    /// Reported components per scored frame (target-free runs: false alarms per frame).
    pub reported_per_frame: f64,
    /// Mean OSPA over all frames.
    pub ospa: f64,
    /// Mean OSPA after the burn-in.
    pub ospa_after_burn_in: f64,
    /// RMSE of the matched component's range (m).
    pub rmse_range_m: f64,
    /// RMSE of its velocity (m/s).
    pub rmse_velocity_mps: f64,
}

fn one_run(sc: &RotorUav, filters: &[FilterSpec], rng: &mut Rng) -> Result<Vec<RunStats>> {
    let truth = sc.truth();
    let mut map_rng = rng.fork(1);
    let mut src = MapSource::new(sc);
    let mut power: Vec<Box<HostFilter>> = Vec::new();
    let mut quant: Vec<Box<HostFilterU8>> = Vec::new();
    for (k, f) in filters.iter().enumerate() {
        let seed = rng.fork(10 + k as u64).next_u64();
        let e = |e| anyhow::anyhow!("{}: {e}", f.name);
        match f.input {
            Input::Power => power.push(boxed::<HostFilter>(&f.cfg, seed).map_err(e)?),
            Input::Quantised => quant.push(boxed::<HostFilterU8>(&f.cfg, seed).map_err(e)?),
        }
    }
    let dq = Dequant::new(sc.filter.noise_var, sc.filter.quant_step);
    let mut stats = vec![RunStats::default(); filters.len()];
    let mut map = Vec::new();
    let mut qmap = Vec::new();
    let bin = sc.geometry().range_bin as f64;
    let (c, p) = sc.ospa;
    for (k, t) in truth.iter().enumerate() {
        src.power(sc, t, k, &mut map_rng, &mut map);
        if !quant.is_empty() {
            qmap.clear();
            qmap.extend(
                map.iter()
                    .map(|&z| quantise(z * dq.scale, sc.filter.quant_step)),
            );
        }
        let (mut ip, mut iq) = (0usize, 0usize);
        for (f, st) in filters.iter().zip(stats.iter_mut()) {
            let dets: Vec<[f64; 2]> = match f.input {
                Input::Power => {
                    let d = &mut power[ip];
                    ip += 1;
                    d.step(&map[..])
                        .map_err(|e| anyhow::anyhow!("{}: {e}", f.name))?;
                    d.detections()
                        .map(|x| [x.state()[0] as f64, x.state()[1] as f64])
                        .collect()
                }
                Input::Quantised => {
                    let d = &mut quant[iq];
                    iq += 1;
                    d.step(&qmap[..])
                        .map_err(|e| anyhow::anyhow!("{}: {e}", f.name))?;
                    d.detections()
                        .map(|x| [x.state()[0] as f64, x.state()[1] as f64])
                        .collect()
                }
            };
            let tr: Vec<[f64; 2]> = if sc.present {
                vec![[t.range, t.velocity]]
            } else {
                vec![]
            };
            let o = ospa(&dets, &tr, c, p).distance;
            st.ospa_all += o;
            if k < sc.burn_in {
                continue;
            }
            st.ospa_burn += o;
            st.scored += 1;
            st.reported += dets.len();
            if sc.present {
                let best = dets
                    .iter()
                    .filter(|d| {
                        (d[0] - t.range).abs() <= sc.gate[0] * bin
                            && (d[1] - t.velocity).abs() <= sc.gate[1]
                    })
                    .min_by(|a, b| {
                        let da = (a[0] - t.range).powi(2) + (a[1] - t.velocity).powi(2);
                        let db = (b[0] - t.range).powi(2) + (b[1] - t.velocity).powi(2);
                        da.total_cmp(&db)
                    });
                if let Some(d) = best {
                    st.hits += 1;
                    st.err_r2 += (d[0] - t.range).powi(2);
                    st.err_v2 += (d[1] - t.velocity).powi(2);
                    st.n_err += 1;
                }
            }
        }
    }
    Ok(stats)
}

/// Runs one set: for every SNR, `runs` runs of the scenario `make(snr)` with `filters`.
fn run_set(
    set: &str,
    snrs: &[f64],
    runs: usize,
    seed: u64,
    make: &dyn Fn(f64) -> RotorUav,
    filters: &dyn Fn(&RotorUav) -> Vec<FilterSpec>,
    pool: &rayon::ThreadPool,
) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    for (j, &snr) in snrs.iter().enumerate() {
        let sc = make(snr);
        let fs = filters(&sc);
        let label = format!("cbmember {set} {snr} dB");
        let all: Vec<Result<Vec<RunStats>>> = pool.install(|| {
            run_trials(derive_seed(seed, j as u64), runs, &label, |_, rng| {
                one_run(&sc, &fs, rng)
            })
        });
        let all: Vec<Vec<RunStats>> = all.into_iter().collect::<Result<_>>()?;
        for (k, f) in fs.iter().enumerate() {
            let mut s = RunStats::default();
            for r in &all {
                let x = r[k];
                s.hits += x.hits;
                s.scored += x.scored;
                s.reported += x.reported;
                s.ospa_all += x.ospa_all;
                s.ospa_burn += x.ospa_burn;
                s.err_r2 += x.err_r2;
                s.err_v2 += x.err_v2;
                s.n_err += x.n_err;
            }
            let pd = proportion(s.hits, s.scored);
            let n_err = s.n_err.max(1) as f64;
            rows.push(Row {
                set: set.to_string(),
                curve: f.name.clone(),
                snr_db: snr,
                runs,
                frames: s.scored,
                hits: s.hits,
                pd: pd.p,
                pd_lo: pd.lo,
                pd_hi: pd.hi,
                reported_per_frame: s.reported as f64 / s.scored.max(1) as f64,
                ospa: s.ospa_all / (runs * sc.frames) as f64,
                ospa_after_burn_in: s.ospa_burn / s.scored.max(1) as f64,
                rmse_range_m: if s.n_err > 0 {
                    (s.err_r2 / n_err).sqrt()
                } else {
                    f64::NAN
                },
                rmse_velocity_mps: if s.n_err > 0 {
                    (s.err_v2 / n_err).sqrt()
                } else {
                    f64::NAN
                },
            });
        }
    }
    Ok(rows)
}

fn joint(sc: &RotorUav, particles: usize) -> FilterSpec {
    FilterSpec {
        name: format!("joint {particles}"),
        cfg: sc.config(PointModel::Joint, particles),
        input: Input::Power,
    }
}

fn doppler(sc: &RotorUav, particles: usize) -> FilterSpec {
    FilterSpec {
        name: format!("Doppler-only {particles}"),
        cfg: sc.config(PointModel::DopplerOnly, particles),
        input: Input::Power,
    }
}

/// The filter with `zeta_v` matched to the physical generator's peak (about one FFT bin
/// plus the blades' smear within a CPI): `zeta_v = 0.2` m/s, exact likelihood (the
/// support is about 11 bins wide, narrower than a 16-bin block).
fn matched(mut f: FilterSpec) -> FilterSpec {
    f.cfg.spread.zeta_v = 0.2;
    f.cfg.likelihood = Likelihood::Exact;
    f.name = format!("{} (zeta_v 0.2)", f.name);
    f
}

/// Points of a curve.
fn curve(rows: &[Row], set: &str, name: &str) -> Vec<PdPoint> {
    rows.iter()
        .filter(|r| r.set == set && r.curve == name)
        .map(|r| PdPoint {
            snr_db: r.snr_db,
            pd: Proportion {
                k: r.hits,
                n: r.frames,
                p: r.pd,
                lo: r.pd_lo,
                hi: r.pd_hi,
            },
        })
        .collect()
}

fn series(rows: &[Row], set: &str, name: &str, label: &str, f: fn(&Row) -> f64) -> Series {
    Series {
        name: label.to_string(),
        points: rows
            .iter()
            .filter(|r| r.set == set && r.curve == name)
            .map(|r| (r.snr_db, f(r)))
            .collect(),
    }
}

/// Table 3 timing row.
#[derive(Debug, Clone, Serialize)]
pub struct TimingRow {
    /// Algorithm.
    pub algorithm: String,
    /// `L_max`.
    pub particles: usize,
    /// Frames timed.
    pub frames: usize,
    /// Mean particles updated per frame (births included).
    pub particles_per_frame: f64,
    /// Mean CPU time per frame of the filter's `step` (ms, one thread; wall time where
    /// the thread's CPU time is not available).
    pub ms_per_frame: f64,
    /// The paper's (s).
    pub paper_s: Option<f64>,
    /// Paper / ours.
    pub speed_up: Option<f64>,
}

/// CPU time of this thread in ns (Linux `/proc/thread-self/schedstat`), or None.
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

fn timing(frames: usize, seed: u64) -> Result<Vec<TimingRow>> {
    let mut sc = RotorUav::new(-10.0);
    sc.frames = frames;
    let truth = sc.truth();
    let mut out = Vec::new();
    for (algo, model, particles) in [
        ("Doppler-only", PointModel::DopplerOnly, 1500usize),
        ("joint", PointModel::Joint, 700),
        ("joint", PointModel::Joint, 1000),
        ("joint", PointModel::Joint, 1500),
    ] {
        let mut rng = Rng::from_stream(seed, 77);
        let mut src = MapSource::new(&sc);
        let mut f = boxed::<HostFilter>(&sc.config(model, particles), seed)?;
        let mut map = Vec::new();
        let mut secs = 0.0;
        let mut parts = 0usize;
        for (k, t) in truth.iter().enumerate() {
            src.power(&sc, t, k, &mut rng, &mut map);
            let (t0, c0) = (Instant::now(), thread_cpu_ns());
            let r = f.step(&map[..]).map_err(|e| anyhow::anyhow!("{e}"))?;
            // Thread CPU time where Linux gives it (a shared machine's waits for a core
            // are not counted), else wall time.
            secs += match (c0, thread_cpu_ns()) {
                (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
                _ => t0.elapsed().as_secs_f64(),
            };
            parts += r.particles;
        }
        let ms = 1e3 * secs / frames as f64;
        let paper = paper::TABLE3
            .iter()
            .find(|p| p.0 == algo && p.1 == particles)
            .map(|p| p.2);
        out.push(TimingRow {
            algorithm: algo.to_string(),
            particles,
            frames,
            particles_per_frame: parts as f64 / frames as f64,
            ms_per_frame: ms,
            paper_s: paper,
            speed_up: paper.map(|p| 1e3 * p / ms),
        });
    }
    Ok(out)
}

fn fmt_db(x: Option<f64>) -> String {
    io::fmt_opt(x, 2)
}

/// Runs the reproduction.
pub fn run(args: &Args) -> Result<()> {
    let e = args.effective()?;
    let pool = crate::montecarlo::pool();
    let want = |s: &str| e.sets.iter().any(|x| x == s);
    let d = &args.out;
    cli::out_dir(d)?;
    let previous: Vec<Row> = match &args.previous {
        Some(p) => {
            let mut r = csv::Reader::from_path(p)
                .with_context(|| format!("--previous: cannot read {}", p.display()))?;
            r.deserialize()
                .collect::<std::result::Result<_, _>>()
                .with_context(|| format!("--previous: {} is not a curves.csv", p.display()))?
        }
        None => Vec::new(),
    };
    let mut rows: Vec<Row> = Vec::new();
    let mut fig11: Vec<usize> = e.particles.clone();
    fig11.sort_unstable();
    fig11.dedup();
    let save = |rows: &[Row]| -> Result<()> { io::write_csv(d.join("curves.csv"), rows) };

    if want("base") {
        let parts = fig11.clone();
        rows.extend(run_set(
            "base",
            &e.snrs,
            e.runs,
            args.seed,
            &RotorUav::new,
            &|sc| {
                let mut v = vec![joint(sc, 1500), doppler(sc, 1500)];
                v.extend(parts.iter().filter(|&&p| p != 1500).map(|&p| joint(sc, p)));
                v
            },
            pool,
        )?);
        save(&rows)?;
    }
    if want("blades") {
        for b in [3u32, 4] {
            rows.extend(run_set(
                &format!("blades {b}"),
                &e.snrs,
                e.runs,
                args.seed,
                &|s| {
                    let mut sc = RotorUav::new(s);
                    sc.blades = b;
                    sc.filter.blades = b;
                    sc
                },
                &|sc| vec![joint(sc, 1500)],
                pool,
            )?);
        }
        save(&rows)?;
    }
    if want("omega") {
        for w in [0.04, 0.08] {
            rows.extend(run_set(
                &format!("omega {w} pi"),
                &e.snrs,
                e.runs,
                args.seed,
                &|s| {
                    let mut sc = RotorUav::new(s);
                    sc.omega = w * std::f64::consts::PI;
                    sc
                },
                &|sc| vec![joint(sc, 1500)],
                pool,
            )?);
        }
        save(&rows)?;
    }
    if want("fa") {
        rows.extend(run_set(
            "target-free",
            &e.snrs,
            e.runs,
            args.seed ^ 0xFA,
            &|s| {
                let mut sc = RotorUav::new(s);
                sc.present = false;
                sc
            },
            &|sc| vec![joint(sc, 1500), doppler(sc, 1500)],
            pool,
        )?);
        save(&rows)?;
    }
    if want("ablation") {
        rows.extend(run_set(
            "ablation",
            &e.snrs,
            e.runs,
            args.seed,
            &RotorUav::new,
            &|sc| {
                let mut est = joint(sc, 1500);
                est.cfg.estimate_blades = true;
                est.name = "joint 1500 B estimated".into();
                let mut q = joint(sc, 1500);
                q.input = Input::Quantised;
                q.name = "joint 1500 u8 map".into();
                vec![est, q]
            },
            pool,
        )?);
        save(&rows)?;
    }
    if want("merge") {
        // The narrower merge gate of the first runs, [2 m, 0.5 m/s]: a birth confirmed
        // in one frame 2-3 m behind the receding target is a second report.
        rows.extend(run_set(
            "merge",
            &e.snrs,
            e.runs,
            args.seed,
            &RotorUav::new,
            &|sc| {
                let narrow = |mut f: FilterSpec| {
                    f.cfg.merge_gate = [2.0, 0.5];
                    f.name = format!("{} merge gate 2 m 0.5 mps", f.name);
                    f
                };
                vec![narrow(joint(sc, 1500)), narrow(doppler(sc, 1500))]
            },
            pool,
        )?);
        save(&rows)?;
    }
    if want("known") {
        // The paper's comparison assumes the micro-Doppler parameters known: births with
        // the true V, omega and phase (referenced to frame 0), no V / omega noise.
        rows.extend(run_set(
            "known",
            &e.snrs,
            e.runs,
            args.seed,
            &RotorUav::new,
            &|sc| {
                let mut f = joint(sc, 1500);
                let b = &mut f.cfg.birth;
                b.blade_speed = [sc.blade_speed as f32; 2];
                b.omega = [sc.omega as f32; 2];
                b.theta = [sc.theta0 as f32; 2];
                b.phase_from_frame0 = true;
                f.cfg.process.blade_speed = 0.0;
                f.cfg.process.omega = 0.0;
                f.name = "joint 1500 micro-Doppler known".into();
                vec![f]
            },
            pool,
        )?);
        save(&rows)?;
    }
    if want("physical") {
        rows.extend(run_set(
            "physical",
            &e.physical_snrs,
            e.runs,
            args.seed,
            &|s| {
                let mut sc = RotorUav::new(s);
                sc.map = MapKind::Physical;
                sc
            },
            &|sc| {
                vec![
                    joint(sc, 1500),
                    doppler(sc, 1500),
                    matched(joint(sc, 1500)),
                    matched(doppler(sc, 1500)),
                ]
            },
            pool,
        )?);
        save(&rows)?;
    }
    let timing_rows = if want("timing") {
        let t = timing(e.timing_frames, args.seed)?;
        io::write_csv(d.join("table3.csv"), &t)?;
        t
    } else {
        Vec::new()
    };
    // Earlier sets that this run did not redo.
    let ran: Vec<String> = rows.iter().map(|r| r.set.clone()).collect();
    rows.extend(previous.into_iter().filter(|r| !ran.contains(&r.set)));
    save(&rows)?;
    plots(d, &rows, &fig11)?;
    let md = summary(&rows, &timing_rows);
    io::write_text(d.join("summary.md"), &md)?;
    println!("{md}");
    Ok(())
}

fn plots(d: &std::path::Path, rows: &[Row], fig11: &[usize]) -> Result<()> {
    let pd = |r: &Row| r.pd;
    // Runs per point of a set (the sets of a merged run can differ).
    let n = |set: &str| {
        rows.iter()
            .filter(|r| r.set == set)
            .map(|r| r.runs)
            .max()
            .unwrap_or(0)
    };
    let runs = n("base");
    let has = |set: &str| rows.iter().any(|r| r.set == set);
    if has("base") {
        io::plot::line_chart(
            d.join("fig7_pd.svg"),
            &format!("Fig. 7: Pd vs SNR, {runs} runs per point"),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(
                    rows,
                    "base",
                    "joint 1500",
                    "joint (Doppler + micro-Doppler)",
                    pd,
                ),
                series(rows, "base", "Doppler-only 1500", "Doppler-only", pd),
            ],
        )?;
        io::plot::line_chart(
            d.join("fig8_ospa.svg"),
            &format!("Fig. 8: mean OSPA (range m, velocity m/s; c = 5, p = 2), {runs} runs"),
            "SNR (dB, eq. 19)",
            "mean OSPA",
            &[
                series(rows, "base", "joint 1500", "joint", |r| r.ospa),
                series(rows, "base", "Doppler-only 1500", "Doppler-only", |r| {
                    r.ospa
                }),
                series(rows, "base", "joint 1500", "joint, after burn-in", |r| {
                    r.ospa_after_burn_in
                }),
            ],
        )?;
        let mut s: Vec<Series> = fig11
            .iter()
            .map(|&p| {
                series(
                    rows,
                    "base",
                    &format!("joint {p}"),
                    &format!("joint {p}"),
                    pd,
                )
            })
            .collect();
        s.push(series(
            rows,
            "base",
            "Doppler-only 1500",
            "Doppler-only 1500",
            pd,
        ));
        io::plot::line_chart(
            d.join("fig11_particles.svg"),
            &format!("Fig. 11: Pd vs SNR by particle count, {runs} runs"),
            "SNR (dB, eq. 19)",
            "Pd",
            &s,
        )?;
    }
    if has("blades 3") {
        io::plot::line_chart(
            d.join("fig9_blades.svg"),
            &format!(
                "Fig. 9: Pd vs SNR by blade count (joint 1500), {} runs (B = 2: {runs})",
                n("blades 3")
            ),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(rows, "base", "joint 1500", "B = 2", pd),
                series(rows, "blades 3", "joint 1500", "B = 3", pd),
                series(rows, "blades 4", "joint 1500", "B = 4", pd),
            ],
        )?;
    }
    if has("omega 0.04 pi") {
        io::plot::line_chart(
            d.join("fig10_omega.svg"),
            &format!(
                "Fig. 10: Pd vs SNR by rotor rate (joint 1500), {} runs (0.06 pi: {runs})",
                n("omega 0.04 pi")
            ),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(rows, "omega 0.04 pi", "joint 1500", "omega = 0.04 pi", pd),
                series(rows, "base", "joint 1500", "omega = 0.06 pi", pd),
                series(rows, "omega 0.08 pi", "joint 1500", "omega = 0.08 pi", pd),
            ],
        )?;
    }
    if has("ablation") {
        io::plot::line_chart(
            d.join("ablation_pd.svg"),
            &format!(
                "Ablations: B estimated, u8 map (joint 1500), {} runs (base: {runs})",
                n("ablation")
            ),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(rows, "base", "joint 1500", "joint (f32 map, B known)", pd),
                series(
                    rows,
                    "ablation",
                    "joint 1500 B estimated",
                    "B estimated",
                    pd,
                ),
                series(rows, "ablation", "joint 1500 u8 map", "u8 map", pd),
                series(rows, "base", "Doppler-only 1500", "Doppler-only", pd),
            ],
        )?;
    }
    if has("known") {
        io::plot::line_chart(
            d.join("known_pd.svg"),
            &format!(
                "Micro-Doppler known (the paper's assumption): Pd, {} runs (base: {runs})",
                n("known")
            ),
            "SNR (dB, eq. 19)",
            "Pd",
            &[
                series(
                    rows,
                    "known",
                    "joint 1500 micro-Doppler known",
                    "joint, V / omega / theta known",
                    pd,
                ),
                series(
                    rows,
                    "base",
                    "joint 1500",
                    "joint, V / omega / theta estimated",
                    pd,
                ),
                series(rows, "base", "Doppler-only 1500", "Doppler-only", pd),
            ],
        )?;
    }
    if has("merge") {
        io::plot::line_chart(
            d.join("merge_ospa.svg"),
            &format!("Merge gate: mean OSPA, {} runs (base: {runs})", n("merge")),
            "SNR (dB, eq. 19)",
            "mean OSPA",
            &[
                series(
                    rows,
                    "base",
                    "joint 1500",
                    "joint, gate [3 m, 5 m/s] (preset)",
                    |r| r.ospa,
                ),
                series(
                    rows,
                    "merge",
                    "joint 1500 merge gate 2 m 0.5 mps",
                    "joint, gate [2 m, 0.5 m/s]",
                    |r| r.ospa,
                ),
                series(
                    rows,
                    "base",
                    "Doppler-only 1500",
                    "Doppler-only, gate [3 m, 5 m/s] (preset)",
                    |r| r.ospa,
                ),
                series(
                    rows,
                    "merge",
                    "Doppler-only 1500 merge gate 2 m 0.5 mps",
                    "Doppler-only, gate [2 m, 0.5 m/s]",
                    |r| r.ospa,
                ),
            ],
        )?;
    }
    if has("physical") {
        let names: Vec<String> = rows
            .iter()
            .filter(|r| r.set == "physical")
            .map(|r| r.curve.clone())
            .fold(Vec::new(), |mut v, n| {
                if !v.contains(&n) {
                    v.push(n);
                }
                v
            });
        let s: Vec<Series> = names
            .iter()
            .map(|n| series(rows, "physical", n, n, pd))
            .collect();
        io::plot::line_chart(
            d.join("physical_pd.svg"),
            &format!(
                "Physical generator (eq. 11 + FFT): Pd vs SNR, {} runs",
                n("physical")
            ),
            "SNR (dB, peak pixel, eq. 19)",
            "Pd",
            &s,
        )?;
    }
    if has("target-free") {
        io::plot::line_chart(
            d.join("false_alarms.svg"),
            &format!(
                "Target-free runs: reported components per frame, {} runs",
                n("target-free")
            ),
            "filter gain set for SNR (dB)",
            "false alarms per frame",
            &[
                series(rows, "target-free", "joint 1500", "joint", |r| {
                    r.reported_per_frame
                }),
                series(
                    rows,
                    "target-free",
                    "Doppler-only 1500",
                    "Doppler-only",
                    |r| r.reported_per_frame,
                ),
            ],
        )?;
    }
    Ok(())
}

/// The Markdown summary: our numbers next to the paper's.
fn summary(rows: &[Row], timing: &[TimingRow]) -> String {
    let mut s = String::new();
    let n = |set: &str| {
        rows.iter()
            .filter(|r| r.set == set)
            .map(|r| r.runs)
            .max()
            .unwrap_or(0)
    };
    let runs = n("base");
    let at = |set: &str, name: &str, lvl: f64| snr_at_pd(&curve(rows, set, name), lvl);
    if rows.iter().any(|r| r.set == "base") {
        s.push_str(
            "### Sensitivity: SNR at Pd 0.9 (Fig. 7, 9, 10, 11, ablations; runs per point in the table)\n\n",
        );
        let mut t = Vec::new();
        let dop = at("base", "Doppler-only 1500", 0.9);
        let names: Vec<String> = rows
            .iter()
            .filter(|r| {
                r.set == "base"
                    || r.set.starts_with("blades")
                    || r.set.starts_with("omega")
                    || r.set == "ablation"
                    || r.set == "merge"
                    || r.set == "known"
            })
            .map(|r| format!("{}|{}", r.set, r.curve))
            .fold(Vec::new(), |mut v, n| {
                if !v.contains(&n) {
                    v.push(n);
                }
                v
            });
        for key in names {
            let (set, name) = key.split_once('|').unwrap_or(("", ""));
            let x = at(set, name, 0.9);
            let gain = match (dop.snr_db, x.snr_db) {
                (Some(a), Some(b)) => Some(a - b),
                _ => None,
            };
            let band = match (dop.lo_db, dop.hi_db, x.lo_db, x.hi_db) {
                (Some(dl), Some(dh), Some(xl), Some(xh)) => {
                    format!("[{:.2}, {:.2}]", dl - xh, dh - xl)
                }
                _ => "-".into(),
            };
            let paper = if name.starts_with("joint") && (set == "base") {
                format!("{:.1}", paper::GAIN_DB)
            } else {
                "-".into()
            };
            t.push(vec![
                set.to_string(),
                name.to_string(),
                n(set).to_string(),
                fmt_db(x.snr_db),
                format!("[{}, {}]", fmt_db(x.lo_db), fmt_db(x.hi_db)),
                fmt_db(gain),
                band,
                paper,
            ]);
        }
        s.push_str(&io::markdown_table(
            &[
                "set",
                "filter",
                "runs per point",
                "SNR at Pd 0.9 (dB)",
                "band (CP bounds)",
                "gain over Doppler-only (dB)",
                "gain band",
                "paper gain (dB)",
            ],
            &t,
        ));
        s.push('\n');
        // OSPA at the highest SNR.
        let top = rows
            .iter()
            .filter(|r| r.set == "base")
            .map(|r| r.snr_db)
            .fold(f64::NEG_INFINITY, f64::max);
        let mut t = Vec::new();
        for r in rows.iter().filter(|r| {
            (r.set == "base" || r.set == "merge" || r.set == "known") && r.snr_db == top
        }) {
            t.push(vec![
                format!("{} ({})", r.curve, r.set),
                format!("{}", r.snr_db),
                format!("{:.3}", r.pd),
                format!("{:.3}", r.reported_per_frame),
                format!("{:.3}", r.ospa),
                format!("{:.3}", r.ospa_after_burn_in),
                format!("{:.3}", r.rmse_range_m),
                format!("{:.3}", r.rmse_velocity_mps),
                format!("{:.1}", paper::OSPA_SETTLED),
            ]);
        }
        s.push_str(&format!(
            "\n### Estimation at the highest SNR (Fig. 8), {runs} runs\n\n"
        ));
        s.push_str(&io::markdown_table(
            &[
                "filter",
                "SNR (dB)",
                "Pd",
                "reported per frame",
                "mean OSPA, all frames",
                "mean OSPA, after burn-in",
                "RMSE range (m)",
                "RMSE velocity (m/s)",
                "paper OSPA (units not stated)",
            ],
            &t,
        ));
    }
    let fa: Vec<&Row> = rows.iter().filter(|r| r.set == "target-free").collect();
    if !fa.is_empty() {
        s.push_str(&format!("\n### False alarms per frame, target-free runs ({} runs per point, after burn-in; paper: none given)\n\n", n("target-free")));
        let t: Vec<Vec<String>> = fa
            .iter()
            .map(|r| {
                vec![
                    r.curve.clone(),
                    format!("{}", r.snr_db),
                    r.frames.to_string(),
                    format!("{:.4}", r.reported_per_frame),
                ]
            })
            .collect();
        s.push_str(&io::markdown_table(
            &[
                "filter",
                "gain set for SNR (dB)",
                "frames",
                "false alarms per frame",
            ],
            &t,
        ));
    }
    let ph: Vec<&Row> = rows.iter().filter(|r| r.set == "physical").collect();
    if !ph.is_empty() {
        s.push_str(&format!(
            "\n### Physical generator (eq. 11 + slow-time FFT), {} runs per point\n\n",
            n("physical")
        ));
        let t: Vec<Vec<String>> = ph
            .iter()
            .map(|r| {
                vec![
                    r.curve.clone(),
                    format!("{}", r.snr_db),
                    format!("{:.3} [{:.3}, {:.3}]", r.pd, r.pd_lo, r.pd_hi),
                    format!("{:.3}", r.reported_per_frame),
                    format!("{:.3}", r.ospa),
                ]
            })
            .collect();
        s.push_str(&io::markdown_table(
            &[
                "filter",
                "SNR (dB)",
                "Pd [95 % CP]",
                "reported per frame",
                "mean OSPA",
            ],
            &t,
        ));
    }
    if !timing.is_empty() {
        s.push_str("\n### Table 3: time per frame (CPU time of one host thread, -10 dB, map generation excluded)\n\n");
        let t: Vec<Vec<String>> = timing
            .iter()
            .map(|r| {
                vec![
                    r.algorithm.clone(),
                    r.particles.to_string(),
                    r.frames.to_string(),
                    format!("{:.0}", r.particles_per_frame),
                    format!("{:.3}", r.ms_per_frame),
                    io::fmt_opt(r.paper_s.map(|p| p * 1e3), 0),
                    io::fmt_opt(r.speed_up, 0),
                ]
            })
            .collect();
        s.push_str(&io::markdown_table(
            &[
                "algorithm",
                "L_max",
                "frames",
                "particles updated per frame",
                "ms per frame (ours)",
                "paper ms (MATLAB)",
                "paper / ours",
            ],
            &t,
        ));
    }
    s
}
