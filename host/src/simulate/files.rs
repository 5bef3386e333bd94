//! `faint simulate`: a preset's frames written in exactly the format `faint detect` reads,
//! with a truth file beside them, so a new user can round-trip without data of their own.
//!
//! | scenario | frames file | truth columns | unit of `--frames` |
//! |---|---|---|---|
//! | `othr` | `(K, 32)` complex64 `.npy` | `frame,fd_hz` | one 32-bin Doppler frame (runs of 32 frames follow each other) |
//! | `sea-clutter` | CSV `scan,amplitude,x,y` | `frame,x_m,y_m` | one scan (periods of 30 scans follow each other) |
//! | `six-targets` | `(K, 142, 150, 90)` float32 `.npy` | `frame,x_m,y_m` | one power cube (at most the preset's 40) |
//! | `rotor-uav` | `(K, 256, 512)` float32 `.npy` power maps | `frame,range_m,velocity_m_per_s` | one range-Doppler map (at most the preset's 40) |
//! | `dim-point` | `(K, 128, 128)` float32 `.npy` intensity images | `frame,x_px,y_px` | one image (at most the preset's 40) |
//!
//! Run `r` of a multi-run file (`othr`, `sea-clutter`) draws from `Rng::from_stream(seed, r)`,
//! the stream trial `r` of a reproduction with master seed `seed` gets; `six-targets`
//! draws its truth from `Rng::from_stream(seed, 0).fork(1)` and its cubes from `.fork(2)`,
//! as the reproduction's run 0 does; `rotor-uav` its maps from
//! `Rng::from_stream(seed, 0).fork(1)` (the reproduction's map stream of a run);
//! `dim-point` draws run 0 at `--speed` from
//! `Rng::from_stream(derive_seed(seed, speed), 0)`, the reproduction's run 0 at that speed
//! (truth: the continuous position, pixel `(x, y)` covering `[x, x+1) x [y, y+1)`).

use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Result};
use faint_core::rng::Rng;
use serde::Serialize;

use crate::cli;
use crate::io::output::{write_complex_frames, write_plots, write_real_frames};
use crate::io::write_csv;
use crate::simulate::cbmember::{MapSource, RotorUav};
use crate::simulate::crpf::{Noise, Othr};
use crate::simulate::dp::{qb_for, DimPoint};
use crate::simulate::mht::SeaClutter;
use crate::simulate::phd::SixTargets;

/// What to simulate.
#[derive(Debug, Clone)]
pub struct Spec {
    /// Scenario preset name (`othr`, `sea-clutter`, `six-targets`).
    pub scenario: String,
    /// Frames file to write (`.npy` for `othr` and `six-targets`, `.csv` for `sea-clutter`).
    pub out: PathBuf,
    /// Seed.
    pub seed: u64,
    /// SNR (dB; `othr`: eq. 18 of Lu et al. 2017, default 8; `six-targets`: default 9;
    /// `rotor-uav`: eq. 19 of the rotor-UAV paper, default 10).
    pub snr_db: Option<f64>,
    /// Frames (default: one run of the preset).
    pub frames: Option<usize>,
    /// Clutter plots per scan (`sea-clutter`, default 80).
    pub lambda: Option<f32>,
    /// SNR `a / sigma`, linear (`dim-point`, default 2).
    pub snr: Option<f64>,
    /// Target speed in px/frame (`dim-point`, 1 or 2, default 1).
    pub speed: Option<u8>,
    /// Background noise (`othr`, default Gaussian).
    pub noise: Noise,
}

/// What was written.
#[derive(Debug, Clone)]
pub struct Simulated {
    /// The frames file.
    pub frames_path: PathBuf,
    /// The truth file.
    pub truth_path: PathBuf,
    /// Frames written.
    pub frames: usize,
}

#[derive(Serialize)]
struct Doppler {
    frame: usize,
    fd_hz: f64,
}

#[derive(Serialize)]
struct RangeVelocity {
    frame: usize,
    range_m: f64,
    velocity_m_per_s: f64,
}

#[derive(Serialize)]
struct XyPx {
    frame: usize,
    x_px: f64,
    y_px: f64,
}

#[derive(Serialize)]
struct Xy {
    frame: usize,
    x_m: f64,
    y_m: f64,
}

