//! `faint detect`: any detector of the library on a user's recorded frames.
//!
//! Every detector is one [`Entry`] of [`REGISTRY`]: its name, the kind of input it reads
//! ([`InputKind`]), its default configuration (the preset's values, as JSON a user edits)
//! and a function that reads the input, validates the configuration and runs the
//! detector through the core's generic frame loop [`faint_core::detect::run`]. A new
//! detector registers by adding one entry.
//!
//! The configuration file is JSON: `{"config": {...}}` holding the core configuration
//! (e.g. `CrpfConfig`), plus `"particles"` for the particle filters (one of
//! [`PARTICLES`]), `"estimate_noise"` for the Gaussian comparators and `"q_b"` for
//! DP-TBD ([`DpFile`]). Unknown keys are rejected; values are checked by the core's own
//! `validate`.
//!
//! Outputs ([`write()`]): `detections.csv` / `detections.json` (frame, detector, score,
//! track id and length, state), `summary.csv` (per frame: detections and best score),
//! `reports.json` (the core's per-frame reports), `score.svg` and `tracks.svg`, and with a
//! truth file `gospa.csv` (per-frame GOSPA, alpha = 2, with its decomposition).

use std::path::Path;

use anyhow::{anyhow, bail, ensure, Result};
use faint_core::detect::bernoulli::BernoulliTbd;
use faint_core::detect::cbmember::CbmemberConfig;
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::dp::{DpConfig, DpReport, Method};
use faint_core::detect::mht::{ClassicHoughConfig, MhtConfig};
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::detect::phd::PhdConfig;
use faint_core::detect::{run as run_frames, Detector, ScoreKind, Validate};
use faint_core::model::doppler::estimate_noise_variance;
use faint_core::model::plot::Plot;
use faint_core::model::range_doppler::PointModel;
use faint_core::Complex32;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::io::input::{read_complex_frames, read_plots, read_real_frames, Frames};
use crate::montecarlo::progress_bar;
use crate::reproduce::mht::{Classic, Mht};
use crate::scenario::cbmember::HostFilter as CbmemberHost;
use crate::scenario::dp::with_dp;
use crate::scenario::mht::SeaClutter;
use crate::scenario::phd::{HostFilter, SixTargets, Variant};
use crate::timing::thread_cpu_seconds as cpu;

pub mod calibration;
mod output;

pub use output::{check_input, read_truth, write, write_plots, Selection, Written};

/// Particle counts the particle-filter detectors are built for (the capacity is a
/// compile-time constant of the core).
pub const PARTICLES: [usize; 4] = [1000, 2000, 4000, 6000];

/// What a detector reads, one frame at a time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    /// `(K, m)` complex64 `.npy`/`.npz` (or `(K, m, 2)` float32 I/Q): `m` Doppler bins per frame.
    DopplerFrames,
    /// CSV `scan,amplitude,x,y`: one scan of plots per frame.
    Plots,
    /// `(K, R, D, A)` float32 `.npy`/`.npz`: one range x Doppler x azimuth power cube per frame.
    PowerCubes,
    /// `(K, Nr, Nv)` float32 `.npy`/`.npz`: one range x velocity power map `|y|^2` per frame.
    PowerMaps,
    /// `(K, M, M)` float32 `.npy`/`.npz`: one square intensity image per frame (row-major,
    /// pixel `(x, y)` = (column, row)).
    Images,
}

impl InputKind {
    /// One-line description of the file format.
    pub fn describe(self) -> &'static str {
        match self {
            InputKind::DopplerFrames => "(K, m) complex64 .npy/.npz or (K, m, 2) float32 I/Q",
            InputKind::Plots => "CSV scan,amplitude,x,y",
            InputKind::PowerCubes => "(K, R, D, A) float32 .npy/.npz power cubes",
            InputKind::PowerMaps => "(K, Nr, Nv) float32 .npy/.npz range-Doppler power maps |y|^2",
            InputKind::Images => "(K, 128, 128) float32 .npy/.npz intensity images",
        }
    }
}

/// One registered detector.
#[derive(Debug, Clone, Copy)]
pub struct Entry {
    /// CLI name (`faint detect <name>`).
    pub name: &'static str,
    /// One-line description with the paper.
    pub about: &'static str,
    /// The input it reads.
    pub input: InputKind,
    /// The default configuration file (the preset's values).
    pub default_config: fn() -> String,
    /// Reads, validates and runs (see [`Request`]).
    pub run: fn(&Request) -> Result<Outcome>,
}

