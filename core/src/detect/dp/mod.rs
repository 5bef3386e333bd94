//! DP-TBD: dynamic-programming track-before-detect of a dim point target in a sequence of
//! `M x M` intensity images, three recursions behind one configuration ([`DpConfig`]):
//!
//! | type | recursion | paper |
//! |---|---|---|
//! | [`ArnoldDp`] | first order, hard `q_B` window | Barniv 1985; Arnold, Shaw, Pasternack 1993 |
//! | [`PulfordDp`] | first order, Kalman velocity gate | Pulford, La Scala 2010 (after Tonissen, Evans 1996) |
//! | [`SecondOrderDp`] | second order over state pairs | Wang, Zhang 2016 (eq. 12-17) |
//!
//! ```text
//! merit (eq. 5, T(z) = z):   s(theta(n..1)) = sum_k T(z_k(theta(k))) [+ sum_k ln p(.) (second order)]
//! first order (eq. 8-9):     I_k(t) = T(z_k(t)) + max_{t' in R_B(t)} I_{k-1}(t')
//! Pulford:                   t' in R_B(t) with t in R_t'(k-1) = 3x3 around t''s Kalman prediction
//! second order (eq. 13-15):  I_k(t, t') = T(z_k(t)) + max_{t'' in R_I} [I_{k-1}(t', t'') + g(e)]
//!                            t' in R_B(t),  R_I = 3x3 around 2 t' - t,  e = t'' - (2 t' - t)
//! transition (eq. 16-17):    g(e) = (sigma^2 / a_design) ln p(e),
//!                            p(e) = exp(-|e|^2 / (2 sigma_I^2)) / sum_{R_I} exp(.),  sigma_I = Delta/2
//! ```
//!
//! A pixel is indexed `(x, y)` = (column, row) of the row-major image; pixel `(x, y)`
//! covers `[x, x+1) x [y, y+1)` and its centre is `(x + 0.5, y + 0.5)`. Windows are
//! clipped at the image edges (a state whose predecessor would lie outside does not
//! exist).
//!
//! ## Integer merits
//! Each pixel is quantised once, `q = round(z / lsb)` (halves to even), clamped to
//! `+-C::ZMAX` LSB ([`MeritCell`]); the recursion then runs in exact integer arithmetic
//! on cells of type `C` (`i16` by default, `i8` to halve the merit memory). After each
//! frame the stored merits are kept relative to the previous frame's best (an exact
//! integer offset, summed in an `i64`), so they stay in range however many frames run:
//! a merit is exact unless it falls more than `C::FLOOR + C::ZMAX` LSB below the best
//! of its frame (`-16384` LSB for `i16`: 1024 intensity units at the preset's
//! `lsb = 1/16`), where it is held at the floor. Such a state is far from every track
//! that can matter; the recursion stays monotone (a larger input never lowers a merit).
//! The second-order transition term is an integer table `g(e)` (LSB) of the same units.
//!
//! ## Bad input
//! A frame of the wrong length is `Error::LengthMismatch`, a NaN or infinite pixel is
//! `Error::NonFinite`, both before any state changes. Finite pixels beyond `ZMAX` LSB
//! (e.g. `1e30`) are clamped and counted in [`DpReport::clamped`], a documented recovery
//! (clamping keeps the recursion monotone); [`first_clamped`] finds such a pixel before a
//! frame is run, for a caller that must refuse it instead. An image of equal
//! values gives every interior state the same merit; ties are broken deterministically
//! (a fixed candidate order, documented per recursion). `L = 0`, a window larger than
//! the image, a method that is not the detector's, or a bad value are
//! `Error::InvalidConfig` from [`Detector::configure`].
//!
//! ## Memory (all fixed at compile time)
//! `L` is the length of a recoverable track in frames. The first order keeps `L - 1`
//! frames of back-pointers, the second order `L - 2` (its state holds the last two
//! positions); a track ending at frame `k` is recovered over frames
//! `max(1, k - L + 1) ..= k`. See each type for its formula; the const functions
//! [`arnold_words`], [`pulford_words`], [`second_order_words`] give the back-pointer
//! storage `W` (in `u32` words) that the type parameters must match (checked at compile
//! time).

