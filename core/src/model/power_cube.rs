//! Power observations over range x Doppler x azimuth cells (Pei et al. 2019, §1.2):
//! cube geometry, the separable point spread (eq. 3), a stable `log I0`, and the
//! Rician-over-exponential cell likelihood ratio (eq. 21-23, restated in the spec).
//!
//! Layout of a cube: `index = (i_r * n_doppler + j_d) * n_azimuth + l_b`, one `f32`
//! power `z >= 0` per cell, borrowed by the detectors as `&[f32]`.

use crate::math;
use crate::{Error, Result};

/// Degrees per radian.
pub const DEG_PER_RAD: f32 = 180.0 / math::PI;

/// Extent and resolution of the observation cube. Cell `i` on an axis spans
/// `[start + i * size, start + (i + 1) * size)` and has its centre at `start + (i + 0.5) * size`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct CubeGeometry {
    /// Number of range cells `U_r`.
    pub n_range: usize,
    /// Number of Doppler cells `U_d`.
    pub n_doppler: usize,
    /// Number of azimuth cells `U_b`.
    pub n_azimuth: usize,
    /// Range of the first cell's lower edge (m).
    pub range_start: f32,
    /// Range cell size `R` (m).
    pub range_cell: f32,
    /// Radial velocity of the first Doppler cell's lower edge (m/s; positive = receding).
    pub doppler_start: f32,
    /// Doppler cell size `D` (m/s).
    pub doppler_cell: f32,
    /// Azimuth of the first cell's lower edge (deg, counter-clockwise from +x).
    pub azimuth_start_deg: f32,
    /// Azimuth cell size `B` (deg).
    pub azimuth_cell_deg: f32,
}

/// A target state seen by the radar: range (m), radial velocity (m/s), azimuth (deg).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RadarCoords {
    /// Range `r = sqrt(x^2 + y^2)`.
    pub range: f32,
    /// Radial velocity `d = (x vx + y vy) / r`.
    pub doppler: f32,
    /// Azimuth `b = atan2(y, x)` in degrees.
    pub azimuth_deg: f32,
}

impl RadarCoords {
    /// Radar coordinates of the CV state `[x, vx, y, vy, ..]` (radar at the origin).
    #[inline]
    pub fn from_state(x: f32, vx: f32, y: f32, vy: f32) -> Self {
        let r = sqrt(x * x + y * y);
        let d = if r > 1e-6 { (x * vx + y * vy) / r } else { 0.0 };
        Self {
            range: r,
            doppler: d,
            azimuth_deg: math::atan2(y, x) * DEG_PER_RAD,
        }
    }
}

impl CubeGeometry {
    /// Number of cells `U_r U_d U_b`.
    pub const fn len(&self) -> usize {
        self.n_range * self.n_doppler * self.n_azimuth
    }

    /// True if the cube has no cells.
    pub const fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Checks sizes and extents.
    pub fn validate(&self) -> Result<()> {
        if self.n_range == 0 || self.n_doppler == 0 || self.n_azimuth == 0 {
            return Err(Error::InvalidConfig("cube dimensions must be non-zero"));
        }
        if self
            .n_range
            .checked_mul(self.n_doppler)
            .and_then(|v| v.checked_mul(self.n_azimuth))
            .is_none_or(|v| v > u32::MAX as usize)
        {
            return Err(Error::InvalidConfig("cube has more than 2^32 cells"));
        }
        for v in [self.range_cell, self.doppler_cell, self.azimuth_cell_deg] {
            if !(v.is_finite() && v > 0.0) {
                return Err(Error::InvalidConfig("cell sizes must be positive"));
            }
        }
        for v in [self.range_start, self.doppler_start, self.azimuth_start_deg] {
            if !v.is_finite() {
                return Err(Error::InvalidConfig("cube start values must be finite"));
            }
        }
        Ok(())
    }

    /// Linear index of cell `(i_r, j_d, l_b)`.
    #[inline]
    pub const fn index(&self, ir: usize, jd: usize, lb: usize) -> usize {
        (ir * self.n_doppler + jd) * self.n_azimuth + lb
    }

    /// Inverse of [`CubeGeometry::index`].
    #[inline]
    pub const fn unindex(&self, idx: usize) -> (usize, usize, usize) {
        // `checked_*`: no division-by-zero path for an unvalidated zero size.
        let (Some(lb), Some(rest)) = (
            idx.checked_rem(self.n_azimuth),
            idx.checked_div(self.n_azimuth),
        ) else {
            return (0, 0, 0);
        };
        match (
            rest.checked_div(self.n_doppler),
            rest.checked_rem(self.n_doppler),
        ) {
            (Some(ir), Some(jd)) => (ir, jd, lb),
            _ => (0, 0, 0),
        }
    }

    /// Centre of range cell `i`.
    #[inline]
    pub fn range_centre(&self, i: usize) -> f32 {
        self.range_start + (i as f32 + 0.5) * self.range_cell
    }
    /// Centre of Doppler cell `j`.
    #[inline]
    pub fn doppler_centre(&self, j: usize) -> f32 {
        self.doppler_start + (j as f32 + 0.5) * self.doppler_cell
    }
    /// Centre of azimuth cell `l` (deg).
    #[inline]
    pub fn azimuth_centre(&self, l: usize) -> f32 {
        self.azimuth_start_deg + (l as f32 + 0.5) * self.azimuth_cell_deg
    }

    /// Fractional cell coordinates `((r - start) / size, ..)` of a radar position.
    #[inline]
    pub fn fractional(&self, c: &RadarCoords) -> (f32, f32, f32) {
        (
            (c.range - self.range_start) / self.range_cell,
            (c.doppler - self.doppler_start) / self.doppler_cell,
            (c.azimuth_deg - self.azimuth_start_deg) / self.azimuth_cell_deg,
        )
    }

    /// The cell holding `c`, or `None` if it lies outside the cube (`D_i, D_j, D_l` of
    /// eq. 25).
    #[inline]
    pub fn cell_of(&self, c: &RadarCoords) -> Option<(usize, usize, usize)> {
        let (fr, fd, fb) = self.fractional(c);
        let ok = |f: f32, n: usize| f >= 0.0 && f < n as f32;
        if ok(fr, self.n_range) && ok(fd, self.n_doppler) && ok(fb, self.n_azimuth) {
            Some((fr as usize, fd as usize, fb as usize))
        } else {
            None
        }
    }

    /// Cartesian position `(x, y)` of the centre of range cell `ir`, azimuth cell `lb`.
    pub fn cell_position(&self, ir: usize, lb: usize) -> (f32, f32) {
        let r = self.range_centre(ir);
        let b = self.azimuth_centre(lb) / DEG_PER_RAD;
        (r * math::cos(b), r * math::sin(b))
    }
}