/// What `faint detect` asks of a detector.
#[derive(Debug, Clone)]
pub struct Request<'a> {
    /// The input file.
    pub input: &'a Path,
    /// The configuration file's text and path (`None`: the defaults).
    pub config: Option<(&'a Path, &'a str)>,
    /// Seed of the detector's random stream.
    pub seed: u64,
    /// Collect every frame's report (for `reports.json`).
    pub reports: bool,
    /// Restart the detector every this many frames (`faint calibrate`'s runs): before
    /// frame `r L` it is reset with the stream `derive_seed(seed, r)`. Frame indices in
    /// the outcome stay those of the input.
    pub restart_every: Option<usize>,
}

/// One detection of one frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Row {
    /// 0-based frame index in the input.
    pub frame: usize,
    /// The detector's score.
    pub score: f32,
    /// Track id, where the detector has tracks.
    pub track_id: Option<u32>,
    /// Track length (associated plots), where the detector has tracks.
    pub track_len: Option<u32>,
    /// State estimate (names in [`Outcome::state_names`]).
    pub state: Vec<f32>,
}

/// What the input looked like, for the plots.
#[derive(Debug, Clone)]
pub enum InputView {
    /// The frames (frame-major) and the centre frequency of each bin.
    Doppler {
        /// `z_b`, `frames x bins`.
        frames: Vec<Complex32>,
        /// Centre frequency (Hz) of each bin, wrapped into the band.
        bin_hz: Vec<f32>,
    },
    /// Every plot of every scan.
    Plots(Vec<Vec<Plot>>),
    /// Nothing drawn behind the estimates.
    None,
}

/// A finished run.
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Detector name.
    pub detector: &'static str,
    /// Names of the state components.
    pub state_names: &'static [&'static str],
    /// What the score measures.
    pub score: ScoreKind,
    /// Frames processed.
    pub frames: usize,
    /// Every detection of every frame.
    pub rows: Vec<Row>,
    /// The core's per-frame reports, each as one line of JSON (empty unless
    /// [`Request::reports`]).
    pub reports: Vec<String>,
    /// The input, for the plots.
    pub view: InputView,
    /// Indices into the state of the position compared with a truth file (empty: the
    /// detector reports no positions).
    pub position: &'static [usize],
    /// CPU seconds spent reading and checking the input (and the configuration).
    pub read_seconds: f64,
    /// CPU seconds spent in the detector's `step` calls (the frame loop's CPU time less
    /// the collection).
    pub detector_seconds: f64,
    /// Seconds spent collecting its detections and reports (wall time of the short
    /// intervals between steps: a CPU-time call per frame would cost more than they do).
    pub collect_seconds: f64,
}

