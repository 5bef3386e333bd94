//! The Doppler-frame detectors: CRPF-TBD and the Gaussian comparators (PF-TBD, JOTT, PF-LRT).

use anyhow::{anyhow, bail, ensure, Result};
use faint_core::detect::bernoulli::BernoulliTbd;
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::detect::Detector;
use faint_core::model::doppler::estimate_noise_variance;
use faint_core::Complex32;
use serde::{Deserialize, Serialize};

use super::{drive, find_default, json, load, valid, InputView, Outcome, Particles, Request};
use crate::io::input::{read_complex_frames, Frames};
use crate::timing::thread_cpu_seconds as cpu;

/// Particle counts the particle-filter detectors are built for (the capacity is a
/// compile-time constant of the core).
pub const PARTICLES: [usize; 4] = [1000, 2000, 4000, 6000];

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

/// CRPF-TBD's default configuration file: the OTHR preset, 1000 particles.
pub(super) fn default_crpf() -> String {
    json(&Particles {
        particles: 1000,
        config: CrpfConfig::othr(),
    })
}

pub(super) fn default_gauss() -> String {
    json(&GaussFile {
        particles: 1000,
        estimate_noise: true,
        config: GaussConfig::othr(1.0),
    })
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

pub(super) fn run_crpf(req: &Request) -> Result<Outcome> {
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

pub(super) fn run_gauss(req: &Request, name: &'static str) -> Result<Outcome> {
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
