//! A second simulator per input kind, written from the physics and not from the models
//! the detectors assume (it calls neither `scenario` nor the core's forward models), and
//! the evaluation harness behind `faint evaluate` ([`evaluate`]).
//!
//! - [`doppler`]: Doppler frames (tone + white noise, window, FFT), for crpf, pf-tbd,
//!   jott, pf-lrt.
//! - [`plots`]: plot lists of a cell-by-cell square-law detector (Poisson clutter), for
//!   mht and hough-classic.
//! - [`images`]: intensity images with a pixel-integrated Gaussian point-spread, for the
//!   DP detectors.
//! - [`cubes`]: range x Doppler x azimuth power cubes (sinc spread per axis), for the
//!   PHD family.
//! - [`maps`]: range x velocity power maps (pulses, window, FFT across them), for
//!   CBMeMBer.
//!
//! Each file's docs state its conventions (DFT sign, bin order, cell and pixel centres,
//! units); docs/detect.md repeats them under "Conventions".

pub mod cubes;
pub mod doppler;
pub mod evaluate;
pub mod images;
pub mod maps;
pub mod plots;

use std::path::Path;

use anyhow::{anyhow, Result};
use faint_core::model::doppler::Window;
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;
use faint_core::Complex32;

use crate::detect::InputKind;

pub use cubes::CubePhysics;
pub use doppler::{DopplerPhysics, Phase};
pub use images::ImagePhysics;
pub use maps::MapPhysics;
pub use plots::PlotPhysics;

/// Swerling amplitude fluctuation, scan to scan (one draw per frame).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Swerling {
    /// Constant amplitude.
    Zero,
    /// Power exponential (chi-square, 2 degrees of freedom), mean 1.
    One,
    /// Power chi-square with 4 degrees of freedom, mean 1.
    Three,
}

impl Swerling {
    /// An amplitude factor `f` with `E f^2 = 1` of this law.
    pub fn draw(self, rng: &mut Rng) -> f64 {
        match self {
            Swerling::Zero => 1.0,
            Swerling::One => f64::from(rng.exponential()).sqrt(),
            Swerling::Three => {
                (0.5 * (f64::from(rng.exponential()) + f64::from(rng.exponential()))).sqrt()
            }
        }
    }
}

/// A simulator for one detector's input kind.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Physics {
    /// Doppler frames.
    Doppler(DopplerPhysics),
    /// Plot lists.
    Plots(PlotPhysics),
    /// Images.
    Images(ImagePhysics),
    /// Power cubes.
    Cubes(CubePhysics),
    /// Power maps.
    Maps(MapPhysics),
}

/// One simulated run.
#[derive(Debug, Clone, PartialEq)]
pub struct SimRun {
    /// Its frames.
    pub data: RunData,
    /// The target's position per frame (truth columns, [`Physics::truth_names`]); empty
    /// without a target.
    pub truth: Vec<Vec<f64>>,
}

/// Frames of one run.
#[derive(Debug, Clone, PartialEq)]
pub enum RunData {
    /// Doppler frames.
    Complex(Vec<Vec<Complex32>>),
    /// Real frames, frame-major.
    Real(Vec<f32>),
    /// Scans of plots.
    Plots(Vec<Vec<Plot>>),
}

/// A field of a detector's configuration JSON (`config.<path>`).
fn field<T: serde::de::DeserializeOwned>(config: &serde_json::Value, path: &[&str]) -> Result<T> {
    let mut v = config
        .get("config")
        .ok_or_else(|| anyhow!("the configuration has no 'config' object"))?;
    for p in path {
        v = v
            .get(p)
            .ok_or_else(|| anyhow!("the configuration has no config.{}", path.join(".")))?;
    }
    serde_json::from_value(v.clone()).map_err(|e| anyhow!("config.{}: {e}", path.join(".")))
}

