//! Hough geometry: an `R x A` (`N_rho x N_theta`) grid, `theta_a = a pi / A`,
//! `rho = (x - x0) cos(theta) + (y - y0) sin(theta)` (Bao et al. 2022, eq. 1 and eq. 7), and the
//! rho quantisation.
//!
//! Two equivalent quantisers are provided:
//! - `rho_index_f32`: `floor((rho + rho_max) / drho)` in `f32`;
//! - `rho_index_q` (used in the hot loops): coordinates in Q-format integers (`|x| <= 2^15`
//!   units over the half-extent `rho_max`), `cos/sin` in Q14, `rho` as an exact `i32`
//!   sum of two products, and the division by `drho` as one 32x32->64 multiply and shift.
//!   The coordinate step is `rho_max / 32767` (0.13 m for the 6 km sea-clutter area,
//!   against a 33 m rho cell), the table error is `2^-15`: the two quantisers disagree only
//!   for points within ~0.3 m of a cell boundary. `benches/mht.rs` measures both.
//!
//! Cells are stored theta-major: `cell = a * R + r`.

use crate::math;

/// Q14 scale of the cos/sin tables.
const TRIG_Q: f32 = 16384.0;
/// Largest integer coordinate magnitude.
const COORD_Q: f32 = 32767.0;

/// An `R x A` Hough grid with its origin and rho quantisation.
#[derive(Debug, Clone, Copy)]
pub struct Geometry<const R: usize, const A: usize> {
    cos: [f32; A],
    sin: [f32; A],
    cos_q: [i32; A],
    sin_q: [i32; A],
    x0: f32,
    y0: f32,
    rho_max: f32,
    drho: f32,
    inv_drho: f32,
    /// metres -> integer coordinate units.
    scale: f32,
    /// `rho_max` in accumulator units (`scale * 2^14`).
    rmax_q: i64,
    /// `floor(R 2^32 / (2 rmax_q))`.
    mul_q: u64,
}

impl<const R: usize, const A: usize> Geometry<R, A> {
    /// Compile-time check of the grid shape: at least one cell on each axis, and rho
    /// cells addressable by the `u16` curves.
    const SHAPE: () = assert!(
        R > 0 && A > 0 && R <= u16::MAX as usize,
        "a Hough grid needs 1..=65535 rho cells and at least one angle"
    );

    /// An all-zero placeholder (for `static` detector storage); replace it with
    /// [`Geometry::new`] before use.
    pub const fn placeholder() -> Self {
        let () = Self::SHAPE;
        Self {
            cos: [0.0; A],
            sin: [0.0; A],
            cos_q: [0; A],
            sin_q: [0; A],
            x0: 0.0,
            y0: 0.0,
            rho_max: 1.0,
            drho: 1.0,
            inv_drho: 1.0,
            scale: 1.0,
            rmax_q: 1,
            mul_q: 0,
        }
    }

    /// A grid with origin `(x0, y0)` covering `rho in [-rho_max, rho_max]`.
    ///
    /// `rho_max` is floored at `1e-3` m (degenerate geometry: all points at the origin
    /// map to the middle rho cell), capped at `f32::MAX / 4`; a non-finite origin falls
    /// back to 0 and a NaN `rho_max` to the floor.
    pub fn new(x0: f32, y0: f32, rho_max: f32) -> Self {
        let () = Self::SHAPE;
        let mut cos = [0.0f32; A];
        let mut sin = [0.0f32; A];
        let mut cos_q = [0i32; A];
        let mut sin_q = [0i32; A];
        for a in 0..A {
            let th = a as f32 * math::PI / A as f32;
            cos[a] = math::cos(th);
            sin[a] = math::sin(th);
            cos_q[a] = math::round(cos[a] * TRIG_Q) as i32;
            sin_q[a] = math::round(sin[a] * TRIG_Q) as i32;
        }
        let fin = |v: f32| if v.is_finite() { v } else { 0.0 };
        // Clamped into `[1e-3, f32::MAX / 4]` (NaN to the floor): `2 rho_max` and the
        // rho cell stay finite for any input.
        let rho_max = if rho_max > 1e-3 {
            rho_max.min(f32::MAX / 4.0)
        } else {
            1e-3
        };
        let drho = 2.0 * rho_max / R as f32;
        let scale = COORD_Q / rho_max;
        let rmax_q = (rho_max * scale * TRIG_Q) as i64;
        let mul_q = ((R as u64) << 32) / (2 * rmax_q.max(1) as u64);
        Self {
            cos,
            sin,
            cos_q,
            sin_q,
            x0: fin(x0),
            y0: fin(y0),
            rho_max,
            drho,
            inv_drho: 1.0 / drho,
            scale,
            rmax_q,
            mul_q,
        }
    }

    /// Grid for a rectangle `[x_min, x_max] x [y_min, y_max]`: origin at its centre,
    /// `rho_max` = half its diagonal (the standard transform of the classic detector and
    /// of the single-frame transform).
    pub fn for_area(area: [f32; 4]) -> Self {
        let x0 = 0.5 * (area[0] + area[1]);
        let y0 = 0.5 * (area[2] + area[3]);
        let hx = 0.5 * (area[1] - area[0]);
        let hy = 0.5 * (area[3] - area[2]);
        Self::new(x0, y0, math::sqrt(hx * hx + hy * hy))
    }

