//! DP-TBD on intensity images.
//!
//! By default the images are made scale-free first ([`DpNoise::Robust`]): every pixel
//! becomes `z' = (z - level) / s`, `level` the median and `s = 1.4826 MAD` of every pixel
//! of the file. The DP's model is i.i.d. Gaussian noise plus a few target pixels (one per
//! frame); the median and the MAD have a 50 % breakdown point, so those pixels (1 in
//! 16384 at 128 x 128) move them by a negligible quantile, and `1.4826 MAD` is the
//! Gaussian's `sigma` (`1 / Phi^-1(3/4)`). The DP then runs in units of that `sigma`.

use anyhow::{anyhow, bail, ensure, Result};
use faint_core::detect::dp::{first_clamped, DpConfig, DpReport, MeritCell, Method, Transition};
use faint_core::detect::Validate;
use serde::{Deserialize, Serialize};

use super::{drive_with, find_default, json, load, Outcome, Request, XY_POSITION};
use crate::io::input::read_real_frames;
use crate::simulate::dp::{capacity, pad_image, with_dp_sized, CAPACITIES};
use crate::stats::noise::{median, MAD_TO_STD};
use crate::timing::thread_cpu_seconds as cpu;

/// Merit LSB of the scale-free mode: `2^-5` noise `sigma` (raised by powers of two when a
/// normalised pixel would lie beyond `16384` LSB, i.e. `512 sigma`).
pub const ROBUST_LSB: f32 = 0.03125;

/// How `faint detect dp-*` scales the images before the DP (`"noise"` of [`DpFile`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub enum DpNoise {
    /// Scale-free (the default): `z' = (z - median) / (1.4826 MAD)` over every pixel of
    /// the file, then the DP with `sigma = 1`, `a_design = design_snr` and
    /// `lsb = 2^-5` (doubled until no pixel lies beyond `16384 lsb`). Merits
    /// are in units of the estimated noise `sigma`.
    Robust {
        /// Design amplitude as a linear SNR `a / sigma` (eq. 29; the preset's 2.0).
        design_snr: f32,
    },
    /// The images as they are, with absolute values (intensity units); a pixel beyond
    /// `+-16384 lsb` is an error naming it.
    AsIs {
        /// Intensity of one merit LSB.
        lsb: f32,
        /// Noise standard deviation `sigma`.
        sigma: f32,
        /// Design amplitude `a_design`.
        a_design: f32,
    },
}

/// The core's [`DpConfig`] without its scale (`lsb`, `sigma`, `a_design`), which
/// [`DpNoise`] gives.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DpSettings {
    /// The recursion; must be the detector's.
    pub method: Method,
    /// `sigma_I` (pixels) of the Gaussian transition.
    pub sigma_i: f32,
    /// Second order: Gaussian transition term or hard window.
    pub transition: Transition,
    /// Pulford: initial covariance `P0 = p0 I_4`.
    pub p0: f32,
    /// Pulford: process noise.
    pub q: f32,
    /// Pulford: measurement variance (px^2).
    pub r: f32,
    /// Pulford: gate half-width.
    pub gate: u8,
    /// Distinct track ends reported per frame.
    pub top_k: u8,
    /// Chebyshev distance (px) between reported ends.
    pub separation: u16,
}

impl DpSettings {
    /// The settings of a core configuration.
    pub fn of(c: &DpConfig) -> Self {
        Self {
            method: c.method,
            sigma_i: c.sigma_i,
            transition: c.transition,
            p0: c.p0,
            q: c.q,
            r: c.r,
            gate: c.gate,
            top_k: c.top_k,
            separation: c.separation,
        }
    }

    /// The core configuration at a scale.
    pub fn config(&self, lsb: f32, sigma: f32, a_design: f32) -> DpConfig {
        DpConfig {
            method: self.method,
            lsb,
            sigma,
            a_design,
            sigma_i: self.sigma_i,
            transition: self.transition,
            p0: self.p0,
            q: self.q,
            r: self.r,
            gate: self.gate,
            top_k: self.top_k,
            separation: self.separation,
        }
    }
}

/// A DP-TBD detector's configuration file: `q_B` (9 or 25, compiled in), how the images
/// are scaled, and the rest of the core configuration; `L = 40` is compiled in, and the
/// image side `M` (128, 256 or 512) is the smallest that holds the images.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DpFile {
    /// Predecessor window `q_B`: 9 (3 x 3, up to 1 px/frame) or 25 (5 x 5, up to 2).
    pub q_b: usize,
    /// Scale-free normalisation (default) or absolute values.
    pub noise: DpNoise,
    /// The core configuration less its scale.
    pub config: DpSettings,
}

impl DpFile {
    /// The core configuration before the data are seen (the robust mode's at
    /// `lsb = 2^-5`).
    pub fn nominal(&self) -> DpConfig {
        match self.noise {
            DpNoise::Robust { design_snr } => self.config.config(ROBUST_LSB, 1.0, design_snr),
            DpNoise::AsIs {
                lsb,
                sigma,
                a_design,
            } => self.config.config(lsb, sigma, a_design),
        }
    }
}

pub(super) fn default_dp(method: Method) -> String {
    json(&DpFile {
        q_b: 9,
        noise: DpNoise::Robust { design_snr: 2.0 },
        config: DpSettings::of(&DpConfig::dim_point(method, 1)),
    })
}

