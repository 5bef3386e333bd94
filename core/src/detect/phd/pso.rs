//! Multi-objective particle swarm step (Pei et al. 2019, §2.1 and §2.3 step 3) with the
//! NSGA-II machinery: weighted crowding distance (eq. 10-12), elitist selection, the
//! three-part mutation, the stop rule; the non-dominated sorts live in [`super::ndsort`].
//!
//! All objectives are **maximised** (fitness values in `[0, 1]`).
//!
//! The swarm's groups are ranked, all exactly and in O(N) memory, by:
//! - two active objectives: ENS-BS ([`super::ndsort::non_dominated_sort`]), O(N log N);
//! - three or four: the divide-and-conquer sort ([`super::ndsort::rank_sorted`]),
//!   O(N log^(M-1) N) whatever the front sizes (ENS-BS spent 70 % of the frame there:
//!   those groups' first fronts hold most of their entries); with five or more, ENS-BS
//!   again (the `log^(M-1) N` factor outgrows it);
//! - one active objective: the best half by that objective (a selection, O(N)).

#![allow(clippy::needless_range_loop)]

use super::ndsort::{self, ens_bs};
use crate::math;
use crate::model::power_cube::exp_neg;
use crate::rng::Rng;
use crate::sort;

const NONE: u32 = u32::MAX;

/// Largest `generations` / `max_generations` a config validates with: a frame's swarm
/// work is bounded (one generation of the preset's 512-particle swarm costs about 60 us
/// on one host core, so the cap is about 0.06 s per frame; 1e5 generations took 6 s).
pub const MAX_GENERATIONS: usize = 1000;

/// Most active objectives a group sorted by the divide-and-conquer sort has (groups with
/// more use ENS-BS, see [`Swarm::select`]).
const DC_OBJECTIVES: usize = 4;

/// `a[to] = a[from]` (nothing when either is out of range: never, for the callers).
#[inline(always)]
fn shift<T: Copy>(a: &mut [T], from: usize, to: usize) {
    if let Some(&v) = a.get(from) {
        if let Some(d) = a.get_mut(to) {
            *d = v;
        }
    }
}

/// Weighted crowding distance (eq. 10-12): per front and objective `j`, sorted by
/// `f_j`, the two ends get `boundary` and inner solutions get
/// `sum_j W_j (f_j[next] - f_j[prev]) / (f_j,max - f_j,min)`. An objective on which the
/// front has zero span adds nothing, not even boundaries (its "ends" would be arbitrary).
///
/// `order` is a workspace of length `>= n`.
pub fn crowding_distance<const OBJECTIVES: usize>(
    f: &[[f32; OBJECTIVES]],
    m: usize,
    weights: &[f32],
    rank: &[u32],
    boundary: f32,
    crowd: &mut [f32],
    order: &mut [u32],
) {
    let n = f.len().min(rank.len()).min(crowd.len()).min(order.len());
    let m = m.min(OBJECTIVES).min(weights.len());
    for c in crowd[..n].iter_mut() {
        *c = 0.0;
    }
    for j in 0..m {
        for (i, o) in order[..n].iter_mut().enumerate() {
            *o = i as u32;
        }
        // (front, f_j), ties by index: a total order, so the result is defined.
        let key = |i: u32| {
            let i = i as usize;
            (
                rank.get(i).copied(),
                f.get(i).and_then(|r| r.get(j)).copied().unwrap_or(0.0),
            )
        };
        sort::sort_unstable_by(&mut order[..n], |&a, &b| {
            let ((ra, fa), (rb, fb)) = (key(a), key(b));
            ra.cmp(&rb)
                .then(fa.partial_cmp(&fb).unwrap_or(core::cmp::Ordering::Equal))
                .then(a.cmp(&b))
        });
        let fj = |i: u32| {
            f.get(i as usize)
                .and_then(|r| r.get(j))
                .copied()
                .unwrap_or(0.0)
        };
        let rk = |i: u32| rank.get(i as usize).copied();
        let order = &order[..n];
        let wj = weights.get(j).copied().unwrap_or(0.0);
        // One front's members are the run order[s..e] of equal rank.
        let mut s = 0usize;
        while let Some(&first) = order.get(s) {
            let r = rk(first);
            let mut e = s + 1;
            while order.get(e).is_some_and(|&o| rk(o) == r) {
                e += 1;
            }
            let Some(front) = order.get(s..e) else {
                break;
            };
            let (Some(&a), Some(&b)) = (front.first(), front.last()) else {
                break;
            };
            let span = fj(b) - fj(a);
            if span > 0.0 {
                for i in [a, b] {
                    if let Some(c) = crowd.get_mut(i as usize) {
                        *c = boundary;
                    }
                }
                for w in front.windows(3) {
                    let (prev, i, next) = (w[0], w[1], w[2]);
                    if let Some(c) = crowd.get_mut(i as usize) {
                        if *c < boundary {
                            *c += wj * (fj(next) - fj(prev)) / span;
                        }
                    }
                }
            }
            s = e;
        }
    }
}