impl Physics {
    /// The simulator matching a detector's input kind, with the geometry its
    /// configuration file reads (Doppler: `model.bins`, `model.ts`, `model.window`;
    /// plots: `area`; images: 128 x 128, `noise.as-is.sigma` as the noise std where the
    /// file states it, else background 1000 and std 20; cubes and maps: `geometry`, `dt`
    /// and the noise power per cell `2 noise_var`; maps also `window`, Hamming if absent).
    pub fn for_detector(kind: InputKind, config: &serde_json::Value) -> Result<Self> {
        let p = match kind {
            InputKind::DopplerFrames => {
                let bins: usize = field(config, &["model", "bins"])?;
                let ts: f32 = field(config, &["model", "ts"])?;
                let window: Window = field(config, &["model", "window"])?;
                Physics::Doppler(DopplerPhysics::new(bins, f64::from(ts), window))
            }
            InputKind::Plots => Physics::Plots(PlotPhysics::new(field(config, &["area"])?)),
            InputKind::Images => {
                // A file that states its noise (`noise.as-is`) gets images at that
                // scale; a robust (scale-free) file gets a camera-like scale (background
                // 1000, noise std 20) that no preset assumes.
                let as_is = config.get("noise").and_then(|n| n.get("as-is"));
                let (sigma, background) = match as_is {
                    Some(a) => {
                        let sigma: f64 = serde_json::from_value(
                            a.get("sigma")
                                .cloned()
                                .ok_or_else(|| anyhow!("noise.as-is has no sigma"))?,
                        )
                        .map_err(|e| anyhow!("noise.as-is.sigma: {e}"))?;
                        (sigma, 0.0)
                    }
                    None => (20.0, 1000.0),
                };
                Physics::Images(ImagePhysics {
                    sigma,
                    background,
                    ..ImagePhysics::new(128, 128)
                })
            }
            InputKind::PowerCubes => {
                let g = |k: &str| field::<f64>(config, &["geometry", k]);
                let n = |k: &str| field::<usize>(config, &["geometry", k]);
                let axis = |nk: &str, sk: &str, ck: &str| -> Result<cubes::Axis> {
                    Ok(cubes::Axis {
                        n: n(nk)?,
                        start: g(sk)?,
                        size: g(ck)?,
                    })
                };
                Physics::Cubes(CubePhysics {
                    dt: field(config, &["dt"])?,
                    noise_power: 2.0 * field::<f64>(config, &["noise_var"])?,
                    ..CubePhysics::new(
                        axis("n_range", "range_start", "range_cell")?,
                        axis("n_doppler", "doppler_start", "doppler_cell")?,
                        axis("n_azimuth", "azimuth_start_deg", "azimuth_cell_deg")?,
                    )
                })
            }
            InputKind::PowerMaps => {
                let g = |k: &str| field::<f64>(config, &["geometry", k]);
                let n = |k: &str| field::<usize>(config, &["geometry", k]);
                let window = match config.get("config").and_then(|c| c.get("window")) {
                    Some(_) => field(config, &["window"])?,
                    None => Window::Hamming,
                };
                let m = MapPhysics::new(
                    cubes::Axis {
                        n: n("n_range")?,
                        start: g("range_start")?,
                        size: g("range_bin")?,
                    },
                    cubes::Axis {
                        n: n("n_velocity")?,
                        start: g("velocity_start")?,
                        size: g("velocity_bin")?,
                    },
                );
                Physics::Maps(MapPhysics {
                    window,
                    dt: field(config, &["dt"])?,
                    noise_power: 2.0 * field::<f64>(config, &["noise_var"])?,
                    ..m
                })
            }
        };
        p.validate()?;
        Ok(p)
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        match self {
            Physics::Doppler(p) => p.validate(),
            Physics::Plots(p) => p.validate(),
            Physics::Images(p) => p.validate(),
            Physics::Cubes(p) => p.validate(),
            Physics::Maps(p) => p.validate(),
        }
    }

