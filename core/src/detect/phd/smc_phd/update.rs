//! The update (eq. 20, 24-25) with the cell grouping by sort and union-find, the
//! systematic resampling to `N_hat` targets' worth of particles (eq. 26), and the state
//! extraction (DBSCAN or K-means).

use super::*;
use crate::model::power_cube;

/// The 13 "forward" neighbours of a cell (the other 13 are found from the other side).
const NEIGHBOURS: [(isize, isize, isize); 13] = [
    (0, 0, 1),
    (0, 1, -1),
    (0, 1, 0),
    (0, 1, 1),
    (1, -1, -1),
    (1, -1, 0),
    (1, -1, 1),
    (1, 0, -1),
    (1, 0, 0),
    (1, 0, 1),
    (1, 1, -1),
    (1, 1, 0),
    (1, 1, 1),
];

/// Union-find root with path halving.
/// (An index out of range is its own root: never, for the callers.)
fn find(parent: &mut [u32], mut r: usize) -> usize {
    while let Some(&p) = parent.get(r) {
        if p as usize == r {
            break;
        }
        let Some(&gp) = parent.get(p as usize) else {
            break;
        };
        parent[r] = gp;
        r = gp as usize;
    }
    r
}

/// `order` becomes `0..order.len()` sorted by `(key[i], i)`: the permutation a sort by
/// that key (unique, as `i` breaks the ties) gives, computed by a stable LSD radix sort
/// of the indices: the particles outside the cube (`key == u32::MAX`, the largest key)
/// go last in index order, the others are sorted by their cell in passes of the digits of
/// `count.len()` (a power of two), `tmp` the other buffer of each pass. Every access is
/// checked (`order`, `tmp` and `key` hold at least `order.len()` entries).
fn sort_by_cell(key: &[u32], order: &mut [u32], tmp: &mut [u32], count: &mut [u32]) {
    let n = order.len().min(tmp.len()).min(key.len());
    let mut m = 0usize;
    let mut dead = 0usize;
    let mut bits = 0u32;
    for (i, &k) in key.iter().enumerate().take(n) {
        if k != u32::MAX {
            if let Some(o) = order.get_mut(m) {
                *o = i as u32;
            }
            m += 1;
            bits |= k;
        } else {
            if let Some(t) = tmp.get_mut(dead) {
                *t = i as u32;
            }
            dead += 1;
        }
    }
    if let (Some(o), Some(t)) = (order.get_mut(m..m + dead), tmp.get(..dead)) {
        o.copy_from_slice(t);
    }
    let digit = count.len().trailing_zeros();
    if count.is_empty() || digit == 0 || !count.len().is_power_of_two() {
        return;
    }
    let mask = count.len() as u32 - 1;
    let width = u32::BITS - bits.leading_zeros();
    let (Some(live), Some(other)) = (order.get_mut(..m), tmp.get_mut(..m)) else {
        return;
    };
    let mut shift = 0u32;
    let mut in_other = false;
    while shift < width {
        if in_other {
            radix_pass(key, other, live, count, shift, mask);
        } else {
            radix_pass(key, live, other, count, shift, mask);
        }
        in_other = !in_other;
        shift += digit;
    }
    if in_other {
        live.copy_from_slice(other);
    }
}

/// One stable counting pass of [`sort_by_cell`]: `to` = `from` ordered by the digit
/// `(key >> shift) & mask`.
fn radix_pass(key: &[u32], from: &[u32], to: &mut [u32], count: &mut [u32], shift: u32, mask: u32) {
    let dig = |i: u32| {
        key.get(i as usize)
            .map_or(0, |&k| ((k >> shift) & mask) as usize)
    };
    count.fill(0);
    for &i in from {
        if let Some(c) = count.get_mut(dig(i)) {
            *c += 1;
        }
    }
    let mut sum = 0u32;
    for c in count.iter_mut() {
        let t = *c;
        *c = sum;
        sum += t;
    }
    for &i in from {
        if let Some(c) = count.get_mut(dig(i)) {
            if let Some(t) = to.get_mut(*c as usize) {
                *t = i;
            }
            *c += 1;
        }
    }
}

