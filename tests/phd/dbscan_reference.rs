//! The grid DBSCAN as it was before each query scanned only its cells' pending members
//! (every member of a cell with a free point was read again per query), kept as the
//! reference of `dbscan_exact.rs`: the same clusters, in the same order, with the same
//! members in the same order, so the filter's estimates keep their bits.

#![allow(clippy::needless_range_loop, dead_code)]

use faint::detect::phd::dbscan::{DbscanParams, NOISE};
use faint::{Error, Result};

const UNVISITED: i32 = -2;

/// Grid-indexed DBSCAN workspace for up to `N` points.
#[derive(Debug, Clone)]
pub struct Dbscan<const N: usize> {
    key: [u64; N],
    order: [u32; N],
    run_of: [u32; N],
    run_start: [u32; N],
    run_len: [u32; N],
    run_key: [u64; N],
    run_free: [u32; N],
    core: [u8; N],
    /// Label per point after [`Dbscan::run`]: cluster id `>= 0` or [`NOISE`].
    pub labels: [i32; N],
    queue: [u32; N],
    n_runs: usize,
    /// A grid cell fits in the eps disc (see [`Dbscan::run`]).
    shortcut: bool,
}

impl<const N: usize> Default for Dbscan<N> {
    fn default() -> Self {
        Self::new()
    }
}

#[inline]
fn pack(gx: u32, gy: u32) -> u64 {
    ((gx as u64) << 32) | gy as u64
}

impl<const N: usize> Dbscan<N> {
    /// Empty workspace.
    pub const fn new() -> Self {
        Self {
            key: [0; N],
            order: [0; N],
            run_of: [0; N],
            run_start: [0; N],
            run_len: [0; N],
            run_key: [0; N],
            run_free: [0; N],
            core: [0; N],
            labels: [0; N],
            queue: [0; N],
            n_runs: 0,
            shortcut: true,
        }
    }

    /// First run with key >= `k`.
    #[inline]
    fn lower_run(&self, k: u64) -> usize {
        self.run_key
            .get(..self.n_runs)
            .map_or(0, |r| r.partition_point(|&x| x < k))
    }

    /// Calls `f(run)` for the runs of the 5 x 5 grid block around grid cell `(gx, gy)`.
    #[inline]
    fn for_block(&self, gx: u32, gy: u32, mut f: impl FnMut(usize) -> bool) {
        for dx in -2i64..=2 {
            let x = gx as i64 + dx;
            if !(0..=u32::MAX as i64).contains(&x) {
                continue;
            }
            let ylo = (gy as i64 - 2).max(0) as u32;
            let yhi = (gy as i64 + 2).min(u32::MAX as i64) as u32;
            let mut r = self.lower_run(pack(x as u32, ylo));
            let end = pack(x as u32, yhi);
            while r < self.n_runs && self.run_key.get(r).is_some_and(|&k| k <= end) {
                if !f(r) {
                    return;
                }
                r += 1;
            }
        }
    }

    /// The points of run `r` (empty out of range).
    #[inline]
    fn members(&self, r: usize) -> &[u32] {
        match (self.run_start.get(r), self.run_len.get(r)) {
            (Some(&s), Some(&l)) => {
                let s = s as usize;
                self.order.get(s..s + l as usize).unwrap_or(&[])
            }
            _ => &[],
        }
    }

    fn is_core(&mut self, p: usize, pts: &[[f32; 2]], eps2: f32, min_pts: usize) -> bool {
        let (Some(&cp), Some(&own), Some(&k), Some(&pp)) = (
            self.core.get(p),
            self.run_of.get(p),
            self.key.get(p),
            pts.get(p),
        ) else {
            return false;
        };
        if cp != 0 {
            return cp == 1;
        }
        let own = own as usize;
        // With the shortcut every point of the own cell is a neighbour; without it the
        // own cell is searched like the others.
        let (own, mut count) = if self.shortcut {
            (own, self.run_len.get(own).map_or(0, |&l| l as usize))
        } else {
            (usize::MAX, 0)
        };
        if count < min_pts {
            let (gx, gy) = ((k >> 32) as u32, k as u32);
            self.for_block(gx, gy, |r| {
                if r != own {
                    for &q in self.members(r) {
                        let Some(q) = pts.get(q as usize) else {
                            continue;
                        };
                        let (dx, dy) = (q[0] - pp[0], q[1] - pp[1]);
                        if dx * dx + dy * dy <= eps2 {
                            count += 1;
                        }
                    }
                }
                count < min_pts
            });
        }
        let c = count >= min_pts;
        if let Some(cp) = self.core.get_mut(p) {
            *cp = if c { 1 } else { 2 };
        }
        c
    }