/// The separable point spread of eq. 3, in cell units:
/// `h = exp(-L_r (r_i - r)^2 / (2 R^2) - L_d (d_j - d)^2 / (2 D^2) - L_b (b_l - b)^2 / (2 B^2))`.
///
/// One convention: `L` is the loss in cell units, `L = 1 / s^2` for a spread whose
/// standard deviation is `s` cells on that axis (`L = 1`: one cell; `L = 0.25`: two
/// cells). The paper writes `(r_i - r)^2 L_r / (2R)`; its loss factor is ours divided by
/// the cell size, `L_paper = L / R`. Only the `(2 w_r + 1) (2 w_d + 1) (2 w_b + 1)` cells
/// around the target's own cell are covered, `w = half_width` per axis (the same
/// truncation in the simulator and in the likelihood); a half width of about `2 s`
/// covers the cells where `h > exp(-2)` of the peak.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct PointSpread {
    /// Range loss `L_r = 1 / s_r^2` (cell units).
    pub loss_range: f32,
    /// Doppler loss `L_d = 1 / s_d^2` (cell units).
    pub loss_doppler: f32,
    /// Azimuth loss `L_b = 1 / s_b^2` (cell units).
    pub loss_azimuth: f32,
    /// Cells covered on each side of the target's cell: range, Doppler, azimuth (each
    /// `0..=8`, at most [`MAX_COVERED_CELLS`] cells in all). A configuration file may
    /// give one number for all three axes (the form written before the axes were
    /// separate).
    #[cfg_attr(
        feature = "serde",
        serde(deserialize_with = "half_width_serde::deserialize")
    )]
    pub half_width: [usize; 3],
}

/// `half_width` as `[w_r, w_d, w_b]` or one number `w` meaning `[w, w, w]`.
#[cfg(feature = "serde")]
mod half_width_serde {
    use core::fmt;
    use serde::de::{Error, SeqAccess, Visitor};

    struct HalfWidth;

    impl<'de> Visitor<'de> for HalfWidth {
        type Value = [usize; 3];

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a half width (cells) or three: [range, doppler, azimuth]")
        }

        fn visit_u64<E: Error>(self, v: u64) -> Result<[usize; 3], E> {
            let w = usize::try_from(v).map_err(|_| E::custom("half width out of range"))?;
            Ok([w; 3])
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<[usize; 3], A::Error> {
            let mut out = [0usize; 3];
            for (i, o) in out.iter_mut().enumerate() {
                *o = seq
                    .next_element()?
                    .ok_or_else(|| A::Error::invalid_length(i, &self))?;
            }
            if seq.next_element::<usize>()?.is_some() {
                return Err(A::Error::invalid_length(4, &self));
            }
            Ok(out)
        }
    }

    pub(super) fn deserialize<'de, D: serde::Deserializer<'de>>(
        d: D,
    ) -> Result<[usize; 3], D::Error> {
        d.deserialize_any(HalfWidth)
    }
}

/// Largest supported half width of one axis of a [`PointSpread`].
pub const MAX_HALF_WIDTH: usize = 8;
const MAX_SPAN: usize = 2 * MAX_HALF_WIDTH + 1;

/// Most cells one particle's spread may cover, `(2 w_r + 1) (2 w_d + 1) (2 w_b + 1)`:
/// the bound of the per-particle cost of the likelihood (one `ln I0` per covered cell,
/// `3 (2w + 1) <= 51` exponentials). `13^3`: a two-cell spread on every axis at
/// `w = 6` (3 standard deviations), or a wider spread on fewer axes.
pub const MAX_COVERED_CELLS: usize = 2197;

/// Smallest loss (cell units) of a [`PointSpread`] axis: a standard deviation of at most
/// 16 cells, twice the widest half width.
pub const MIN_LOSS: f32 = 1.0 / 256.0;

impl PointSpread {
    /// The spread used before the losses were set per sensor: one-cell standard deviation
    /// and half width 1 on every axis (3 x 3 x 3 cells).
    pub const ONE_CELL: Self = Self {
        loss_range: 1.0,
        loss_doppler: 1.0,
        loss_azimuth: 1.0,
        half_width: [1, 1, 1],
    };

    /// The spread with standard deviations `std` (cells: range, Doppler, azimuth) and
    /// half widths `half_width`: `L = 1 / std^2` per axis.
    pub fn from_std(std: [f32; 3], half_width: [usize; 3]) -> Self {
        let loss = std.map(|s| 1.0 / (s * s));
        Self {
            loss_range: loss[0],
            loss_doppler: loss[1],
            loss_azimuth: loss[2],
            half_width,
        }
    }

    /// The same losses over at most one cell on each side of the target's cell
    /// (`3 x 3 x 3` cells at most): the window of the cube-wide peak statistics
    /// `sum h^2 z` (births, swarm points), whose cost per cell stays 27 products
    /// whatever the spread. Equal to `self` for half widths of at most 1.
    pub fn central(&self) -> Self {
        Self {
            half_width: self.half_width.map(|w| w.min(1)),
            ..*self
        }
    }

    /// Checks the losses and the coverage.
    pub fn validate(&self) -> Result<()> {
        for v in [self.loss_range, self.loss_doppler, self.loss_azimuth] {
            if !(v.is_finite() && v >= MIN_LOSS) {
                return Err(Error::InvalidConfig(
                    "point-spread losses must be >= 1/256 (a std of at most 16 cells)",
                ));
            }
        }
        if self.half_width.iter().any(|&w| w > MAX_HALF_WIDTH) {
            return Err(Error::InvalidConfig("point-spread half width above 8"));
        }
        if self.covered() > MAX_COVERED_CELLS {
            return Err(Error::InvalidConfig(
                "point spread covers more than 2197 cells per particle",
            ));
        }
        Ok(())
    }

    /// Half width of axis `a` (0 range, 1 Doppler, 2 azimuth), clamped to
    /// [`MAX_HALF_WIDTH`].
    #[inline]
    pub fn half(&self, a: usize) -> usize {
        self.half_width
            .get(a)
            .copied()
            .unwrap_or(0)
            .min(MAX_HALF_WIDTH)
    }

    /// Loss of axis `a` (0 range, 1 Doppler, 2 azimuth).
    #[inline]
    pub fn loss(&self, a: usize) -> f32 {
        match a {
            0 => self.loss_range,
            1 => self.loss_doppler,
            _ => self.loss_azimuth,
        }
    }

    /// Cells covered around an interior target, `prod (2 w + 1)`.
    pub fn covered(&self) -> usize {
        (0..3).map(|a| 2 * self.half(a) + 1).product()
    }

    /// Radius (cells) within which two peaks of the matched statistic `sum h^2 z` are
    /// taken as one target on axis `a`: the spread's standard deviation `1 / sqrt(L)`
    /// rounded, at least 1, at most the half width (at least 1).
    #[inline]
    pub fn peak_radius(&self, a: usize) -> usize {
        let s = 1.0 / math::sqrt(self.loss(a));
        let r = math::round(s);
        let r = if r.is_finite() && r >= 1.0 {
            r as usize
        } else {
            1
        };
        r.min(self.half(a).max(1))
    }

