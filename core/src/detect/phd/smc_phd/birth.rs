//! Births (eq. 16-17): the birth model ([`BirthModel`]: Gaussian components, or
//! measurement-driven cells), the birth particles appended each frame, and the choice of
//! the next frame's birth cells.

use super::*;
use crate::model::power_cube;

/// Maximum number of birth components.
pub const MAX_BIRTH_COMPONENTS: usize = 4;
/// Maximum cells a measurement-driven birth component samples from.
pub const MAX_BIRTH_CELLS: usize = 16;
/// Maximum cells of [`BirthMode::Region`] (the components' cell stores, pooled).
pub const MAX_REGION_CELLS: usize = MAX_BIRTH_CELLS * MAX_BIRTH_COMPONENTS;

/// One birth component: Gaussian over `[x, vx, y, vy]` with independent axes.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct BirthComponent {
    /// Mean `[x, vx, y, vy]`.
    pub mean: [f32; 4],
    /// Standard deviations `[x, vx, y, vy]`.
    pub std: [f32; 4],
}

/// How birth particles are drawn.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum BirthMode {
    /// From the Gaussian mixture (equal component weights), as in the paper.
    Gaussian,
    /// Measurement-driven: per component, the `cells` strongest cells of the previous
    /// frame inside the component's `3 sigma` position window (all Doppler cells), ranked
    /// by the point-spread-matched statistic `sum h^2 z`; a birth particle is uniform
    /// inside one of them (range, azimuth, radial velocity) with a tangential velocity
    /// `N(0, tangential_std^2)`, propagated one CV step.
    Measurement {
        /// Strongest cells kept per component (1..=16).
        cells: usize,
        /// Standard deviation of the unobserved tangential velocity (m/s).
        tangential_std: f32,
        /// Two-frame velocity (0 = off): a birth particle's tangential velocity is
        /// instead its displacement from a point drawn in one of the component's cells
        /// of the frame before (k-2) over `T`, if that gives a speed of at most this
        /// (m/s) with the particle's Doppler; up to 4 cells tried, else
        /// `N(0, tangential_std^2)`.
        pair_max_speed: f32,
    },
    /// Measurement-driven over the whole cube (no birth points; the components are not
    /// used): the `cells` strongest local peaks of the previous frame's statistic
    /// `sum h^2 z` over every cell, a peak being stronger than every kept cell within one
    /// cell on each axis; a birth particle is uniform inside one of them (range, azimuth,
    /// radial velocity) with a tangential velocity `N(0, tangential_std^2)`, propagated
    /// one CV step. On the first frame (no previous frame) births are uniform over the
    /// cube's range, azimuth and Doppler extent.
    Region {
        /// Peaks kept (1..=64).
        cells: usize,
        /// Standard deviation of the unobserved tangential velocity (m/s).
        tangential_std: f32,
    },
}

/// Birth density.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct BirthModel {
    /// Components (the first `n_components` are used).
    pub components: [BirthComponent; MAX_BIRTH_COMPONENTS],
    /// Number of components in use.
    pub n_components: usize,
    /// Sampling mode.
    pub mode: BirthMode,
    /// Birth particles per frame `J_k`.
    pub particles: usize,
    /// Expected number of births per frame (total birth PHD mass).
    pub mass: f32,
    /// Birth intensities are `U[lo, hi]`, `0 <= lo <= hi <= MAX_INTENSITY`.
    pub intensity: [f32; 2],
}