/// Every detector `faint detect` can run.
pub const REGISTRY: &[Entry] = &[
    Entry {
        name: "crpf",
        about: "CRPF-TBD, cost-reference particle filter with existence (Lu, Wang, Zhang 2017)",
        input: InputKind::DopplerFrames,
        default_config: || {
            json(&Particles {
                particles: 1000,
                config: CrpfConfig::othr(),
            })
        },
        run: run_crpf,
    },
    Entry {
        name: "pf-tbd",
        about: "PF-TBD, particle filter with existence, Gaussian likelihood (Ristic et al. 2004)",
        input: InputKind::DopplerFrames,
        default_config: default_gauss,
        run: |r| run_gauss(r, "pf-tbd"),
    },
    Entry {
        name: "jott",
        about:
            "JOTT / Bernoulli particle filter, Gaussian likelihood (Ristic, Vo, Vo, Farina 2013)",
        input: InputKind::DopplerFrames,
        default_config: default_gauss,
        run: |r| run_gauss(r, "jott"),
    },
    Entry {
        name: "pf-lrt",
        about: "PF-LRT, particle-filter likelihood-ratio test (Boers, Driessen 2003)",
        input: InputKind::DopplerFrames,
        default_config: default_gauss,
        run: |r| run_gauss(r, "pf-lrt"),
    },
    Entry {
        name: "mht",
        about: "MHT-TBD, modified and data-matched Hough transform TBD (Bao et al. 2022)",
        input: InputKind::Plots,
        default_config: || {
            json(&Plain {
                config: MhtConfig::sea_clutter(),
            })
        },
        run: run_mht,
    },
    Entry {
        name: "hough-classic",
        about: "classic two-stage Hough TBD, binary integration (Carlson, Evans, Wilson 1994)",
        input: InputKind::Plots,
        default_config: || {
            json(&Plain {
                config: default_classic(),
            })
        },
        run: run_classic,
    },
    Entry {
        name: "phd-tbd",
        about: "SMC-PHD TBD with K-means extraction (the baseline of Pei et al. 2019)",
        input: InputKind::PowerCubes,
        default_config: || default_phd(Variant::PhdTbd),
        run: |r| run_phd(r, "phd-tbd"),
    },
    Entry {
        name: "pso-phd-kmeans",
        about: "PSO-PHD-TBD, NSGA-II particle swarm, K-means extraction (Pei et al. 2019)",
        input: InputKind::PowerCubes,
        default_config: || default_phd(Variant::PsoKMeans),
        run: |r| run_phd(r, "pso-phd-kmeans"),
    },
    Entry {
        name: "pso-phd-dbscan",
        about: "PSO-PHD-TBD, NSGA-II particle swarm, DBSCAN extraction (Pei et al. 2019)",
        input: InputKind::PowerCubes,
        default_config: || default_phd(Variant::PsoDbscan),
        run: |r| run_phd(r, "pso-phd-dbscan"),
    },
    Entry {
        name: "cbmember",
        about: "CBMeMBer TBD, joint Doppler / micro-Doppler (rotor-UAV paper, 2023)",
        input: InputKind::PowerMaps,
        default_config: || default_cbmember(PointModel::Joint),
        run: |r| run_cbmember(r, "cbmember", PointModel::Joint),
    },
    Entry {
        name: "cbmember-doppler",
        about: "CBMeMBer TBD, Doppler only (the baseline of the rotor-UAV paper, 2023)",
        input: InputKind::PowerMaps,
        default_config: || default_cbmember(PointModel::DopplerOnly),
        run: |r| run_cbmember(r, "cbmember-doppler", PointModel::DopplerOnly),
    },
    Entry {
        name: "dp-arnold",
        about: "first-order DP-TBD, hard q_B window (Barniv 1985; Arnold et al. 1993)",
        input: InputKind::Images,
        default_config: || default_dp(Method::Arnold),
        run: |r| run_dp(r, "dp-arnold", Method::Arnold),
    },
    Entry {
        name: "dp-pulford",
        about: "first-order DP-TBD, Kalman velocity gate (Pulford, La Scala 2010)",
        input: InputKind::Images,
        default_config: || default_dp(Method::Pulford),
        run: |r| run_dp(r, "dp-pulford", Method::Pulford),
    },
    Entry {
        name: "dp-second",
        about: "second-order DP-TBD over state pairs (Wang, Zhang 2016)",
        input: InputKind::Images,
        default_config: || default_dp(Method::SecondOrder),
        run: |r| run_dp(r, "dp-second", Method::SecondOrder),
    },
];

/// A DP-TBD detector's configuration file: `q_B` (9 or 25, compiled in) and the core
/// configuration; `M = 128` and `L = 40` are compiled in.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DpFile {
    /// Predecessor window `q_B`: 9 (3 x 3, up to 1 px/frame) or 25 (5 x 5, up to 2).
    pub q_b: usize,
    /// The core configuration.
    pub config: DpConfig,
}

fn default_dp(method: Method) -> String {
    json(&DpFile {
        q_b: 9,
        config: DpConfig::dim_point(method, 1),
    })
}

/// A DP report as one line of `reports.json`.
#[derive(Serialize)]
struct DpReportJson {
    frame: u32,
    best_x: u16,
    best_y: u16,
    best_merit: f32,
    clamped: u32,
}

fn dp_report_json(r: &DpReport) -> String {
    serde_json::to_string(&DpReportJson {
        frame: r.frame,
        best_x: r.best.x,
        best_y: r.best.y,
        best_merit: r.best.merit,
        clamped: r.clamped,
    })
    .unwrap_or_default()
}