    /// Calls `f(index, h)` for every in-cube cell the spread of `c` covers.
    ///
    /// Cost: `(2w_r + 1) + (2w_d + 1) + (2w_b + 1)` exponentials and
    /// `(2w_r + 1)(2w_d + 1)(2w_b + 1)` products; cells outside the cube are skipped
    /// (they contribute a likelihood ratio of 1).
    #[inline]
    pub fn for_each_cell(&self, g: &CubeGeometry, c: &RadarCoords, f: impl FnMut(usize, f32)) {
        let (fr, fd, fb) = g.fractional(c);
        let r = self.axis_weights(0, fr, g.n_range);
        let d = self.axis_weights(1, fd, g.n_doppler);
        let b = self.axis_weights(2, fb, g.n_azimuth);
        self.for_each_cell_of(g, &r, &d, &b, f);
    }

    /// One axis of [`PointSpread::for_each_cell`]: the covered cells and weights
    /// `exp(-L delta^2 / 2)` of axis `a` (0 range, 1 Doppler, 2 azimuth) around the
    /// fractional cell coordinate `frac` (a component of [`CubeGeometry::fractional`]) on
    /// an axis of `n` cells. Callers that scan a grid of positions compute each axis
    /// once per grid line and combine them with [`PointSpread::for_each_cell_of`]
    /// (bit-identical to `for_each_cell`).
    #[inline]
    pub fn axis_weights(&self, a: usize, frac: f32, n: usize) -> AxisWeights {
        self.axis_weights_in(a, frac, n)
    }

    /// [`PointSpread::axis_weights`] into `S` slots (the first `S` covered cells; the
    /// likelihood uses `S = 3` for half widths of at most 1, which spares it clearing
    /// and copying 17 slots per axis).
    #[inline(always)]
    fn axis_weights_in<const S: usize>(&self, a: usize, frac: f32, n: usize) -> AxisWeightsN<S> {
        let mut out = AxisWeightsN::<S>::NONE;
        if !frac.is_finite() {
            return out;
        }
        let half_loss = 0.5 * self.loss(a);
        let w = self.half(a) as i32;
        // Clamp so that far-away states do not overflow the i32 conversion (i32, not
        // i64: the M4 converts an i64 to f32 in software).
        let centre = floor_i32(frac.clamp(-1.0e6, 1.0e6));
        // The covered cells inside the axis are one run `first..=last`.
        let first = (centre - w).max(0);
        let last = (centre + w).min(n.min(1 << 24) as i32 - 1);
        let mut k = 0usize;
        for i in first..=last {
            let delta = i as f32 + 0.5 - frac;
            if let Some(h) = out.h.get_mut(k) {
                *h = exp_neg(-half_loss * delta * delta);
                k += 1;
            }
        }
        out.lo = first.max(0) as usize;
        out.len = k;
        out
    }

    /// [`PointSpread::axis_weights_in`] with `S = 3` for a half width of at most 1, its
    /// three slots written at constant positions (so that the weights stay in registers):
    /// the same cells, in the same slots, with the same weights.
    #[inline(always)]
    fn axis_weights_3(&self, a: usize, frac: f32, n: usize) -> AxisWeightsN<3> {
        let mut out = AxisWeightsN::<3>::NONE;
        if !frac.is_finite() {
            return out;
        }
        let half_loss = 0.5 * self.loss(a);
        let w = self.half(a) as i32;
        let centre = floor_i32(frac.clamp(-1.0e6, 1.0e6));
        let first = (centre - w).max(0);
        let last = (centre + w).min(n.min(1 << 24) as i32 - 1);
        let mut k = 0usize;
        for (slot, h) in out.h.iter_mut().enumerate() {
            let i = first + slot as i32;
            if i <= last {
                let delta = i as f32 + 0.5 - frac;
                *h = exp_neg(-half_loss * delta * delta);
                k = slot + 1;
            }
        }
        out.lo = first.max(0) as usize;
        out.len = k;
        out
    }

    /// Calls `f(index, h)` for the cells of the product of three axes' weights (range,
    /// Doppler, azimuth), in the order and with the products of
    /// [`PointSpread::for_each_cell`].
    #[inline]
    pub fn for_each_cell_of(
        &self,
        g: &CubeGeometry,
        r: &AxisWeights,
        d: &AxisWeights,
        b: &AxisWeights,
        mut f: impl FnMut(usize, f32),
    ) {
        for (ir, &hr) in (r.lo..).zip(r.weights()) {
            for (jd, &hd) in (d.lo..).zip(d.weights()) {
                let hab = hr * hd;
                let base = (ir * g.n_doppler + jd) * g.n_azimuth + b.lo;
                for (l, &h) in b.weights().iter().enumerate() {
                    f(base + l, hab * h);
                }
            }
        }
    }
}

/// `floor(x) as i32` for `|x| <= 1e6` (the axis weights' clamped coordinate) without
/// `math::floor`'s bit manipulation: the conversion truncates toward zero, one less when
/// that rounded up (a negative non-integer). The same integer as `math::floor(x) as i32`
/// (`-0.0` gives 0 either way).
#[inline(always)]
fn floor_i32(x: f32) -> i32 {
    let t = x as i32;
    if t as f32 > x {
        t - 1
    } else {
        t
    }
}

/// Covered cells and weights of one axis of a [`PointSpread`] (see
/// [`PointSpread::axis_weights`]).
pub type AxisWeights = AxisWeightsN<MAX_SPAN>;

/// Covered cells and weights of one axis, in at most `S` slots ([`AxisWeights`]: all
/// `2 w + 1` of the widest spread).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisWeightsN<const S: usize> {
    /// Weights of the covered cells `lo..lo + len` (those inside the axis).
    h: [f32; S],
    /// First covered cell.
    lo: usize,
    /// Covered cells inside the axis, at most `2 w + 1`.
    len: usize,
}

impl<const S: usize> AxisWeightsN<S> {
    /// No covered cell.
    pub const NONE: Self = Self {
        h: [0.0; S],
        lo: 0,
        len: 0,
    };

    /// The weights of the covered cells, in cell order.
    #[inline]
    fn weights(&self) -> &[f32] {
        self.h.get(..self.len).unwrap_or(&[])
    }
}

/// `sqrt(x)`, correctly rounded: the FPU's `VSQRT.F32` on the Cortex-M4F (three
/// instructions with the moves; the portable `math::sqrt` is a software routine of
/// about 57 there), the
/// portable `math::sqrt` elsewhere. Both are IEEE 754 square roots, so the results are
/// the same bits (the golden lines check it).
#[cfg(faint_m4_asm)]
#[allow(unsafe_code)]
#[inline(always)]
pub fn sqrt(x: f32) -> f32 {
    let r: u32;
    // SAFETY: moves between a core register and s0 (declared clobbered) and one
    // `vsqrt.f32`: no memory, stack or flags touched.
    unsafe {
        core::arch::asm!(
            "vmov s0, {x}",
            "vsqrt.f32 s0, s0",
            "vmov {r}, s0",
            x = in(reg) x.to_bits(),
            r = lateout(reg) r,
            out("s0") _,
            options(pure, nomem, nostack, preserves_flags)
        );
    }
    f32::from_bits(r)
}

