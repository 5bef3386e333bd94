//! Noise models for `faint calibrate --from-input`: estimated robustly from a file that
//! may hold targets (medians, which a few target cells do not move), then simulated as
//! noise-only runs in the same file format. The models are [`NoiseModel`].

use std::path::Path;

use anyhow::{anyhow, ensure, Context, Result};
use faint_core::model::doppler::Window;
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;
use faint_core::Complex32;
use rustfft::num_complex::Complex64;
use rustfft::FftPlanner;

use crate::detect::calibration::NoiseModel;
use crate::detect::InputKind;
use crate::io::input::{read_complex_frames, read_plots, read_real_frames};
use crate::io::output::{write_complex_frames, write_plots, write_real_frames};
use crate::stats::noise::{median, MAD_TO_STD};

/// What a file holds: its frame count and the shape of one frame (`[m]` Doppler bins,
/// `[R, D, A]`, `[Nr, Nv]`, `[M, M]`; empty for plot lists).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Frames (scans) in the file.
    pub frames: usize,
    /// Shape of one frame.
    pub frame_shape: Vec<usize>,
}

fn rank(kind: InputKind) -> usize {
    match kind {
        InputKind::PowerCubes => 4,
        _ => 3,
    }
}

/// The frame count and frame shape of `path`, read as `kind`.
pub fn layout(kind: InputKind, path: &Path) -> Result<Layout> {
    Ok(match kind {
        InputKind::DopplerFrames => {
            let f = read_complex_frames(path)?;
            Layout {
                frames: f.frames(),
                frame_shape: vec![f.frame_len()],
            }
        }
        InputKind::Plots => Layout {
            frames: read_plots(path)?.len(),
            frame_shape: Vec::new(),
        },
        _ => {
            let f = read_real_frames(path, rank(kind))?;
            Layout {
                frames: f.frames(),
                frame_shape: f.shape[1..].to_vec(),
            }
        }
    })
}

/// A field of the configuration JSON (`config.<path...>`), deserialised.
fn config_field<T: serde::de::DeserializeOwned>(
    config: &serde_json::Value,
    path: &[&str],
) -> Result<T> {
    let mut v = config
        .get("config")
        .ok_or_else(|| anyhow!("the configuration has no 'config' object"))?;
    for p in path {
        v = v
            .get(p)
            .ok_or_else(|| anyhow!("the configuration has no config.{}", path.join(".")))?;
    }
    serde_json::from_value(v.clone()).with_context(|| format!("config.{}", path.join(".")))
}

/// Estimates the noise model of `path` (read as `kind`); `config` is the detector's
/// configuration file (the window of Doppler frames, the area of plot lists).
pub fn estimate(
    kind: InputKind,
    path: &Path,
    config: &serde_json::Value,
) -> Result<(NoiseModel, Layout)> {
    let p = path.display();
    match kind {
        InputKind::DopplerFrames => {
            let f = read_complex_frames(path)?;
            let mut power: Vec<f64> = f.data.iter().map(|z| f64::from(z.norm_sqr())).collect();
            let med = median(&mut power).ok_or_else(|| anyhow!("{p}: no samples"))?;
            ensure!(
                med > 0.0,
                "{p}: the median bin power is 0: no noise to model"
            );
            let window: Window = config_field(config, &["model", "window"])?;
            Ok((
                NoiseModel::WindowedComplexGaussian {
                    bin_variance: med / std::f64::consts::LN_2,
                    window,
                },
                Layout {
                    frames: f.frames(),
                    frame_shape: vec![f.frame_len()],
                },
            ))
        }
        InputKind::Plots => {
            let scans = read_plots(path)?;
            let mut counts: Vec<f64> = scans.iter().map(|s| s.len() as f64).collect();
            let per_scan = median(&mut counts).ok_or_else(|| anyhow!("{p}: no scans"))?;
            let amplitudes = scans.iter().map(Vec::len).sum();
            ensure!(amplitudes > 0, "{p}: no plots to draw amplitudes from");
            let area: [f32; 4] = config_field(config, &["area"])?;
            Ok((
                NoiseModel::PoissonClutter {
                    plots_per_scan: per_scan,
                    area,
                    amplitudes,
                },
                Layout {
                    frames: scans.len(),
                    frame_shape: Vec::new(),
                },
            ))
        }
        InputKind::PowerCubes | InputKind::PowerMaps => {
            let f = read_real_frames(path, rank(kind))?;
            let mut v: Vec<f64> = f.data.iter().map(|&x| f64::from(x)).collect();
            let med = median(&mut v).ok_or_else(|| anyhow!("{p}: no cells"))?;
            ensure!(
                med > 0.0,
                "{p}: the median cell power is 0: no noise to model"
            );
            Ok((
                NoiseModel::Exponential {
                    mean: med / std::f64::consts::LN_2,
                },
                Layout {
                    frames: f.frames(),
                    frame_shape: f.shape[1..].to_vec(),
                },
            ))
        }
        InputKind::Images => {
            let f = read_real_frames(path, 3)?;
            let mut v: Vec<f64> = f.data.iter().map(|&x| f64::from(x)).collect();
            let mean = median(&mut v).ok_or_else(|| anyhow!("{p}: no pixels"))?;
            let mut dev: Vec<f64> = v.iter().map(|x| (x - mean).abs()).collect();
            let std = MAD_TO_STD * median(&mut dev).unwrap_or(0.0);
            ensure!(
                std > 0.0,
                "{p}: the pixels' median absolute deviation is 0: no noise to model"
            );
            Ok((
                NoiseModel::Gaussian { mean, std },
                Layout {
                    frames: f.frames(),
                    frame_shape: f.shape[1..].to_vec(),
                },
            ))
        }
    }
}

