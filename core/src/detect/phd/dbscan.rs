//! DBSCAN (Ester et al. 1996; Pei et al. 2019 §2.2) on 2-D points with a grid index.
//!
//! Neighbourhood: `|p - q| <= eps` (a point is its own neighbour); core point: at least
//! `min_pts` neighbours. The grid has square cells of side `0.7 eps` (< `eps / sqrt 2`),
//! so all points sharing a grid cell are neighbours; a query scans the 5 x 5 block of
//! cells around a point. A grid cell holding `>= min_pts` points makes all of them core
//! without distance checks, and cells whose points are all labelled are skipped during
//! expansion, so dense particle clouds cost near-linear time. Memory: O(N) fixed arrays.
//!
//! A resampled particle cloud holds many copies of each particle at consecutive indices
//! (systematic resampling keeps a particle's copies together), so the work is done once
//! per place where that gives the same result: the points are sorted
//! into cells by groups of consecutive indices in one cell; a copy of the previous point
//! of its cell takes its core flag; a core point whose copy was already expanded is not
//! expanded again (it would add nothing); and an expansion reads only each cell's
//! pending members (not yet in a cluster), kept in their order. The clusters, their
//! order and their members' order are those of the full search (`tests/phd/dbscan_exact.rs`
//! checks them against it), so the estimates summed over the members keep their bits.

#![allow(clippy::needless_range_loop)]

use crate::{Error, Result};

const UNVISITED: i32 = -2;
/// `core` flags: a core point, a core point expanded (or a copy of one at the same place
/// that was), not a core point.
const CORE: u8 = 1;
const NOT_CORE: u8 = 2;
const EXPANDED: u8 = 3;

/// The same place, bit for bit (two copies of one particle).
#[inline]
fn same(a: &[f32; 2], b: &[f32; 2]) -> bool {
    a[0].to_bits() == b[0].to_bits() && a[1].to_bits() == b[1].to_bits()
}
/// Label of a noise point.
pub const NOISE: i32 = -1;

/// DBSCAN parameters: radius `E` and density threshold `Th_min`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct DbscanParams {
    /// Neighbourhood radius `E` (m).
    pub eps: f32,
    /// Minimum neighbourhood size (including the point) of a core point, `Th_min`.
    pub min_pts: usize,
}

impl DbscanParams {
    /// Checks `eps > 0` finite and `min_pts >= 1`.
    pub fn validate(&self) -> Result<()> {
        if !(self.eps.is_finite() && self.eps > 0.0) {
            return Err(Error::InvalidConfig("dbscan eps must be positive"));
        }
        if self.min_pts == 0 {
            return Err(Error::InvalidConfig("dbscan min_pts must be >= 1"));
        }
        Ok(())
    }
}

/// Grid-indexed DBSCAN workspace for up to `N` points.
#[derive(Debug, Clone)]
pub struct Dbscan<const N: usize> {
    /// Grid key of each group of consecutive points in one cell (first index in `queue`
    /// while the runs are built).
    key: [u64; N],
    order: [u32; N],
    run_of: [u32; N],
    run_start: [u32; N],
    /// Members of each run; during the expansion, the length of its pending prefix.
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

    /// The points of run `r` (empty out of range): all of them until [`Dbscan::cores`]
    /// has run, then the run's pending prefix (see [`Dbscan::run`]).
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