mod arnold;
mod pulford;
mod second;

pub use arnold::ArnoldDp;
pub use pulford::PulfordDp;
pub use second::SecondOrderDp;

use crate::detect::{Detection, Detector, TrackInfo, Validate};
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
    /// First-order DP with a hard `q_B` window (Barniv 1985, Arnold et al. 1993): [`ArnoldDp`].
    Arnold,
    /// First-order DP with a Kalman velocity gate (Pulford, La Scala 2010): [`PulfordDp`].
    Pulford,
    /// Second-order DP over state pairs (Wang, Zhang 2016): [`SecondOrderDp`].
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
    /// The recursion; must be the detector type's ([`ArnoldDp`]: `Arnold`, ...).
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

/// The end of a track: pixel and merit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrackEnd {
    /// Column.
    pub x: u16,
    /// Row.
    pub y: u16,
    /// Merit of the best track ending here (intensity units).
    pub merit: f32,
}

/// What one DP step returns.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DpReport {
    /// Frames processed since `configure`/`reset`, this one included.
    pub frame: u32,
    /// The best track end of this frame (ties: the first in row-major order).
    pub best: TrackEnd,
    /// Pixels of this frame clamped to `+-ZMAX` LSB.
    pub clamped: u32,
}

/// What the three DP detectors offer beyond [`Detector`]: merits at any pixel and track
/// recovery.
pub trait DpTrack: Detector<Frame = [f32], Config = DpConfig, Report = DpReport> {
    /// Image side `M`.
    const SIDE: usize;
    /// Recoverable track length `L` (frames).
    const HISTORY: usize;
    /// Frames processed since `configure`/`reset`.
    fn frames(&self) -> u32;
    /// Merit of the best track ending at pixel `(x, y)` (`None` outside the image or
    /// before the first frame).
    fn merit(&self, x: usize, y: usize) -> Option<f32>;
    /// Recovers the best track ending at `(x, y)` into `out`, newest position first
    /// (`out[0] = (x, y)` at the last frame, `out[1]` one frame earlier, ...). Returns
    /// the number of positions written: `min(out.len(), L, frames)`, 0 outside the image.
    fn track(&self, x: usize, y: usize, out: &mut [[u16; 2]]) -> usize;
    /// The best end of the last frame.
    fn best(&self) -> Option<TrackEnd>;
    /// The best track end within Chebyshev distance `radius` of `(x, y)` (ties: first in
    /// row-major order), for the track-level detection test.
    fn best_within(&self, x: usize, y: usize, radius: usize) -> Option<TrackEnd> {
        let m = Self::SIDE;
        if x >= m || y >= m {
            return None;
        }
        let mut best: Option<TrackEnd> = None;
        for yy in y.saturating_sub(radius)..=(y + radius).min(m - 1) {
            for xx in x.saturating_sub(radius)..=(x + radius).min(m - 1) {
                if let Some(v) = self.merit(xx, yy) {
                    if best.is_none_or(|b| v > b.merit) {
                        best = Some(TrackEnd {
                            x: xx as u16,
                            y: yy as u16,
                            merit: v,
                        });
                    }
                }
            }
        }
        best
    }
}

/// `ceil(log2(n))` for `n >= 1` (bits to hold `0..n`).
pub(crate) const fn bits_for(n: usize) -> u32 {
    let mut b = 0;
    while (1usize << b) < n {
        b += 1;
    }
    b
}

/// Window radius of a `q`-pixel square window (`q = (2R+1)^2`), 0 if `q` is not one.
pub(crate) const fn radius_of(q: usize) -> usize {
    let mut r = 1;
    while r <= 3 {
        if (2 * r + 1) * (2 * r + 1) == q {
            return r;
        }
        r += 1;
    }
    0
}

/// `u32` words of `frames` frames of `bits`-bit codes per pixel of an `m x m` image.
pub(crate) const fn words(m: usize, bits: usize, frames: usize) -> usize {
    frames * (m * m * bits).div_ceil(32)
}