/// PSO settings (eq. 8-9, 18-19 and the stop rule).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct PsoConfig {
    /// Generations run every frame, `gen` (paper: 10). §3.1: "after the iteration count
    /// is reached, the fitness threshold is the final condition for ending the
    /// optimisation", so the threshold is checked only once `gen` generations ran.
    pub generations: usize,
    /// After `generations`, continue while the swarm's mean best-objective fitness is
    /// below this, `Th_pso` (0.7).
    pub threshold: f32,
    /// Hard cap on generations per frame (ours: bounded work per frame; the paper has
    /// none). Values below `generations` are treated as `generations`. Both are at most
    /// [`MAX_GENERATIONS`].
    pub max_generations: usize,
    /// `Z_m` at the local maximum of the frame's log likelihood ratio inside the chosen
    /// cell (sub-cell), instead of the cell centre.
    pub refine_points: bool,
    /// Inertia `w` of eq. 8.
    pub inertia: f32,
    /// Cognitive factor `c1`.
    pub c1: f32,
    /// Social factor `c2`.
    pub c2: f32,
    /// Update factor `r` of eq. 9.
    pub step: f32,
    /// Fitness length scale `sqrt(c sigma_n^2)` of eq. 18, metres.
    pub fitness_scale: f32,
    /// A particle joins the swarm if its best single-objective fitness is at least this;
    /// objective values below it are floored to 0.
    pub gate: f32,
    /// Half width (m) of the uniform mutation increments, at most `f32::MAX / 4`.
    pub mutation: f32,
    /// Number of measurement-derived points `Z_m` (objectives), at most the capacity `POINTS`.
    pub points: usize,
    /// At most this many particles join the swarm per frame, evenly spaced in index
    /// order among the gated ones (`usize::MAX`: all of them); also bounded by the
    /// swarm's capacity `S / 2`. The others keep their predicted positions.
    ///
    /// The paper's abstract moves "all the particles", but its timing (Table 4: the
    /// swarm adds ~0.2 s per frame in MATLAB to PHD-TBD's ~0.31 s) is far below what an
    /// `O(M N^2)` NSGA-II over thousands of particles for ten generations costs, and its
    /// §3.2 names moving only part of the particles (the newborn ones) the fastest case.
    /// The preset's 512 is the largest power of two that keeps PSO-PHD-TBD under 10 ms per
    /// frame on one host core; measured to lose no accuracy (README).
    pub max_members: usize,
}

impl PsoConfig {
    /// Defaults used by the six-targets preset (documented in the README).
    pub const fn paper() -> Self {
        Self {
            generations: 10,
            threshold: 0.7,
            max_generations: 20,
            refine_points: true,
            inertia: 0.5,
            c1: 1.0,
            c2: 1.0,
            step: 1.0,
            fitness_scale: 20.0,
            gate: 1.0e-3,
            mutation: 2.0,
            points: 8,
            max_members: 512,
        }
    }