impl<const PARTICLES: usize, const SWARM: usize, const POINTS: usize, const TARGETS: usize>
    SmcPhdTbd<PARTICLES, SWARM, POINTS, TARGETS>
{
    /// The log weights `ln w_i + ln L_i` and cells `c(i)` of eq. 20, 24-25 (in `lw`,
    /// `key`).
    pub(super) fn likelihood(&mut self, cube: &PowerCube<'_>) {
        let g = *cube.geometry();
        let psf = self.cfg.psf;
        let s2 = self.cfg.noise_var;
        let n = self.n.min(PARTICLES);
        for i in 0..n {
            let s = self.x[i];
            let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
            let (ll, cell) = if self.w[i] > 0.0 && g.cell_of(&c).is_some() {
                {
                    // `max(0.0)` without the library call (NaN also gives 0).
                    let inten = if s[4] > 0.0 { s[4] } else { 0.0 };
                    cube.log_lr_argmax(&psf, &c, power_cube::sqrt(inten), s2)
                }
            } else {
                (0.0, usize::MAX)
            };
            if cell == usize::MAX {
                // Outside the surveillance cube (or zero weight): the particle dies.
                self.key[i] = u32::MAX;
                self.lw[i] = f32::NEG_INFINITY;
            } else {
                // Resolution cell of eq. 25: the covered cell with the largest factor.
                self.key[i] = cell as u32;
                let l = power_cube::ln_fast(self.w[i]) + ll;
                self.lw[i] = if l.is_nan() || l == f32::INFINITY {
                    f32::NEG_INFINITY
                } else {
                    l
                };
            }
            self.order[i] = i as u32;
        }
    }

    /// Weight update of eq. 20/24-25 from [`Self::likelihood`]'s log weights; returns
    /// `sum w`.
    pub(super) fn update(&mut self) -> f32 {
        let g = self.cfg.geometry;
        let n = self.n.min(PARTICLES);
        {
            // By `(cell, index)`, the order a sort by that key gives (radix passes of
            // up to 8 bits; `parent` and `run_key`, written below, are the scratch
            // buffer and the digit counts).
            let digits = 1usize << (usize::BITS - 1 - PARTICLES.leading_zeros()).min(8);
            sort_by_cell(
                &self.key,
                &mut self.order[..n],
                &mut self.parent,
                self.run_key.get_mut(..digits).unwrap_or(&mut []),
            );
        }
        let ln_lambda = math::ln(self.cfg.clutter_lambda);
        // Runs of equal cell; `run_of[i]` for every particle (u32::MAX outside).
        let mut nr = 0usize;
        let mut s = 0usize;
        let order = &self.order[..n];
        let key = &self.key;
        let cell = |o: u32| key.get(o as usize).copied().unwrap_or(u32::MAX);
        while let Some(&first) = order.get(s) {
            let k = cell(first);
            let mut e = s;
            while let Some(&o) = order.get(e).filter(|&&o| cell(o) == k) {
                if let Some(a) = self.anc.get_mut(o as usize) {
                    *a = if k == u32::MAX { u32::MAX } else { nr as u32 };
                }
                e += 1;
            }
            if k != u32::MAX {
                if let (Some(rk), Some(p)) = (self.run_key.get_mut(nr), self.parent.get_mut(nr)) {
                    (*rk, *p) = (k, nr as u32);
                }
                nr += 1;
            }
            s = e.max(s + 1);
        }
        let nr = nr.min(PARTICLES);
        // Merge runs whose cells touch (|d| <= 1 on every axis): one target's energy
        // spreads over neighbouring cells, and particles attributed to either are one
        // "resolution cell" for the normalisation of eq. 20 (else every neighbour cell
        // claims up to one target).
        if self.cfg.merge_adjacent_cells {
            for r in 0..nr {
                let (ir, jd, lb) = g.unindex(self.run_key[r] as usize);
                for (a, b, c) in NEIGHBOURS {
                    // `usize` arithmetic (the M4 does `i64` in pairs of registers): a
                    // step below 0 wraps to a value above every axis length, which the
                    // validated geometry keeps below 2^32.
                    let (x, y, z) = (
                        ir.wrapping_add_signed(a),
                        jd.wrapping_add_signed(b),
                        lb.wrapping_add_signed(c),
                    );
                    if x >= g.n_range || y >= g.n_doppler || z >= g.n_azimuth {
                        continue;
                    }
                    let idx = g.index(x, y, z) as u32;
                    if let Ok(q) = self.run_key[..nr].binary_search(&idx) {
                        let (ra, rb) = (find(&mut self.parent, r), find(&mut self.parent, q));
                        if ra != rb {
                            let (lo, hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
                            if let Some(p) = self.parent.get_mut(hi) {
                                *p = lo as u32;
                            }
                        }
                    }
                }
            }
        }
        // Per group: max log weight, then sum, then denominator (in `pts[root]`).
        for r in 0..nr {
            self.pts[r] = [f32::NEG_INFINITY, 0.0];
        }
        for i in 0..n {
            let r = self.anc[i];
            if r != u32::MAX {
                let root = find(&mut self.parent, r as usize);
                self.anc[i] = root as u32;
                if let Some(p) = self.pts.get_mut(root) {
                    // `f32::max` without the library call (the same value: `lw` is never
                    // NaN, `likelihood` maps NaN to -inf, and `p[0]` starts at -inf).
                    let l = self.lw[i];
                    p[0] = if l > p[0] { l } else { p[0] };
                }
            }
        }
        for i in 0..n {
            if let Some(p) = self.pts.get_mut(self.anc[i] as usize) {
                if p[0] > f32::NEG_INFINITY {
                    p[1] += power_cube::exp_neg(self.lw[i] - p[0]);
                }
            }
        }
        for r in 0..nr {
            if self.parent[r] as usize == r && self.pts[r][0] > f32::NEG_INFINITY {
                let log_rho = self.pts[r][0] + math::ln(self.pts[r][1]);
                self.pts[r][1] = math::log_add_exp(ln_lambda, log_rho);
            }
        }
        let mut total = KahanSum::new();
        for i in 0..n {
            let r = self.anc[i];
            let wi = match self.pts.get(r as usize) {
                Some(p) if r != u32::MAX && self.lw[i] != f32::NEG_INFINITY => {
                    power_cube::exp_neg(self.lw[i] - p[1])
                }
                _ => 0.0,
            };
            self.w[i] = wi;
            total.add(wi);
        }
        total.value()
    }

    pub(super) fn resample(&mut self, n_hat: usize, mass: f32) -> bool {
        let cap = PARTICLES - self.cfg.birth.particles;
        let l = self
            .cfg
            .particles_per_target
            .saturating_mul(n_hat)
            .max(self.cfg.min_particles)
            .min(cap);
        if l == 0 || self.n == 0 {
            return false;
        }
        let (Some(w), Some(anc)) = (self.w.get(..self.n), self.anc.get_mut(..l)) else {
            return false;
        };
        if resample(Scheme::Systematic, w, anc, &mut self.rng).is_err() {
            return false;
        }
        for (sc, &a) in self.scratch.iter_mut().zip(&*anc) {
            *sc = self.x.get(a as usize).copied().unwrap_or_default();
        }
        let l = anc.len();
        let (Some(x), Some(sc)) = (self.x.get_mut(..l), self.scratch.get(..l)) else {
            return false;
        };
        x.copy_from_slice(sc);
        let wl = mass / l as f32;
        for w in self.w.iter_mut().take(l) {
            *w = wl;
        }
        self.n = l;
        true
    }

    pub(super) fn extract(&mut self, n_hat: usize) -> Result<()> {
        self.n_est = 0;
        let n = self.n.min(PARTICLES);
        if n_hat == 0 || n == 0 {
            return Ok(());
        }
        for i in 0..n {
            self.pts[i] = [self.x[i][0], self.x[i][2]];
        }
        match self.cfg.extractor {
            Extractor::Dbscan(p) => {
                let x = &self.x;
                let est = &mut self.est;
                let n_est = &mut self.n_est;
                let want = n_hat.min(TARGETS);
                self.dbscan.run(&self.pts[..n], &p, |members| {
                    let size = members.len() as u32;
                    if *n_est == want && est[want - 1].support >= size {
                        return;
                    }
                    let mut acc = [0.0f32; 5];
                    for &m in members {
                        let Some(xm) = x.get(m as usize) else {
                            continue;
                        };
                        for (a, v) in acc.iter_mut().zip(xm) {
                            *a += v;
                        }
                    }
                    let inv = 1.0 / size as f32;
                    let e = Estimate {
                        state: acc.map(|a| a * inv),
                        support: size,
                    };
                    let mut pos = (*n_est).min(want - 1);
                    if *n_est < want {
                        *n_est += 1;
                    }
                    while pos > 0 && est[pos - 1].support < size {
                        est[pos] = est[pos - 1];
                        pos -= 1;
                    }
                    est[pos] = e;
                })?;
            }
            Extractor::KMeans { max_iter } => {
                let k = self
                    .kmeans
                    .run(&self.pts[..n], n_hat, max_iter, &mut self.rng)?;
                let mut acc = [[0.0f32; 5]; TARGETS];
                for i in 0..n {
                    let c = self.kmeans.assign[i] as usize;
                    if let Some(a) = acc.get_mut(c).filter(|_| c < k) {
                        for (a, v) in a.iter_mut().zip(&self.x[i]) {
                            *a += v;
                        }
                    }
                }
                for (&cnt, a) in self.kmeans.counts.iter().zip(&acc).take(k) {
                    if cnt > 0 {
                        let inv = 1.0 / cnt as f32;
                        if let Some(e) = self.est.get_mut(self.n_est) {
                            *e = Estimate {
                                state: a.map(|a| a * inv),
                                support: cnt,
                            };
                            self.n_est += 1;
                        }
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The radix sort gives the permutation of the comparison sort by `(key, index)`:
    /// random cells (small and full 32-bit ranges), particles outside the cube
    /// (`u32::MAX`), many ties, digit counts of 2 to 256 slots.
    #[test]
    fn sort_by_cell_matches_the_sort_by_key_and_index() {
        let mut rng = crate::rng::Rng::seed_from_u64(7);
        for (n, range, digits) in [
            (0usize, 10u32, 256usize),
            (1, 10, 256),
            (2400, 32768, 256),
            (2400, 5, 256),
            (1000, u32::MAX, 256),
            (777, 40000, 16),
            (300, 1000, 2),
        ] {
            let key: std::vec::Vec<u32> = (0..n)
                .map(|_| {
                    if rng.below(10) == 0 {
                        u32::MAX
                    } else {
                        ((rng.uniform() as f64) * range as f64) as u32 % range.max(1)
                    }
                })
                .collect();
            let mut want: std::vec::Vec<u32> = (0..n as u32).collect();
            crate::sort::sort_unstable_by_key(&mut want, |&i| (key[i as usize], i));
            let mut order = std::vec![0u32; n];
            let mut tmp = std::vec![0u32; n];
            let mut count = std::vec![0u32; digits];
            sort_by_cell(&key, &mut order, &mut tmp, &mut count);
            assert_eq!(order, want, "{n} {range} {digits}");
        }
    }
}
