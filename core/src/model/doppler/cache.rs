//! The per-frame [`ProjectionCache`] of the five-bin row sums, and
//! [`DopplerModel::project_cached`] that reads it (the continuing particles' projection).

use super::response::{DopplerModel, Projection, TABLE_STEPS};
use crate::Complex32;

/// Entries of the [`ProjectionCache`] (direct-mapped on `(first bin mod 8, table row)`).
const CACHE_LEN: usize = 1024;
/// Keys `first * 128 + row` the cache holds (`first < 32`; the other first bins of
/// larger frames project directly). An entry's tag is `frame * 4096 + key`.
const CACHE_KEYS: u32 = 4096;

/// Per-frame cache of the five-bin sums `A`, `D` of [`DopplerModel::project_cached`] for a
/// (first bin, table row): direct-mapped, 1024 entries, each tagged with its key and the
/// frame, filled on first use in a frame (20 KB). Call [`new_frame`](Self::new_frame)
/// before the first projection of every frame (also of a new or zeroed cache: its
/// frame stamp 0 is not valid).
#[derive(Debug, Clone)]
pub struct ProjectionCache {
    sums: [[f32; 4]; CACHE_LEN],
    /// `frame * 4096 + key` of each entry.
    tag: [u32; CACHE_LEN],
    /// Frame stamp (1-based; 0 marks empty entries).
    cur: u32,
}

impl Default for ProjectionCache {
    fn default() -> Self {
        Self::new()
    }
}

impl ProjectionCache {
    /// An empty cache (all zero, so a `static` of it lands in `.bss`).
    pub const fn new() -> Self {
        Self {
            sums: [[0.0; 4]; CACHE_LEN],
            tag: [0; CACHE_LEN],
            cur: 0,
        }
    }

    /// Invalidates every entry (call once per new frame).
    pub fn new_frame(&mut self) {
        self.cur += 1;
        if self.cur >= u32::MAX / CACHE_KEYS {
            self.tag = [0; CACHE_LEN];
            self.cur = 1;
        }
    }
}

impl DopplerModel {
    /// `[Re A, Im A, Re D, Im D]`, `A = sum_j conj(z_{first+j}) a_j`, `D` the same with
    /// `d_j = b_j - a_j`, over row `i0` (bins wrap mod `m`).
    fn sums(&self, z: &[Complex32], first: usize, i0: usize) -> [f32; 4] {
        let row = self.row(i0);
        let mut out = [0.0f32; 4];
        let mut b = first;
        for c in row.iter() {
            if let Some(zb) = z.get(b) {
                out[0] += zb.re * c[0] + zb.im * c[1];
                out[1] += zb.re * c[1] - zb.im * c[0];
                out[2] += zb.re * c[2] + zb.im * c[3];
                out[3] += zb.re * c[3] - zb.im * c[2];
            }
            b += 1;
            if b == self.m {
                b = 0;
            }
        }
        out
    }

    /// [`project`](Self::project) through a per-frame cache of the row sums `A`, `D` (see
    /// [`ProjectionCache`]): `<z, h> = amp (A + frac D)`, `||h||^2 = amp^2 (H0 + frac (H1 +
    /// frac H2))`; the same values up to rounding (relative difference below 4e-6, test
    /// `crpf_model`). `IM = false`: `Im <z, h>` is 0. The table position comes from
    /// `U = 128 (fd ts m + 1/2 + m)`: `U >> 7` the nearest bin (plus `m`), `U & 127` the
    /// row, `U - floor(U)` the fraction. Not finite or outside the band, or `m > 32`:
    /// the direct [`project`](Self::project). `cache` must be valid for `z`:
    /// [`ProjectionCache::new_frame`] once before a frame's first call (a new cache too).
    #[inline(always)]
    pub fn project_cached<const IM: bool>(
        &self,
        cache: &mut ProjectionCache,
        z: &[Complex32],
        fd: f32,
        amp: f32,
    ) -> Projection {
        let u = fd * self.u_scale + self.u_off;
        // In the band, 0 <= U < 256 m; NaN and anything else go to the direct path.
        if !(u >= 0.0 && u < self.u_off * 2.0) {
            return self.project_direct::<IM>(z, fd, amp);
        }
        let iu = u as u32;
        let frac = u - iu as f32;
        let i0 = (iu as usize) & (TABLE_STEPS - 1);
        let first = match self.first_of.get((iu >> 7) as usize) {
            Some(&f) => f as usize,
            None => return self.project_direct::<IM>(z, fd, amp),
        };
        let key = first * TABLE_STEPS + i0;
        let slot = key & (CACHE_LEN - 1);
        let tag = cache.cur * CACHE_KEYS + key as u32;
        let (Some(e), Some(t), Some(h)) = (
            cache.sums.get_mut(slot),
            cache.tag.get_mut(slot),
            self.hq.get(i0),
        ) else {
            return self.project_direct::<IM>(z, fd, amp);
        };
        if key >= CACHE_KEYS as usize {
            return self.project_direct::<IM>(z, fd, amp);
        }
        if *t != tag {
            *e = self.sums(z, first, i0);
            *t = tag;
        }
        let zr = e[0] + frac * e[2];
        let zi = if IM { e[1] + frac * e[3] } else { 0.0 };
        let hh = h[0] + frac * (h[1] + frac * h[2]);
        Projection {
            zh: Complex32::new(zr * amp, zi * amp),
            hh: hh * amp * amp,
        }
    }
}