    /// The paper's settings with at most 128 particles in the swarm per frame (the
    /// preset's 512 over four): the configuration for a Cortex-M4F budget of 30 M
    /// instructions per frame. On the firmware's three-target scene (`SmcPhdTbdM4`, 1000
    /// particles per target, 500 births, 10 frames) the swarm costs about a seventh of the
    /// preset's, and on the paper's six-target scene (100 runs per SNR at 9, 7 and 5 dB)
    /// its OSPA and count spread lie within the preset's 95 % intervals; 64 did not
    /// (docs/phd.md, "Cortex-M4F: instructions per frame").
    pub const fn cortex_m4() -> Self {
        Self {
            max_members: 128,
            ..Self::paper()
        }
    }
}

/// Swarm workspace for up to `SWARM / 2` particles (parents plus children fill `SWARM`)
/// and `POINTS` objectives (one per measurement point). Memory is O(SWARM POINTS).
#[derive(Debug, Clone)]
pub struct Swarm<const SWARM: usize, const POINTS: usize> {
    /// Position (x, y) per entry.
    pub pos: [[f32; 2]; SWARM],
    vel: [[f32; 2]; SWARM],
    pbest: [[f32; 2]; SWARM],
    pbest_fit: [f32; SWARM],
    /// Objective values per entry.
    pub fit: [[f32; POINTS]; SWARM],
    /// PHD weight carried from parent to child.
    pub weight: [f32; SWARM],
    /// Filter particle each entry descends from.
    pub src: [u32; SWARM],
    /// Selection group of each entry (the caller's target group; children inherit it).
    group: [u16; SWARM],
    rank: [u32; SWARM],
    /// Crowding distance as `f32` bits (non-negative, so the bits order like the values);
    /// the divide-and-conquer sort's Fenwick tree while ranks are computed.
    crowd: [u32; SWARM],
    order: [u32; SWARM],
    next: [u32; SWARM],
    head: [u32; SWARM],
    aux: [u32; SWARM],
    /// Sort keys `key << 32 | index` (a `u64` sort needs no lookups in the comparator).
    keys: [u64; SWARM],
    kept: [bool; SWARM],
    /// A group's active objectives by sorted position, for the divide-and-conquer sort
    /// (one contiguous load per value instead of two dependent ones: -7 % instructions
    /// per frame on the host, -3 % on the Cortex-M4F).
    objs: [[f32; DC_OBJECTIVES]; SWARM],
    /// Active entries (parents) after [`Swarm::run`].
    pub len: usize,
}

/// What one swarm run did.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SwarmReport {
    /// Generations run.
    pub generations: usize,
    /// Mean best-objective fitness of the swarm at the end.
    pub mean_fitness: f32,
}

impl<const SWARM: usize, const POINTS: usize> Default for Swarm<SWARM, POINTS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const SWARM: usize, const POINTS: usize> Swarm<SWARM, POINTS> {
    /// Zeroed workspace.
    pub const fn new() -> Self {
        Self {
            pos: [[0.0; 2]; SWARM],
            vel: [[0.0; 2]; SWARM],
            pbest: [[0.0; 2]; SWARM],
            pbest_fit: [0.0; SWARM],
            fit: [[0.0; POINTS]; SWARM],
            weight: [0.0; SWARM],
            src: [0; SWARM],
            group: [0; SWARM],
            rank: [0; SWARM],
            crowd: [0; SWARM],
            order: [0; SWARM],
            next: [0; SWARM],
            head: [0; SWARM],
            aux: [0; SWARM],
            keys: [0; SWARM],
            kept: [false; SWARM],
            objs: [[0.0; DC_OBJECTIVES]; SWARM],
            len: 0,
        }
    }

    /// Parent capacity `S / 2`.
    pub const fn capacity() -> usize {
        SWARM / 2
    }

    /// Clears the swarm.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Adds a parent in selection group `group`; returns false when full.
    ///
    /// The elitist selection keeps, per group, as many entries as the group had parents:
    /// the swarm moves particles, it must not move them between the PHD's targets.
    pub fn push(&mut self, pos: [f32; 2], weight: f32, src: u32, group: u16) -> bool {
        if self.len >= SWARM / 2 {
            return false;
        }
        let i = self.len;
        self.pos[i] = pos;
        self.vel[i] = [0.0; 2];
        self.pbest[i] = pos;
        self.pbest_fit[i] = -1.0;
        self.weight[i] = weight;
        self.src[i] = src;
        self.group[i] = group;
        self.len += 1;
        true
    }

