//! K-means (Lloyd) on 2-D points, the baseline state extractor (Pei et al. 2019 §3.2).
//!
//! Seeding: k-means++ (Arthur & Vassilvitskii 2007): the first centre is a uniformly drawn
//! point, each next one a point drawn with probability proportional to its squared
//! distance to the nearest chosen centre, from the caller's [`Rng`] (so host and target
//! agree bit for bit for the same seed). Farthest-first (maximin) seeding was used
//! before and picked single stray particles (births, resampling stragglers 300-600 m
//! away) as centres, merging two real targets into one cluster; k-means++ weighs a
//! candidate by how many particles sit there. Then at most `max_iter` Lloyd
//! iterations, stopping when no assignment changes. Memory: one `u16` label per point.

#![allow(clippy::needless_range_loop)]

use crate::math::KahanSum;
use crate::rng::Rng;
use crate::{Error, Result};

/// K-means workspace for up to `N` points and `K` clusters.
#[derive(Debug, Clone)]
pub struct KMeans<const N: usize, const K: usize> {
    /// Cluster of each point after [`KMeans::run`].
    pub assign: [u16; N],
    /// Centres.
    pub centres: [[f32; 2]; K],
    /// Points per centre.
    pub counts: [u32; K],
}

impl<const N: usize, const K: usize> Default for KMeans<N, K> {
    fn default() -> Self {
        Self::new()
    }
}

#[inline]
fn d2(a: [f32; 2], b: [f32; 2]) -> f32 {
    let (dx, dy) = (a[0] - b[0], a[1] - b[1]);
    dx * dx + dy * dy
}

impl<const N: usize, const K: usize> KMeans<N, K> {
    /// Empty workspace.
    pub const fn new() -> Self {
        Self {
            assign: [0; N],
            centres: [[0.0; 2]; K],
            counts: [0; K],
        }
    }

    #[inline]
    fn nearest_d2(&self, p: [f32; 2], c: usize) -> f32 {
        let mut dn = f32::INFINITY;
        for &q in self.centres.iter().take(c) {
            dn = dn.min(d2(p, q));
        }
        dn
    }

    /// Clusters `pts` into `k` groups (`k <= K`, `k <= pts.len()`, else clamped);
    /// returns the number of centres. Errors: [`Error::Capacity`] for more than `N`
    /// points, [`Error::NonFinite`].
    pub fn run(
        &mut self,
        pts: &[[f32; 2]],
        k: usize,
        max_iter: usize,
        rng: &mut Rng,
    ) -> Result<usize> {
        let n = pts.len();
        if n > N {
            return Err(Error::Capacity {
                capacity: N,
                requested: n,
            });
        }
        let k = k.min(K).min(n).min(u16::MAX as usize);
        if k == 0 {
            return Ok(0);
        }
        for p in pts {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(Error::NonFinite);
            }
        }
        // k-means++ seeding.
        if let Some(&p) = pts.get((rng.below(n as u32) as usize).min(n - 1)) {
            self.centres[0] = p;
        }
        // Sums in f32 with compensation (an f64 add is a software routine on the M4).
        for c in 1..k {
            let mut total = KahanSum::new();
            for &p in pts {
                total.add(self.nearest_d2(p, c));
            }
            let total = total.value();
            let mut pick = n - 1;
            if total > 0.0 {
                let target = rng.uniform() * total;
                let mut acc = KahanSum::new();
                for (i, &p) in pts.iter().enumerate() {
                    acc.add(self.nearest_d2(p, c));
                    if acc.value() > target {
                        pick = i;
                        break;
                    }
                }
            }
            if let (Some(slot), Some(&p)) = (self.centres.get_mut(c), pts.get(pick)) {
                *slot = p;
            }
        }
        for a in self.assign[..n].iter_mut() {
            *a = u16::MAX;
        }
        for _ in 0..max_iter.max(1) {
            let mut changed = false;
            for (&p, a) in pts.iter().zip(self.assign.iter_mut()) {
                let mut best = (0usize, f32::INFINITY);
                for (c, &q) in self.centres[..k].iter().enumerate() {
                    let d = d2(p, q);
                    if d < best.1 {
                        best = (c, d);
                    }
                }
                if *a as usize != best.0 {
                    *a = best.0 as u16;
                    changed = true;
                }
            }
            // The mean as the old centre plus the mean offset from it: f32 sums of small
            // offsets (a cluster's spread, not its distance from the origin), so no f64.
            let mut sums = [[0.0f32; 2]; K];
            self.counts = [0; K];
            for (&p, &a) in pts.iter().zip(self.assign.iter()) {
                let c = a as usize;
                if let (Some(s), Some(n), Some(q)) =
                    (sums.get_mut(c), self.counts.get_mut(c), self.centres.get(c))
                {
                    s[0] += p[0] - q[0];
                    s[1] += p[1] - q[1];
                    *n += 1;
                }
            }
            for c in 0..k {
                if self.counts[c] > 0 {
                    let inv = 1.0 / self.counts[c] as f32;
                    let q = self.centres[c];
                    self.centres[c] = [q[0] + sums[c][0] * inv, q[1] + sums[c][1] * inv];
                }
            }
            if !changed {
                break;
            }
        }
        Ok(k)
    }
}