fn run_dp(req: &Request, name: &'static str, method: Method) -> Result<Outcome> {
    let t = cpu();
    let default = find_default(name);
    let file: DpFile = load(req, default, |f: &DpFile| {
        ensure!(
            f.q_b == 9 || f.q_b == 25,
            "q_b = {}: must be 9 or 25 (compiled in)",
            f.q_b
        );
        ensure!(
            f.config.method == method,
            "config.method is {:?}; {name} runs {:?}",
            f.config.method,
            method
        );
        valid(&f.config)
    })?;
    let images = read_real_frames(req.input, 3)?;
    let m = crate::scenario::dp::SIDE;
    ensure!(
        images.shape[1..] == [m, m],
        "{}: images of shape {:?}, the DP detectors are built for (K, {m}, {m})",
        req.input.display(),
        images.shape
    );
    let read = cpu() - t;
    let cfg = file.config;
    let mut out = with_dp!(method, file.q_b, &cfg, |det| {
        let mut det = det;
        drive_with(
            name,
            det.as_mut(),
            (0..images.frames()).map(|k| images.frame(k)),
            req,
            XY_POSITION,
            dp_report_json,
        )?
    });
    out.read_seconds = read;
    Ok(out)
}

fn default_cbmember(model: PointModel) -> String {
    json(&Plain {
        config: CbmemberConfig {
            model,
            ..CbmemberConfig::rotor_uav()
        },
    })
}

fn run_cbmember(req: &Request, name: &'static str, model: PointModel) -> Result<Outcome> {
    let t = cpu();
    let default = match model {
        PointModel::Joint => find_default("cbmember"),
        PointModel::DopplerOnly => find_default("cbmember-doppler"),
    };
    let file: Plain<CbmemberConfig> =
        load(req, default, |f: &Plain<CbmemberConfig>| valid(&f.config))?;
    let maps = read_real_frames(req.input, 3)?;
    let g = file.config.geometry;
    let want = [g.n_range, g.n_velocity];
    ensure!(
        maps.shape[1..] == want,
        "{}: maps of shape {:?}, the config's geometry is (n_range, n_velocity) = {:?}",
        req.input.display(),
        &maps.shape[1..],
        want
    );
    let read = cpu() - t;
    let cfg = file.config;
    let mut det =
        crate::montecarlo::on_worker_stack(move || CbmemberHost::new(cfg, 0).map(Box::new))
            .map_err(|e| anyhow!("{e}"))?;
    det.configure(&cfg, req.seed).map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        name,
        det.as_mut(),
        (0..maps.frames()).map(|k| maps.frame(k)),
        req,
        &[0, 1],
    )?;
    out.read_seconds = read;
    Ok(out)
}

/// The entry called `name`; an unknown name lists the known ones.
pub fn find(name: &str) -> Result<&'static Entry> {
    REGISTRY.iter().find(|e| e.name == name).ok_or_else(|| {
        let known: Vec<&str> = REGISTRY.iter().map(|e| e.name).collect();
        anyhow!(
            "unknown detector '{name}'; known detectors: {}",
            known.join(", ")
        )
    })
}

/// A particle filter's configuration file: the particle count and the core config.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Particles<C> {
    /// Particles (one of [`PARTICLES`]).
    pub particles: usize,
    /// The core configuration.
    pub config: C,
}

/// A Gaussian comparator's configuration file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GaussFile {
    /// Particles (one of [`PARTICLES`]).
    pub particles: usize,
    /// Replace `config.noise_var` by the mean bin power of the whole input
    /// (`estimate_noise_variance`), as the reproduction does with each run.
    pub estimate_noise: bool,
    /// The core configuration.
    pub config: GaussConfig,
}

/// The configuration file of a detector without a particle count.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plain<C> {
    /// The core configuration.
    pub config: C,
}

/// Pretty JSON of a configuration file (`f32` values print as their shortest form).
fn json<T: Serialize>(v: &T) -> String {
    serde_json::to_string_pretty(v).unwrap_or_default()
}

fn default_gauss() -> String {
    json(&GaussFile {
        particles: 1000,
        estimate_noise: true,
        config: GaussConfig::othr(1.0),
    })
}

