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
        let r = math::sqrt(x * x + y * y);
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
        let mut out = AxisWeights::NONE;
        if !frac.is_finite() {
            return out;
        }
        let loss = self.loss(a);
        let w = self.half(a) as i64;
        let span = 2 * w as usize + 1;
        out.span = span;
        // Clamp so that far-away states do not overflow the i64 conversion.
        let centre = math::floor(frac.clamp(-1.0e6, 1.0e6)) as i64;
        for k in 0..span.min(MAX_SPAN) {
            let i = centre - w + k as i64;
            if i >= 0 && (i as usize) < n {
                let delta = i as f32 + 0.5 - frac;
                out.h[k] = math::exp(-0.5 * loss * delta * delta);
                out.id[k] = i as usize;
            }
        }
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
        let sb = b.span.min(MAX_SPAN);
        for (&ir, &hr) in r.id.iter().zip(&r.h).take(r.span) {
            if ir == usize::MAX {
                continue;
            }
            for (&jd, &hd) in d.id.iter().zip(&d.h).take(d.span) {
                if jd == usize::MAX {
                    continue;
                }
                let hab = hr * hd;
                let base = (ir * g.n_doppler + jd) * g.n_azimuth;
                for (&l, &h) in b.id[..sb].iter().zip(&b.h[..sb]) {
                    if l != usize::MAX {
                        f(base + l, hab * h);
                    }
                }
            }
        }
    }
}

/// Covered cells and weights of one axis of a [`PointSpread`] (see
/// [`PointSpread::axis_weights`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisWeights {
    h: [f32; MAX_SPAN],
    /// Cell index per slot, `usize::MAX` outside the axis.
    id: [usize; MAX_SPAN],
    /// Slots in use, `2 w + 1`.
    span: usize,
}

impl AxisWeights {
    /// No covered cell.
    pub const NONE: Self = Self {
        h: [0.0; MAX_SPAN],
        id: [usize::MAX; MAX_SPAN],
        span: 0,
    };
}

/// `ln I0(x)` for `x >= 0` (modified Bessel function of the first kind, order 0), stable
/// for every finite `x` (no overflow: `I0(x) ~ e^x / sqrt(2 pi x)`).
///
/// Abramowitz & Stegun 9.8.1 (`x <= 3.75`, `ln1p` of the series) and 9.8.2 (`x > 3.75`,
/// `x - ln(x)/2 + ln(poly(3.75/x))`); relative error of `I0` below `2e-7`, so the
/// absolute error of the log is below `~3e-7` plus `f32` rounding of `x`. Negative `x`
/// uses `I0(-x) = I0(x)`; NaN gives NaN.
#[allow(clippy::excessive_precision)]
pub fn log_i0(x: f32) -> f32 {
    let ax = if x < 0.0 { -x } else { x };
    if ax <= 3.75 {
        let t = (ax / 3.75) * (ax / 3.75);
        let p = t
            * (3.515_622_9
                + t * (3.089_942_4
                    + t * (1.206_749_2 + t * (0.265_973_2 + t * (0.036_076_8 + t * 0.004_581_3)))));
        math::ln1p(p)
    } else {
        let t = 3.75 / ax;
        let p = 0.398_942_28
            + t * (0.013_285_92
                + t * (0.002_253_19
                    + t * (-0.001_575_65
                        + t * (0.009_162_81
                            + t * (-0.020_577_06
                                + t * (0.026_355_37 + t * (-0.016_476_33 + t * 0.003_923_77)))))));
        ax - 0.5 * math::ln(ax) + math::ln(p)
    }
}

/// Log likelihood ratio of one cell's power `z` (Rician with amplitude `mu` over the
/// noise-only exponential, per-component noise variance `sigma2`):
/// `ln L(z | x) = -mu^2 / (2 sigma^2) + ln I0(mu sqrt(z) / sigma^2)` (eq. 21-23).
#[inline]
pub fn cell_log_lr(z: f32, mu: f32, sigma2: f32) -> f32 {
    -mu * mu / (2.0 * sigma2) + log_i0(mu * math::sqrt(z) / sigma2)
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
        let mut bad_nan = false;
        let mut bad_neg = false;
        for &z in data {
            bad_nan |= !z.is_finite();
            bad_neg |= z < 0.0;
        }
        if bad_nan {
            return Err(Error::NonFinite);
        }
        if bad_neg {
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
        let mut s = 0.0f32;
        let mut best = (usize::MAX, f32::NEG_INFINITY);
        let data = self.data;
        psf.for_each_cell(&self.geometry, c, |idx, h| {
            if let Some(&z) = data.get(idx) {
                let l = cell_log_lr(z, amp * h, sigma2);
                s += l;
                if l > best.1 {
                    best = (idx, l);
                }
            }
        });
        (s, best.0)
    }

    /// `sum over covered cells of ln L(z | x)` for a target at `c` with amplitude `amp`
    /// (the log of the product in eq. 20 and 24).
    #[inline]
    pub fn log_lr(&self, psf: &PointSpread, c: &RadarCoords, amp: f32, sigma2: f32) -> f32 {
        let mut s = 0.0f32;
        let data = self.data;
        psf.for_each_cell(&self.geometry, c, |idx, h| {
            if let Some(&z) = data.get(idx) {
                s += cell_log_lr(z, amp * h, sigma2);
            }
        });
        s
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
        // Tolerance: A&S relative error 2e-7 plus f32 rounding of x - ln x/2 (relative
        // 6e-8 of a value up to ~1e4).
        let mut x = 0.0f64;
        while x < 1.0e4 {
            let got = log_i0(x as f32) as f64;
            let want = log_i0_ref(x as f32 as f64);
            let tol = 1e-6 + 2e-7 * want.abs();
            assert!((got - want).abs() <= tol, "x={x} got={got} want={want}");
            x = if x < 10.0 { x + 0.01 } else { x * 1.01 };
        }
        assert!(log_i0(1.0e30).is_finite());
        assert_eq!(log_i0(-2.0), log_i0(2.0));
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