impl<const PARTICLES: usize, const SWARM: usize, const POINTS: usize, const TARGETS: usize>
    SmcPhdTbd<PARTICLES, SWARM, POINTS, TARGETS>
{
    pub(super) fn add_births(&mut self) {
        let b = self.cfg.birth;
        let g = self.cfg.geometry;
        let j = b.particles.min(PARTICLES - self.n);
        if j == 0 {
            return;
        }
        if let BirthMode::Region { tangential_std, .. } = b.mode {
            self.add_region_births(j, tangential_std);
            return;
        }
        let wb = b.mass / j as f32;
        let nc = b.n_components;
        let mut k = self.n;
        for (ci, &comp) in b.components.iter().enumerate().take(nc) {
            let count = j / nc + usize::from(ci < j % nc);
            // Measurement-driven: strongest cells of the component's window on the
            // *previous* frame, propagated one step (`choose_birth_cells`).
            let cells = self.birth_cells[ci];
            let nb = self.birth_nb[ci];
            let (tang, vmax) = match b.mode {
                BirthMode::Measurement {
                    tangential_std,
                    pair_max_speed,
                    ..
                } => (tangential_std, pair_max_speed),
                BirthMode::Gaussian | BirthMode::Region { .. } => (0.0, 0.0),
            };
            let prev = self.birth_prev[ci];
            let np = if vmax > 0.0 {
                self.birth_prev_nb[ci]
            } else {
                0
            };
            for _ in 0..count {
                let pick = if nb > 0 {
                    cells.get(self.rng.below(nb as u32) as usize).copied()
                } else {
                    None
                };
                let s = if let Some((idx, _)) = pick {
                    let (ir, jd, lb) = g.unindex(idx);
                    let r = g.range_start + (ir as f32 + self.rng.uniform()) * g.range_cell;
                    let d = g.doppler_start + (jd as f32 + self.rng.uniform()) * g.doppler_cell;
                    let az = (g.azimuth_start_deg
                        + (lb as f32 + self.rng.uniform()) * g.azimuth_cell_deg)
                        / DEG_PER_RAD;
                    let (sb, cb) = power_cube::sin_cos(az);
                    let mut vt = tang * self.rng.normal();
                    for _ in 0..np.min(4) {
                        let Some(&(pidx, _)) = prev.get(self.rng.below(np as u32) as usize) else {
                            break;
                        };
                        let (pr, _, pl) = g.unindex(pidx);
                        let r2 = g.range_start + (pr as f32 + self.rng.uniform()) * g.range_cell;
                        let a2 = (g.azimuth_start_deg
                            + (pl as f32 + self.rng.uniform()) * g.azimuth_cell_deg)
                            / DEG_PER_RAD;
                        let (dx, dy) = (r * cb - r2 * math::cos(a2), r * sb - r2 * math::sin(a2));
                        // Tangential part of the displacement (the radial velocity comes
                        // from the Doppler cell).
                        let v2 = (-dx * sb + dy * cb) / self.cfg.dt;
                        if d * d + v2 * v2 <= vmax * vmax {
                            vt = v2;
                            break;
                        }
                    }
                    let (vx, vy) = (d * cb - vt * sb, d * sb + vt * cb);
                    let t = self.cfg.dt;
                    [r * cb + t * vx, vx, r * sb + t * vy, vy]
                } else {
                    let mut s = [0.0f32; 4];
                    for (d, v) in s.iter_mut().enumerate() {
                        *v = comp.mean[d] + comp.std[d] * self.rng.normal();
                    }
                    s
                };
                let inten = self.rng.uniform_range(b.intensity[0], b.intensity[1]);
                // k < n + j <= N
                if let (Some(x), Some(w)) = (self.x.get_mut(k), self.w.get_mut(k)) {
                    *x = [s[0], s[1], s[2], s[3], inten.max(self.cfg.min_intensity)];
                    *w = wb;
                    k += 1;
                }
            }
        }
        self.n = k;
    }

    /// [`BirthMode::Region`] births: `j` particles, each uniform in one of the previous
    /// frame's peaks (or over the whole cube before the first frame).
    fn add_region_births(&mut self, j: usize, tang: f32) {
        let b = self.cfg.birth;
        let g = self.cfg.geometry;
        let t = self.cfg.dt;
        let wb = b.mass / j as f32;
        let nb = self.region_nb;
        let mut k = self.n;
        for _ in 0..j {
            let (ir, jd, lb) = if nb > 0 {
                let pick = self.rng.below(nb as u32) as usize;
                let idx = self.birth_cells.as_flattened().get(pick).map_or(0, |c| c.0);
                g.unindex(idx)
            } else {
                (
                    self.rng.below(g.n_range as u32) as usize,
                    self.rng.below(g.n_doppler as u32) as usize,
                    self.rng.below(g.n_azimuth as u32) as usize,
                )
            };
            let r = g.range_start + (ir as f32 + self.rng.uniform()) * g.range_cell;
            let d = g.doppler_start + (jd as f32 + self.rng.uniform()) * g.doppler_cell;
            let az = (g.azimuth_start_deg + (lb as f32 + self.rng.uniform()) * g.azimuth_cell_deg)
                / DEG_PER_RAD;
            let (sb, cb) = power_cube::sin_cos(az);
            let vt = tang * self.rng.normal();
            let (vx, vy) = (d * cb - vt * sb, d * sb + vt * cb);
            let inten = self.rng.uniform_range(b.intensity[0], b.intensity[1]);
            // k < n + j <= N
            if let (Some(x), Some(w)) = (self.x.get_mut(k), self.w.get_mut(k)) {
                *x = [
                    r * cb + t * vx,
                    vx,
                    r * sb + t * vy,
                    vy,
                    inten.max(self.cfg.min_intensity),
                ];
                *w = wb;
                k += 1;
            }
        }
        self.n = k;
    }

    /// [`BirthMode::Region`]: the `want` strongest local peaks of `sum h^2 z` (a target
    /// at the cell centre) over the whole cube, into the pooled birth-cell store. A cell
    /// within [`PointSpread::peak_radius`] (the spread's standard deviation, at least one
    /// cell) on every axis of a kept one replaces it if stronger, else is skipped, so
    /// that one target's spread does not fill the store.
    ///
    /// The statistic covers [`PointSpread::central`] (27 cells at most per cell of the
    /// cube, whatever the spread's half width).
    pub(super) fn choose_region_cells(&mut self, cube: &PowerCube<'_>, want: usize) {
        let g = self.cfg.geometry;
        let rad = [
            self.cfg.psf.peak_radius(0),
            self.cfg.psf.peak_radius(1),
            self.cfg.psf.peak_radius(2),
        ];
        let (w3, wa) = centre_weights(&self.cfg.psf);
        let data = cube.data();
        let out = self.birth_cells.as_flattened_mut();
        let want = want.min(out.len());
        let mut n = 0usize;
        // The weakest kept statistic once the store is full.
        let mut min = f32::NEG_INFINITY;
        let near = |a: usize, b: usize, r: usize| a.abs_diff(b) <= r;
        for ir in 0..g.n_range {
            for jd in 0..g.n_doppler {
                for lb in 0..g.n_azimuth {
                    let z = matched(data, &g, &w3, wa, ir, jd, lb);
                    if n == want && z <= min {
                        continue;
                    }
                    let idx = g.index(ir, jd, lb);
                    // A kept neighbour: the stronger of the two stays.
                    let kept = out.get_mut(..n).unwrap_or(&mut []);
                    if let Some(c) = kept.iter_mut().find(|c| {
                        let (pr, pd, pl) = g.unindex(c.0);
                        near(pr, ir, rad[0]) && near(pd, jd, rad[1]) && near(pl, lb, rad[2])
                    }) {
                        if z > c.1 {
                            *c = (idx, z);
                        }
                        continue;
                    }
                    if n < want {
                        if let Some(c) = out.get_mut(n) {
                            *c = (idx, z);
                            n += 1;
                        }
                    } else if let Some(c) = out
                        .get_mut(..n)
                        .unwrap_or(&mut [])
                        .iter_mut()
                        .min_by(|a, b| a.1.partial_cmp(&b.1).unwrap_or(core::cmp::Ordering::Equal))
                    {
                        *c = (idx, z);
                    }
                    if n == want {
                        min = out
                            .get(..n)
                            .unwrap_or(&[])
                            .iter()
                            .map(|c| c.1)
                            .fold(f32::INFINITY, f32::min);
                    }
                }
            }
        }
        self.region_nb = n;
    }

    /// Top cells by power inside the `3 sigma` position window of `comp`.
    /// Measurement-driven birth: picks each component's strongest cells on this frame
    /// for the births of the *next* frame. Births placed on a frame's strongest cells and
    /// updated with the same frame use the data twice: their likelihood ratio is biased
    /// up by the selection (the strongest noise cells of a ~4500-cell window look like a
    /// target), and noise births were confirmed as persistent false tracks at the birth
    /// windows. Drawing from the previous frame (Ristic, Clark, Vo, Vo 2012, adaptive
    /// target birth) keeps the update's data independent of where births were placed.
    pub(super) fn choose_birth_cells(&mut self, cube: &PowerCube<'_>) {
        let b = self.cfg.birth;
        let g = self.cfg.geometry;
        if let BirthMode::Region { cells, .. } = b.mode {
            self.choose_region_cells(cube, cells);
            return;
        }
        self.birth_prev = self.birth_cells;
        self.birth_prev_nb = self.birth_nb;
        for ci in 0..b.n_components.min(MAX_BIRTH_COMPONENTS) {
            self.birth_nb[ci] = match b.mode {
                BirthMode::Measurement { cells: want, .. } => Self::strongest_in_window(
                    cube,
                    &g,
                    &self.cfg.psf.central(),
                    &b.components[ci],
                    &mut self.birth_cells[ci][..want.min(MAX_BIRTH_CELLS)],
                ),
                BirthMode::Gaussian | BirthMode::Region { .. } => 0,
            };
        }
    }

    fn strongest_in_window(
        cube: &PowerCube<'_>,
        g: &CubeGeometry,
        psf: &PointSpread,
        comp: &BirthComponent,
        out: &mut [(usize, f32)],
    ) -> usize {
        let c = RadarCoords::from_state(comp.mean[0], 0.0, comp.mean[2], 0.0);
        let dr = 3.0 * comp.std[0].max(comp.std[2]);
        let db = if c.range > 1.0 {
            dr / c.range * DEG_PER_RAD
        } else {
            180.0
        };
        let lo = |v: f32, start: f32, size: f32| math::floor((v - start) / size).max(0.0) as usize;
        let hi = |v: f32, start: f32, size: f32, n: usize| {
            let h = math::floor((v - start) / size);
            if h < 0.0 {
                0
            } else {
                (h as usize).saturating_add(1).min(n)
            }
        };
        let r0 = lo(c.range - dr, g.range_start, g.range_cell);
        let r1 = hi(c.range + dr, g.range_start, g.range_cell, g.n_range);
        let b0 = lo(c.azimuth_deg - db, g.azimuth_start_deg, g.azimuth_cell_deg);
        let b1 = hi(
            c.azimuth_deg + db,
            g.azimuth_start_deg,
            g.azimuth_cell_deg,
            g.n_azimuth,
        );
        let data = cube.data();
        let (w3, wa) = centre_weights(psf);
        let mut n = 0usize;
        // The weakest kept statistic and its slot once `out` is full.
        let mut min = (f32::NEG_INFINITY, 0usize);
        for ir in r0..r1 {
            for jd in 0..g.n_doppler {
                let rows = interior_rows(data, g, wa, ir, jd);
                for lb in b0..b1 {
                    let idx = g.index(ir, jd, lb);
                    // Point-spread-matched statistic `sum h^2 z` of a target at the cell
                    // centre, as for the swarm's points.
                    let z = match rows.as_ref().and_then(|r| line_matched(r, &w3, lb)) {
                        Some(z) => z,
                        None => matched(data, g, &w3, wa, ir, jd, lb),
                    };
                    if n < out.len() {
                        out[n] = (idx, z);
                        n += 1;
                    } else if z > min.0 {
                        if let Some(o) = out.get_mut(min.1) {
                            *o = (idx, z);
                        }
                    } else {
                        continue;
                    }
                    if n == out.len() {
                        // The first of the smallest, as `min_by` picks it.
                        min = (f32::INFINITY, 0);
                        for (k, o) in out.iter().enumerate() {
                            if o.1 < min.0 {
                                min = (o.1, k);
                            }
                        }
                    }
                }
            }
        }
        n
    }
}