/// The classic Hough TBD's default: the sea-clutter area and period, and the threshold
/// the binomial strip model gives for a whole-grid false-alarm rate of 1e-4 at a clutter
/// density of 80 plots per scan (28 counts; the reproduction's value at that density).
pub fn default_classic() -> ClassicHoughConfig {
    let sc = SeaClutter::paper(80.0);
    let gamma = crate::analysis::mht::classic_gamma(
        f64::from(sc.area[1] - sc.area[0]),
        crate::reproduce::mht::NR,
        crate::reproduce::mht::NT,
        sc.n_scans,
        f64::from(sc.lambda),
        1e-4,
    );
    ClassicHoughConfig {
        area: sc.area,
        n_scans: sc.n_scans,
        gamma: gamma.min(255) as u8,
    }
}

fn default_phd(v: Variant) -> String {
    json(&Plain {
        config: SixTargets::new(9.0).config(v),
    })
}

/// Parses the configuration file (or the defaults) into `T` and validates `config`.
fn load<T: DeserializeOwned>(
    req: &Request,
    default: fn() -> String,
    check: impl Fn(&T) -> Result<()>,
) -> Result<T> {
    let v: T = match req.config {
        Some((path, text)) => {
            serde_json::from_str(text).map_err(|e| anyhow!("config {}: {e}", path.display()))?
        }
        None => serde_json::from_str(&default()).map_err(|e| anyhow!("default config: {e}"))?,
    };
    let name = req.config.map_or("default config".to_string(), |(p, _)| {
        format!("config {}", p.display())
    });
    check(&v).map_err(|e| anyhow!("{name}: {e}"))?;
    Ok(v)
}

fn valid<C: Validate>(c: &C) -> Result<()> {
    c.validate().map_err(|e| anyhow!("{e}"))
}

fn particles_ok(n: usize) -> Result<()> {
    ensure!(
        PARTICLES.contains(&n),
        "particles = {n}: must be one of {PARTICLES:?}"
    );
    Ok(())
}

/// Reads Doppler frames and checks their bin count against the model's.
fn doppler_input(req: &Request, bins: usize) -> Result<Frames<Complex32>> {
    let f = read_complex_frames(req.input)?;
    ensure!(
        f.frame_len() == bins,
        "{}: frames have {} bins, the config's model.bins is {bins}",
        req.input.display(),
        f.frame_len()
    );
    Ok(f)
}

/// The frames as the plots' background: bin `b` is the frequency `b / (m ts)`, aliased
/// into the band `[-1/(2 ts), 1/(2 ts))`.
fn doppler_view(f: Frames<Complex32>, ts: f32) -> InputView {
    let bins = f.frame_len();
    let width = 1.0 / ts;
    let bin_hz = (0..bins)
        .map(|b| {
            let f = b as f32 * width / bins as f32;
            if f >= 0.5 * width {
                f - width
            } else {
                f
            }
        })
        .collect();
    InputView::Doppler {
        frames: f.data,
        bin_hz,
    }
}

/// Drives `det` over `frames` with the core's frame loop, timing the detector apart from
/// the collection of its output.
fn drive<'f, D>(
    name: &'static str,
    det: &mut D,
    frames: impl ExactSizeIterator<Item = &'f D::Frame>,
    req: &Request,
    position: &'static [usize],
) -> Result<Outcome>
where
    D: Detector,
    D::Frame: 'f,
    D::Report: Serialize,
{
    drive_with(name, det, frames, req, position, |r| {
        serde_json::to_string(r).unwrap_or_default()
    })
}