/// The robust noise estimate of a file: `(level, sigma)` = (median, `1.4826 MAD`) of
/// every pixel of every frame; `None` for no pixels.
pub fn robust_noise(data: &[f32]) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = data.iter().map(|&x| f64::from(x)).collect();
    let level = median(&mut v)?;
    for x in v.iter_mut() {
        *x = (*x - level).abs();
    }
    Some((level, MAD_TO_STD * median(&mut v)?))
}

/// A DP report as one line of `reports.json`, with the scale the run used.
#[derive(Serialize)]
struct DpReportJson {
    frame: u32,
    best_x: u16,
    best_y: u16,
    best_merit: f32,
    clamped: u32,
    noise_level: f64,
    noise_sigma: f64,
    lsb: f32,
}

pub(super) fn run_dp(req: &Request, name: &'static str, method: Method) -> Result<Outcome> {
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
        if let DpNoise::Robust { design_snr } = f.noise {
            ensure!(
                design_snr.is_finite() && (0.01..=1000.0).contains(&design_snr),
                "noise.robust.design_snr = {design_snr}: must lie in [0.01, 1000] (a / sigma)"
            );
        }
        f.nominal().validate().map_err(|e| anyhow!("{e}"))
    })?;
    let mut images = read_real_frames(req.input, 3)?;
    let (h, w) = (images.shape[1], images.shape[2]);
    let largest = CAPACITIES[CAPACITIES.len() - 1];
    let m = capacity(h, w).ok_or_else(|| {
        anyhow!(
            "{}: images of {h} x {w} (H x W); the DP detectors take (K, H, W) with H, W up to {largest}",
            req.input.display()
        )
    })?;
    let mut cfg = file.nominal();
    let (mut level, mut sigma) = (0.0, 1.0);
    if let DpNoise::Robust { .. } = file.noise {
        (level, sigma) = normalise(req, &mut images.data)?;
        let big = images.data.iter().fold(0.0f32, |a, z| a.max(z.abs()));
        while big * (1.0 / cfg.lsb) > i16::ZMAX as f32 && cfg.lsb < 1e19 {
            cfg.lsb *= 2.0;
        }
        cfg.validate()
            .map_err(|e| anyhow!("{}: {e}", req.input.display()))?;
    } else if let DpNoise::AsIs { sigma: s, .. } = file.noise {
        sigma = f64::from(s);
    }
    refuse_clamped(req, &cfg, &images.data, h, w)?;
    let k = images.frames();
    let padded = (h, w) != (m, m);
    if padded {
        let fill = -((i16::ZMAX - 1) as f32) * cfg.lsb;
        images.data = pad_image(&images.data, k, h, w, m, fill);
    }
    let read = cpu() - t;
    let lsb = cfg.lsb;
    let report_json = |r: &DpReport| {
        serde_json::to_string(&DpReportJson {
            frame: r.frame,
            best_x: r.best.x,
            best_y: r.best.y,
            best_merit: r.best.merit,
            clamped: r.clamped,
            noise_level: level,
            noise_sigma: sigma,
            lsb,
        })
        .unwrap_or_default()
    };
    let n = m * m;
    let mut out = with_dp_sized!(method, file.q_b, m, &cfg, |det| {
        let mut det = det;
        drive_with(
            name,
            det.as_mut(),
            images.data.chunks_exact(n),
            req,
            XY_POSITION,
            report_json,
        )?
    });
    if padded {
        // Track ends in the padding (possible only for states held near the merit floor).
        out.rows
            .retain(|r| r.state.first() < Some(&(w as f32)) && r.state.get(1) < Some(&(h as f32)));
    }
    out.read_seconds = read;
    Ok(out)
}

/// Replaces every pixel by `(z - level) / sigma` (computed in `f64`) and returns
/// `(level, sigma)` ([`robust_noise`]); a zero `sigma` is an error.
fn normalise(req: &Request, data: &mut [f32]) -> Result<(f64, f64)> {
    let p = req.input.display();
    let (level, sigma) = robust_noise(data).ok_or_else(|| anyhow!("{p}: no pixels"))?;
    if !(sigma > 0.0 && sigma.is_finite()) {
        bail!(
            "{p}: the pixels' median absolute deviation is {sigma}: no noise scale to normalise by (use \"noise\": {{\"as-is\": ...}} with absolute values)"
        );
    }
    for z in data.iter_mut() {
        *z = ((f64::from(*z) - level) / sigma) as f32;
    }
    Ok((level, sigma))
}

/// Refuses input the quantiser would clamp (the core clamps and counts such pixels; here
/// they are an error naming the first one, before the detector runs): frame `k`, pixel
/// `(x, y)` of a row-major `h x w` frame.
fn refuse_clamped(req: &Request, cfg: &DpConfig, data: &[f32], h: usize, w: usize) -> Result<()> {
    let n = (h * w).max(1);
    for (k, frame) in data.chunks(n).enumerate() {
        if let Some(i) = first_clamped::<i16>(cfg, frame) {
            let lim = i16::ZMAX as f32 * cfg.lsb;
            bail!(
                "{}: frame {k}, pixel (x, y) = ({}, {}) is {}, outside the DP quantiser's range +-{lim} ({} LSB of lsb = {}); use the default \"noise\": {{\"robust\": ...}} or raise lsb",
                req.input.display(),
                i % w,
                i / w,
                frame[i],
                i16::ZMAX,
                cfg.lsb
            );
        }
    }
    Ok(())
}