/// The truth file beside `out`: `frames.npy` -> `frames.truth.csv`.
pub fn truth_path(out: &Path) -> PathBuf {
    let stem = out
        .file_stem()
        .map_or("frames".into(), |s| s.to_string_lossy().into_owned());
    out.with_file_name(format!("{stem}.truth.csv"))
}

fn extension_is(out: &Path, ext: &str, scenario: &str) -> Result<()> {
    ensure!(
        out.extension().is_some_and(|e| e.eq_ignore_ascii_case(ext)),
        "--out {}: {scenario} frames are written as .{ext}",
        out.display()
    );
    Ok(())
}

/// Checks the arguments against the scenario (before anything is drawn or written).
pub fn check(spec: &Spec) -> Result<()> {
    if let Some(k) = spec.frames {
        cli::runs("--frames", k)?;
    }
    if let Some(s) = spec.snr_db {
        cli::snr_db("--snr-db", s)?;
    }
    match spec.scenario.as_str() {
        "othr" => extension_is(&spec.out, "npy", "othr"),
        "sea-clutter" => {
            if let Some(l) = spec.lambda {
                cli::within("--lambda", l.into(), 0.0..=10_000.0, " plots per scan")?;
            }
            ensure!(
                spec.snr_db.is_none(),
                "--snr-db: sea-clutter has no SNR (use --lambda)"
            );
            extension_is(&spec.out, "csv", "sea-clutter")
        }
        "rotor-uav" => {
            let max = RotorUav::new(10.0).frames;
            if let Some(k) = spec.frames {
                ensure!(k <= max, "--frames {k}: rotor-uav has {max} frames");
            }
            extension_is(&spec.out, "npy", "rotor-uav")
        }
        "six-targets" => {
            let max = SixTargets::new(9.0).frames;
            if let Some(k) = spec.frames {
                ensure!(k <= max, "--frames {k}: six-targets has {max} frames");
            }
            extension_is(&spec.out, "npy", "six-targets")
        }
        "dim-point" => {
            let max = DimPoint::default().frames;
            if let Some(k) = spec.frames {
                ensure!(k <= max, "--frames {k}: dim-point has {max} frames");
            }
            ensure!(
                spec.snr_db.is_none(),
                "--snr-db: dim-point's SNR is the linear a / sigma (use --snr)"
            );
            if let Some(s) = spec.snr {
                cli::within("--snr", s, 0.0..=100.0, " (a / sigma)")?;
            }
            if let Some(v) = spec.speed {
                qb_for(v).map_err(|e| anyhow::anyhow!("--speed: {e}"))?;
            }
            extension_is(&spec.out, "npy", "dim-point")
        }
        other => {
            bail!("unknown scenario '{other}' for simulate; known: othr, sea-clutter, six-targets, rotor-uav, dim-point")
        }
    }?;
    if spec.scenario != "dim-point" {
        ensure!(spec.snr.is_none(), "--snr: only dim-point (use --snr-db)");
        ensure!(spec.speed.is_none(), "--speed: only dim-point has a speed");
    }
    if spec.scenario != "sea-clutter" {
        ensure!(
            spec.lambda.is_none(),
            "--lambda: only sea-clutter has clutter plots"
        );
    }
    Ok(())
}