    /// Objective values of eq. 18 for entry `i`; returns the eq. 19 total (`w_m = 1/m`).
    ///
    /// `f_m = exp(-d^2 inv_two_s2)`, set to 0 where `d^2 inv_two_s2 > cut = -ln(gate)`
    /// (below the gate): far points then tie exactly, so each particle has only the few
    /// objectives of the points near it, and no `exp` is spent on the others.
    fn evaluate(&mut self, i: usize, points: &[[f32; 2]], inv_two_s2: f32, cut: f32) -> f32 {
        let (Some(&p), Some(fit), Some(best_fit), Some(best)) = (
            self.pos.get(i),
            self.fit.get_mut(i),
            self.pbest_fit.get_mut(i),
            self.pbest.get_mut(i),
        ) else {
            return 0.0;
        };
        let mut total = 0.0;
        for (f, z) in fit.iter_mut().zip(points) {
            let dx = p[0] - z[0];
            let dy = p[1] - z[1];
            let a = (dx * dx + dy * dy) * inv_two_s2;
            // NaN (a non-finite position) is below the gate too: fitness is never NaN.
            let v = if a <= cut { exp_neg(-a) } else { 0.0 };
            *f = v;
            total += v;
        }
        if !points.is_empty() {
            total /= points.len().min(POINTS) as f32;
        }
        if total > *best_fit {
            *best_fit = total;
            *best = p;
        }
        total
    }

    /// Best objective index and value of entry `i`.
    #[inline]
    pub fn best_objective(&self, i: usize, m: usize) -> (usize, f32) {
        let mut best = (0usize, f32::NEG_INFINITY);
        let Some(fit) = self.fit.get(i) else {
            return best;
        };
        for (j, &v) in fit[..m.min(POINTS)].iter().enumerate() {
            if v > best.1 {
                best = (j, v);
            }
        }
        best
    }