/// [`drive`] with the report written as JSON by `report_json`.
fn drive_with<'f, D>(
    name: &'static str,
    det: &mut D,
    frames: impl ExactSizeIterator<Item = &'f D::Frame>,
    req: &Request,
    position: &'static [usize],
    report_json: impl Fn(&D::Report) -> String,
) -> Result<Outcome>
where
    D: Detector,
    D::Frame: 'f,
{
    let n = frames.len();
    let input = req.input;
    let keep_reports = req.reports;
    let pb = progress_bar(name, n);
    let mut rows = Vec::new();
    let mut reports = Vec::with_capacity(if keep_reports { n } else { 0 });
    let mut collect = 0.0f64;
    let t0 = cpu();
    // One chunk of the whole input unless the runs of `faint calibrate` restart it.
    let every = req.restart_every.unwrap_or(n).max(1);
    let frames: Vec<&D::Frame> = frames.collect();
    let mut res = Ok(0);
    for (r, chunk) in frames.chunks(every).enumerate() {
        if r > 0 {
            det.reset(faint_core::rng::derive_seed(req.seed, r as u64));
        }
        let first = r * every;
        let part = run_frames(det, chunk.iter().copied(), |k, det, report| {
            let k = first + k;
            let t = std::time::Instant::now();
            for d in det.detections() {
                rows.push(Row {
                    frame: k,
                    score: d.score,
                    track_id: d.track.map(|t| t.id),
                    track_len: d.track.map(|t| t.len),
                    state: d.state().to_vec(),
                });
            }
            if keep_reports {
                reports.push(report_json(report));
            }
            if k % 64 == 0 {
                pb.set_position(k as u64);
            }
            collect += t.elapsed().as_secs_f64();
        });
        match part {
            Ok(m) => res = res.map(|done| done + m),
            Err(e) => {
                res = Err(faint_core::detect::FrameError {
                    frame: first + e.frame,
                    error: e.error,
                });
                break;
            }
        }
    }
    let total = cpu() - t0;
    pb.finish_and_clear();
    let frames = res.map_err(|e| anyhow!("{}: frame {}: {}", input.display(), e.frame, e.error))?;
    Ok(Outcome {
        detector: name,
        state_names: D::STATE,
        score: D::SCORE,
        frames,
        rows,
        reports,
        view: InputView::None,
        position,
        read_seconds: 0.0,
        detector_seconds: total - collect,
        collect_seconds: collect,
    })
}

/// Builds a boxed detector of `N` particles and drives it.
macro_rules! with_particles {
    ($n:expr, $ty:ident, |$det:ident| $body:expr) => {
        match $n {
            1000 => {
                let $det = Box::new($ty::<1000>::default_for_box()?);
                $body
            }
            2000 => {
                let $det = Box::new($ty::<2000>::default_for_box()?);
                $body
            }
            4000 => {
                let $det = Box::new($ty::<4000>::default_for_box()?);
                $body
            }
            6000 => {
                let $det = Box::new($ty::<6000>::default_for_box()?);
                $body
            }
            n => bail!("particles = {n}: must be one of {PARTICLES:?}"),
        }
    };
}

/// A detector built with a valid preset, to be configured in place by the caller.
trait DefaultForBox: Sized {
    fn default_for_box() -> Result<Self>;
}

impl<const N: usize> DefaultForBox for CrpfTbd<N> {
    fn default_for_box() -> Result<Self> {
        CrpfTbd::new(CrpfConfig::othr(), 0).map_err(|e| anyhow!("{e}"))
    }
}

macro_rules! gauss_default {
    ($($t:ident),*) => {$(
        impl<const N: usize> DefaultForBox for $t<N> {
            fn default_for_box() -> Result<Self> {
                $t::new(GaussConfig::othr(1.0), 0).map_err(|e| anyhow!("{e}"))
            }
        }
    )*};
}
gauss_default!(PfTbd, BernoulliTbd, PfLrt);

const DOPPLER_POSITION: &[usize] = &[0];
const XY_POSITION: &[usize] = &[0, 1];
const PHD_POSITION: &[usize] = &[0, 2];

fn run_crpf(req: &Request) -> Result<Outcome> {
    let t = cpu();
    let file: Particles<CrpfConfig> = load(req, find_default("crpf"), |f: &Particles<_>| {
        particles_ok(f.particles)?;
        valid(&f.config)
    })?;
    let frames = doppler_input(req, file.config.model.bins)?;
    let read = cpu() - t;
    let mut out = with_particles!(file.particles, CrpfTbd, |det| {
        let mut det = det;
        det.configure(&file.config, req.seed)
            .map_err(|e| anyhow!("{e}"))?;
        drive(
            "crpf",
            det.as_mut(),
            frame_slices(&frames),
            req,
            DOPPLER_POSITION,
        )?
    });
    out.view = doppler_view(frames, file.config.model.ts);
    out.read_seconds = read;
    Ok(out)
}