/// Writes `frames` noise-only frames of `model` with frames of `frame_shape` to `out`
/// (the format of the model's input kind). Frame `k` draws from
/// `Rng::from_stream(seed, k)`. Plot-list amplitudes are drawn from those of `source`.
pub fn simulate(
    model: &NoiseModel,
    frame_shape: &[usize],
    frames: usize,
    seed: u64,
    source: &Path,
    out: &Path,
) -> Result<()> {
    ensure!(frames > 0, "no frames to simulate");
    match *model {
        NoiseModel::WindowedComplexGaussian {
            bin_variance,
            window,
        } => {
            let m = frame_shape.first().copied().unwrap_or(0);
            ensure!(m > 0, "Doppler frames of 0 bins");
            let w: Vec<f64> = (0..m).map(|n| window.coefficient(n, m)).collect();
            let energy: f64 = w.iter().map(|x| x * x).sum();
            // Per quadrature: time-sample variance / 2.
            let sd = (bin_variance / energy / 2.0).sqrt();
            let fft = FftPlanner::<f64>::new().plan_fft_forward(m);
            let mut buf = vec![Complex64::new(0.0, 0.0); m];
            let mut all = Vec::with_capacity(frames);
            for k in 0..frames {
                let mut rng = Rng::from_stream(seed, k as u64);
                for (b, &wn) in buf.iter_mut().zip(&w) {
                    let re = f64::from(rng.normal()) * sd;
                    let im = f64::from(rng.normal()) * sd;
                    *b = Complex64::new(re * wn, im * wn);
                }
                // z_b = sum_n w_n x_n exp(-2 pi i n b / m) (rustfft's forward sign).
                fft.process(&mut buf);
                all.push(
                    buf.iter()
                        .map(|z| Complex32::new(z.re as f32, z.im as f32))
                        .collect::<Vec<_>>(),
                );
            }
            write_complex_frames(out, &all)
        }
        NoiseModel::Exponential { mean } => {
            let cells: usize = frame_shape.iter().product();
            let mut data = Vec::with_capacity(frames * cells);
            for k in 0..frames {
                let mut rng = Rng::from_stream(seed, k as u64);
                data.extend((0..cells).map(|_| (f64::from(rng.exponential()) * mean) as f32));
            }
            let mut shape = vec![frames];
            shape.extend_from_slice(frame_shape);
            write_real_frames(out, &shape, &data)
        }
        NoiseModel::Gaussian { mean, std } => {
            let cells: usize = frame_shape.iter().product();
            let mut data = Vec::with_capacity(frames * cells);
            for k in 0..frames {
                let mut rng = Rng::from_stream(seed, k as u64);
                data.extend((0..cells).map(|_| (mean + std * f64::from(rng.normal())) as f32));
            }
            let mut shape = vec![frames];
            shape.extend_from_slice(frame_shape);
            write_real_frames(out, &shape, &data)
        }
        NoiseModel::PoissonClutter {
            plots_per_scan,
            area,
            ..
        } => {
            let pool: Vec<f32> = read_plots(source)?
                .iter()
                .flatten()
                .map(|p| p.amplitude)
                .collect();
            ensure!(!pool.is_empty(), "{}: no plot amplitudes", source.display());
            let [x0, x1, y0, y1] = area;
            let scans: Vec<Vec<Plot>> = (0..frames)
                .map(|k| {
                    let mut rng = Rng::from_stream(seed, k as u64);
                    let n = crate::simulate::mht::poisson(&mut rng, plots_per_scan as f32);
                    (0..n)
                        .map(|_| {
                            let a = pool[rng.below(pool.len() as u32) as usize];
                            Plot::new(a, rng.uniform_range(x0, x1), rng.uniform_range(y0, y1))
                        })
                        .collect()
                })
                .collect();
            write_plots(out, &scans)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windowed_noise_has_the_estimated_bin_variance() {
        // 4000 frames of 32 bins through a Hamming window: the mean |z|^2 must be the
        // model's bin variance within 3 % (4000 x 32 exponential powers, correlated
        // across bins by the window: sd of the mean about 0.6 %, well inside).
        let dir = std::env::temp_dir().join(format!("faint-noise-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("n.npy");
        let model = NoiseModel::WindowedComplexGaussian {
            bin_variance: 2.5,
            window: Window::Hamming,
        };
        simulate(&model, &[32], 4000, 7, &out, &out).unwrap();
        let f = read_complex_frames(&out).unwrap();
        let mean =
            f.data.iter().map(|z| f64::from(z.norm_sqr())).sum::<f64>() / f.data.len() as f64;
        assert!((mean / 2.5 - 1.0).abs() < 0.03, "{mean}");
        // And the estimate recovers it (median / ln 2 of exponential powers: 3 %).
        let cfg = serde_json::json!({"config": {"model": {"window": "Hamming"}}});
        let (est, lay) = estimate(InputKind::DopplerFrames, &out, &cfg).unwrap();
        assert_eq!(lay.frames, 4000);
        match est {
            NoiseModel::WindowedComplexGaussian {
                bin_variance,
                window,
            } => {
                assert!((bin_variance / 2.5 - 1.0).abs() < 0.03, "{bin_variance}");
                assert_eq!(window, Window::Hamming);
            }
            other => panic!("{other:?}"),
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
}