/// Back-pointer words `W` of an [`ArnoldDp<M, QB, L, W>`](ArnoldDp):
/// `(L - 1) ceil(M^2 b / 32)`, `b = 4` bits for `q_B = 9`, 5 for 25, 6 for 49.
pub const fn arnold_words(m: usize, qb: usize, l: usize) -> usize {
    words(m, arnold::ptr_bits(qb) as usize, l.saturating_sub(1))
}

/// Back-pointer words `W` of a [`PulfordDp<M, QB, L, W>`](PulfordDp):
/// `(L - 1) ceil(M^2 b / 32)`, `b = ceil(log2(q_B + 1))` (4 bits for 9, 5 for 25).
pub const fn pulford_words(m: usize, qb: usize, l: usize) -> usize {
    words(m, bits_for(qb + 1) as usize, l.saturating_sub(1))
}

/// Back-pointer words `W` of a [`SecondOrderDp<M, QB, L, W>`](SecondOrderDp):
/// `(L - 2) ceil(M^2 b / 32)`, `b` the bits of one pixel's mixed-radix code (22 for
/// `q_B = 9`, 70 for 25; see [`SecondOrderDp`]).
pub const fn second_order_words(m: usize, qb: usize, l: usize) -> usize {
    words(m, second::code_bits(qb) as usize, l.saturating_sub(2))
}

/// Bytes of the fixed fields every DP detector carries (configuration, quantiser,
/// running merit offset, reported ends), the same on 32- and 64-bit targets.
pub const FIXED_BYTES: usize = 144;

/// Static RAM (bytes) of an [`ArnoldDp<M, QB, L, W, C>`](ArnoldDp), `c = size_of::<C>()`:
/// `M^2 c` merits + `44 M` row keys and buffers + `4 W` back-pointers + [`FIXED_BYTES`]
/// (`M` a multiple of 4), rounded up to a multiple of 8 (the alignment). `M = 128`,
/// `q_B = 9`, `L = 8`: 95 888 B (`i16`), 79 504 B (`i8`).
pub const fn arnold_bytes(m: usize, qb: usize, l: usize, c: usize) -> usize {
    (m * m * c + 44 * m + 4 * arnold_words(m, qb, l) + FIXED_BYTES).next_multiple_of(8)
}

/// Static RAM (bytes) of a [`PulfordDp<M, QB, L, W, C>`](PulfordDp):
/// `(M^2 + 4 M)(c + 24)` merits and Kalman filters (current and 4 delayed rows) + `5 M`
/// row buffers + 264 B of gains + `4 W` back-pointers + [`FIXED_BYTES`] (`M` a multiple
/// of 4), rounded up to a multiple of 8. `M = 128`, `q_B = 9`, `L = 8`, `i16`: 497 688 B.
pub const fn pulford_bytes(m: usize, qb: usize, l: usize, c: usize) -> usize {
    ((m * m + 4 * m) * (c + 24) + 5 * m + 264 + 4 * pulford_words(m, qb, l) + FIXED_BYTES)
        .next_multiple_of(8)
}

/// Static RAM (bytes) of a [`SecondOrderDp<M, QB, L, W, C>`](SecondOrderDp):
/// `(M^2 + 5 M) q_B c` state merits and `J` rows + `4 M` row buffer + 64 B of transition
/// keys + `4 W` back-pointers + [`FIXED_BYTES`] (`M` a multiple of 4), rounded up to a
/// multiple of 8. `M = 128`,
/// `q_B = 9`, `L = 8`: 577 488 B (564 KiB) with `i16`, 424 272 B (414 KiB) with `i8`; the
/// back-pointers are `(L - 2) 45 056` B, so within 512 KiB: `i16` merits up to `L = 6`
/// (487 376 B), `i8` merits up to `L = 10` (514 384 B).
pub const fn second_order_bytes(m: usize, qb: usize, l: usize, c: usize) -> usize {
    ((m * m + 5 * m) * qb * c + 4 * m + 64 + 4 * second_order_words(m, qb, l) + FIXED_BYTES)
        .next_multiple_of(8)
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

/// Input quantiser of one configuration: `q = round(z / lsb)` clamped to `+-zmax`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Quant {
    inv_lsb: f32,
    /// `(256 - e) << 23`, `e` the biased exponent of the largest power of two `2^e'`
    /// with `2^e' / lsb <= zmax`: `(bits & EXP) + large_add` sets bit 31 exactly for
    /// `|z| >= 2^e'` (and NaN/inf).
    large_add: u32,
    zmax: f32,
}