fn run_gauss(req: &Request, name: &'static str) -> Result<Outcome> {
    let t = cpu();
    let file: GaussFile = load(req, default_gauss, |f: &GaussFile| {
        particles_ok(f.particles)?;
        if f.estimate_noise {
            // The variance is replaced from the input; check the rest with a valid one.
            valid(&GaussConfig {
                noise_var: 1.0,
                ..f.config
            })
        } else {
            valid(&f.config)
        }
    })?;
    let bins = file.config.model.bins;
    let frames = doppler_input(req, bins)?;
    let mut cfg = file.config;
    if file.estimate_noise {
        cfg.noise_var = estimate_noise_variance(frame_slices(&frames), bins)
            .map_err(|e| anyhow!("{}: noise variance: {e}", req.input.display()))?;
    }
    let read = cpu() - t;
    macro_rules! go {
        ($ty:ident) => {
            with_particles!(file.particles, $ty, |det| {
                let mut det = det;
                det.configure(&cfg, req.seed).map_err(|e| anyhow!("{e}"))?;
                drive(
                    name,
                    det.as_mut(),
                    frame_slices(&frames),
                    req,
                    DOPPLER_POSITION,
                )?
            })
        };
    }
    let mut out = match name {
        "pf-tbd" => go!(PfTbd),
        "jott" => go!(BernoulliTbd),
        _ => go!(PfLrt),
    };
    out.view = doppler_view(frames, cfg.model.ts);
    out.read_seconds = read;
    Ok(out)
}

fn frame_slices(f: &Frames<Complex32>) -> impl ExactSizeIterator<Item = &[Complex32]> {
    (0..f.frames()).map(move |k| f.frame(k))
}

fn find_default(name: &str) -> fn() -> String {
    REGISTRY
        .iter()
        .find(|e| e.name == name)
        .map_or(String::new, |e| e.default_config)
}

fn run_mht(req: &Request) -> Result<Outcome> {
    let t = cpu();
    let file: Plain<MhtConfig> = load(req, find_default("mht"), |f: &Plain<MhtConfig>| {
        valid(&f.config)?;
        ensure!(
            f.config.n_scans <= crate::reproduce::mht::NS,
            "invalid configuration value: n_scans (at most {} here)",
            crate::reproduce::mht::NS
        );
        Ok(())
    })?;
    let scans = read_plots(req.input)?;
    let read = cpu() - t;
    let mut det = Box::new(Mht::unconfigured());
    det.configure(&file.config, req.seed)
        .map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        "mht",
        det.as_mut(),
        scans.iter().map(|s| s.as_slice()),
        req,
        XY_POSITION,
    )?;
    out.view = InputView::Plots(scans);
    out.read_seconds = read;
    Ok(out)
}

fn run_classic(req: &Request) -> Result<Outcome> {
    let t = cpu();
    let file: Plain<ClassicHoughConfig> = load(
        req,
        find_default("hough-classic"),
        |f: &Plain<ClassicHoughConfig>| valid(&f.config),
    )?;
    let scans = read_plots(req.input)?;
    let read = cpu() - t;
    let mut det = Box::new(Classic::new(file.config).map_err(|e| anyhow!("{e}"))?);
    det.configure(&file.config, req.seed)
        .map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        "hough-classic",
        det.as_mut(),
        scans.iter().map(|s| s.as_slice()),
        req,
        &[],
    )?;
    out.view = InputView::Plots(scans);
    out.read_seconds = read;
    Ok(out)
}

fn run_phd(req: &Request, name: &'static str) -> Result<Outcome> {
    let t = cpu();
    let default = find_default(name);
    let file: Plain<PhdConfig> = load(req, default, |f: &Plain<PhdConfig>| valid(&f.config))?;
    let cubes = read_real_frames(req.input, 4)?;
    let g = file.config.geometry;
    let want = [g.n_range, g.n_doppler, g.n_azimuth];
    ensure!(
        cubes.shape[1..] == want,
        "{}: cubes of shape {:?}, the config's geometry is (n_range, n_doppler, n_azimuth) = {:?}",
        req.input.display(),
        &cubes.shape[1..],
        want
    );
    let read = cpu() - t;
    let cfg = file.config;
    // Large filter: built on a worker stack, then boxed.
    let mut det = crate::montecarlo::on_worker_stack(move || HostFilter::new(cfg, 0).map(Box::new))
        .map_err(|e| anyhow!("{e}"))?;
    det.configure(&cfg, req.seed).map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        name,
        det.as_mut(),
        (0..cubes.frames()).map(|k| cubes.frame(k)),
        req,
        PHD_POSITION,
    )?;
    out.read_seconds = read;
    Ok(out)
}