    /// Names of the truth columns (the detectors' position names).
    pub fn truth_names(&self) -> &'static [&'static str] {
        match self {
            Physics::Doppler(_) => &["fd_hz"],
            Physics::Plots(_) => &["x_m", "y_m"],
            Physics::Images(_) => &["x_px", "y_px"],
            Physics::Cubes(_) => &["x_m", "y_m"],
            Physics::Maps(_) => &["range_m", "velocity_m_per_s"],
        }
    }

    /// Gate of a correct position (units of [`Physics::distance`], [`Physics::gate_unit`]):
    /// one Doppler bin `1 / (m ts)` (Hz), 100 m (plots), 2 px (images), 2 cells (cubes:
    /// range and azimuth; maps: range and velocity).
    pub fn gate(&self) -> f64 {
        match self {
            Physics::Doppler(p) => 1.0 / (p.bins as f64 * p.ts),
            Physics::Plots(_) => 100.0,
            Physics::Images(_) => 2.0,
            Physics::Cubes(_) | Physics::Maps(_) => 2.0,
        }
    }

    /// The unit of [`Physics::gate`].
    pub fn gate_unit(&self) -> &'static str {
        match self {
            Physics::Doppler(_) => "Hz",
            Physics::Plots(_) => "m",
            Physics::Images(_) => "px",
            Physics::Cubes(_) => "cells (range, azimuth)",
            Physics::Maps(_) => "cells (range, velocity)",
        }
    }

    /// Distance between an estimated position and the truth (Doppler wraps in the band).
    /// Cubes and maps count cells: `sqrt((dr / range_cell)^2 + (db / azimuth_cell)^2)`
    /// from the range and azimuth of each `(x, y)` (cubes),
    /// `sqrt((dr / range_bin)^2 + (dv / velocity_bin)^2)` with `dv` wrapped into
    /// `[-Va / 2, Va / 2)` (maps).
    pub fn distance(&self, est: &[f64], truth: &[f64]) -> f64 {
        match self {
            Physics::Doppler(p) => match (est.first(), truth.first()) {
                (Some(&e), Some(&t)) => p.wrap(e - t).abs(),
                _ => f64::INFINITY,
            },
            Physics::Cubes(p) => match (est, truth) {
                ([ex, ey], [tx, ty]) => p.cell_distance([*ex, *ey], [*tx, *ty]),
                _ => f64::INFINITY,
            },
            Physics::Maps(p) => match (est, truth) {
                ([er, ev], [tr, tv]) => {
                    ((er - tr) / p.range.size).hypot(p.wrap(ev - tv) / p.velocity.size)
                }
                _ => f64::INFINITY,
            },
            _ => est
                .iter()
                .zip(truth)
                .map(|(e, t)| (e - t) * (e - t))
                .sum::<f64>()
                .sqrt(),
        }
    }

    /// What `snr_db` means for this kind (for tables).
    pub fn snr_definition(&self) -> &'static str {
        match self {
            Physics::Doppler(_) => {
                "peak-bin SNR a^2 (sum w)^2 / (sigma^2 sum w^2) (eq. 18 of Lu et al. 2017)"
            }
            Physics::Plots(_) => {
                "mean cell SNR of a Swerling-1 target (Pd = pfa^(1/(1+snr)) per scan)"
            }
            Physics::Images(_) => "20 log10(a / sigma), a the spot's total amplitude",
            Physics::Cubes(_) => {
                "peak-cell power over noise power a^2 / P, target at a cell centre (the intensity of Pei et al. 2019)"
            }
            Physics::Maps(_) => {
                "peak-pixel SNR a^2 (sum w)^2 / (sigma^2 sum w^2), target at a pixel centre (eq. 19 of the rotor-UAV paper, 2023)"
            }
        }
    }

    /// Shape of one frame of a kind with real frames (`None`: Doppler frames, plots).
    pub fn frame_shape(&self) -> Option<Vec<usize>> {
        match self {
            Physics::Images(p) => Some(vec![p.height, p.width]),
            Physics::Cubes(p) => Some(vec![p.range.n, p.doppler.n, p.azimuth.n]),
            Physics::Maps(p) => Some(vec![p.range.n, p.velocity.n]),
            Physics::Doppler(_) | Physics::Plots(_) => None,
        }
    }

    /// Simulates one run of `frames` frames; `snr_db = None` is noise (clutter) only.
    pub fn simulate(&self, frames: usize, snr_db: Option<f64>, rng: &mut Rng) -> SimRun {
        match self {
            Physics::Doppler(p) => {
                let (f, t) = p.simulate(frames, snr_db.map(|s| p.amplitude(s)), rng);
                SimRun {
                    data: RunData::Complex(f),
                    truth: t.iter().map(|x| vec![x.fd]).collect(),
                }
            }
            Physics::Plots(p) => {
                let (f, t) = p.simulate(frames, snr_db.map(|s| 10f64.powf(s / 10.0)), rng);
                SimRun {
                    data: RunData::Plots(f),
                    truth: t.iter().map(|x| x.to_vec()).collect(),
                }
            }
            Physics::Images(p) => {
                let (f, t) =
                    p.simulate(frames, snr_db.map(|s| p.sigma * 10f64.powf(s / 20.0)), rng);
                SimRun {
                    data: RunData::Real(f),
                    truth: t.iter().map(|x| x.to_vec()).collect(),
                }
            }
            Physics::Cubes(p) => {
                let (f, t) = p.simulate(frames, snr_db.map(|s| p.amplitude(s)), rng);
                SimRun {
                    data: RunData::Real(f),
                    truth: t.iter().map(|x| x.position.to_vec()).collect(),
                }
            }
            Physics::Maps(p) => {
                let (f, t) = p.simulate(frames, snr_db.map(|s| p.amplitude(s)), rng);
                SimRun {
                    data: RunData::Real(f),
                    truth: t.iter().map(|x| vec![x.range, x.velocity]).collect(),
                }
            }
        }
    }

    /// Writes `runs` one after the other as one input file, and (when `truth` is given)
    /// the truth file `frame,<names>` with frames numbered through the whole file.
    pub fn write(&self, runs: &[SimRun], path: &Path, truth: Option<&Path>) -> Result<()> {
        match self {
            Physics::Doppler(_) => {
                let frames: Vec<Vec<Complex32>> = runs
                    .iter()
                    .flat_map(|r| match &r.data {
                        RunData::Complex(f) => f.clone(),
                        _ => Vec::new(),
                    })
                    .collect();
                crate::io::output::write_complex_frames(path, &frames)?;
            }
            Physics::Plots(_) => {
                let scans: Vec<Vec<Plot>> = runs
                    .iter()
                    .flat_map(|r| match &r.data {
                        RunData::Plots(f) => f.clone(),
                        _ => Vec::new(),
                    })
                    .collect();
                crate::io::output::write_plots(path, &scans)?;
            }
            Physics::Images(_) | Physics::Cubes(_) | Physics::Maps(_) => {
                let shape = self.frame_shape().unwrap_or_default();
                let data: Vec<f32> = runs
                    .iter()
                    .flat_map(|r| match &r.data {
                        RunData::Real(f) => f.iter().copied(),
                        _ => [].iter().copied(),
                    })
                    .collect();
                let k = data.len() / shape.iter().product::<usize>().max(1);
                let full: Vec<usize> = std::iter::once(k).chain(shape).collect();
                crate::io::output::write_real_frames(path, &full, &data)?;
            }
        }
        if let Some(tp) = truth {
            let mut text = format!("frame,{}\n", self.truth_names().join(","));
            let mut first = 0usize;
            for r in runs {
                for (k, row) in r.truth.iter().enumerate() {
                    let cols: Vec<String> = row.iter().map(|v| format!("{v}")).collect();
                    text.push_str(&format!("{},{}\n", first + k, cols.join(",")));
                }
                first += match &r.data {
                    RunData::Complex(f) => f.len(),
                    RunData::Plots(f) => f.len(),
                    RunData::Real(f) => {
                        f.len()
                            / self
                                .frame_shape()
                                .map_or(1, |s| s.iter().product::<usize>().max(1))
                    }
                };
            }
            crate::io::write_text(tp, &text)?;
        }
        Ok(())
    }
}
