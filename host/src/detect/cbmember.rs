//! CBMeMBer TBD on range x velocity power maps.
//!
//! The configuration file is `{"noise", "snr_db", "config"}` as for the PHD family
//! ([`super::phd`]): with `"noise": "estimate"` (the default) every map is divided by its
//! noise power (median pixel power over `ln 2`), `config.noise_var` is `0.5`,
//! `config.gain` makes `rho` the linear peak SNR (eq. 19) at the map's centre range, and
//! births draw `rho = 10^(U[lo, hi] / 10)` from `snr_db.birth`; `"noise": "as-is"` takes
//! the map and `config` in absolute units (the preset).
//!
//! `"spread"` sets the measurement model's spread `config.spread`: `{"geometry": {...}}`
//! (the default file) derives it from the map's geometry, the slow-time window, the
//! range resolution and the blades' velocity sweep within a CPI
//! ([`RdSpread::from_geometry`]); `"config"` (also when the key is absent) takes
//! `config.spread` as written (the paper's fixed `zeta_r = 3` m, `zeta_v = 5` m/s).

use anyhow::{anyhow, bail, ensure, Result};
use faint_core::detect::cbmember::{gain_for_snr, BirthPlacement, CbmemberConfig};
use faint_core::detect::{Detector, Validate};
use faint_core::model::doppler::Window;
use faint_core::model::range_doppler::{PointModel, RdSpread};
use serde::{Deserialize, Serialize};

use super::phd::normalise;
use super::{drive, find_default, json, load, NoiseLevel, Outcome, Request};
use crate::instances::cbmember::HostFilter as CbmemberHost;
use crate::io::input::read_real_frames;
use crate::timing::thread_cpu_seconds as cpu;

/// Scale-dependent values of the CBMeMBer configuration in dB over the noise power.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CbmemberSnr {
    /// Birth peak SNR (eq. 19) `U[lo, hi]` dB.
    pub birth: [f32; 2],
}

/// How the spread of the measurement model is set.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum SpreadFrom {
    /// `config.spread` as written.
    #[default]
    Config,
    /// From the map's geometry ([`RdSpread::from_geometry`]).
    Geometry(GeometrySpread),
}

/// What [`RdSpread::from_geometry`] needs beyond `config.geometry`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeometrySpread {
    /// Window across the pulses of the slow-time DFT.
    pub window: Window,
    /// Range resolution of the compressed pulse (m).
    pub range_resolution_m: f32,
    /// Velocity a blade sweeps within a CPI (m/s; 0 for the body alone), uniform.
    pub blade_sweep_m_per_s: f32,
}

impl GeometrySpread {
    /// The spread for `c`'s geometry.
    pub fn spread(&self, c: &CbmemberConfig) -> Result<RdSpread> {
        RdSpread::from_geometry(
            &c.geometry,
            self.window,
            self.range_resolution_m,
            self.blade_sweep_m_per_s,
        )
        .ok_or_else(|| {
            anyhow!(
                "spread.geometry: range_resolution_m must be finite and > 0 and \
                 blade_sweep_m_per_s finite and >= 0 (got {} and {})",
                self.range_resolution_m,
                self.blade_sweep_m_per_s
            )
        })
    }
}

/// The blade sweep of the rotor-UAV preset's rotor within one CPI, as an rms over the
/// blade phase: `V omega CPI / sqrt(2)` with `V = 10` m/s, `omega = 0.06 pi` rad/s and
/// `CPI = lambda / (2 velocity_bin)` (`lambda = 0.03` m, 0.192 s on the default map):
/// 0.256 m/s.
pub fn rotor_uav_blade_sweep(c: &CbmemberConfig) -> f32 {
    let cpi = 0.03 / (2.0 * f64::from(c.geometry.velocity_bin));
    (10.0 * 0.06 * std::f64::consts::PI * cpi / std::f64::consts::SQRT_2) as f32
}

/// `faint detect`'s configuration file for CBMeMBer.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CbmemberFile {
    /// The input's scale (`"estimate"` or `"as-is"`).
    #[serde(default)]
    pub noise: NoiseLevel,
    /// SNR values (required with `"estimate"`, refused with `"as-is"`).
    #[serde(default)]
    pub snr_db: Option<CbmemberSnr>,
    /// How `config.spread` is set (absent: `"config"`).
    #[serde(default)]
    pub spread: SpreadFrom,
    /// The core configuration.
    pub config: CbmemberConfig,
}

/// Default birth SNR: -5 to 15 dB (the paper's Pd sweep lies around 0 dB).
pub const DEFAULT_CBMEMBER_SNR: CbmemberSnr = CbmemberSnr {
    birth: [-5.0, 15.0],
};

/// `gain` that makes `rho` the linear peak SNR at the centre range of `c`'s map with
/// `noise_var = 0.5`.
fn unit_gain(c: &CbmemberConfig) -> f32 {
    let g = c.geometry;
    let centre = g.range_start + 0.5 * g.n_range as f32 * g.range_bin;
    gain_for_snr(0.0, centre, 1.0, 0.5)
}

