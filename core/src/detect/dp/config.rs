//! The DP-TBD configuration: the recursion, the quantiser's LSB, the transition term and
//! the Pulford filter, and its validation.

use crate::detect::Validate;
use crate::{math, Error, Result};

/// Most track ends a detector reports ([`DpConfig::top_k`]).
pub const MAX_ENDS: usize = 8;

/// Which recursion a [`DpConfig`] asks for (each detector type runs one).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum Method {
    /// First-order DP with a hard `q_B` window (Barniv 1985, Arnold et al. 1993): [`ArnoldDp`](super::ArnoldDp).
    Arnold,
    /// First-order DP with a Kalman velocity gate (Pulford, La Scala 2010): [`PulfordDp`](super::PulfordDp).
    Pulford,
    /// Second-order DP over state pairs (Wang, Zhang 2016): [`SecondOrderDp`](super::SecondOrderDp).
    SecondOrder,
}

impl Method {
    /// Short name (`arnold`, `pulford`, `second_order`).
    pub const fn name(self) -> &'static str {
        match self {
            Method::Arnold => "arnold",
            Method::Pulford => "pulford",
            Method::SecondOrder => "second_order",
        }
    }
}

/// The second-order transition term.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum Transition {
    /// `g(e) = (sigma^2 / a_design) ln p(e)`, `p` the Gaussian of eq. 16 normalised over
    /// the 9 pixels of `R_I` (the paper's).
    Gaussian,
    /// `g = 0`: a hard `R_I` window (ablation).
    Hard,
}

/// Runtime configuration of the DP-TBD detectors (one struct for the three recursions;
/// fields a recursion does not use are ignored by it but still validated).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct DpConfig {
    /// The recursion; must be the detector type's ([`ArnoldDp`](super::ArnoldDp): `Arnold`, ...).
    pub method: Method,
    /// Intensity of one merit LSB: pixels are quantised to `round(z / lsb)`. A power of
    /// two keeps the scaling exact. Preset: `2^-4` (`sigma / 24` at `sigma = 1.5`).
    pub lsb: f32,
    /// Noise standard deviation `sigma` (intensity), scales the transition term.
    pub sigma: f32,
    /// Design amplitude `a_design` (intensity): the transition term is `ln p` in units of
    /// the Gaussian log-likelihood ratio, `sigma^2 / a_design` per nat.
    pub a_design: f32,
    /// `sigma_I` (pixels) of the Gaussian transition (eq. 16-17: `Delta/2` for
    /// `P_miss = 0.01`).
    pub sigma_i: f32,
    /// Second order: Gaussian transition term or hard window.
    pub transition: Transition,
    /// Pulford: initial covariance `P0 = p0 I_4` (px^2, (px/frame)^2); paper `E` at
    /// 1 px/frame (`p0 = 1`) and `4E` at 2 px/frame.
    pub p0: f32,
    /// Pulford: process noise `Q = q G G^T`, `G = [1/2, 1]^T` per axis (px^2/frame^3).
    pub q: f32,
    /// Pulford: measurement variance `R` (px^2), `Delta^2 / 12` (pixel quantisation).
    pub r: f32,
    /// Pulford: half-width of the gate `R_theta(k-1)` around the prediction (1: 3x3).
    pub gate: u8,
    /// Number of distinct track ends reported as detections, `1..=MAX_ENDS`.
    pub top_k: u8,
    /// Two reported ends are distinct when their Chebyshev distance exceeds this (px).
    pub separation: u16,
}

impl DpConfig {
    /// The configuration of an unconfigured detector: all-zero bits (it fails
    /// validation), so an unconfigured detector is all zeros and a `static` of it lands
    /// in `.bss`.
    pub(crate) const UNSET: Self = Self {
        method: Method::Arnold,
        lsb: 0.0,
        sigma: 0.0,
        a_design: 0.0,
        sigma_i: 0.0,
        transition: Transition::Gaussian,
        p0: 0.0,
        q: 0.0,
        r: 0.0,
        gate: 0,
        top_k: 0,
        separation: 0,
    };

    /// The `dim-point` preset (Wang, Zhang 2016, §4): noise `sigma = 1.5`, design
    /// amplitude `a = 2 sigma = 3` (SNR 2.0, the analysis figure's), `sigma_I = 0.5` px,
    /// Gaussian transition, Pulford `P0 = speed^2 E` (`E` at 1 px/frame, `4E` at
    /// 2 px/frame), `q = 0.05`, `R = 1/12`, 3x3 gate, `lsb = 2^-4`, one reported end.
    pub const fn dim_point(method: Method, speed_px: u8) -> Self {
        let s = speed_px as f32;
        Self {
            method,
            lsb: 0.0625,
            sigma: 1.5,
            a_design: 3.0,
            sigma_i: 0.5,
            transition: Transition::Gaussian,
            p0: s * s,
            q: 0.05,
            r: 1.0 / 12.0,
            gate: 1,
            top_k: 1,
            separation: 2,
        }
    }
}

fn positive(x: f32) -> bool {
    x.is_finite() && x > 0.0
}

impl Validate for DpConfig {
    fn validate(&self) -> Result<()> {
        if !(self.lsb.is_finite() && (1e-20..=1e20).contains(&self.lsb)) {
            return Err(Error::InvalidConfig("lsb"));
        }
        if !positive(self.sigma) {
            return Err(Error::InvalidConfig("sigma"));
        }
        if !positive(self.a_design) {
            return Err(Error::InvalidConfig("a_design"));
        }
        if !(positive(self.sigma_i) && self.sigma_i >= 0.05) {
            return Err(Error::InvalidConfig("sigma_i"));
        }
        if !positive(self.p0) {
            return Err(Error::InvalidConfig("p0"));
        }
        if !(self.q.is_finite() && self.q >= 0.0) {
            return Err(Error::InvalidConfig("q"));
        }
        if !positive(self.r) {
            return Err(Error::InvalidConfig("r"));
        }
        if !(1..=3).contains(&self.gate) {
            return Err(Error::InvalidConfig("gate"));
        }
        if self.top_k == 0 || usize::from(self.top_k) > MAX_ENDS {
            return Err(Error::InvalidConfig("top_k"));
        }
        let table = transition_table(self);
        if table.iter().any(|&g| !(-(1 << 20)..=0).contains(&g)) {
            return Err(Error::InvalidConfig("transition term out of range"));
        }
        Ok(())
    }
}

/// The second-order transition term `g(e)` in LSB for `e = (ex, ey)`, index
/// `(ey + 1) * 3 + (ex + 1)`: `round(ln p(e) sigma^2 / (a_design lsb))` (Gaussian) or 0.
pub fn transition_table(cfg: &DpConfig) -> [i32; 9] {
    let mut t = [0i32; 9];
    if cfg.transition == Transition::Hard {
        return t;
    }
    let s2 = 2.0 * cfg.sigma_i * cfg.sigma_i;
    let mut z = 0.0f32;
    for ey in -1i32..=1 {
        for ex in -1i32..=1 {
            z += math::exp(-((ex * ex + ey * ey) as f32) / s2);
        }
    }
    let ln_z = math::ln(z);
    let scale = cfg.sigma * cfg.sigma / (cfg.a_design * cfg.lsb);
    for (i, g) in t.iter_mut().enumerate() {
        let ex = (i % 3) as i32 - 1;
        let ey = (i / 3) as i32 - 1;
        let lnp = -((ex * ex + ey * ey) as f32) / s2 - ln_z;
        let v = math::round(lnp * scale);
        *g = if v.is_finite() && v > -2.0e9 {
            v as i32
        } else {
            i32::MIN
        };
    }
    t
}
