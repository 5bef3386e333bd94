//! The PSO step of PSO-PHD-TBD (Pei et al. 2019, §3): the measurement-derived points
//! among the predicted survivors' cells, refined to the local log-LR maximum, and the
//! swarm move of the gated particles.

use super::*;
use crate::model::power_cube;

impl<const PARTICLES: usize, const SWARM: usize, const POINTS: usize, const TARGETS: usize>
    SmcPhdTbd<PARTICLES, SWARM, POINTS, TARGETS>
{
    pub(super) fn select_points(&mut self, cube: &PowerCube<'_>, n_surv: usize, want: usize) {
        let g = *cube.geometry();
        let data = cube.data();
        let want = want.min(POINTS);
        // The statistic over at most 3 x 3 x 3 cells (`PointSpread::central`), the
        // thinning over the spread's own peak radius.
        let rad = [
            self.cfg.psf.peak_radius(0),
            self.cfg.psf.peak_radius(1),
            self.cfg.psf.peak_radius(2),
        ];
        let psf = self.cfg.psf.central();
        // (z, ir, lb, jd) sorted descending by z.
        let mut top = [(0.0f32, 0usize, 0usize, 0usize); POINTS];
        let mut amp = [0.0f32; POINTS];
        let mut nt = 0usize;
        let mut last_cell = usize::MAX;
        if want == 0 {
            self.n_z = 0;
            return;
        }
        for &s in self.x.iter().take(n_surv) {
            let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
            let Some((ir, jd, lb)) = g.cell_of(&c) else {
                continue;
            };
            let cell = g.index(ir, jd, lb);
            if cell == last_cell {
                continue;
            }
            last_cell = cell;
            // Point-spread-matched statistic `sum h^2 z` over the cells a target at the
            // cell centre would cover (the small-signal form of the log likelihood
            // ratio, `ln I0(x) ~ x^2 / 4`), not the single cell's power.
            let centre = RadarCoords {
                range: g.range_centre(ir),
                doppler: g.doppler_centre(jd),
                azimuth_deg: g.azimuth_centre(lb),
            };
            let mut z = 0.0f32;
            psf.for_each_cell(&g, &centre, |idx, h| {
                if let Some(&v) = data.get(idx) {
                    z += h * h * v;
                }
            });
            if nt == want && top.get(nt.wrapping_sub(1)).is_some_and(|t| z <= t.0) {
                continue;
            }
            // Thinning in range, azimuth *and* Doppler: targets born at the same place
            // (Table 1: three at (250, 1500), three at (1750, 500)) share range/azimuth
            // cells for several frames but not Doppler cells; thinning on position alone
            // left one point for two targets and the swarm merged their clouds.
            // Within the spread's peak radius on every axis (one cell for a one-cell
            // spread: 3 x 3 x 3 blocks).
            let near = |e: &(f32, usize, usize, usize)| {
                e.1.abs_diff(ir) <= rad[0]
                    && e.2.abs_diff(lb) <= rad[2]
                    && e.3.abs_diff(jd) <= rad[1]
            };
            if top.iter().take(nt).any(|e| near(e) && e.0 >= z) {
                continue;
            }
            // Drop weaker neighbours, then insert.
            let mut k = 0;
            for t in 0..nt.min(POINTS) {
                if !near(&top[t]) {
                    // k <= t
                    if k < t {
                        top[k] = top[t];
                        amp[k] = amp[t];
                    }
                    k += 1;
                }
            }
            nt = k;
            let mut p = nt.min(want - 1);
            if nt < want {
                nt += 1;
            }
            // p < want <= M
            while p > 0 {
                let (Some(&tp), Some(&ap)) = (top.get(p - 1), amp.get(p - 1)) else {
                    break;
                };
                if tp.0.partial_cmp(&z) != Some(core::cmp::Ordering::Less) {
                    break;
                }
                if let (Some(t), Some(a)) = (top.get_mut(p), amp.get_mut(p)) {
                    (*t, *a) = (tp, ap);
                }
                p -= 1;
            }
            let a = math::sqrt(s[4].max(0.0));
            if let (Some(t), Some(am)) = (top.get_mut(p), amp.get_mut(p)) {
                (*t, *am) = ((z, ir, lb, jd), a);
            }
        }
        let refine = self.cfg.pso.is_some_and(|p| p.refine_points);
        for (k, e) in top.iter().enumerate().take(nt) {
            let (x, y) = if refine {
                self.refine_point(cube, e.1, e.3, e.2, amp[k])
            } else {
                g.cell_position(e.1, e.2)
            };
            self.zpts[k] = [x, y];
        }
        self.n_z = nt;
    }

    /// Sub-cell `Z_m`: the (range, Doppler, azimuth) maximising the frame's log
    /// likelihood ratio `sum ln L(z | x)` (eq. 20-23) of a target with amplitude `amp`
    /// within cell `(ir, jd, lb)`: a 5 x 3 x 5 grid of quarter-cell steps, then a
    /// 3 x 3 x 3 grid of eighth-cell steps around its best. Returns `(x, y)`.
    fn refine_point(
        &self,
        cube: &PowerCube<'_>,
        ir: usize,
        jd: usize,
        lb: usize,
        amp: f32,
    ) -> (f32, f32) {
        let g = *cube.geometry();
        let psf = self.cfg.psf;
        let s2 = self.cfg.noise_var;
        let mut best = (
            f32::NEG_INFINITY,
            g.range_centre(ir),
            g.doppler_centre(jd),
            g.azimuth_centre(lb),
        );
        for (half, step) in [(2i32, 0.25f32), (1, 0.125)] {
            let (r0, d0, b0) = (best.1, best.2, best.3);
            for a in -half..=half {
                for c in -half..=half {
                    for d in -1i32..=1 {
                        let rc = RadarCoords {
                            range: r0 + a as f32 * step * g.range_cell,
                            doppler: d0 + d as f32 * step * g.doppler_cell,
                            azimuth_deg: b0 + c as f32 * step * g.azimuth_cell_deg,
                        };
                        let l = cube.log_lr(&psf, &rc, amp, s2);
                        if l > best.0 {
                            best = (l, rc.range, rc.doppler, rc.azimuth_deg);
                        }
                    }
                }
            }
        }
        let b = best.3 / DEG_PER_RAD;
        (best.1 * math::cos(b), best.1 * math::sin(b))
    }

    /// The swarm over at most `pso.max_members` of the gated particles.
    pub(super) fn swarm_step(&mut self, pso: &PsoConfig) -> (usize, usize) {
        let m = self.n_z.min(POINTS);
        if m == 0 {
            return (0, 0);
        }
        let zpts = &self.zpts[..m];
        let inv = 1.0 / (2.0 * pso.fitness_scale * pso.fitness_scale);
        let nearest = |p: [f32; 2], z: &[[f32; 2]]| {
            let mut best = (0usize, f32::INFINITY);
            for (k, q) in z.iter().enumerate() {
                let (dx, dy) = (p[0] - q[0], p[1] - q[1]);
                let d = dx * dx + dy * dy;
                if d < best.1 {
                    best = (k, d);
                }
            }
            best
        };
        self.swarm.clear();
        // The gated particles (index in `order`, nearest point in `key`).
        let mut gated = 0usize;
        for (i, x) in self.x.iter().enumerate().take(self.n) {
            let (k, d) = nearest([x[0], x[2]], zpts);
            if power_cube::exp_neg(-d * inv) >= pso.gate {
                // gated <= i
                if let (Some(o), Some(kk)) = (self.order.get_mut(gated), self.key.get_mut(gated)) {
                    (*o, *kk) = (i as u32, k as u32);
                }
                gated += 1;
            }
        }
        // At most `max_members` of them (and the swarm's capacity), evenly spaced:
        // member `j` is gated particle `floor(j gated / take)`.
        let take = gated
            .min(pso.max_members)
            .min(Swarm::<SWARM, POINTS>::capacity());
        let mut before = [0.0f32; POINTS];
        let mut n_s = 0usize;
        for j in 0..take {
            let g = (j as u64 * gated as u64 / take as u64) as usize;
            let (Some(&i), Some(&k)) = (self.order.get(g), self.key.get(g)) else {
                break;
            };
            let (i, k) = (i as usize, k as usize);
            let (Some(x), Some(&w)) = (self.x.get(i), self.w.get(i)) else {
                break;
            };
            if !self.swarm.push([x[0], x[2]], w, i as u32, k as u16) {
                break;
            }
            // `g >= j`: slot `j` of `order` is free once read.
            if let Some(o) = self.order.get_mut(n_s) {
                *o = i as u32;
            }
            if let Some(b) = before.get_mut(k) {
                *b += w;
            }
            n_s += 1;
        }
        if n_s == 0 {
            return (0, 0);
        }
        let rep = self.swarm.run(pso, zpts, &mut self.rng);
        let n_s = n_s.min(SWARM);
        let mut after = [0.0f32; POINTS];
        for k in 0..n_s {
            let (g, _) = nearest(self.swarm.pos[k], zpts);
            if let Some(a) = after.get_mut(g) {
                *a += self.swarm.weight[k];
            }
        }

        let mut scale = [1.0f32; POINTS];
        for g in 0..m {
            if after[g] > 0.0 {
                scale[g] = before[g] / after[g];
            }
        }
        for k in 0..n_s {
            let src = self.swarm.src[k] as usize;
            let mut s = self.x.get(src).copied().unwrap_or_default();
            s[0] = self.swarm.pos[k][0];
            s[2] = self.swarm.pos[k][1];
            let (g, _) = nearest(self.swarm.pos[k], zpts);
            let w = self.swarm.weight[k] * scale.get(g).copied().unwrap_or(1.0);
            if let (Some(sc), Some(lw)) = (self.scratch.get_mut(k), self.lw.get_mut(k)) {
                (*sc, *lw) = (s, w);
            }
        }
        for ((&slot, &s), &w) in self.order.iter().zip(&self.scratch).zip(&self.lw).take(n_s) {
            if let (Some(x), Some(wt)) =
                (self.x.get_mut(slot as usize), self.w.get_mut(slot as usize))
            {
                (*x, *wt) = (s, w);
            }
        }
        (n_s, rep.generations)
    }
}