/// Simulates and writes the frames and the truth.
pub fn simulate(spec: &Spec) -> Result<Simulated> {
    check(spec)?;
    let truth_path = truth_path(&spec.out);
    let frames = match spec.scenario.as_str() {
        "othr" => {
            let sc = Othr::default();
            let k = spec.frames.unwrap_or(sc.frames);
            let snr = spec.snr_db.unwrap_or(8.0);
            let mut frames = Vec::with_capacity(k);
            let mut truth = Vec::new();
            let mut r = 0u64;
            while frames.len() < k {
                let run = sc.simulate(Some(snr), spec.noise, &mut Rng::from_stream(spec.seed, r));
                for (z, t) in run.frames.into_iter().zip(run.truth) {
                    if frames.len() == k {
                        break;
                    }
                    if let Some(x) = t {
                        truth.push(Doppler {
                            frame: frames.len(),
                            fd_hz: x[0],
                        });
                    }
                    frames.push(z);
                }
                r += 1;
            }
            write_complex_frames(&spec.out, &frames)?;
            write_csv(&truth_path, &truth)?;
            k
        }
        "sea-clutter" => {
            let sc = SeaClutter::paper(spec.lambda.unwrap_or(80.0));
            let k = spec.frames.unwrap_or(sc.n_scans);
            let mut scans = Vec::with_capacity(k);
            let mut truth = Vec::new();
            let mut r = 0u64;
            while scans.len() < k {
                let trial = sc.generate(&mut Rng::from_stream(spec.seed, r));
                for (s, scan) in trial.scans.into_iter().enumerate() {
                    if scans.len() == k {
                        break;
                    }
                    for t in &trial.targets {
                        let (x, y) = t.position(s as f32 * sc.t_scan);
                        truth.push(Xy {
                            frame: scans.len(),
                            x_m: f64::from(x),
                            y_m: f64::from(y),
                        });
                    }
                    scans.push(scan.plots);
                }
                r += 1;
            }
            write_plots(&spec.out, &scans)?;
            write_csv(&truth_path, &truth)?;
            k
        }
        "rotor-uav" => {
            let sc = RotorUav::new(spec.snr_db.unwrap_or(10.0));
            let k = spec.frames.unwrap_or(sc.frames);
            let mut map_rng = Rng::from_stream(spec.seed, 0).fork(1);
            let mut src = MapSource::new(&sc);
            let g = sc.geometry();
            let mut data = Vec::with_capacity(k * g.len());
            let mut map = Vec::new();
            let mut truth = Vec::new();
            for (f, t) in sc.truth().iter().take(k).enumerate() {
                src.power(&sc, t, f, &mut map_rng, &mut map);
                data.extend_from_slice(&map);
                truth.push(RangeVelocity {
                    frame: f,
                    range_m: t.range,
                    velocity_m_per_s: t.velocity,
                });
            }
            write_real_frames(&spec.out, &[k, g.n_range, g.n_velocity], &data)?;
            write_csv(&truth_path, &truth)?;
            k
        }
        "dim-point" => {
            let sc = DimPoint::default();
            let k = spec.frames.unwrap_or(sc.frames);
            let speed = spec.speed.unwrap_or(1);
            let mut rng = Rng::from_stream(DimPoint::target_seed(spec.seed, speed), 0);
            let run = sc.run(Some(spec.snr.unwrap_or(2.0)), speed, &mut rng)?;
            let mut data = Vec::with_capacity(k * sc.side * sc.side);
            let mut truth = Vec::new();
            for (f, z) in run.frames.iter().take(k).enumerate() {
                data.extend_from_slice(z);
                if let Some(t) = &run.truth {
                    let p = t.position(f);
                    truth.push(XyPx {
                        frame: f,
                        x_px: p[0],
                        y_px: p[1],
                    });
                }
            }
            write_real_frames(&spec.out, &[k, sc.side, sc.side], &data)?;
            write_csv(&truth_path, &truth)?;
            k
        }
        _ => {
            let sc = SixTargets::new(spec.snr_db.unwrap_or(9.0));
            let k = spec.frames.unwrap_or(sc.frames);
            let mut seed_rng = Rng::from_stream(spec.seed, 0);
            let mut truth_rng = seed_rng.fork(1);
            let mut cube_rng = seed_rng.fork(2);
            let tr = sc.truth(&mut truth_rng);
            let g = sc.geometry();
            let mut data = Vec::with_capacity(k * g.len());
            let mut cube = Vec::new();
            let mut truth = Vec::new();
            for (f, targets) in tr.iter().take(k).enumerate() {
                sc.cube(targets, &mut cube_rng, &mut cube);
                data.extend_from_slice(&cube);
                truth.extend(targets.iter().map(|t| Xy {
                    frame: f,
                    x_m: t.state[0],
                    y_m: t.state[2],
                }));
            }
            write_real_frames(&spec.out, &[k, g.n_range, g.n_doppler, g.n_azimuth], &data)?;
            write_csv(&truth_path, &truth)?;
            k
        }
    };
    Ok(Simulated {
        frames_path: spec.out.clone(),
        truth_path,
        frames,
    })
}
