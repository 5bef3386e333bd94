//! The motion of eq. 16 ([`Motion`]) and the birth box ([`PriorBox`]).

use crate::rng::Rng;
use crate::{Error, Result};

/// Axis-aligned box `I_x0` of births and initial particles, `x ~ U(I_x0)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct PriorBox {
    /// Doppler range (Hz).
    pub fd: (f32, f32),
    /// Doppler-rate range (Hz/s).
    pub fda: (f32, f32),
    /// Amplitude range (time-domain units).
    pub amp: (f32, f32),
}

impl PriorBox {
    /// Checks the ranges are finite with `lo <= hi` and a non-negative amplitude.
    pub fn validate(&self) -> Result<()> {
        for (lo, hi) in [self.fd, self.fda, self.amp] {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(Error::InvalidConfig("prior box range"));
            }
        }
        if self.amp.0 < 0.0 {
            return Err(Error::InvalidConfig("prior box amplitude"));
        }
        Ok(())
    }

    /// One draw from `U(I_x0)`.
    #[inline]
    pub fn sample(&self, rng: &mut Rng) -> [f32; 3] {
        [
            rng.uniform_range(self.fd.0, self.fd.1),
            rng.uniform_range(self.fda.0, self.fda.1),
            rng.uniform_range(self.amp.0, self.amp.1),
        ]
    }
}

/// The constant-Doppler-rate motion of eq. 16.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Frame time `dT` (s).
    pub dt: f32,
    /// Standard deviation of `v1`, the Doppler acceleration (Hz/s^2).
    pub accel_std: f32,
    /// Standard deviation of `v2`, the amplitude drift rate (1/s).
    pub amp_std: f32,
    /// Doppler band `[lo, hi)`; Doppler is wrapped into it (the DFT is periodic).
    pub band: (f32, f32),
}

impl Motion {
    /// Checks the values are finite, `dt > 0`, stds `>= 0`, band non-empty.
    pub fn validate(&self) -> Result<()> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::InvalidConfig("frame time dT"));
        }
        if !(self.accel_std >= 0.0
            && self.accel_std.is_finite()
            && self.amp_std >= 0.0
            && self.amp_std.is_finite())
        {
            return Err(Error::InvalidConfig("process noise std"));
        }
        if !(self.band.0.is_finite() && self.band.1.is_finite() && self.band.0 < self.band.1) {
            return Err(Error::InvalidConfig("Doppler band"));
        }
        Ok(())
    }

    /// Width of the Doppler band `W` (Hz).
    #[inline]
    pub fn band_width(&self) -> f32 {
        self.band.1 - self.band.0
    }

    /// The offset `fd - reference` brought into `[-W/2, W/2]` by one band width `width`
    /// (`W`, from [`band_width`](Self::band_width)): what a weighted Doppler mean
    /// averages, so that a cloud across the band edge is not split; the mean is then
    /// `wrap(reference + sum w d / sum w)`. Used by every Doppler-frame detector's
    /// estimate.
    #[inline(always)]
    pub fn wrap_offset(fd: f32, reference: f32, width: f32) -> f32 {
        let d = fd - reference;
        if d > 0.5 * width {
            d - width
        } else if d < -0.5 * width {
            d + width
        } else {
            d
        }
    }

    /// Wraps a Doppler into the band: by one band width (the usual case), else by as many
    /// as it takes (`fd - W floor((fd - lo) / W)`, kept inside `[lo, hi)`); NaN or
    /// infinity becomes `lo`.
    #[inline]
    pub fn wrap(&self, fd: f32) -> f32 {
        let w = self.band.1 - self.band.0;
        let r = if fd >= self.band.1 {
            fd - w
        } else if fd < self.band.0 {
            fd + w
        } else {
            return fd;
        };
        if r >= self.band.0 && r < self.band.1 {
            r
        } else {
            self.wrap_far(fd)
        }
    }

    #[cold]
    #[inline(never)]
    fn wrap_far(&self, fd: f32) -> f32 {
        let (lo, hi) = self.band;
        let w = hi - lo;
        if !fd.is_finite() {
            return lo;
        }
        let k = crate::math::floor((fd - lo) / w);
        let r = fd - k * w;
        if r >= lo && r < hi {
            r
        } else {
            lo
        }
    }

    /// `F x` (Doppler wrapped).
    #[inline]
    pub fn predict(&self, x: [f32; 3]) -> [f32; 3] {
        [self.wrap(x[0] + self.dt * x[1]), x[1], x[2]]
    }

    /// `F x + G v`, `v ~ N(0, diag(accel_std^2, amp_std^2))` (Doppler wrapped, amplitude
    /// kept non-negative by reflection).
    #[inline]
    pub fn propagate(&self, x: [f32; 3], rng: &mut Rng) -> [f32; 3] {
        let v1 = rng.normal() * self.accel_std;
        let v2 = rng.normal() * self.amp_std;
        let dt = self.dt;
        let a = x[2] + dt * v2;
        [
            self.wrap(x[0] + dt * x[1] + 0.5 * dt * dt * v1),
            x[1] + dt * v1,
            if a < 0.0 { -a } else { a },
        ]
    }
}