    /// Runs the multi-objective PSO on the parents `0..len` towards `points`:
    /// per generation, children by eq. 8-9 plus mutation (entry `i % 3`: 0 unchanged,
    /// 1 one common uniform increment, 2 an own uniform increment), fitness eq. 18-19,
    /// merge, and the elitist selection of `Swarm::select`. Runs `generations`, then
    /// continues while the mean best-objective fitness is below `threshold`, at most
    /// `max_generations` in all. Weights ride along; the caller renormalises.
    ///
    /// The leader of objective `j` (the `gBest` of eq. 8 for the particles whose best
    /// objective is `j`) is the parent with the largest `f_j` (ties: larger eq. 19 total,
    /// then lower index), which is always on the first front.
    pub fn run(&mut self, cfg: &PsoConfig, points: &[[f32; 2]], rng: &mut Rng) -> SwarmReport {
        // `push` keeps `len <= S / 2`; `len` is public.
        let n = self.len.min(SWARM / 2);
        let m = points.len().min(POINTS);
        if n == 0 || m == 0 {
            return SwarmReport::default();
        }
        let inv_two_s2 = 1.0 / (2.0 * cfg.fitness_scale * cfg.fitness_scale);
        let cut = -math::ln(cfg.gate);
        let mut mean_best = 0.0f32;
        for i in 0..n {
            self.evaluate(i, points, inv_two_s2, cut);
            mean_best += self.best_objective(i, m).1;
        }
        mean_best /= n as f32;
        let obj_w = 1.0f32 / m as f32;
        let mut gens = 0usize;
        let cap = cfg.max_generations.max(cfg.generations);
        while gens < cap && (gens < cfg.generations || mean_best < cfg.threshold) {
            gens += 1;
            let mut leader = [0usize; POINTS];
            let mut lval = [(f32::NEG_INFINITY, f32::NEG_INFINITY); POINTS];
            for i in 0..n {
                let mut tot = 0.0f32;
                for j in 0..m {
                    tot += self.fit[i][j];
                }
                for j in 0..m {
                    let v = (self.fit[i][j], tot);
                    if v.0 > lval[j].0 || (v.0 == lval[j].0 && v.1 > lval[j].1) {
                        lval[j] = v;
                        leader[j] = i;
                    }
                }
            }
            let common = [
                rng.uniform_range(-cfg.mutation, cfg.mutation),
                rng.uniform_range(-cfg.mutation, cfg.mutation),
            ];
            for i in 0..n {
                let c = n + i;
                if c >= SWARM {
                    break;
                }
                let g = leader
                    .get(self.best_objective(i, m).0)
                    .and_then(|&l| self.pos.get(l))
                    .copied()
                    .unwrap_or(self.pos[i]);
                let mut v = [0.0f32; 2];
                let mut x = [0.0f32; 2];
                for d in 0..2 {
                    let r1 = rng.uniform();
                    let r2 = rng.uniform();
                    v[d] = cfg.inertia * self.vel[i][d]
                        + cfg.c1 * r1 * (self.pbest[i][d] - self.pos[i][d])
                        + cfg.c2 * r2 * (g[d] - self.pos[i][d]);
                    x[d] = self.pos[i][d] + cfg.step * v[d];
                }
                match i % 3 {
                    1 => {
                        x[0] += common[0];
                        x[1] += common[1];
                    }
                    2 => {
                        x[0] += rng.uniform_range(-cfg.mutation, cfg.mutation);
                        x[1] += rng.uniform_range(-cfg.mutation, cfg.mutation);
                    }
                    _ => {}
                }
                self.pos[c] = x;
                self.vel[c] = v;
                self.pbest[c] = self.pbest[i];
                self.pbest_fit[c] = self.pbest_fit[i];
                self.weight[c] = self.weight[i];
                self.src[c] = self.src[i];
                self.group[c] = self.group[i];
                self.evaluate(c, points, inv_two_s2, cut);
            }
            self.select(2 * n, m, obj_w);
            // Compact the kept entries in ascending index order (safe forward copy).
            let mut k = 0usize;
            mean_best = 0.0;
            for s in 0..(2 * n).min(SWARM) {
                if !self.kept[s] {
                    continue;
                }
                // k <= s
                if k < s {
                    shift(&mut self.pos, s, k);
                    shift(&mut self.vel, s, k);
                    shift(&mut self.pbest, s, k);
                    shift(&mut self.pbest_fit, s, k);
                    shift(&mut self.fit, s, k);
                    shift(&mut self.weight, s, k);
                    shift(&mut self.src, s, k);
                    shift(&mut self.group, s, k);
                }
                mean_best += self.best_objective(k, m).1;
                k += 1;
            }
            mean_best /= n as f32;
        }
        SwarmReport {
            generations: gens,
            mean_fitness: mean_best,
        }
    }