const EXP_MASK: u32 = 0x7F80_0000;
/// `1.5 * 2^23`: adding it rounds `|y| < 2^22` to an integer held in the low mantissa bits.
const MAGIC: f32 = 12_582_912.0;
const MAGIC_BITS: i32 = 0x4B40_0000;

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
/// [`DpReport::clamped`]), or `None`. The same arithmetic as the detectors' quantiser, so
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

/// Checks the frame length against `M x M`.
pub(crate) fn check_len(frame: &[f32], m: usize) -> Result<()> {
    if frame.len() != m * m {
        return Err(Error::LengthMismatch {
            expected: m * m,
            got: frame.len(),
        });
    }
    Ok(())
}

/// Common configuration checks of a detector of side `m`, window radius `r`
/// (0 = invalid window) and history `l`.
pub(crate) fn check_shape(
    cfg: &DpConfig,
    method: Method,
    m: usize,
    r: usize,
    l: usize,
) -> Result<()> {
    cfg.validate()?;
    if cfg.method != method {
        return Err(Error::InvalidConfig("method"));
    }
    if l == 0 {
        return Err(Error::InvalidConfig("L"));
    }
    if m == 0 || m > 4096 {
        return Err(Error::InvalidConfig("M"));
    }
    if r == 0 {
        return Err(Error::InvalidConfig("q_b"));
    }
    if 2 * r + 1 > m {
        return Err(Error::InvalidConfig("window larger than the image"));
    }
    Ok(())
}

/// Appends fixed-width codes to a word slice, least significant bit first (words past
/// the slice are dropped, never written).
pub(crate) struct BitWriter<'a> {
    words: &'a mut [u32],
    next: usize,
    acc: u32,
    fill: u32,
}

impl<'a> BitWriter<'a> {
    pub(crate) fn new(words: &'a mut [u32]) -> Self {
        Self {
            words,
            next: 0,
            acc: 0,
            fill: 0,
        }
    }

    /// Appends the low `bits` bits of `v` (`1 <= bits <= 32`, `v < 2^bits`).
    #[inline(always)]
    pub(crate) fn push(&mut self, v: u32, bits: u32) {
        self.acc |= v.wrapping_shl(self.fill);
        let total = self.fill + bits;
        if total >= 32 {
            if let Some(w) = self.words.get_mut(self.next) {
                *w = self.acc;
            }
            self.next += 1;
            self.acc = if self.fill == 0 {
                0
            } else {
                v.wrapping_shr(32 - self.fill)
            };
            self.fill = total - 32;
        } else {
            self.fill = total;
        }
    }

    /// For a writer outside (the second order's Cortex-M4 `J` row): the unwritten
    /// words, the pending bits and their count; [`Self::skip`] then counts the words
    /// it wrote.
    #[cfg_attr(not(faint_m4_asm), allow(dead_code))]
    pub(crate) fn parts(&mut self) -> (&mut [u32], &mut u32, &mut u32) {
        let words = self.words.get_mut(self.next..).unwrap_or(&mut []);
        (words, &mut self.acc, &mut self.fill)
    }

    /// `n` more words written (see [`Self::parts`]).
    #[cfg_attr(not(faint_m4_asm), allow(dead_code))]
    pub(crate) fn skip(&mut self, n: usize) {
        self.next += n;
    }