impl CbmemberFile {
    /// The configuration the filter runs (see the module doc). Errors: a value `snr_db`
    /// sets that differs in `config`, `snr_db` with `"as-is"` or missing with
    /// `"estimate"`, a non-finite or inverted dB range.
    pub fn effective(&self) -> Result<CbmemberConfig> {
        let c = self.config;
        match (self.noise, self.snr_db) {
            (NoiseLevel::AsIs, None) => {}
            (NoiseLevel::AsIs, Some(_)) => {
                bail!(
                    "snr_db is only used with \"noise\": \"estimate\"; remove it or the noise line"
                )
            }
            (NoiseLevel::Estimate, None) => {
                bail!("\"noise\": \"estimate\" needs snr_db {{\"birth\": [lo, hi]}}")
            }
            (NoiseLevel::Estimate, Some(s)) => {
                let [lo, hi] = s.birth;
                ensure!(
                    lo.is_finite() && hi.is_finite() && lo <= hi && hi <= 250.0,
                    "snr_db.birth must be finite dB with lo <= hi <= 250, got [{lo}, {hi}]"
                );
                let gain = unit_gain(&c);
                for (name, same) in [
                    ("config.noise_var", c.noise_var == 0.5),
                    ("config.gain", c.gain == gain),
                    ("config.birth.rho_db", c.birth.rho_db == Some(s.birth)),
                ] {
                    ensure!(
                        same,
                        "{name} is set by \"noise\": \"estimate\" and snr_db (noise_var 0.5, \
                         gain {gain}, birth.rho_db {:?}); edit snr_db, or use \"noise\": \"as-is\"",
                        s.birth
                    );
                }
            }
        }
        if let SpreadFrom::Geometry(gs) = self.spread {
            let want = gs.spread(&c)?;
            ensure!(
                c.spread == want,
                "config.spread is set by \"spread\": {{\"geometry\": ..}} (zeta_r {}, zeta_v {} \
                 for this geometry); write those values, or use \"spread\": \"config\"",
                want.zeta_r,
                want.zeta_v
            );
        }
        c.validate().map_err(|e| anyhow!("{e}"))?;
        Ok(c)
    }
}

/// The default configuration file for `model`: the rotor-UAV filter with births placed
/// from the data ([`BirthPlacement::RangePeak`]) and SNR-relative power.
pub fn default_cbmember_file(model: PointModel) -> CbmemberFile {
    let mut c = CbmemberConfig {
        model,
        ..CbmemberConfig::rotor_uav()
    };
    let s = DEFAULT_CBMEMBER_SNR;
    c.noise_var = 0.5;
    c.gain = unit_gain(&c);
    c.birth.rho_db = Some(s.birth);
    c.birth.placement = BirthPlacement::RangePeak;
    c.birth.range[1] = c.spread.zeta_r / 2.0;
    // rho is the linear SNR: a random walk of 5 % of a 0 dB target per frame.
    c.process.rho = 0.05;
    let gs = GeometrySpread {
        window: Window::Hamming,
        range_resolution_m: c.geometry.range_bin,
        blade_sweep_m_per_s: match model {
            PointModel::Joint => rotor_uav_blade_sweep(&c),
            PointModel::DopplerOnly => 0.0,
        },
    };
    apply_geometry_spread(&mut c, &gs);
    CbmemberFile {
        noise: NoiseLevel::Estimate,
        snr_db: Some(s),
        spread: SpreadFrom::Geometry(gs),
        config: c,
    }
}

/// Sets `c.spread` from `gs` and the values tied to the spread: the birth range std
/// (`zeta_r / 2`) and the likelihood (the exact form: a block of 16 velocity bins would
/// be wider than the spread).
fn apply_geometry_spread(c: &mut CbmemberConfig, gs: &GeometrySpread) {
    if let Ok(s) = gs.spread(c) {
        c.spread = s;
    }
    c.birth.range[1] = c.spread.zeta_r / 2.0;
    c.likelihood = faint_core::detect::cbmember::Likelihood::Exact;
}

pub(super) fn default_cbmember(model: PointModel) -> String {
    json(&default_cbmember_file(model))
}

pub(super) fn run_cbmember(
    req: &Request,
    name: &'static str,
    model: PointModel,
) -> Result<Outcome> {
    let t = cpu();
    let default = match model {
        PointModel::Joint => find_default("cbmember"),
        PointModel::DopplerOnly => find_default("cbmember-doppler"),
    };
    let file: CbmemberFile = load(req, default, |f: &CbmemberFile| f.effective().map(|_| ()))?;
    let cfg = file.effective()?;
    let mut maps = read_real_frames(req.input, 3)?;
    let g = cfg.geometry;
    let want = [g.n_range, g.n_velocity];
    ensure!(
        maps.shape[1..] == want,
        "{}: maps of shape {:?}, the config's geometry is (n_range, n_velocity) = {:?}",
        req.input.display(),
        &maps.shape[1..],
        want
    );
    if file.noise == NoiseLevel::Estimate {
        normalise(&mut maps, &req.input.display().to_string())?;
    }
    let read = cpu() - t;
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
