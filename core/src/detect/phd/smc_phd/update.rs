//! The update (eq. 20, 24-25) with the cell grouping by sort and union-find, the
//! systematic resampling to `N_hat` targets' worth of particles (eq. 26), and the state
//! extraction (DBSCAN or K-means).

use super::*;
use crate::model::power_cube;

/// The 13 "forward" neighbours of a cell (the other 13 are found from the other side).
const NEIGHBOURS: [(i64, i64, i64); 13] = [
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
            let key = &self.key;
            crate::sort::sort_unstable_by_key(&mut self.order[..n], |&i| {
                (key.get(i as usize).copied().unwrap_or(u32::MAX), i)
            });
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
                    let (x, y, z) = (ir as i64 + a, jd as i64 + b, lb as i64 + c);
                    if x < 0
                        || y < 0
                        || z < 0
                        || x >= g.n_range as i64
                        || y >= g.n_doppler as i64
                        || z >= g.n_azimuth as i64
                    {
                        continue;
                    }
                    let idx = g.index(x as usize, y as usize, z as usize) as u32;
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
                    p[0] = p[0].max(self.lw[i]);
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
