//! The Doppler-frame detectors: CRPF-TBD and the Gaussian comparators (PF-TBD, JOTT, PF-LRT).

use anyhow::{anyhow, bail, ensure, Result};
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::jott::JottTbd;
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::model::doppler::{Likelihood, ModelConfig, Phase, Window};
use faint_core::Complex32;
use serde::{Deserialize, Serialize};

use std::path::Path;

use super::{drive, find_default, json, load, valid, InputView, NoiseLevel, Outcome, Request};
use crate::io::input::{read_complex_frames, Frames};
use crate::stats::noise::exponential_mean;
use crate::timing::thread_cpu_seconds as cpu;

/// Particle counts the particle-filter detectors are built for (the capacity is a
/// compile-time constant of the core).
pub use crate::instances::doppler::DETECT_PARTICLES as PARTICLES;

/// A Doppler-frame detector's configuration file (CRPF-TBD: `C = CrpfConfig`; the
/// Gaussian comparators: `C = GaussConfig`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DopplerFile<C> {
    /// Particles (one of [`PARTICLES`]).
    pub particles: usize,
    /// Where the noise level comes from.
    pub noise: NoiseLevel,
    /// Amplitude prior as eq. 18's SNR (Lu, Wang, Zhang 2017), dB over the noise level,
    /// `SNR = 10 log10(A^2 (sum w)^2 / (s2 sum w^2))` with `s2` the time-domain noise
    /// variance: replaces `config.model.prior.amp` (needs `noise: estimate`). `null`
    /// keeps `config.model.prior.amp`.
    pub amplitude_snr_db: Option<[f32; 2]>,
    /// Births over the whole unambiguous Doppler band `[-1/(2 ts), 1/(2 ts))`: replaces
    /// `config.model.prior.fd`. `false` keeps it.
    pub births_over_band: bool,
    /// The core configuration.
    pub config: C,
}

/// A Gaussian comparator's configuration file.
pub type GaussFile = DopplerFile<GaussConfig>;

/// The defaults of a Doppler file: estimated noise, the preset's amplitude box as SNR
/// (rounded outwards to 0.1 dB), births over the band.
fn doppler_defaults<C>(particles: usize, config: C, model: &ModelConfig) -> DopplerFile<C> {
    let (lo, hi) = model.prior.amp;
    let gain = window_gain_db(model.window, model.bins);
    let db = |a: f32| 20.0 * f64::from(a).log10() + gain;
    DopplerFile {
        particles,
        noise: NoiseLevel::Estimate,
        amplitude_snr_db: Some([
            ((db(lo) * 10.0).floor() / 10.0) as f32,
            ((db(hi) * 10.0).ceil() / 10.0) as f32,
        ]),
        births_over_band: true,
        config,
    }
}

/// `10 log10((sum w)^2 / sum w^2)`: eq. 18's SNR less the time-domain `A^2 / s2` (dB).
fn window_gain_db(window: Window, m: usize) -> f64 {
    let (s, s2) = (0..m).fold((0.0f64, 0.0f64), |(s, s2), n| {
        let w = window.coefficient(n, m);
        (s + w, s2 + w * w)
    });
    10.0 * (s * s / s2).log10()
}

/// CRPF-TBD's default configuration file: the OTHR preset, 1000 particles, an unknown
/// phase per frame (recorded echoes; the preset's zero phase is the paper's model).
pub(super) fn default_crpf() -> String {
    let mut c = CrpfConfig::othr();
    c.model.phase = Phase::Unknown;
    json(&doppler_defaults(1000, c, &c.model))
}

/// The Gaussian comparators' default configuration file: as [`default_crpf`], with the
/// window-aware likelihood (the preset's Hamming bins are correlated; the paper's
/// independent-bin likelihood is the reproduction's).
pub(super) fn default_gauss() -> String {
    let mut c = GaussConfig::othr(1.0);
    c.model.phase = Phase::Unknown;
    c.likelihood = Likelihood::Window;
    json(&doppler_defaults(1000, c, &c.model))
}

/// Per-bin noise variance of Doppler frames, robust to targets: the bins of white noise
/// are circular complex Gaussian, `|z_b|^2` exponential, and `s2 = median |z_b|^2 / ln 2`
/// over every bin of every frame ([`exponential_mean`]).
pub fn bin_variance(frames: &Frames<Complex32>) -> Option<f64> {
    exponential_mean(frames.data.iter().map(|z| f64::from(z.norm_sqr())))
}