    /// Writes a partly filled last word.
    pub(crate) fn finish(self) {
        if self.fill > 0 {
            if let Some(w) = self.words.get_mut(self.next) {
                *w = self.acc;
            }
        }
    }
}

/// The `bits`-bit code at bit offset `bit` of `words` (0 past the end).
#[inline]
pub(crate) fn read_bits(words: &[u32], bit: usize, bits: u32) -> u32 {
    let w = bit >> 5;
    let sh = (bit & 31) as u32;
    let lo = words.get(w).copied().unwrap_or(0).wrapping_shr(sh);
    let hi = if sh != 0 && sh + bits > 32 {
        words.get(w + 1).copied().unwrap_or(0).wrapping_shl(32 - sh)
    } else {
        0
    };
    let v = lo | hi;
    if bits >= 32 {
        v
    } else {
        v & ((1u32 << bits) - 1)
    }
}

/// Running merit bookkeeping shared by the three recursions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Tally {
    /// Frames processed.
    pub(crate) frames: u32,
    /// Stored merit + `offset` = merit in LSB.
    pub(crate) offset: i64,
    /// Best stored merit of the last frame (subtracted from the next frame's).
    pub(crate) best_raw: i32,
    /// Where it is.
    pub(crate) best_xy: (u16, u16),
    /// Pixels clamped in the last frame.
    pub(crate) clamped: u32,
}

impl Tally {
    pub(crate) const fn new() -> Self {
        Self {
            frames: 0,
            offset: 0,
            best_raw: 0,
            best_xy: (0, 0),
            clamped: 0,
        }
    }

    /// Merit (intensity) of a stored value.
    #[inline]
    pub(crate) fn merit(&self, raw: i32, lsb: f32) -> f32 {
        (i64::from(raw) + self.offset) as f32 * lsb
    }

    /// Merit of a stored value, `None` before the first frame or without a value.
    pub(crate) fn merit_of(&self, raw: Option<i32>, lsb: f32) -> Option<f32> {
        if self.frames == 0 {
            return None;
        }
        raw.map(|v| self.merit(v, lsb))
    }

    /// Ends a frame: stored merits were re-centred by `sub`; `best` at `xy` is the best.
    pub(crate) fn advance(&mut self, sub: i32, best: i32, xy: (u16, u16), clamped: u32) {
        self.offset += i64::from(sub);
        self.best_raw = best;
        self.best_xy = xy;
        self.clamped = clamped;
        self.frames = self.frames.wrapping_add(1);
    }
}

/// The checks before a detector's recursion runs on `frame` (configured, length `m x m`,
/// finite): whether the frame needs the clamping path ([`Quant::check`]).
pub(crate) fn begin(configured: bool, quant: &Quant, frame: &[f32], m: usize) -> Result<bool> {
    if !configured {
        return Err(Error::InvalidConfig("unconfigured"));
    }
    check_len(frame, m)?;
    quant.check(frame)
}

/// The report of the frame just run, after refilling `ends` (best merit at `raw(x, y)`).
pub(crate) fn finish(
    cfg: &DpConfig,
    t: &Tally,
    ends: &mut Ends,
    m: usize,
    raw: impl Fn(usize, usize) -> Option<i32>,
) -> DpReport {
    let lsb = cfg.lsb;
    ends.fill(
        m,
        usize::from(cfg.top_k),
        usize::from(cfg.separation),
        t.best_xy,
        t,
        lsb,
        |x, y| raw(x, y).unwrap_or(i32::MIN),
    );
    DpReport {
        frame: t.frames,
        best: TrackEnd {
            x: t.best_xy.0,
            y: t.best_xy.1,
            merit: t.merit(t.best_raw, lsb),
        },
        clamped: t.clamped,
    }
}

/// The distinct track ends of the last frame, best first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ends {
    /// Number of ends (`u32`, so the detectors' sizes are the same on 32- and 64-bit targets).
    pub(crate) n: u32,
    pub(crate) ends: [TrackEnd; MAX_ENDS],
}

impl Ends {
    pub(crate) const fn new() -> Self {
        Self {
            n: 0,
            ends: [TrackEnd {
                x: 0,
                y: 0,
                merit: 0.0,
            }; MAX_ENDS],
        }
    }