    /// Elitist selection over entries `0..tot` (parents and children): per selection
    /// group, keep the best half by (front, weighted crowding distance eq. 10-12), ties by
    /// lower index; writes `kept`.
    ///
    /// Sorting and crowding run per group, over the group's *active* objectives only
    /// (those some member has above the gate): the selection is per group (a global cut
    /// would keep the groups whose fronts are wide, i.e. targets near several points, and
    /// drop the others' particles: measured, a target with one point lost 99.9 % of its
    /// swarm entries in one frame), an objective that is 0 for the whole group neither
    /// dominates nor crowds, and dominance by another group's entries would only reorder
    /// fronts that are cut per group anyway. Group ids `>= M` share group `M - 1`.
    /// A group with one active objective keeps its best half by that objective (its
    /// fronts are the distinct values and crowding adds nothing), with two the sort checks
    /// one member per front, so the selection is O(N log N) whatever the front sizes;
    /// with three or four the divide-and-conquer sort of [`ndsort`], with five or more
    /// ENS-BS checking every front member. Only the front that is cut gets
    /// crowding distances (NSGA-II), since the fronts before it are kept whole.
    fn select(&mut self, tot: usize, m: usize, obj_w: f32) {
        let tot = tot.min(SWARM);
        let m = m.min(POINTS);
        // Counting sort of the entries by group into `order`.
        let mut start = [0usize; POINTS];
        for &g in self.group.iter().take(tot) {
            start[(g as usize).min(POINTS - 1)] += 1;
        }
        let mut acc = 0usize;
        for c in start.iter_mut() {
            let k = *c;
            *c = acc;
            acc += k;
        }
        let mut end = start;
        // Active objectives per group: some member has the objective above the gate.
        let mut active = [[false; POINTS]; POINTS];
        for i in 0..tot {
            let g = (self.group[i] as usize).min(POINTS - 1);
            if let Some(o) = self.order.get_mut(end[g]) {
                *o = i as u32;
            }
            end[g] += 1;
            self.kept[i] = false;
            for (a, &v) in active[g].iter_mut().zip(&self.fit[i]).take(m) {
                *a |= v > 0.0;
            }
        }
        for g in 0..POINTS {
            let (s, e) = (start[g], end[g]);
            let keep = (e - s) / 2;
            if keep == 0 {
                continue;
            }
            // Active objectives of the group, the group's own point first (any objective
            // order gives the same fronts; with its own point first, whose fitness few
            // members lack, the lexicographic sort rarely needs a second objective).
            let mut act = [0usize; POINTS];
            let mut na = 0usize;
            if g < m && active[g][g] {
                act[0] = g;
                na = 1;
            }
            for j in 0..m {
                if active[g][j] && !(na > 0 && act[0] == j) {
                    if let Some(a) = act.get_mut(na) {
                        *a = j;
                    }
                    na += 1;
                }
            }
            let act = act.get(..na).unwrap_or(&act);
            let fit = &self.fit;
            let value = |i: u32, j: usize| {
                fit.get(i as usize)
                    .and_then(|r| r.get(j))
                    .copied()
                    .unwrap_or(0.0)
            };
            let Some(members) = self.order.get_mut(s..e) else {
                continue;
            };
            let Some(keys) = self.keys.get_mut(..members.len()) else {
                continue;
            };
            // Descending by the first active objective, ties by index: `u64` keys
            // `!bits(f) << 32 | i` (`bits` orders like the values; fitness is never NaN
            // or -0 for finite positions).
            let first = |i: u32| act.first().map_or(0.0, |&j| value(i, j));
            for (k, &i) in keys.iter_mut().zip(members.iter()) {
                *k = (u64::from(!ndsort::ordered_bits(first(i))) << 32) | u64::from(i);
            }
            let Some(rest) = act.get(1..).filter(|_| na > 1) else {
                // Fronts are the distinct values of the one objective, best first.
                sort::select_nth_unstable(keys, keep - 1);
                for &k in keys.iter().take(keep) {
                    if let Some(kept) = self.kept.get_mut(k as u32 as usize) {
                        *kept = true;
                    }
                }
                continue;
            };
            // Lexicographically descending on the active objectives, ties by index: by
            // the first objective's keys, then the runs of equal first objective by the
            // others.
            sort::sort_unstable(keys);
            for (m, &k) in members.iter_mut().zip(keys.iter()) {
                *m = k as u32;
            }
            let mut a = 0usize;
            while let Some(&ka) = keys.get(a) {
                let mut b = a + 1;
                while keys.get(b).is_some_and(|&kb| kb >> 32 == ka >> 32) {
                    b += 1;
                }
                if let Some(run) = members.get_mut(a..b).filter(|r| r.len() > 1) {
                    sort::sort_unstable_by(run, |&x, &y| {
                        let (Some(fx), Some(fy)) = (fit.get(x as usize), fit.get(y as usize))
                        else {
                            return x.cmp(&y);
                        };
                        for &j in rest {
                            let (Some(&u), Some(&v)) = (fx.get(j), fy.get(j)) else {
                                break;
                            };
                            if u > v {
                                return core::cmp::Ordering::Less;
                            }
                            if u < v {
                                return core::cmp::Ordering::Greater;
                            }
                        }
                        x.cmp(&y)
                    });
                }
                a = b;
            }
            // Two objectives: ENS-BS checking one member per front; three or four: the
            // divide-and-conquer sort; five or more: ENS-BS with full front checks (the
            // divide-and-conquer's `log^(M-1) N` factor outgrows it at these group
            // sizes: measured -2 % to -5 % per frame, same selections).
            let (taken, cut_len) = if na == 2 || na > DC_OBJECTIVES {
                self.fronts_ens(s, e, keep, act)
            } else {
                self.fronts_many(s, e, keep, act)
            };
            if cut_len > 0 {
                self.crowd_cut(s, cut_len, keep - taken, act, obj_w);
            }
        }
    }

