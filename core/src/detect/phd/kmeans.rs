//! K-means (Lloyd) on 2-D points, the baseline state extractor (Pei et al. 2019 §3.2).
//!
//! Deterministic seeding (no random draws, so host and target agree): the first centre
//! is the point farthest from the mean, each next one the point farthest from its
//! nearest chosen centre (maximin / farthest-first). Then at most `max_iter` Lloyd
//! iterations, stopping when no assignment changes. Memory: one `u16` label per point.

#![allow(clippy::needless_range_loop)]

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

    /// Clusters `pts` into `k` groups (`k <= K`, `k <= pts.len()`, else clamped);
    /// returns the number of centres. Errors: [`Error::Capacity`] for more than `N`
    /// points, [`Error::NonFinite`].
    pub fn run(&mut self, pts: &[[f32; 2]], k: usize, max_iter: usize) -> Result<usize> {
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
        let (mut mx, mut my) = (0.0f64, 0.0f64);
        for p in pts {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(Error::NonFinite);
            }
            mx += p[0] as f64;
            my += p[1] as f64;
        }
        let mean = [(mx / n as f64) as f32, (my / n as f64) as f32];
        // Farthest-first seeding.
        let mut far = (0usize, -1.0f32);
        for (i, &p) in pts.iter().enumerate() {
            let d = d2(p, mean);
            if d > far.1 {
                far = (i, d);
            }
        }
        self.centres[0] = pts[far.0];
        for c in 1..k {
            let mut best = (0usize, -1.0f32);
            for (i, &p) in pts.iter().enumerate() {
                let mut dn = f32::INFINITY;
                for &q in &self.centres[..c] {
                    dn = dn.min(d2(p, q));
                }
                if dn > best.1 {
                    best = (i, dn);
                }
            }
            self.centres[c] = pts[best.0];
        }
        for a in self.assign[..n].iter_mut() {
            *a = u16::MAX;
        }
        for _ in 0..max_iter.max(1) {
            let mut changed = false;
            for (i, &p) in pts.iter().enumerate() {
                let mut best = (0usize, f32::INFINITY);
                for (c, &q) in self.centres[..k].iter().enumerate() {
                    let d = d2(p, q);
                    if d < best.1 {
                        best = (c, d);
                    }
                }
                if self.assign[i] as usize != best.0 {
                    self.assign[i] = best.0 as u16;
                    changed = true;
                }
            }
            let mut sums = [[0.0f64; 2]; K];
            self.counts = [0; K];
            for (i, &p) in pts.iter().enumerate() {
                let c = self.assign[i] as usize;
                sums[c][0] += p[0] as f64;
                sums[c][1] += p[1] as f64;
                self.counts[c] += 1;
            }
            for c in 0..k {
                if self.counts[c] > 0 {
                    let m = self.counts[c] as f64;
                    self.centres[c] = [(sums[c][0] / m) as f32, (sums[c][1] / m) as f32];
                }
            }
            if !changed {
                break;
            }
        }
        Ok(k)
    }
}
