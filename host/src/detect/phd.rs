//! The PHD family on range x Doppler x azimuth power cubes.
//!
//! The configuration file is `{"noise", "snr_db", "config"}`: with `"noise": "estimate"`
//! (the default) every frame is divided by its noise power, estimated as the median cell
//! power over `ln 2` (the median of exponential noise powers is `ln 2` times their mean;
//! a few target cells among a cube's ~10^6 do not move it), so the cube's noise power is
//! 1, `config.noise_var` is `0.5` and the intensities are set in dB over the noise from
//! `snr_db`; `"noise": "as-is"` takes the cube and every value of `config` in the file's
//! own units (the presets).

use anyhow::{anyhow, bail, ensure, Result};
use faint_core::detect::phd::{BirthMode, PhdConfig};
use serde::{Deserialize, Serialize};

use faint_core::detect::{Detector, Validate};

use super::{drive, find_default, json, load, NoiseLevel, Outcome, Request};
use crate::instances::phd::HostFilter;
use crate::io::input::{read_real_frames, Frames};
use crate::simulate::phd::SixTargets;
pub(super) use crate::simulate::phd::Variant;
use crate::stats::noise::{exponential_mean, median};
use crate::timing::thread_cpu_seconds as cpu;

/// The state indices of the PHD state's position `(x, y)`.
const PHD_POSITION: &[usize] = &[0, 2];

/// Scale-dependent values of the PHD configuration in dB over the noise power.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhdSnr {
    /// Birth intensities `I ~ U[10^(lo/10), 10^(hi/10)]` (target power over noise power).
    pub birth: [f32; 2],
    /// Lower clamp of the predicted intensity (`min_intensity`).
    pub floor: f32,
}

/// `faint detect`'s configuration file for the PHD family.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PhdFile {
    /// The input's scale (`"estimate"` or `"as-is"`).
    #[serde(default)]
    pub noise: NoiseLevel,
    /// Intensities in dB (required with `"estimate"`, refused with `"as-is"`).
    #[serde(default)]
    pub snr_db: Option<PhdSnr>,
    /// The core configuration.
    pub config: PhdConfig,
}

/// `10^(db / 10)`.
pub(super) fn from_db(db: f32) -> f32 {
    10f32.powf(db / 10.0)
}

/// The default SNR values: births `U[4, 12]` dB (the papers' 5-9 dB with a margin),
/// intensity floor -4 dB (the preset's `0.05 P` at 9 dB).
pub const DEFAULT_SNR: PhdSnr = PhdSnr {
    birth: [4.0, 12.0],
    floor: -4.0,
};

/// Peaks of the region birth in the default configuration.
pub const DEFAULT_REGION_CELLS: usize = 32;

impl PhdFile {
    /// The configuration the filter runs: `config` with the `snr_db` values applied in
    /// noise units. Errors: a value `snr_db` sets that differs in `config`, `snr_db` with
    /// `"as-is"` or missing with `"estimate"`, a non-finite or inverted dB value.
    pub fn effective(&self) -> Result<PhdConfig> {
        let mut c = self.config;
        match (self.noise, self.snr_db) {
            (NoiseLevel::AsIs, None) => {}
            (NoiseLevel::AsIs, Some(_)) => {
                bail!(
                    "snr_db is only used with \"noise\": \"estimate\"; remove it or the noise line"
                )
            }
            (NoiseLevel::Estimate, None) => {
                bail!("\"noise\": \"estimate\" needs snr_db {{\"birth\": [lo, hi], \"floor\": dB}}")
            }
            (NoiseLevel::Estimate, Some(s)) => {
                let [lo, hi] = s.birth;
                ensure!(
                    lo.is_finite() && hi.is_finite() && lo <= hi && hi <= 250.0,
                    "snr_db.birth must be finite dB with lo <= hi <= 250, got [{lo}, {hi}]"
                );
                ensure!(
                    s.floor.is_finite() && s.floor <= 250.0,
                    "snr_db.floor must be finite dB <= 250, got {}",
                    s.floor
                );
                let want = (0.5, [from_db(lo), from_db(hi)], from_db(s.floor));
                for (name, same) in [
                    ("config.noise_var", c.noise_var == want.0),
                    ("config.birth.intensity", c.birth.intensity == want.1),
                    ("config.min_intensity", c.min_intensity == want.2),
                ] {
                    ensure!(
                        same,
                        "{name} is set by \"noise\": \"estimate\" and snr_db (noise_var {}, \
                         intensity {:?}, min_intensity {}); edit snr_db, or use \"noise\": \"as-is\"",
                        want.0,
                        want.1,
                        want.2
                    );
                }
                c.noise_var = want.0;
                c.birth.intensity = want.1;
                c.min_intensity = want.2;
            }
        }
        c.validate().map_err(|e| anyhow!("{e}"))?;
        Ok(c)
    }
}

