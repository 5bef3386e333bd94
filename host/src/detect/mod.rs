//! `faint detect`: any detector of the library on a user's recorded frames.
//!
//! Every detector is one [`Entry`] of [`REGISTRY`]: its name, the kind of input it reads
//! ([`InputKind`]), its default configuration (the preset's values, as JSON a user edits)
//! and a function that reads the input, validates the configuration and runs the
//! detector through the core's generic frame loop [`faint_core::detect::run`]. A new
//! detector registers by adding one entry.
//!
//! The configuration file is JSON: `{"config": {...}}` holding the core configuration
//! (e.g. `CrpfConfig`), plus `"particles"` (one of [`PARTICLES`]) and the noise level,
//! SNR prior and birth settings for the Doppler-frame detectors ([`DopplerFile`]) and
//! `"q_b"` and `"noise"` for DP-TBD ([`DpFile`]). Unknown keys are rejected; values are checked by the core's own
//! `validate`.
//!
//! Outputs ([`write()`]): `detections.csv` / `detections.json` (frame, detector, score,
//! track id and length, state), `summary.csv` (per frame: detections and best score),
//! `reports.json` (the core's per-frame reports), `score.svg` and `tracks.svg`, and with a
//! truth file `gospa.csv` (per-frame GOSPA, alpha = 2, with its decomposition).

use std::path::Path;

use anyhow::{anyhow, Result};
use faint_core::detect::dp::Method;
use faint_core::detect::{run as run_frames, Detector, ScoreKind, Validate};
use faint_core::model::plot::Plot;
use faint_core::model::range_doppler::PointModel;
use faint_core::Complex32;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

use crate::montecarlo::progress_bar;
use crate::timing::thread_cpu_seconds as cpu;

pub mod calibration;
mod cbmember;
mod doppler;
mod dp;
mod output;
mod phd;
mod plots;

pub use cbmember::{
    default_cbmember_file, rotor_uav_blade_sweep, CbmemberFile, CbmemberSnr, GeometrySpread,
    SpreadFrom,
};
pub use doppler::{bin_variance, DopplerFile, GaussFile, PARTICLES};
pub use dp::{robust_noise, DpFile, DpNoise, DpSettings};
pub use output::{check_input, read_truth, write, write_charts, Selection, Written};
pub use phd::{default_phd_file, normalise_frame, PhdFile, PhdSnr};
pub use plots::{
    classic_threshold, clutter_density, default_classic, mht_gamma, PlotFile, DEFAULT_GRID_PFA,
};

use cbmember::{default_cbmember, run_cbmember};
use doppler::{default_crpf, default_gauss, run_crpf, run_gauss};
use dp::{default_dp, run_dp};
use phd::{default_phd, run_phd};
use plots::{default_hough, default_mht, run_classic, run_mht};

/// Where the noise level of an input comes from (the `"noise"` key of the Doppler, PHD
/// and CBMeMBer configuration files; DP-TBD's [`DpNoise`] also carries its units).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum NoiseLevel {
    /// Estimated robustly from the input ([`crate::stats::noise`]) and divided out, so
    /// the configuration's scale-dependent values are SNRs over it (the default).
    #[default]
    Estimate,
    /// The input's own units: the configuration's absolute values are used as they are.
    AsIs,
}

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
    /// `(K, H, W)` float32 `.npy`/`.npz`, `H, W <= 512`: one intensity image per frame
    /// (row-major, pixel `(x, y)` = (column, row)).
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
            InputKind::Images => "(K, H, W) float32 .npy/.npz intensity images, H and W up to 512",
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
    /// Only these runs of [`restart_every`](Self::restart_every) frames (one shard of
    /// `faint calibrate`): run `r` still starts from the stream `derive_seed(seed, r)`
    /// (run 0 from `seed`), so its scores are those of the whole input's run `r`.
    pub runs: Option<std::ops::Range<usize>>,
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
    /// What the run set from the input (noise level, clutter density, thresholds), one
    /// line each, for the user.
    pub notes: Vec<String>,
    /// What the user must know about the run's result (e.g. a threshold that cannot
    /// hold the wanted false-alarm rate), one line each.
    pub warnings: Vec<String>,
    /// CPU seconds spent reading and checking the input (and the configuration).
    pub read_seconds: f64,
    /// CPU seconds spent in the detector's `step` calls (the frame loop's CPU time less
    /// the collection).
    pub detector_seconds: f64,
    /// Seconds spent collecting its detections and reports (wall time of the short
    /// intervals between steps: a CPU-time call per frame would cost more than they do).
    pub collect_seconds: f64,
}

/// The state indices of an `(x, y)` position.
const XY_POSITION: &[usize] = &[0, 1];

/// Every detector `faint detect` can run.
pub const REGISTRY: &[Entry] = &[
    Entry {
        name: "crpf",
        about: "CRPF-TBD, cost-reference particle filter with existence (Lu, Wang, Zhang 2017)",
        input: InputKind::DopplerFrames,
        default_config: default_crpf,
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
        default_config: default_mht,
        run: run_mht,
    },
    Entry {
        name: "hough-classic",
        about: "classic two-stage Hough TBD, binary integration (Carlson, Evans, Wilson 1994)",
        input: InputKind::Plots,
        default_config: default_hough,
        run: run_classic,
    },
    Entry {
        name: "phd-tbd",
        about: "SMC-PHD TBD, DBSCAN extraction (the baseline of Pei et al. 2019, K-means there)",
        input: InputKind::PowerCubes,
        default_config: || default_phd(phd::Variant::PhdTbd),
        run: |r| run_phd(r, "phd-tbd"),
    },
    Entry {
        name: "pso-phd-kmeans",
        about: "PSO-PHD-TBD, NSGA-II particle swarm, K-means extraction (Pei et al. 2019)",
        input: InputKind::PowerCubes,
        default_config: || default_phd(phd::Variant::PsoKMeans),
        run: |r| run_phd(r, "pso-phd-kmeans"),
    },
    Entry {
        name: "pso-phd-dbscan",
        about: "PSO-PHD-TBD, NSGA-II particle swarm, DBSCAN extraction (Pei et al. 2019)",
        input: InputKind::PowerCubes,
        default_config: || default_phd(phd::Variant::PsoDbscan),
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
        if req.runs.as_ref().is_some_and(|runs| !runs.contains(&r)) {
            continue;
        }
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
            if k.is_multiple_of(64) {
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
        notes: Vec::new(),
        warnings: Vec::new(),
        read_seconds: 0.0,
        detector_seconds: total - collect,
        collect_seconds: collect,
    })
}

fn find_default(name: &str) -> fn() -> String {
    REGISTRY
        .iter()
        .find(|e| e.name == name)
        .map_or(String::new, |e| e.default_config)
}