    /// Origin `(x0, y0)`.
    pub fn origin(&self) -> (f32, f32) {
        (self.x0, self.y0)
    }
    /// Half rho extent.
    pub fn rho_max(&self) -> f32 {
        self.rho_max
    }
    /// Rho cell size.
    pub fn drho(&self) -> f32 {
        self.drho
    }
    /// `theta_a = a pi / A`.
    pub fn theta(&self, a: usize) -> f32 {
        a as f32 * math::PI / A as f32
    }
    /// `(cos theta_a, sin theta_a)`; `(1, 0)` for an angle index `a >= A`.
    pub fn trig(&self, a: usize) -> (f32, f32) {
        match (self.cos.get(a), self.sin.get(a)) {
            (Some(&c), Some(&s)) => (c, s),
            _ => (1.0, 0.0),
        }
    }
    /// Centre of rho cell `r`.
    pub fn rho_center(&self, r: usize) -> f32 {
        -self.rho_max + (r as f32 + 0.5) * self.drho
    }

    /// `rho` of `(x, y)` at angle `a` (f32); the angle `theta_0 = 0` for `a >= A`.
    #[inline]
    pub fn rho(&self, x: f32, y: f32, a: usize) -> f32 {
        let (c, s) = self.trig(a);
        (x - self.x0) * c + (y - self.y0) * s
    }

    /// Rho cell of `(x, y)` at angle `a` (f32 quantiser), clamped to `0..R`.
    #[inline]
    pub fn rho_index_f32(&self, x: f32, y: f32, a: usize) -> usize {
        let u = (self.rho(x, y, a) + self.rho_max) * self.inv_drho;
        if u <= 0.0 {
            0
        } else {
            (u as usize).min(R - 1)
        }
    }

    /// Integer coordinates of `(x, y)` (saturating: points outside `rho_max` of the
    /// origin clamp to the grid edge).
    #[inline]
    pub fn quantise(&self, x: f32, y: f32) -> (i32, i32) {
        let q = |v: f32| {
            let s = v * self.scale;
            if s >= COORD_Q {
                COORD_Q as i32
            } else if s <= -COORD_Q {
                -(COORD_Q as i32)
            } else {
                math::round(s) as i32
            }
        };
        (q(x - self.x0), q(y - self.y0))
    }

    /// Rho cell of integer coordinates at angle `a` (integer quantiser), in `0..R`.
    /// Coordinates are those of [`quantise`](Self::quantise) (`|xq|, |yq| <= 32767`;
    /// larger ones give an unspecified cell in `0..R`); the angle `theta_0 = 0` for
    /// `a >= A`.
    #[inline]
    pub fn rho_index_q(&self, xq: i32, yq: i32, a: usize) -> usize {
        let (c, s) = match (self.cos_q.get(a), self.sin_q.get(a)) {
            (Some(&c), Some(&s)) => (c, s),
            _ => (TRIG_Q as i32, 0),
        };
        self.rho_cell_q(xq, yq, c, s)
    }

    /// [`rho_index_q`](Self::rho_index_q) with the angle's Q14 `(cos, sin)` given.
    #[inline(always)]
    fn rho_cell_q(&self, xq: i32, yq: i32, c: i32, s: i32) -> usize {
        // |acc| <= 2 * 32767 * 16384 < 2^31 for quantised coordinates; others wrap (no
        // panic, a cell in 0..R all the same).
        let acc = xq.wrapping_mul(c).wrapping_add(yq.wrapping_mul(s));
        let u = (i64::from(acc) + self.rmax_q).max(0) as u64;
        (((u * self.mul_q) >> 32) as usize).min(R - 1)
    }

    /// Rho cells of one point for every angle, integer quantiser, into `out` (length `A`).
    #[inline]
    pub fn curve_q(&self, xq: i32, yq: i32, out: &mut [u16; A]) {
        for (o, (&c, &s)) in out.iter_mut().zip(self.cos_q.iter().zip(&self.sin_q)) {
            *o = self.rho_cell_q(xq, yq, c, s) as u16;
        }
    }

    /// True if some angle puts every point of `pts` (integer coordinates) in one rho cell:
    /// the points share a cell `(rho, theta)`, i.e. the cell is hit in each of their scans.
    pub fn share_cell(&self, pts: &[(i32, i32)]) -> bool {
        let Some((&first, rest)) = pts.split_first() else {
            return false;
        };
        'angles: for (&c, &s) in self.cos_q.iter().zip(&self.sin_q) {
            let r0 = self.rho_cell_q(first.0, first.1, c, s);
            for p in rest {
                if self.rho_cell_q(p.0, p.1, c, s) != r0 {
                    continue 'angles;
                }
            }
            return true;
        }
        false
    }

    /// Neighbour of cell `(r, a)` at offset `(dr, da)`, with the theta wrap-around
    /// `(rho, theta + pi) = (-rho, theta)`; `None` past the rho edges.
    #[inline]
    pub fn neighbour(r: usize, a: usize, dr: isize, da: isize) -> Option<usize> {
        let mut aa = a as isize + da;
        let mut rr = r as isize;
        if aa < 0 {
            aa += A as isize;
            rr = R as isize - 1 - rr;
        } else if aa >= A as isize {
            aa -= A as isize;
            rr = R as isize - 1 - rr;
        }
        let flip = aa != a as isize + da;
        let rr = if flip { rr - dr } else { rr + dr };
        if rr < 0 || rr >= R as isize {
            None
        } else {
            Some(aa as usize * R + rr as usize)
        }
    }
}