    /// Core flags (`core`: 1 core, 2 not) of every point, run by run: a point is core
    /// when at least `min_pts` points (itself included) lie within `eps`. With the
    /// shortcut every point of the own grid cell is a neighbour (the cell fits in the
    /// eps disc), so a cell of `min_pts` points or more is core throughout; otherwise
    /// the other cells of the 5 x 5 block are searched, their runs looked up once per
    /// cell, stopping at `min_pts`.
    fn cores(&mut self, pts: &[[f32; 2]], eps2: f32, min_pts: usize) {
        for own in 0..self.n_runs {
            let (Some(&k), Some(&len)) = (self.run_key.get(own), self.run_len.get(own)) else {
                continue;
            };
            let len = len as usize;
            let base = if self.shortcut { len } else { 0 };
            let mut runs = [0u32; 25];
            let mut nr = 0usize;
            if base < min_pts {
                self.for_block((k >> 32) as u32, k as u32, |r| {
                    if r != own || !self.shortcut {
                        if let Some(slot) = runs.get_mut(nr) {
                            *slot = r as u32;
                            nr += 1;
                        }
                    }
                    true
                });
            }
            let runs = runs.get(..nr).unwrap_or(&[]);
            // The previous member's point and flag: a point at the same place (the
            // resampled filter's copies) has the same neighbours.
            let mut prev: Option<([f32; 2], u8)> = None;
            for j in 0..len {
                let Some(&p) = self
                    .run_start
                    .get(own)
                    .and_then(|&s| self.order.get(s as usize + j))
                else {
                    continue;
                };
                let Some(&pp) = pts.get(p as usize) else {
                    continue;
                };
                if let Some((_, c)) = prev.filter(|(q, _)| same(q, &pp)) {
                    if let Some(cp) = self.core.get_mut(p as usize) {
                        *cp = c;
                    }
                    continue;
                }
                let mut count = base;
                'block: for &r in runs {
                    if count >= min_pts {
                        break;
                    }
                    for &q in self.members(r as usize) {
                        let Some(q) = pts.get(q as usize) else {
                            continue;
                        };
                        let (dx, dy) = (q[0] - pp[0], q[1] - pp[1]);
                        if dx * dx + dy * dy <= eps2 {
                            count += 1;
                            if count >= min_pts {
                                break 'block;
                            }
                        }
                    }
                }
                let c = if count >= min_pts { CORE } else { NOT_CORE };
                if let Some(cp) = self.core.get_mut(p as usize) {
                    *cp = c;
                }
                prev = Some((pp, c));
            }
        }
    }

    /// Marks `q` and the points next to it in input order at the same place as
    /// [`EXPANDED`] (the resampled filter's copies of one particle have consecutive
    /// indices): expanding one of them again would add nothing, since every free point
    /// within `eps` of that place (and of its own cell, with the shortcut) was labelled by
    /// the first, and labels are never taken back.
    fn mark_expanded(&mut self, q: usize, pts: &[[f32; 2]]) {
        let Some(&pq) = pts.get(q) else {
            return;
        };
        if let Some(c) = self.core.get_mut(q) {
            *c = EXPANDED;
        }
        let mut i = q;
        while i > 0 && pts.get(i - 1).is_some_and(|p| same(p, &pq)) {
            i -= 1;
            if let Some(c) = self.core.get_mut(i) {
                *c = EXPANDED;
            }
        }
        let mut i = q + 1;
        while pts.get(i).is_some_and(|p| same(p, &pq)) {
            if let Some(c) = self.core.get_mut(i) {
                *c = EXPANDED;
            }
            i += 1;
        }
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
        // Groups: maximal ranges of consecutive indices in one grid cell (a resampled
        // cloud's copies of a particle are consecutive), key in `key[g]`, first index in
        // `queue[g]`. Sorting the groups by (key, group) orders the points by (key,
        // index), as sorting the points would, for a fraction of the work.
        let mut ng = 0usize;
        let mut last = None;
        for (i, p) in pts.iter().enumerate() {
            let k = pack(grid(p[0], minx), grid(p[1], miny));
            if last != Some(k) {
                // ng <= i < N
                if let (Some(kg), Some(sg), Some(o)) = (
                    self.key.get_mut(ng),
                    self.queue.get_mut(ng),
                    self.order.get_mut(ng),
                ) {
                    (*kg, *sg, *o) = (k, i as u32, ng as u32);
                }
                ng += 1;
                last = Some(k);
            }
            if let (Some(l), Some(c)) = (self.labels.get_mut(i), self.core.get_mut(i)) {
                (*l, *c) = (UNVISITED, 0);
            }
        }
        if let Some(groups) = self.order.get_mut(..ng) {
            let key = &self.key;
            crate::sort::sort_unstable_by_key(groups, |&g| {
                (key.get(g as usize).copied().unwrap_or(u64::MAX), g)
            });
        }
        // Runs: the sorted groups of one key. Counted first, then the groups are laid
        // out from the last: sorted group `j` starts at position `>= j` (every group
        // has a point), so writing it never overwrites the unread entries `order[..j]`.
        let mut n_runs = 0usize;
        let mut last = None;
        for &g in self.order.iter().take(ng) {
            let k = self.key.get(g as usize).copied();
            if last != Some(k) {
                n_runs += 1;
                last = Some(k);
            }
        }
        self.n_runs = n_runs;
        let mut pos = n;
        let mut r = n_runs;
        let mut last = None;
        for j in (0..ng).rev() {
            let Some(&g) = self.order.get(j) else {
                break;
            };
            let g = g as usize;
            let (Some(&k), Some(&s)) = (self.key.get(g), self.queue.get(g)) else {
                break;
            };
            let e = if g + 1 < ng {
                self.queue.get(g + 1).map_or(n, |&e| e as usize)
            } else {
                n
            };
            let s = s as usize;
            let len = e.saturating_sub(s);
            if last != Some(k) {
                last = Some(k);
                r = r.saturating_sub(1);
                if let (Some(rl), Some(rk)) = (self.run_len.get_mut(r), self.run_key.get_mut(r)) {
                    (*rl, *rk) = (0, k);
                }
            }
            pos = pos.saturating_sub(len);
            for t in 0..len {
                if let (Some(o), Some(ro)) =
                    (self.order.get_mut(pos + t), self.run_of.get_mut(s + t))
                {
                    (*o, *ro) = ((s + t) as u32, r as u32);
                }
            }
            if let (Some(rs), Some(rl), Some(rf)) = (
                self.run_start.get_mut(r),
                self.run_len.get_mut(r),
                self.run_free.get_mut(r),
            ) {
                *rs = pos as u32;
                *rl += len as u32;
                *rf = *rl;
            }
        }
        self.cores(pts, eps2, params.min_pts);
        // From here a run's `order[start..start + run_len]` is its pending prefix: its
        // members that may still join a cluster (unvisited or noise), in their sorted
        // order, plus cluster seeds labelled since the run was last scanned. A scan
        // drops the members it labels and those labelled before, keeping the others in
        // order, so each query sees the candidates in the order of the whole run
        // without re-reading the members already in a cluster.
        let mut clusters = 0usize;
        let mut qlen = 0usize;
        for p in 0..n {
            let (Some(lab), Some(&c)) = (self.labels.get_mut(p), self.core.get(p)) else {
                break;
            };
            if *lab != UNVISITED {
                continue;
            }
            if c == NOT_CORE {
                *lab = NOISE;
                continue;
            }
            let id = clusters as i32;
            clusters += 1;
            let start = qlen;
            *lab = id;
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
                // Not core, or a copy of a point already expanded: nothing to add.
                if self.core.get(q).is_none_or(|&c| c != CORE) {
                    continue;
                }
                self.mark_expanded(q, pts);
                let (Some(&pq), Some(&own)) = (pts.get(q), self.run_of.get(q)) else {
                    continue;
                };
                let own = own as usize;
                let Some(&k) = self.run_key.get(own) else {
                    continue;
                };
                let (gx, gy) = ((k >> 32) as u32, k as u32);
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
                    let take_all = self.shortcut && r == own;
                    let mut kept = 0usize;
                    for i in 0..len as usize {
                        let Some(&o32) = self.order.get(st + i) else {
                            break;
                        };
                        let o = o32 as usize;
                        let (Some(lab), Some(po)) = (self.labels.get_mut(o), pts.get(o)) else {
                            continue;
                        };
                        if *lab != UNVISITED && *lab != NOISE {
                            continue;
                        }
                        let (dx, dy) = (po[0] - pq[0], po[1] - pq[1]);
                        if take_all || dx * dx + dy * dy <= eps2 {
                            *lab = id;
                            if let Some(f) = self.run_free.get_mut(r) {
                                *f -= 1;
                            }
                            if let Some(slot) = self.queue.get_mut(qlen) {
                                *slot = o32;
                            }
                            qlen += 1;
                        } else {
                            // kept <= i
                            if let Some(d) = self.order.get_mut(st + kept) {
                                *d = o32;
                            }
                            kept += 1;
                        }
                    }
                    if let Some(l) = self.run_len.get_mut(r) {
                        *l = kept as u32;
                    }
                }
            }
            on_cluster(self.queue.get(start..qlen).unwrap_or(&[]));
        }
        Ok(clusters)
    }
}