/// Divides every frame of `frames` by its noise power `median / ln 2` (see the module
/// doc). Errors: a frame whose median is 0 or not finite (no noise to normalise by).
pub(super) fn normalise(frames: &mut Frames<f32>, what: &str) -> Result<()> {
    let n = frames.frame_len();
    if n == 0 {
        return Ok(());
    }
    for (k, f) in frames.data.chunks_mut(n).enumerate() {
        normalise_frame(f).map_err(|m| {
            anyhow!(
                "{what}: frame {k}: the median cell power is {m}, no noise level to normalise \
                 by; use \"noise\": \"as-is\" with absolute values"
            )
        })?;
    }
    Ok(())
}

/// Divides one frame by its noise power `median / ln 2` ([`exponential_mean`]) and
/// returns that power; `Err(median)` if it is 0 or not finite (frame unchanged).
pub fn normalise_frame(f: &mut [f32]) -> Result<f32, f32> {
    if f.is_empty() {
        return Ok(1.0);
    }
    let Some(noise) = exponential_mean(f.iter().map(|&x| f64::from(x))) else {
        let mut v: Vec<f64> = f.iter().map(|&x| f64::from(x)).collect();
        return Err(median(&mut v).unwrap_or(0.0) as f32);
    };
    let noise = noise as f32;
    if !(noise.is_finite() && noise > 0.0) {
        return Err(noise);
    }
    for v in f.iter_mut() {
        *v /= noise;
    }
    Ok(noise)
}

/// `faint detect`'s default for `v`: the six-targets preset's filter with births over
/// the whole cube ([`BirthMode::Region`], the preset's birth points only reach targets
/// born near them) and the input normalised to unit noise power.
pub(super) fn default_phd(v: Variant) -> String {
    json(&default_phd_file(v))
}

/// The default configuration file of `v`: the six-targets preset's filter with births
/// over the whole cube ([`BirthMode::Region`]) and the input normalised to unit noise
/// power (`"noise": "estimate"`). PHD-TBD extracts its states by DBSCAN (the preset's
/// `E`, `Th_min`), not by the paper's K-means: on the physics simulator's cubes it is
/// no worse in Pd at the same measured Pfa and better in OSPA (docs/phd.md).
pub fn default_phd_file(v: Variant) -> PhdFile {
    let preset = match v {
        Variant::PhdTbd => Variant::PhdDbscan,
        v => v,
    };
    let mut config = SixTargets::new(9.0).config(preset);
    let s = DEFAULT_SNR;
    config.noise_var = 0.5;
    config.birth.intensity = [from_db(s.birth[0]), from_db(s.birth[1])];
    config.min_intensity = from_db(s.floor);
    config.birth.n_components = 0;
    config.birth.mode = BirthMode::Region {
        cells: DEFAULT_REGION_CELLS,
        tangential_std: 40.0,
    };
    PhdFile {
        noise: NoiseLevel::Estimate,
        snr_db: Some(s),
        config,
    }
}

pub(super) fn run_phd(req: &Request, name: &'static str) -> Result<Outcome> {
    let t = cpu();
    let default = find_default(name);
    let file: PhdFile = load(req, default, |f: &PhdFile| f.effective().map(|_| ()))?;
    let cfg = file.effective()?;
    let mut cubes = read_real_frames(req.input, 4)?;
    let g = cfg.geometry;
    let want = [g.n_range, g.n_doppler, g.n_azimuth];
    ensure!(
        cubes.shape[1..] == want,
        "{}: cubes of shape {:?}, the config's geometry is (n_range, n_doppler, n_azimuth) = {:?}",
        req.input.display(),
        &cubes.shape[1..],
        want
    );
    if file.noise == NoiseLevel::Estimate {
        normalise(&mut cubes, &req.input.display().to_string())?;
    }
    let read = cpu() - t;
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