/// `sqrt(x)`, correctly rounded (the portable `math::sqrt`; the Cortex-M4F build uses
/// the FPU's `VSQRT.F32`, which gives the same bits).
#[cfg(not(faint_m4_asm))]
#[inline(always)]
pub fn sqrt(x: f32) -> f32 {
    math::sqrt(x)
}

/// `ln(2)` split so that `e * LN2_HI` is exact for every `f32` exponent `e` (the split
/// of musl's `logf`: `0.693138122..` with 7 trailing zero bits, and the rest).
const LN2_HI: f32 = f32::from_bits(0x3f31_7180);
const LN2_LO: f32 = f32::from_bits(0x3717_f7d1);

/// `e^x` for `x <= 0` with a few instructions: `x = n ln 2 + r`, `|r| <= ln(2) / 2`,
/// `e^r` by its Taylor polynomial of degree 6 (the first neglected term, `r^7 / 7!`, is
/// below `1.3e-7` relative), scaled by `2^n` through the exponent bits. Relative error
/// below `4e-7` on `[-87, 0]` (checked against `f64::exp`); `x < -87` gives 0 (the
/// true value is below `1.7e-38`); positive and NaN arguments go to `math::exp`.
/// For the non-positive exponents of the point spread's weights, the weight
/// normalisation and the swarm's fitness.
#[inline]
pub fn exp_neg(x: f32) -> f32 {
    if x > 0.0 || x.is_nan() {
        return math::exp(x);
    }
    if x < -87.0 {
        return 0.0;
    }
    // n = round(x / ln 2) in [-126, 0].
    let n = -((0.5 - x * core::f32::consts::LOG2_E) as i32);
    let nf = n as f32;
    let r = (x - nf * LN2_HI) - nf * LN2_LO;
    let p = 1.0
        + r * (1.0
            + r * (0.5
                + r * (1.0 / 6.0 + r * (1.0 / 24.0 + r * (1.0 / 120.0 + r * (1.0 / 720.0))))));
    p * f32::from_bits(((n + 127) as u32) << 23)
}

/// `pi / 2` split so that `k * PIO2_HI` is exact for `|k| < 256` (16 significant bits).
const PIO2_HI: f32 = f32::from_bits(0x3fc9_0f00);
const PIO2_LO: f32 = f32::from_bits(0x37da_a221);

/// `(sin x, cos x)` with a few instructions (`math::sin` and `math::cos` reduce their
/// argument in f64, a software routine on the Cortex-M4F): `x = k pi/2 + r`,
/// `|r| <= pi/4`, Taylor polynomials of degree 9 (sine) and 8 (cosine), whose first
/// neglected terms are below `2e-9` and `3e-8`. Absolute error below `3e-7` for
/// `|x| <= 200` (checked against `f64`); larger and NaN arguments go to `math::sin` /
/// `math::cos`.
#[inline]
pub fn sin_cos(x: f32) -> (f32, f32) {
    if !(-200.0..=200.0).contains(&x) {
        return (math::sin(x), math::cos(x));
    }
    let t = x * core::f32::consts::FRAC_2_PI;
    let k = if t < 0.0 {
        (t - 0.5) as i32
    } else {
        (t + 0.5) as i32
    };
    let kf = k as f32;
    let r = (x - kf * PIO2_HI) - kf * PIO2_LO;
    let r2 = r * r;
    let sin = r + r
        * r2
        * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0 + r2 * (1.0 / 362_880.0))));
    let cos = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 * (1.0 / 40_320.0))));
    match k & 3 {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

/// `ln(1 + f)` for `|f| <= sqrt(2) - 1` by the series of `2 atanh(s)`, `s = f / (2 + f)`
/// (`|s| <= 0.1716`; the first neglected term, `2 s^11 / 11`, is below `7e-10`).
#[inline(always)]
fn ln1p_reduced(f: f32) -> f32 {
    let s = f / (2.0 + f);
    let s2 = s * s;
    let p = s2
        * (2.0 / 3.0 + s2 * (2.0 / 5.0 + s2 * (2.0 / 7.0 + s2 * (2.0 / 9.0 + s2 * (2.0 / 11.0)))));
    2.0 * s + s * p
}

/// `ln(y)` for `y > 0` with a few instructions: `y = 2^e m`, `m` in
/// `[sqrt(1/2), sqrt(2))`, `ln y = e ln 2 + ln m` (`ln(1 + f)` by the series in `s = f / (2 + f)` above). Absolute error
/// below `4e-7` for `y` in `[2^-126, 2^128)` (f32 rounding; checked against `f64::ln`);
/// subnormal, zero, infinite and NaN arguments go to `math::ln`.
#[inline]
pub fn ln_fast(y: f32) -> f32 {
    if !(f32::MIN_POSITIVE..=f32::MAX).contains(&y) {
        return math::ln(y);
    }
    let b = y.to_bits();
    let mut e = (b >> 23) as i32 - 127;
    let mut m = f32::from_bits((b & 0x007f_ffff) | 0x3f80_0000);
    if m > core::f32::consts::SQRT_2 {
        m *= 0.5;
        e += 1;
    }
    let e = e as f32;
    e * LN2_HI + (ln1p_reduced(m - 1.0) + e * LN2_LO)
}

/// Table step of [`log_i0`] below [`LOG_I0_TABLE_MAX`]: `1 / 64`.
const LOG_I0_STEPS_PER_UNIT: f32 = 64.0;
/// End of [`log_i0`]'s table: `ln I0` is tabulated on `[0, 32]`.
pub const LOG_I0_TABLE_MAX: f32 = 32.0;
const LOG_I0_ENTRIES: usize = 32 * 64 + 1;

/// `ln I0(k / 64)`, `k = 0..=2048`, rounded to f32 from an f64 evaluation at compile time
/// (the power series of `I0`, `sum (x^2/4)^k / (k!)^2`, and [`ln_f64_const`]).
static LOG_I0_TABLE: [f32; LOG_I0_ENTRIES] = log_i0_table();

const fn log_i0_table() -> [f32; LOG_I0_ENTRIES] {
    let mut t = [0.0f32; LOG_I0_ENTRIES];
    let mut k = 0;
    while k < LOG_I0_ENTRIES {
        let x = k as f64 / 64.0;
        let q = x * x / 4.0;
        let (mut term, mut sum, mut j) = (1.0f64, 1.0f64, 1.0f64);
        while term > sum * 1e-18 {
            term *= q / (j * j);
            sum += term;
            j += 1.0;
        }
        t[k] = ln_f64_const(sum) as f32;
        k += 1;
    }
    t
}

/// `ln(y)` for `y >= 1` in f64 at compile time: halve to `m` in `[1, sqrt 2]` (exact),
/// then `2 atanh((m - 1) / (m + 1))` summed until the terms vanish.
const fn ln_f64_const(mut y: f64) -> f64 {
    let mut e = 0.0f64;
    while y > core::f64::consts::SQRT_2 {
        y /= 2.0;
        e += 1.0;
    }
    let s = (y - 1.0) / (y + 1.0);
    let s2 = s * s;
    let (mut pow, mut sum, mut k) = (s, 0.0f64, 1.0f64);
    while pow > 1e-20 || pow < -1e-20 {
        sum += pow / k;
        pow *= s2;
        k += 2.0;
    }
    2.0 * sum + e * core::f64::consts::LN_2
}

/// `ln I0(x)` for `x >= 0` (modified Bessel function of the first kind, order 0), stable
/// for every finite `x` (no overflow: `I0(x) ~ e^x / sqrt(2 pi x)`).
///
/// Below [`LOG_I0_TABLE_MAX`] (every cell but the strongest of a bright target): linear
/// interpolation in a table of step `1/64` (8 KiB, built at compile time); the error of
/// the chord is at most `max |(ln I0)''| h^2 / 8 = 0.5 / (8 * 64^2) = 1.53e-5`, always
/// an overestimate (`ln I0` is convex), plus f32 rounding. Above it: Abramowitz & Stegun
/// 9.8.2, `x + ln(poly(3.75/x) / sqrt(x))` (relative error of `I0` below `2e-7`). So the
/// absolute error is below `1.6e-5 + 2e-7 ln I0(x)` (tested against an f64 reference).
/// Negative `x` uses `I0(-x) = I0(x)`; NaN gives NaN.
#[allow(clippy::excessive_precision)]
#[inline(never)]
pub fn log_i0(x: f32) -> f32 {
    let ax = if x < 0.0 { -x } else { x };
    let u = ax * LOG_I0_STEPS_PER_UNIT;
    if u < (LOG_I0_ENTRIES - 1) as f32 {
        let k = u as usize;
        let f = u - k as f32;
        match (LOG_I0_TABLE.get(k), LOG_I0_TABLE.get(k + 1)) {
            (Some(&a), Some(&b)) => a + f * (b - a),
            _ => 0.0,
        }
    } else if ax < 1.0e30 {
        let t = 3.75 / ax;
        let p = 0.398_942_28
            + t * (0.013_285_92
                + t * (0.002_253_19
                    + t * (-0.001_575_65
                        + t * (0.009_162_81
                            + t * (-0.020_577_06
                                + t * (0.026_355_37 + t * (-0.016_476_33 + t * 0.003_923_77)))))));
        ax + ln_fast(p / sqrt(ax))
    } else {
        // Far beyond any cell (and NaN): the two logs of the asymptotic form.
        let t = 3.75 / ax;
        ax - 0.5 * math::ln(ax) + math::ln(0.398_942_28 + t * 0.013_285_92)
    }
}

/// [`log_i0`] with its table branch inlined (the likelihood's per-cell call): the same
/// bits for every `x`. `|x|` by clearing the sign bit differs from `log_i0`'s `-x` only
/// for `-0.0` (the table gives `+0.0` from either zero: `0 + (+-0) (b - a)` with
/// `a = ln I0(0) = 0`) and for NaN, which the table branch never takes; every `x` outside
/// the table goes to `log_i0` itself. The index is masked to the table's range, which it
/// already is (`0 <= u < 2048`), so that no bounds check remains.
#[inline(always)]
fn log_i0_inline(x: f32) -> f32 {
    let ax = f32::from_bits(x.to_bits() & 0x7fff_ffff);
    let u = ax * LOG_I0_STEPS_PER_UNIT;
    if u < (LOG_I0_ENTRIES - 1) as f32 {
        let k = u as usize;
        let f = u - k as f32;
        let k = k & (LOG_I0_ENTRIES - 2);
        let (a, b) = (LOG_I0_TABLE[k], LOG_I0_TABLE[k + 1]);
        a + f * (b - a)
    } else {
        log_i0(x)
    }
}

/// Log likelihood ratio of one cell's power `z` (Rician with amplitude `mu` over the
/// noise-only exponential, per-component noise variance `sigma2`):
/// `ln L(z | x) = -mu^2 / (2 sigma^2) + ln I0(mu sqrt(z) / sigma^2)` (eq. 21-23).
#[inline]
pub fn cell_log_lr(z: f32, mu: f32, sigma2: f32) -> f32 {
    let inv = 1.0 / sigma2;
    cell_llr(z, mu, inv, 0.5 * inv)
}

/// [`cell_log_lr`] with `inv = 1 / sigma^2` and `half_inv = 1 / (2 sigma^2)` hoisted.
#[inline(always)]
fn cell_llr(z: f32, mu: f32, inv: f32, half_inv: f32) -> f32 {
    log_i0_inline(mu * sqrt(z) * inv) - mu * mu * half_inv
}

/// A validated, borrowed power cube.
#[derive(Debug, Clone, Copy)]
pub struct PowerCube<'a> {
    data: &'a [f32],
    geometry: CubeGeometry,
}