    /// Clusters `pts` (at most `N`; NaN/inf coordinates are [`Error::NonFinite`]).
    ///
    /// Calls `on_cluster(members)` once per cluster, in discovery order (points visited
    /// in input order), with the member indices; returns the number of clusters. Labels
    /// are left in [`Dbscan::labels`]. Border points reachable from two clusters go to
    /// the first that reaches them (as in the original algorithm).
    pub fn run(
        &mut self,
        pts: &[[f32; 2]],
        params: &DbscanParams,
        mut on_cluster: impl FnMut(&[u32]),
    ) -> Result<usize> {
        params.validate()?;
        let n = pts.len();
        if n > N {
            return Err(Error::Capacity {
                capacity: N,
                requested: n,
            });
        }
        if n == 0 {
            return Ok(0);
        }
        let (mut minx, mut miny) = (f32::INFINITY, f32::INFINITY);
        let (mut maxx, mut maxy) = (f32::NEG_INFINITY, f32::NEG_INFINITY);
        for p in pts {
            if !(p[0].is_finite() && p[1].is_finite()) {
                return Err(Error::NonFinite);
            }
            minx = minx.min(p[0]);
            miny = miny.min(p[1]);
            maxx = maxx.max(p[0]);
            maxy = maxy.max(p[1]);
        }
        // Half extents never overflow (`|a/2 - b/2| <= f32::MAX`). A grid of more than
        // 2^31 cells per axis (points spread over more than ~1.5e9 eps) gets larger
        // cells and loses the shortcuts that need a cell to fit in the eps disc; the
        // clustering stays exact.
        let half = |v: f32, lo: f32| 0.5 * v - 0.5 * lo;
        let extent = half(maxx, minx).max(half(maxy, miny));
        let side = (0.7 * params.eps).max(f32::MIN_POSITIVE);
        let (half_side, shortcut) = if extent / (0.5 * side) < 2.0e9 {
            (0.5 * side, true)
        } else {
            (extent / 2.0e9, false)
        };
        self.shortcut = shortcut;
        let eps2 = params.eps * params.eps;
        let grid = |v: f32, lo: f32| -> u32 { (half(v, lo) / half_side) as u32 };
        for (i, p) in pts.iter().enumerate() {
            self.key[i] = pack(grid(p[0], minx), grid(p[1], miny));
            self.order[i] = i as u32;
            self.labels[i] = UNVISITED;
            self.core[i] = 0;
        }
        {
            let key = &self.key;
            faint::sort::sort_unstable_by_key(&mut self.order[..n], |&i| {
                (key.get(i as usize).copied().unwrap_or(u64::MAX), i)
            });
        }
        self.n_runs = 0;
        let mut s = 0usize;
        let order = &self.order[..n];
        while let Some(&first) = order.get(s) {
            let k = self.key.get(first as usize).copied().unwrap_or(0);
            let mut e = s;
            while let Some(&o) = order.get(e) {
                match (self.key.get(o as usize), self.run_of.get_mut(o as usize)) {
                    (Some(&ko), Some(ro)) if ko == k => *ro = self.n_runs as u32,
                    _ => break,
                }
                e += 1;
            }
            let r = self.n_runs;
            if let (Some(rs), Some(rl), Some(rf), Some(rk)) = (
                self.run_start.get_mut(r),
                self.run_len.get_mut(r),
                self.run_free.get_mut(r),
                self.run_key.get_mut(r),
            ) {
                (*rs, *rl, *rf, *rk) = (s as u32, (e - s) as u32, (e - s) as u32, k);
            }
            self.n_runs += 1;
            s = e.max(s + 1);
        }
        let mut clusters = 0usize;
        let mut qlen = 0usize;
        for p in 0..n {
            if self.labels[p] != UNVISITED {
                continue;
            }
            if !self.is_core(p, pts, eps2, params.min_pts) {
                self.labels[p] = NOISE;
                continue;
            }
            let id = clusters as i32;
            clusters += 1;
            let start = qlen;
            self.labels[p] = id;
            if let Some(f) = self
                .run_of
                .get(p)
                .and_then(|&r| self.run_free.get_mut(r as usize))
            {
                *f -= 1;
            }
            if let Some(slot) = self.queue.get_mut(qlen) {
                *slot = p as u32;
            }
            qlen += 1;
            let mut head = start;
            while let Some(&q) = self.queue.get(head).filter(|_| head < qlen) {
                let q = q as usize;
                head += 1;
                if !self.is_core(q, pts, eps2, params.min_pts) {
                    continue;
                }
                let (Some(&k), Some(&pq), Some(&own)) =
                    (self.key.get(q), pts.get(q), self.run_of.get(q))
                else {
                    continue;
                };
                let (gx, gy) = ((k >> 32) as u32, k as u32);
                let own = own as usize;
                let mut r_lo = 0usize;
                // Collect the block's runs first (borrowck: for_block borrows self).
                let mut runs = [0u32; 25];
                self.for_block(gx, gy, |r| {
                    if r_lo < 25 {
                        runs[r_lo] = r as u32;
                        r_lo += 1;
                    }
                    true
                });
                for &r in runs.iter().take(r_lo) {
                    let r = r as usize;
                    if self.run_free.get(r).is_none_or(|&f| f == 0) {
                        continue;
                    }
                    let (Some(&st), Some(&len)) = (self.run_start.get(r), self.run_len.get(r))
                    else {
                        continue;
                    };
                    let st = st as usize;
                    let Some(members) = self.order.get(st..st + len as usize) else {
                        continue;
                    };
                    for &o in members {
                        let o = o as usize;
                        let (Some(lab), Some(po)) = (self.labels.get_mut(o), pts.get(o)) else {
                            continue;
                        };
                        if *lab != UNVISITED && *lab != NOISE {
                            continue;
                        }
                        let (dx, dy) = (po[0] - pq[0], po[1] - pq[1]);
                        if (self.shortcut && r == own) || dx * dx + dy * dy <= eps2 {
                            *lab = id;
                            if let Some(f) = self.run_free.get_mut(r) {
                                *f -= 1;
                            }
                            if let Some(slot) = self.queue.get_mut(qlen) {
                                *slot = o as u32;
                            }
                            qlen += 1;
                        }
                    }
                }
            }
            on_cluster(self.queue.get(start..qlen).unwrap_or(&[]));
        }
        Ok(clusters)
    }
}