    pub(crate) fn as_slice(&self) -> &[TrackEnd] {
        self.ends.get(..self.n as usize).unwrap_or(&[])
    }

    /// Fills the ends: the best (`best`), then up to `k - 1` more, each the best pixel
    /// (by `raw(x, y)`, ties first in row-major order) farther than `sep` (Chebyshev)
    /// from all chosen so far.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn fill(
        &mut self,
        m: usize,
        k: usize,
        sep: usize,
        best: (u16, u16),
        tally: &Tally,
        lsb: f32,
        raw: impl Fn(usize, usize) -> i32,
    ) {
        let mut chosen = [(0usize, 0usize, 0i32); MAX_ENDS];
        chosen[0] = (
            usize::from(best.0),
            usize::from(best.1),
            raw(usize::from(best.0), usize::from(best.1)),
        );
        let mut n = 1usize;
        let k = k.min(MAX_ENDS);
        while n < k {
            let mut cand: Option<(usize, usize, i32)> = None;
            for y in 0..m {
                for x in 0..m {
                    let v = raw(x, y);
                    if cand.is_some_and(|c| v <= c.2) {
                        continue;
                    }
                    let far = chosen
                        .iter()
                        .take(n)
                        .all(|c| c.0.abs_diff(x) > sep || c.1.abs_diff(y) > sep);
                    if far {
                        cand = Some((x, y, v));
                    }
                }
            }
            match (cand, chosen.get_mut(n)) {
                (Some(c), Some(slot)) => *slot = c,
                _ => break,
            }
            n += 1;
        }
        self.n = n as u32;
        for (e, c) in self.ends.iter_mut().zip(chosen.iter().take(n)) {
            *e = TrackEnd {
                x: c.0 as u16,
                y: c.1 as u16,
                merit: tally.merit(c.2, lsb),
            };
        }
    }
}

/// Least-squares velocity (px/frame) of a track given newest first.
pub(crate) fn velocity(track: &[[u16; 2]]) -> (f32, f32) {
    let n = track.len();
    if n < 2 {
        return (0.0, 0.0);
    }
    // time t_j = -j; slope = sum (t - tbar)(p - pbar) / sum (t - tbar)^2
    let tbar = -((n - 1) as f32) / 2.0;
    let (mut sx, mut sy, mut st) = (0.0f32, 0.0f32, 0.0f32);
    let (mut mx, mut my) = (0.0f32, 0.0f32);
    for p in track {
        mx += f32::from(p[0]);
        my += f32::from(p[1]);
    }
    mx /= n as f32;
    my /= n as f32;
    for (j, p) in track.iter().enumerate() {
        let dt = -(j as f32) - tbar;
        sx += dt * (f32::from(p[0]) - mx);
        sy += dt * (f32::from(p[1]) - my);
        st += dt * dt;
    }
    (sx / st, sy / st)
}

/// Detection `i` of a DP detector: end `i` of [`Ends`], state
/// `[x + 0.5, y + 0.5, vx, vy]` (pixel centre, least-squares velocity of the recovered
/// track), score = merit, track id `i` and the recovered length.
pub(crate) fn detection<D: DpTrack, const L: usize>(
    det: &D,
    ends: &Ends,
    i: usize,
) -> Option<Detection> {
    let e = ends.as_slice().get(i)?;
    let mut buf = [[0u16; 2]; L];
    let n = det.track(usize::from(e.x), usize::from(e.y), &mut buf);
    let (vx, vy) = velocity(buf.get(..n).unwrap_or(&[]));
    Some(Detection::new(
        &[f32::from(e.x) + 0.5, f32::from(e.y) + 0.5, vx, vy],
        e.merit,
        Some(TrackInfo {
            id: i as u32,
            len: n as u32,
        }),
    ))
}

/// Names of a DP detection's state.
pub(crate) const STATE: &[&str] = &["x_px", "y_px", "vx_px_per_frame", "vy_px_per_frame"];