/// The products `(h_r^2 h_d^2) h_b^2` of the squared weights `h^2 = exp(-L delta^2)` of a
/// target at a cell centre (`delta = k - w` cells, `k = 0..=2w` per axis) over the central
/// `3 x 3 x 3` cells ([`PointSpread::central`]), and the half widths: the same for every
/// cell, so computed once per frame. Each product is rounded exactly as the statistic's
/// per-cell `(h_r^2 h_d^2) h_b^2` was, so [`matched`] sums the same terms in the same order.
fn centre_weights(psf: &PointSpread) -> ([[[f32; 3]; 3]; 3], [usize; 3]) {
    let psf = psf.central();
    let wa = [psf.half(0), psf.half(1), psf.half(2)];
    let mut h2 = [[0.0f32; 3]; 3];
    for (a, row) in h2.iter_mut().enumerate() {
        let loss = psf.loss(a);
        for (k, v) in row.iter_mut().enumerate().take(2 * wa[a] + 1) {
            let dl = k as f32 - wa[a] as f32;
            *v = math::exp(-loss * dl * dl);
        }
    }
    let mut w = [[[0.0f32; 3]; 3]; 3];
    for (wr, &hr) in w.iter_mut().zip(&h2[0]) {
        for (wrd, &hd) in wr.iter_mut().zip(&h2[1]) {
            let hrd = hr * hd;
            for (v, &hb) in wrd.iter_mut().zip(&h2[2]) {
                *v = hrd * hb;
            }
        }
    }
    (w, wa)
}