impl<'a> PowerCube<'a> {
    /// Wraps `data` after checking its length against `geometry` and that every cell is
    /// finite and non-negative ([`Error::LengthMismatch`], [`Error::NonFinite`],
    /// [`Error::NegativeWeight`] for a negative power).
    pub fn new(data: &'a [f32], geometry: CubeGeometry) -> Result<Self> {
        geometry.validate()?;
        if data.len() != geometry.len() {
            return Err(Error::LengthMismatch {
                expected: geometry.len(),
                got: data.len(),
            });
        }
        // One unsigned compare per cell: the bits of a finite `z >= 0` are below those of
        // `+inf`; so are those of every cell if their largest is. Otherwise `-0.0` (bits
        // `0x8000_0000`, a valid zero power) may be the only cell above, so the cells are
        // scanned again for one that is not, and the error told apart.
        let inf = f32::INFINITY.to_bits();
        let top = data.iter().fold(0u32, |t, z| t.max(z.to_bits()));
        if top >= inf
            && data.iter().any(|z| {
                let b = z.to_bits();
                b >= inf && b != 0x8000_0000
            })
        {
            if data.iter().any(|z| !z.is_finite()) {
                return Err(Error::NonFinite);
            }
            return Err(Error::NegativeWeight);
        }
        Ok(Self { data, geometry })
    }

