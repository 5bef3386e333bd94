//! Integer merits: the merit cell types and the input quantiser `q = round(z / lsb)`.

use super::config::DpConfig;
use crate::{Error, Result};

/// The storage type of a merit (sealed: `i16` and `i8`).
pub trait MeritCell: Copy + PartialEq + core::fmt::Debug + sealed::Sealed {
    /// The zero value (for `const` constructors).
    const ZERO: Self;
    /// The lowest stored merit (LSB, relative to the previous frame's best).
    const FLOOR: i32;
    /// Largest quantised pixel magnitude (LSB); pixels beyond are clamped.
    const ZMAX: i32;
    /// The value.
    fn get(self) -> i32;
    /// `v` saturated to the cell's range.
    fn sat(v: i32) -> Self;
}

mod sealed {
    pub trait Sealed {
        /// `v` (already in the cell's range) as a cell.
        fn trunc(v: i32) -> Self;
    }
    impl Sealed for i16 {
        #[inline(always)]
        fn trunc(v: i32) -> Self {
            v as i16
        }
    }
    impl Sealed for i8 {
        #[inline(always)]
        fn trunc(v: i32) -> Self {
            v as i8
        }
    }
}

impl MeritCell for i16 {
    const ZERO: Self = 0;
    const FLOOR: i32 = i16::MIN as i32;
    const ZMAX: i32 = 16384;
    #[inline(always)]
    fn get(self) -> i32 {
        i32::from(self)
    }
    #[inline(always)]
    fn sat(v: i32) -> Self {
        v.clamp(i16::MIN as i32, i16::MAX as i32) as i16
    }
}

impl MeritCell for i8 {
    const ZERO: Self = 0;
    const FLOOR: i32 = i8::MIN as i32;
    const ZMAX: i32 = 63;
    #[inline(always)]
    fn get(self) -> i32 {
        i32::from(self)
    }
    #[inline(always)]
    fn sat(v: i32) -> Self {
        v.clamp(i8::MIN as i32, i8::MAX as i32) as i8
    }
}

/// Input quantiser of one configuration: `q = round(z / lsb)` clamped to `+-zmax`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Quant {
    pub(crate) inv_lsb: f32,
    /// `(256 - e) << 23`, `e` the biased exponent of the largest power of two `2^e'`
    /// with `2^e' / lsb <= zmax`: `(bits & EXP) + large_add` sets bit 31 exactly for
    /// `|z| >= 2^e'` (and NaN/inf).
    large_add: u32,
    zmax: f32,
}

const EXP_MASK: u32 = 0x7F80_0000;
/// `1.5 * 2^23`: adding it rounds `|y| < 2^22` to an integer held in the low mantissa bits.
pub(crate) const MAGIC: f32 = 12_582_912.0;
pub(crate) const MAGIC_BITS: i32 = 0x4B40_0000;

impl Quant {
    pub(crate) const fn zero() -> Self {
        Self {
            inv_lsb: 0.0,
            large_add: 0,
            zmax: 0.0,
        }
    }

    pub(crate) fn new(lsb: f32, zmax: i32) -> Result<Self> {
        let inv_lsb = 1.0 / lsb;
        let lim = zmax as f32 * lsb;
        let e = (lim.to_bits() & EXP_MASK) >> 23;
        if !inv_lsb.is_finite() || !lim.is_finite() || !(1..255).contains(&e) {
            return Err(Error::InvalidConfig("lsb"));
        }
        Ok(Self {
            inv_lsb,
            large_add: (256 - e) << 23,
            zmax: zmax as f32,
        })
    }

    /// Checks a frame: `Err(NonFinite)` on NaN/inf, else whether some pixel needs the
    /// clamping path (`|z| >= 2^e'`).
    pub(crate) fn check(&self, frame: &[f32]) -> Result<bool> {
        // `bits << 1` (sign dropped) + `(256 - e) << 24` carries exactly for `|z| >= 2^e'`:
        // one add and one add-with-carry per pixel
        let add = self.large_add << 1;
        let mut large = 0u32;
        let mut it = frame.chunks_exact(8);
        for c in it.by_ref() {
            for z in c {
                let (_, carry) = (z.to_bits() << 1).overflowing_add(add);
                large += u32::from(carry);
            }
        }
        for z in it.remainder() {
            let (_, carry) = (z.to_bits() << 1).overflowing_add(add);
            large += u32::from(carry);
        }
        if large == 0 {
            return Ok(false);
        }
        if frame.iter().any(|z| !z.is_finite()) {
            return Err(Error::NonFinite);
        }
        Ok(true)
    }

    /// The offset [`Quant::fast`] subtracts for merits re-centred by `sub`.
    #[inline(always)]
    pub(crate) const fn base(sub: i32) -> i32 {
        MAGIC_BITS.wrapping_add(sub)
    }

    /// `round(z / lsb) - sub` of one pixel of a frame that needs no clamping (see
    /// [`Quant::check`]), `base = Quant::base(sub)`.
    #[inline(always)]
    pub(crate) fn fast(&self, z: f32, base: i32) -> i32 {
        ((z * self.inv_lsb + MAGIC).to_bits() as i32).wrapping_sub(base)
    }

    /// Quantises one row into `out` as `q - sub`, returns the number of clamped pixels
    /// (`slow` = the frame needs the clamping path, see [`Quant::check`]).
    #[inline]
    pub(crate) fn row(&self, src: &[f32], sub: i32, slow: bool, out: &mut [i32]) -> u32 {
        let base = Self::base(sub);
        let inv = self.inv_lsb;
        if !slow {
            for (o, &z) in out.iter_mut().zip(src) {
                *o = self.fast(z, base);
            }
            return 0;
        }
        let zmax = self.zmax;
        let mut clamped = 0u32;
        for (o, &z) in out.iter_mut().zip(src) {
            let mut y = z * inv;
            if y > zmax {
                y = zmax;
                clamped += 1;
            } else if y < -zmax {
                y = -zmax;
                clamped += 1;
            }
            *o = ((y + MAGIC).to_bits() as i32).wrapping_sub(base);
        }
        clamped
    }
}

/// The index of the first pixel of `frame` that a detector with merit cells `C` and
/// configuration `cfg` would clamp (`|z / lsb| > C::ZMAX`, the pixels counted in
/// [`DpReport::clamped`](super::DpReport::clamped)), or `None`. The same arithmetic as the detectors' quantiser, so
/// a caller can refuse such a frame before any state changes. NaN is never reported here
/// (the detectors reject it as `Error::NonFinite`).
pub fn first_clamped<C: MeritCell>(cfg: &DpConfig, frame: &[f32]) -> Option<usize> {
    let inv_lsb = 1.0 / cfg.lsb;
    let zmax = C::ZMAX as f32;
    frame.iter().position(|&z| {
        let y = z * inv_lsb;
        y > zmax || y < -zmax
    })
}