/// The point-spread-matched statistic `sum h^2 z` of a target at the centre of cell
/// `(ir, jd, lb)` over the in-cube cells of the central spread ([`centre_weights`]): the
/// terms `((h_r^2 h_d^2) h_b^2) z` summed in cell order (range, Doppler, azimuth).
#[inline(always)]
fn matched(
    data: &[f32],
    g: &CubeGeometry,
    w: &[[[f32; 3]; 3]; 3],
    wa: [usize; 3],
    ir: usize,
    jd: usize,
    lb: usize,
) -> f32 {
    // The cells `c - w ..= c + w` inside the axis, and the weight slot `k = i + w - c`
    // of the first one.
    let span = |c: usize, w: usize, n: usize| {
        let lo = c.saturating_sub(w);
        (lo, (c + w).min(n.saturating_sub(1)), lo + w - c)
    };
    let (i0, i1, ki) = span(ir, wa[0], g.n_range);
    let (j0, j1, kj) = span(jd, wa[1], g.n_doppler);
    let (l0, l1, kl) = span(lb, wa[2], g.n_azimuth);
    let mut z = 0.0f32;
    for (i, wr) in (i0..=i1).zip(w.get(ki..).unwrap_or(&[])) {
        for (j, wrd) in (j0..=j1).zip(wr.get(kj..).unwrap_or(&[])) {
            let base = (i * g.n_doppler + j) * g.n_azimuth;
            if let Some(row) = data.get(base + l0..=base + l1) {
                for (&v, &h) in row.iter().zip(wrd.get(kl..).unwrap_or(&[])) {
                    z += h * v;
                }
            }
        }
    }
    z
}