    /// Two, or more than [`DC_OBJECTIVES`], active objectives: ENS-BS over the group's
    /// lexicographic order in `order[s..e]`, checking one member per front with two
    /// objectives (O(N log N)), every member with more. Marks the fronts that
    /// fit in `keep` and copies the members of the front that is cut to `head[s..]`;
    /// returns (kept, members of the cut front).
    fn fronts_ens(&mut self, s: usize, e: usize, keep: usize, act: &[usize]) -> (usize, usize) {
        let fit = &self.fit;
        let (Some(order), Some(head)) = (self.order.get(s..e), self.head.get_mut(s..e)) else {
            return (0, 0);
        };
        let fronts = ens_bs(
            order,
            act.len() <= 2,
            &mut self.rank,
            &mut self.next,
            head,
            |a, b| {
                let (Some(fa), Some(fb)) = (fit.get(a), fit.get(b)) else {
                    return false;
                };
                let mut strict = false;
                for &j in act {
                    let (Some(&x), Some(&y)) = (fa.get(j), fb.get(j)) else {
                        return false;
                    };
                    if x < y {
                        return false;
                    }
                    strict |= x > y;
                }
                strict
            },
        );
        let next = &self.next;
        let after = |t: u32| next.get(t as usize).copied().unwrap_or(NONE);
        let mut taken = 0usize;
        for fr in 0..fronts {
            let Some(&first) = head.get(fr) else {
                break;
            };
            let mut cnt = 0usize;
            let mut t = first;
            while t != NONE {
                cnt += 1;
                t = after(t);
            }
            let mut t = first;
            if taken + cnt <= keep {
                while t != NONE {
                    if let Some(k) = self.kept.get_mut(t as usize) {
                        *k = true;
                    }
                    t = after(t);
                }
                taken += cnt;
                if taken == keep {
                    return (taken, 0);
                }
            } else {
                // `head[fr]` was read: `head[..]` is free for the members.
                let mut c = 0usize;
                while t != NONE {
                    if let Some(h) = head.get_mut(c) {
                        *h = t;
                    }
                    c += 1;
                    t = after(t);
                }
                return (taken, c);
            }
        }
        (taken, 0)
    }