    /// The cells.
    #[inline]
    pub fn data(&self) -> &'a [f32] {
        self.data
    }

    /// The geometry.
    #[inline]
    pub fn geometry(&self) -> &CubeGeometry {
        &self.geometry
    }

    /// Like [`PowerCube::log_lr`], also returning the covered cell with the largest
    /// factor `ln L(z | x)` (`usize::MAX` if no cell is covered).
    #[inline]
    pub fn log_lr_argmax(
        &self,
        psf: &PointSpread,
        c: &RadarCoords,
        amp: f32,
        sigma2: f32,
    ) -> (f32, usize) {
        if psf.half_width.iter().all(|&w| w <= 1) {
            self.log_lr_argmax_3(psf, c, amp, sigma2)
        } else {
            self.log_lr_argmax_in::<MAX_SPAN>(psf, c, amp, sigma2)
        }
    }

    #[inline(always)]
    fn log_lr_argmax_in<const S: usize>(
        &self,
        psf: &PointSpread,
        c: &RadarCoords,
        amp: f32,
        sigma2: f32,
    ) -> (f32, usize) {
        let g = &self.geometry;
        let (fr, fd, fb) = g.fractional(c);
        let r = psf.axis_weights_in::<S>(0, fr, g.n_range);
        let d = psf.axis_weights_in::<S>(1, fd, g.n_doppler);
        let b = psf.axis_weights_in::<S>(2, fb, g.n_azimuth);
        let inv = 1.0 / sigma2;
        let half_inv = 0.5 * inv;
        let mut s = 0.0f32;
        let mut best = (usize::MAX, f32::NEG_INFINITY);
        // The loops of `PointSpread::for_each_cell_of` (same cells, order and products),
        // written out so that the sums stay in registers.
        let hb = b.weights();
        for (ir, &hr) in (r.lo..).zip(r.weights()) {
            for (jd, &hd) in (d.lo..).zip(d.weights()) {
                let hab = hr * hd;
                let base = (ir * g.n_doppler + jd) * g.n_azimuth + b.lo;
                let Some(row) = self.data.get(base..base + hb.len()) else {
                    continue;
                };
                for (k, (&z, &h)) in row.iter().zip(hb).enumerate() {
                    let l = cell_llr(z, amp * (hab * h), inv, half_inv);
                    s += l;
                    if l > best.1 {
                        best = (base + k, l);
                    }
                }
            }
        }
        (s, best.0)
    }

    /// [`PowerCube::log_lr_argmax_in`] for half widths of at most 1 (three slots per
    /// axis): the same cells, order and operations, with a row of three azimuth cells
    /// inside the cube read at once and its three weights kept in registers.
    #[inline(always)]
    fn log_lr_argmax_3(
        &self,
        psf: &PointSpread,
        c: &RadarCoords,
        amp: f32,
        sigma2: f32,
    ) -> (f32, usize) {
        let g = &self.geometry;
        let (fr, fd, fb) = g.fractional(c);
        let r = psf.axis_weights_3(0, fr, g.n_range);
        let d = psf.axis_weights_3(1, fd, g.n_doppler);
        let b = psf.axis_weights_3(2, fb, g.n_azimuth);
        let inv = 1.0 / sigma2;
        let half_inv = 0.5 * inv;
        let mut s = 0.0f32;
        let mut best = (usize::MAX, f32::NEG_INFINITY);
        let hb = b.weights();
        let [h0, h1, h2] = b.h;
        if hb.len() == 3 {
            // The rows' weights `h_r h_d` and first cells, then the rows: fewer values
            // live in the cell loop (the same products, rows and order).
            let mut habs = [0.0f32; 9];
            let mut bases = [0usize; 9];
            let mut m = 0usize;
            for (ir, &hr) in (r.lo..).zip(r.weights()) {
                for (jd, &hd) in (d.lo..).zip(d.weights()) {
                    if let (Some(h), Some(o)) = (habs.get_mut(m), bases.get_mut(m)) {
                        *h = hr * hd;
                        *o = (ir * g.n_doppler + jd) * g.n_azimuth + b.lo;
                        m += 1;
                    }
                }
            }
            for (&hab, &base) in habs.iter().zip(&bases).take(m) {
                let Some(&[z0, z1, z2]) = self
                    .data
                    .get(base..base + 3)
                    .and_then(|row| <&[f32; 3]>::try_from(row).ok())
                else {
                    continue;
                };
                let l = cell_llr(z0, amp * (hab * h0), inv, half_inv);
                s += l;
                if l > best.1 {
                    best = (base, l);
                }
                let l = cell_llr(z1, amp * (hab * h1), inv, half_inv);
                s += l;
                if l > best.1 {
                    best = (base + 1, l);
                }
                let l = cell_llr(z2, amp * (hab * h2), inv, half_inv);
                s += l;
                if l > best.1 {
                    best = (base + 2, l);
                }
            }
            return (s, best.0);
        }
        // Rows of fewer than three cells (the azimuth axis's edges).
        for (ir, &hr) in (r.lo..).zip(r.weights()) {
            for (jd, &hd) in (d.lo..).zip(d.weights()) {
                let hab = hr * hd;
                let base = (ir * g.n_doppler + jd) * g.n_azimuth + b.lo;
                let Some(row) = self.data.get(base..base + hb.len()) else {
                    continue;
                };
                for (k, (&z, &h)) in row.iter().zip(hb).enumerate() {
                    let l = cell_llr(z, amp * (hab * h), inv, half_inv);
                    s += l;
                    if l > best.1 {
                        best = (base + k, l);
                    }
                }
            }
        }
        (s, best.0)
    }

    /// `sum over covered cells of ln L(z | x)` for a target at `c` with amplitude `amp`
    /// (the log of the product in eq. 20 and 24).
    #[inline]
    pub fn log_lr(&self, psf: &PointSpread, c: &RadarCoords, amp: f32, sigma2: f32) -> f32 {
        self.log_lr_argmax(psf, c, amp, sigma2).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// f64 reference: power series for x <= 30, asymptotic expansion above.
    fn log_i0_ref(x: f64) -> f64 {
        if x <= 30.0 {
            let q = x * x / 4.0;
            let mut term = 1.0f64;
            let mut s = 1.0f64;
            for k in 1..400 {
                term *= q / ((k * k) as f64);
                s += term;
                if term < s * 1e-18 {
                    break;
                }
            }
            s.ln()
        } else {
            let mut s = 1.0f64;
            let mut term = 1.0f64;
            for k in 1..12 {
                let a = (2 * k - 1) as f64;
                term *= a * a / (k as f64 * 8.0 * x);
                s += term;
            }
            x - 0.5 * (2.0 * core::f64::consts::PI * x).ln() + s.ln()
        }
    }

    #[test]
    fn log_i0_matches_f64_reference() {
        // Tolerance: below 32 the table's chord error (at most 1.53e-5, `log_i0`'s doc)
        // plus f32 rounding of entries up to ~28 (1e-6); above, the A&S relative error
        // 2e-7 plus f32 rounding of x - ln x/2 (relative 6e-8 of a value up to ~1e4).
        // The step 0.001 below 40 puts points between every pair of table entries.
        let mut x = 0.0f64;
        let mut worst = 0.0f64;
        while x < 1.0e4 {
            let got = log_i0(x as f32) as f64;
            let want = log_i0_ref(x as f32 as f64);
            let tol = if x < 32.0 { 1.7e-5 } else { 1e-6 } + 2e-7 * want.abs();
            if x < 32.0 {
                worst = worst.max(got - want);
            }
            assert!((got - want).abs() <= tol, "x={x} got={got} want={want}");
            x = if x < 40.0 { x + 0.001 } else { x * 1.01 };
        }
        // The bound is nearly reached (the chord's error near 0 is 0.5 h^2 / 8).
        assert!(worst > 1.0e-5, "{worst}");
        assert!(log_i0(1.0e30).is_finite());
        assert_eq!(log_i0(-2.0), log_i0(2.0));
    }

    /// `ln_fast` against `f64::ln` over the normal range (a geometric sweep, ratio
    /// 1.0001, plus the neighbours of powers of two and of their `sqrt(2)` multiples,
    /// where the reduction switches). Tolerance `4e-7 + 6e-8 |ln y|`: the series is exact
    /// to `7e-10`; the rest is f32 rounding of the reduced log (a few ulps of a value
    /// below 0.35) and of the final sum (half an ulp, `6e-8` relative).
    #[test]
    fn ln_fast_matches_f64() {
        let mut checked = 0usize;
        let mut check = |y: f32| {
            let got = ln_fast(y) as f64;
            let want = (y as f64).ln();
            let err = (got - want).abs();
            assert!(
                err <= 4e-7 + 6e-8 * want.abs(),
                "y={y:e} got={got} want={want}"
            );
            checked += 1;
        };
        let mut y = f32::MIN_POSITIVE;
        while y < f32::MAX / 1.0001 {
            check(y);
            y *= 1.0001;
        }
        for e in -126..128 {
            let p = 2.0f32.powi(e);
            for v in [p, p * core::f32::consts::SQRT_2] {
                for u in [-2i32, -1, 0, 1, 2] {
                    let b = (v.to_bits() as i32 + u) as u32;
                    let y = f32::from_bits(b);
                    if y.is_finite() && y >= f32::MIN_POSITIVE {
                        check(y);
                    }
                }
            }
        }
        assert!(checked > 1_000_000, "{checked}");
        assert_eq!(ln_fast(0.0), f32::NEG_INFINITY);
        assert!(ln_fast(-1.0).is_nan());
        assert_eq!(ln_fast(f32::INFINITY), f32::INFINITY);
        assert_eq!(ln_fast(1.0), 0.0);
    }

    /// `exp_neg` against `f64::exp` on `[-87, 0]` (step 1e-4, plus the points where
    /// the reduction's `n` changes). Tolerance `4e-7` relative: the polynomial's
    /// truncation (1.3e-7) plus f32 rounding of the reduction and of Horner's steps.
    #[test]
    fn exp_neg_matches_f64() {
        let check = |x: f32| {
            let got = exp_neg(x) as f64;
            let want = (x as f64).exp();
            assert!(
                (got - want).abs() <= 4e-7 * want,
                "x={x} got={got} want={want}"
            );
        };
        let mut k = 0u32;
        while k <= 870_000 {
            check(-(k as f32) * 1e-4);
            k += 1;
        }
        for n in 0..126 {
            let x = -(n as f32 + 0.5) * core::f32::consts::LN_2;
            for u in [-1i32, 0, 1] {
                check(f32::from_bits((x.to_bits() as i32 + u) as u32));
            }
        }
        assert_eq!(exp_neg(0.0), 1.0);
        assert_eq!(exp_neg(-100.0), 0.0);
        assert_eq!(exp_neg(f32::NEG_INFINITY), 0.0);
        assert_eq!(exp_neg(1.0), math::exp(1.0));
        assert!(exp_neg(f32::NAN).is_nan());
    }

    /// `sin_cos` against `f64` on `[-200, 200]` (step 1e-3, plus the points where the
    /// quadrant changes). Tolerance `3e-7` absolute: the polynomials' truncation (below
    /// 3e-8) plus f32 rounding of the reduction and of Horner's steps (values up to 1,
    /// a few ulps of 6e-8).
    #[test]
    fn sin_cos_matches_f64() {
        let check = |x: f32| {
            let (s, c) = sin_cos(x);
            let (ws, wc) = (x as f64).sin_cos();
            assert!((s as f64 - ws).abs() <= 3e-7, "sin x={x} got={s} want={ws}");
            assert!((c as f64 - wc).abs() <= 3e-7, "cos x={x} got={c} want={wc}");
        };
        let mut k = -200_000i32;
        while k <= 200_000 {
            check(k as f32 * 1e-3);
            k += 1;
        }
        for q in -127..=127 {
            let x = (q as f32 + 0.5) * core::f32::consts::FRAC_PI_2;
            for u in [-1i32, 0, 1] {
                check(f32::from_bits((x.to_bits() as i32 + u) as u32));
            }
        }
        assert_eq!(sin_cos(1.0e6), (math::sin(1.0e6), math::cos(1.0e6)));
        assert!(sin_cos(f32::NAN).0.is_nan());
    }

    /// The likelihood's inlined and specialised helpers give the bits of the general ones:
    /// `log_i0_inline` against `log_i0` (a sweep over the table and beyond, both zeros,
    /// negative, infinite and NaN arguments), `floor_i32` against `math::floor`,
    /// `axis_weights_3` against `axis_weights_in::<3>`, and `log_lr_argmax` (the
    /// three-slot path) against the `MAX_SPAN` path on every cell centre and off-centre
    /// point of a cube, edges included.
    #[test]
    fn specialised_likelihood_helpers_are_bit_identical() {
        let mut x = 0.0f32;
        while x < 40.0 {
            for v in [x, -x] {
                assert_eq!(log_i0_inline(v).to_bits(), log_i0(v).to_bits(), "{v}");
            }
            x += 0.000_37;
        }
        for v in [
            0.0,
            -0.0,
            31.999_998,
            32.0,
            1e30,
            f32::INFINITY,
            -f32::INFINITY,
        ] {
            assert_eq!(log_i0_inline(v).to_bits(), log_i0(v).to_bits(), "{v}");
        }
        assert!(log_i0_inline(f32::NAN).is_nan());
        let mut f = -1.0e6f32;
        while f <= 1.0e6 {
            for v in [f, f + 0.25, f + 0.5, -0.0] {
                assert_eq!(floor_i32(v), math::floor(v) as i32, "{v}");
            }
            f += 997.13;
        }
        let g = geom();
        let data: std::vec::Vec<f32> = (0..g.len())
            .map(|i| ((i * 7919) % 113) as f32 * 0.37)
            .collect();
        let cube = PowerCube::new(&data, g).unwrap();
        for psf in [
            PointSpread::ONE_CELL,
            PointSpread::from_std([0.7, 1.3, 2.0], [1, 0, 1]),
        ] {
            let mut k = 0u32;
            for ir in 0..=2 * g.n_range {
                for jd in 0..=2 * g.n_doppler {
                    for lb in 0..=2 * g.n_azimuth {
                        k = k.wrapping_mul(1_103_515_245).wrapping_add(12345);
                        let jitter = (k >> 16) as f32 / 65536.0 * 0.5;
                        let c = RadarCoords {
                            range: g.range_start + (ir as f32 * 0.5 + jitter) * g.range_cell,
                            doppler: g.doppler_start + (jd as f32 * 0.5 + jitter) * g.doppler_cell,
                            azimuth_deg: g.azimuth_start_deg
                                + (lb as f32 * 0.5 - jitter) * g.azimuth_cell_deg,
                        };
                        let (fr, fd, fb) = g.fractional(&c);
                        for (a, fx, n) in [
                            (0, fr, g.n_range),
                            (1, fd, g.n_doppler),
                            (2, fb, g.n_azimuth),
                        ] {
                            assert_eq!(
                                psf.axis_weights_3(a, fx, n),
                                psf.axis_weights_in::<3>(a, fx, n)
                            );
                        }
                        for amp in [0.0, 0.8, 3.0, 40.0] {
                            let (s3, i3) = cube.log_lr_argmax(&psf, &c, amp, 0.5);
                            let (s17, i17) = cube.log_lr_argmax_in::<MAX_SPAN>(&psf, &c, amp, 0.5);
                            assert_eq!((s3.to_bits(), i3), (s17.to_bits(), i17), "{c:?} {amp}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn likelihood_ratio_is_one_without_target() {
        assert_eq!(cell_log_lr(3.0, 0.0, 1.0), 0.0);
    }

    fn geom() -> CubeGeometry {
        CubeGeometry {
            n_range: 10,
            n_doppler: 6,
            n_azimuth: 8,
            range_start: 0.0,
            range_cell: 20.0,
            doppler_start: -3.0,
            doppler_cell: 1.0,
            azimuth_start_deg: 0.0,
            azimuth_cell_deg: 1.0,
        }
    }

    #[test]
    fn index_roundtrip_and_cube_checks() {
        let g = geom();
        for idx in 0..g.len() {
            let (a, b, c) = g.unindex(idx);
            assert_eq!(g.index(a, b, c), idx);
        }
        let mut v = std::vec![1.0f32; g.len()];
        assert!(PowerCube::new(&v, g).is_ok());
        assert_eq!(
            PowerCube::new(&v[1..], g).err(),
            Some(Error::LengthMismatch {
                expected: g.len(),
                got: g.len() - 1
            })
        );
        v[7] = f32::NAN;
        assert_eq!(PowerCube::new(&v, g).err(), Some(Error::NonFinite));
        v[7] = -1.0;
        assert_eq!(PowerCube::new(&v, g).err(), Some(Error::NegativeWeight));
        // -0.0 is a zero power (its bits are above +inf's): alone it passes, beside a bad
        // cell the error is that cell's.
        v[7] = -0.0;
        v[9] = -0.0;
        assert!(PowerCube::new(&v, g).is_ok());
        v[3] = -2.0;
        assert_eq!(PowerCube::new(&v, g).err(), Some(Error::NegativeWeight));
        v[11] = f32::INFINITY;
        assert_eq!(PowerCube::new(&v, g).err(), Some(Error::NonFinite));
    }

    #[test]
    fn spread_covers_neighbourhood_and_peaks_at_own_cell() {
        let g = geom();
        let psf = PointSpread::ONE_CELL;
        let c = RadarCoords {
            range: 90.0,
            doppler: 0.5,
            azimuth_deg: 3.5,
        };
        let own = g.cell_of(&c).map(|(a, b, l)| g.index(a, b, l));
        let mut n = 0;
        let mut best = (0usize, 0.0f32);
        psf.for_each_cell(&g, &c, |i, h| {
            n += 1;
            if h > best.1 {
                best = (i, h);
            }
        });
        assert_eq!(n, 27);
        assert_eq!(Some(best.0), own);
        // At a corner only 8 cells are inside the cube.
        let corner = RadarCoords {
            range: 1.0,
            doppler: -2.9,
            azimuth_deg: 0.2,
        };
        let mut m = 0;
        psf.for_each_cell(&g, &corner, |_, _| m += 1);
        assert_eq!(m, 8);
        // Far outside: nothing, no panic.
        let mut k = 0;
        let far = RadarCoords {
            range: f32::INFINITY,
            doppler: f32::NAN,
            azimuth_deg: 1e30,
        };
        psf.for_each_cell(&g, &far, |_, _| k += 1);
        assert_eq!(k, 0);
    }

    #[test]
    fn spread_validation_bounds_the_cost_and_the_width() {
        let ok = PointSpread::from_std([2.0, 2.0, 2.0], [6, 6, 6]);
        assert_eq!(ok.covered(), 2197);
        assert!(ok.validate().is_ok());
        for bad in [
            PointSpread {
                half_width: [9, 0, 0],
                ..ok
            },
            PointSpread {
                half_width: [8, 8, 8],
                ..ok
            },
            PointSpread::from_std([17.0, 1.0, 1.0], [1, 1, 1]),
            PointSpread::from_std([0.0, 1.0, 1.0], [1, 1, 1]),
            PointSpread {
                loss_doppler: f32::NAN,
                ..ok
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
        assert_eq!(PointSpread::ONE_CELL.peak_radius(0), 1);
        assert_eq!(ok.peak_radius(1), 2);
        assert_eq!(PointSpread::from_std([0.5; 3], [1; 3]).peak_radius(2), 1);
        assert_eq!(ok.central().half_width, [1, 1, 1]);
    }

    /// Per-axis half widths and losses against an f64 evaluation of eq. 3 at every
    /// covered cell (tolerance: f32 rounding of `exp` of an argument up to ~50, relative
    /// 1e-5), for the widest valid spreads; `log_lr` stays finite on a cube of large
    /// powers at every position, in the cube or outside it.
    #[test]
    fn per_axis_spread_matches_eq3_and_log_lr_stays_finite() {
        let g = CubeGeometry {
            n_range: 30,
            n_doppler: 20,
            n_azimuth: 25,
            ..geom()
        };
        let data: std::vec::Vec<f32> = (0..g.len()).map(|i| (i % 97) as f32 * 1e3).collect();
        let cube = PowerCube::new(&data, g).unwrap();
        for psf in [
            PointSpread::from_std([2.0, 0.5, 16.0], [6, 1, 8]),
            PointSpread::from_std([16.0, 16.0, 16.0], [6, 6, 6]),
            PointSpread::from_std([0.0625, 1.0, 3.0], [0, 8, 3]),
        ] {
            psf.validate().unwrap();
            let c = RadarCoords {
                range: 310.0,
                doppler: 4.3,
                azimuth_deg: 11.7,
            };
            let (fr, fd, fb) = g.fractional(&c);
            let mut n = 0;
            psf.for_each_cell(&g, &c, |idx, h| {
                let (i, j, l) = g.unindex(idx);
                let d = |k: usize, f: f32| k as f64 + 0.5 - f as f64;
                let want = (-0.5
                    * (psf.loss_range as f64 * d(i, fr).powi(2)
                        + psf.loss_doppler as f64 * d(j, fd).powi(2)
                        + psf.loss_azimuth as f64 * d(l, fb).powi(2)))
                .exp();
                assert!((h as f64 - want).abs() <= 1e-5 * want + 1e-30, "{h} {want}");
                n += 1;
            });
            let interior: usize = (0..3).map(|a| 2 * psf.half(a) + 1).product();
            assert!(n <= interior && n > 0);
            for (r, d, b) in [
                (310.0, 4.3, 11.7),
                (-1e30, 0.0, 0.0),
                (1e6, -1e6, 1e6),
                (f32::NAN, 0.0, 0.0),
            ] {
                let rc = RadarCoords {
                    range: r,
                    doppler: d,
                    azimuth_deg: b,
                };
                for amp in [0.0, 1.0, 1e6] {
                    let l = cube.log_lr(&psf, &rc, amp, 0.5);
                    assert!(l.is_finite(), "{psf:?} {rc:?} {amp}: {l}");
                }
            }
        }
    }
}