/// Applies `file`'s noise, SNR and birth settings to `model` and, with an estimated
/// noise level, scales `frames` to unit time-domain noise variance. Returns the per-bin
/// noise variance of the frames as the detector sees them (`None`: as-is).
fn normalise<C>(
    file: &DopplerFile<C>,
    model: &mut ModelConfig,
    frames: &mut Frames<Complex32>,
    input: &Path,
) -> Result<Option<f32>> {
    if file.births_over_band {
        let h = 0.5 / model.ts;
        model.prior.fd = (-h, h);
    }
    if file.noise == NoiseLevel::AsIs {
        return Ok(None);
    }
    let energy = model.window.energy(model.bins);
    let v = bin_variance(frames).ok_or_else(|| {
        anyhow!(
            "{}: the median bin power is 0 or not finite: no noise level to estimate \
             (use \"noise\": \"as-is\")",
            input.display()
        )
    })?;
    let scale = (energy / v).sqrt();
    ensure!(
        scale.is_finite() && scale > 0.0,
        "{}: noise level {v:e} cannot be normalised",
        input.display()
    );
    let scale = scale as f32;
    for z in frames.data.iter_mut() {
        *z = Complex32::new(z.re * scale, z.im * scale);
        ensure!(
            z.re.is_finite() && z.im.is_finite(),
            "{}: a sample overflows f32 once scaled to unit noise ({scale:e})",
            input.display()
        );
    }
    if let Some([lo, hi]) = file.amplitude_snr_db {
        let gain = window_gain_db(model.window, model.bins);
        let amp = |db: f32| (10f64.powf((f64::from(db) - gain) / 20.0)) as f32;
        model.prior.amp = (amp(lo), amp(hi));
    }
    Ok(Some(energy as f32))
}

/// The file-level checks of a Doppler file.
fn check_file<C>(f: &DopplerFile<C>) -> Result<()> {
    particles_ok(f.particles)?;
    if let Some([lo, hi]) = f.amplitude_snr_db {
        ensure!(
            f.noise == NoiseLevel::Estimate,
            "amplitude_snr_db needs \"noise\": \"estimate\" (as-is data has no noise level)"
        );
        ensure!(
            lo.is_finite()
                && hi.is_finite()
                && (-60.0..=60.0).contains(&lo)
                && lo <= hi
                && hi <= 60.0,
            "amplitude_snr_db = [{lo}, {hi}]: must be finite, in [-60, 60] dB, low <= high"
        );
    }
    Ok(())
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

/// Builds a boxed detector of `N` particles configured with `$cfg` and drives it.
macro_rules! with_particles {
    ($n:expr, $ty:ident, $cfg:expr, $seed:expr, |$det:ident| $body:expr) => {
        match $n {
            1000 => {
                let $det = crate::instances::boxed::<$ty<1000>>($cfg, $seed)?;
                $body
            }
            2000 => {
                let $det = crate::instances::boxed::<$ty<2000>>($cfg, $seed)?;
                $body
            }
            4000 => {
                let $det = crate::instances::boxed::<$ty<4000>>($cfg, $seed)?;
                $body
            }
            6000 => {
                let $det = crate::instances::boxed::<$ty<6000>>($cfg, $seed)?;
                $body
            }
            n => bail!("particles = {n}: must be one of {PARTICLES:?}"),
        }
    };
}

const DOPPLER_POSITION: &[usize] = &[0];

pub(super) fn run_crpf(req: &Request) -> Result<Outcome> {
    let t = cpu();
    let file: DopplerFile<CrpfConfig> =
        load(req, find_default("crpf"), |f: &DopplerFile<CrpfConfig>| {
            check_file(f)?;
            valid(&f.config)
        })?;
    let mut frames = doppler_input(req, file.config.model.bins)?;
    let mut cfg = file.config;
    normalise(&file, &mut cfg.model, &mut frames, req.input)?;
    valid(&cfg).map_err(|e| anyhow!("with the input's noise level: {e}"))?;
    let read = cpu() - t;
    let mut out = with_particles!(file.particles, CrpfTbd, &cfg, req.seed, |det| {
        let mut det = det;
        drive(
            "crpf",
            det.as_mut(),
            frame_slices(&frames),
            req,
            DOPPLER_POSITION,
        )?
    });
    out.view = doppler_view(frames, cfg.model.ts);
    out.read_seconds = read;
    Ok(out)
}

pub(super) fn run_gauss(req: &Request, name: &'static str) -> Result<Outcome> {
    let t = cpu();
    let file: GaussFile = load(req, default_gauss, |f: &GaussFile| {
        check_file(f)?;
        valid(&f.config)
    })?;
    let mut frames = doppler_input(req, file.config.model.bins)?;
    let mut cfg = file.config;
    if let Some(v) = normalise(&file, &mut cfg.model, &mut frames, req.input)? {
        cfg.noise_var = v;
    }
    valid(&cfg).map_err(|e| anyhow!("with the input's noise level: {e}"))?;
    let read = cpu() - t;
    macro_rules! go {
        ($ty:ident) => {
            with_particles!(file.particles, $ty, &cfg, req.seed, |det| {
                let mut det = det;
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
        "jott" => go!(JottTbd),
        _ => go!(PfLrt),
    };
    out.view = doppler_view(frames, cfg.model.ts);
    out.read_seconds = read;
    Ok(out)
}

fn frame_slices(f: &Frames<Complex32>) -> impl ExactSizeIterator<Item = &[Complex32]> {
    (0..f.frames()).map(move |k| f.frame(k))
}