    /// Three or four active objectives (at most [`DC_OBJECTIVES`]; more are not read):
    /// ranks by [`ndsort::rank_sorted`] on the objectives copied to `objs` (position
    /// ranks in `rank[s..e]`, workspaces `head`, `next`, `aux`, `crowd` over `s..e`), then
    /// as [`Swarm::fronts_ens`].
    fn fronts_many(&mut self, s: usize, e: usize, keep: usize, act: &[usize]) -> (usize, usize) {
        let (Some(order), Some(rank), Some(head), Some(next), Some(aux), Some(crowd)) = (
            self.order.get(s..e),
            self.rank.get_mut(s..e),
            self.head.get_mut(s..e),
            self.next.get_mut(s..e),
            self.aux.get_mut(s..e),
            self.crowd.get_mut(s..e),
        ) else {
            return (0, 0);
        };
        for (o, &i) in self.objs.iter_mut().zip(order) {
            let Some(f) = self.fit.get(i as usize) else {
                continue;
            };
            for (v, &j) in o.iter_mut().zip(act) {
                *v = f.get(j).copied().unwrap_or(0.0);
            }
        }
        let objs = &self.objs;
        let fronts = ndsort::rank_sorted(
            order.len(),
            act.len().min(DC_OBJECTIVES),
            // j < DC_OBJECTIVES: `% DC_OBJECTIVES` only shows the optimiser the bound
            |p, j| objs.get(p).map_or(0.0, |r| r[j % DC_OBJECTIVES]),
            rank,
            ndsort::Workspace {
                work: head,
                scratch: next,
                order1: aux,
                fenwick: crowd,
            },
        );
        // The workspaces again (the borrows ended with the call).
        let (Some(rank), Some(head), Some(count)) = (
            self.rank.get(s..e),
            self.head.get_mut(s..e),
            self.next.get_mut(s..e),
        ) else {
            return (0, 0);
        };
        // Front sizes (fronts <= len), then the front that is cut.
        for c in count.iter_mut().take(fronts) {
            *c = 0;
        }
        for &r in rank {
            if let Some(c) = count.get_mut(r as usize) {
                *c += 1;
            }
        }
        let mut taken = 0usize;
        let mut cut = fronts;
        for (fr, &c) in count.iter().take(fronts).enumerate() {
            if taken + c as usize > keep {
                cut = fr;
                break;
            }
            taken += c as usize;
            if taken == keep {
                cut = fr + 1;
                break;
            }
        }
        let collect = taken < keep;
        let mut c = 0usize;
        for (&r, &i) in rank.iter().zip(order) {
            let r = r as usize;
            if r < cut {
                if let Some(k) = self.kept.get_mut(i as usize) {
                    *k = true;
                }
            } else if collect && r == cut {
                if let Some(h) = head.get_mut(c) {
                    *h = i;
                }
                c += 1;
            }
        }
        (taken, c)
    }

    /// Crowding distance (eq. 10-12) over the `len` members of the cut front in
    /// `head[s..s + len]`, on the active objectives; keeps the `need` most isolated
    /// (ties: lower index).
    fn crowd_cut(&mut self, s: usize, len: usize, need: usize, act: &[usize], obj_w: f32) {
        let fit = &self.fit;
        let Some(members) = self.head.get_mut(s..s + len) else {
            return;
        };
        for &i in members.iter() {
            if let Some(c) = self.crowd.get_mut(i as usize) {
                *c = 0;
            }
        }
        let boundary = f32::MAX.to_bits();
        for &j in act {
            // Ascending by `f_j`, ties by index.
            let fj = |i: u32| {
                fit.get(i as usize)
                    .and_then(|r| r.get(j))
                    .copied()
                    .unwrap_or(0.0)
            };
            let Some(keys) = self.keys.get_mut(..members.len()) else {
                return;
            };
            for (k, &i) in keys.iter_mut().zip(members.iter()) {
                *k = (u64::from(ndsort::ordered_bits(fj(i))) << 32) | u64::from(i);
            }
            sort::sort_unstable(keys);
            for (m, &k) in members.iter_mut().zip(keys.iter()) {
                *m = k as u32;
            }
            let (Some(&lo), Some(&hi)) = (members.first(), members.last()) else {
                continue;
            };
            let span = fj(hi) - fj(lo);
            if span > 0.0 {
                for i in [lo, hi] {
                    if let Some(c) = self.crowd.get_mut(i as usize) {
                        *c = boundary;
                    }
                }
                for w in members.windows(3) {
                    let (prev, i, next) = (w[0], w[1], w[2]);
                    if let Some(c) = self.crowd.get_mut(i as usize) {
                        if *c < boundary {
                            let d = fj(next) - fj(prev);
                            *c = (f32::from_bits(*c) + obj_w * d / span).to_bits();
                        }
                    }
                }
            }
        }
        if need == 0 || need > len {
            return;
        }
        // Most isolated first, ties by index: keys `!crowd << 32 | i`.
        let Some(keys) = self.keys.get_mut(..members.len()) else {
            return;
        };
        for (k, &i) in keys.iter_mut().zip(members.iter()) {
            let c = self.crowd.get(i as usize).copied().unwrap_or(0);
            *k = (u64::from(!c) << 32) | u64::from(i);
        }
        sort::select_nth_unstable(keys, need - 1);
        for &k in keys.iter().take(need) {
            if let Some(kept) = self.kept.get_mut(k as u32 as usize) {
                *kept = true;
            }
        }
    }
}