/// The nine azimuth rows `(ir - 1 + a, jd - 1 + b)`, `a, b` in `0..3`, around the line
/// `(ir, jd)` of the cube, each the whole row: for [`line_matched`] on the line's cells
/// whose `3 x 3 x 3` neighbourhood is inside the cube. `None` unless the spread covers
/// `3 x 3 x 3` cells and `(ir, jd)` is interior on its two axes.
#[inline(always)]
fn interior_rows<'d>(
    data: &'d [f32],
    g: &CubeGeometry,
    wa: [usize; 3],
    ir: usize,
    jd: usize,
) -> Option<[&'d [f32]; 9]> {
    if wa[0] != 1 || wa[1] != 1 || wa[2] != 1 || ir == 0 || jd == 0 {
        return None;
    }
    if ir + 1 >= g.n_range || jd + 1 >= g.n_doppler {
        return None;
    }
    let n = g.n_azimuth;
    let mut rows: [&[f32]; 9] = [&[]; 9];
    for (k, r) in rows.iter_mut().enumerate() {
        let o = ((ir - 1 + k / 3) * g.n_doppler + (jd - 1 + k % 3)) * n;
        *r = data.get(o..o + n)?;
    }
    Some(rows)
}

/// [`matched`] of cell `lb` of a line whose [`interior_rows`] are `rows`, for
/// `1 <= lb < n_azimuth - 1`: the same 27 terms `((h_r^2 h_d^2) h_b^2) z`, summed in the
/// same order, without the per-cell spans. `None` if `lb` is not interior.
#[inline(always)]
fn line_matched(rows: &[&[f32]; 9], w: &[[[f32; 3]; 3]; 3], lb: usize) -> Option<f32> {
    let l = lb.checked_sub(1)?;
    let mut z = 0.0f32;
    for (row, wrd) in rows.iter().zip(w.as_flattened()) {
        let &[v0, v1, v2] = row.get(l..l + 3)? else {
            return None;
        };
        z += wrd[0] * v0;
        z += wrd[1] * v1;
        z += wrd[2] * v2;
    }
    Some(z)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The per-line interior path gives the bits of the per-cell statistic on every cell
    /// it covers, and declines the edge cells.
    #[test]
    fn line_matched_is_bit_identical_to_matched() {
        let g = CubeGeometry {
            n_range: 7,
            n_doppler: 5,
            n_azimuth: 9,
            range_start: 0.0,
            range_cell: 10.0,
            doppler_start: -2.0,
            doppler_cell: 1.0,
            azimuth_start_deg: 0.0,
            azimuth_cell_deg: 1.0,
        };
        let data: std::vec::Vec<f32> = (0..g.len())
            .map(|i| ((i * 7919) % 101) as f32 * 0.731)
            .collect();
        for psf in [
            PointSpread::ONE_CELL,
            PointSpread::from_std([0.8, 1.7, 0.6], [2, 1, 3]),
            PointSpread::from_std([1.0, 1.0, 1.0], [1, 0, 1]),
        ] {
            let (w3, wa) = centre_weights(&psf);
            let mut fast = 0;
            for ir in 0..g.n_range {
                for jd in 0..g.n_doppler {
                    let rows = interior_rows(&data, &g, wa, ir, jd);
                    for lb in 0..g.n_azimuth {
                        let want = matched(&data, &g, &w3, wa, ir, jd, lb);
                        if let Some(z) = rows.as_ref().and_then(|r| line_matched(r, &w3, lb)) {
                            assert_eq!(z.to_bits(), want.to_bits(), "{ir} {jd} {lb}");
                            fast += 1;
                        }
                    }
                }
            }
            let interior = if wa == [1, 1, 1] { 5 * 3 * 7 } else { 0 };
            assert_eq!(fast, interior, "{psf:?}");
        }
    }
}
