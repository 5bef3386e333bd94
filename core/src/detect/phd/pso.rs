//! Multi-objective particle swarm step (Pei et al. 2019, §2.1 and §2.3 step 3) with the
//! NSGA-II machinery: fast non-dominated sorting in O(N) memory, weighted crowding
//! distance (eq. 10-12), elitist selection, the three-part mutation, the stop rule.
//!
//! All objectives are **maximised** (fitness values in `[0, 1]`).
//!
//! Non-dominated sorting uses ENS-BS (Zhang, Tian, Cheng, Jin, "An efficient approach to
//! nondominated sorting for evolutionary multiobjective optimization", IEEE TEVC 2015):
//! solutions are visited in lexicographic order (so none can be dominated by a later
//! one), and each is placed by binary search over the fronts found so far, checking the
//! members of a front newest first. Fronts are kept as linked lists through one `next`
//! array, so memory is O(N) (no N^2 domination lists); the worst-case time is
//! O(M N^2), typical O(M N log N).

#![allow(clippy::needless_range_loop)]

use crate::math;
use crate::rng::Rng;

const NONE: u32 = u32::MAX;

/// `a` dominates `b` (maximisation): `a >= b` in every objective, `>` in at least one.
#[inline]
pub fn dominates(a: &[f32], b: &[f32]) -> bool {
    let mut strict = false;
    for (x, y) in a.iter().zip(b) {
        if x < y {
            return false;
        }
        strict |= x > y;
    }
    strict
}

/// Lexicographic "better first" order on objective vectors (descending).
#[inline]
fn lex_desc(a: &[f32], b: &[f32]) -> core::cmp::Ordering {
    for (x, y) in a.iter().zip(b) {
        match y.partial_cmp(x) {
            Some(core::cmp::Ordering::Equal) | None => continue,
            Some(o) => return o,
        }
    }
    core::cmp::Ordering::Equal
}

/// ENS-BS non-dominated sort of `f[..n]` (first `m` objectives of each row, maximised).
///
/// Writes the front index (0 = non-dominated) of each solution into `rank[..n]` and
/// returns the number of fronts. Workspace: `order`, `next`, `head` of length `>= n`.
/// Objective values must be finite (NaN compares as "equal" and does not panic).
pub fn non_dominated_sort<const M: usize>(
    f: &[[f32; M]],
    m: usize,
    rank: &mut [u32],
    order: &mut [u32],
    next: &mut [u32],
    head: &mut [u32],
) -> usize {
    let n = f
        .len()
        .min(rank.len())
        .min(order.len())
        .min(next.len())
        .min(head.len());
    let m = m.min(M);
    for (i, o) in order[..n].iter_mut().enumerate() {
        *o = i as u32;
    }
    order[..n].sort_unstable_by(|&a, &b| {
        lex_desc(&f[a as usize][..m], &f[b as usize][..m]).then(a.cmp(&b))
    });
    let mut fronts = 0usize;
    for k in 0..n {
        let s = order[k] as usize;
        let fs = &f[s][..m];
        // Is s dominated by some member of front `j`?
        let dominated_by = |j: usize, head: &[u32], next: &[u32]| {
            let mut t = head[j];
            while t != NONE {
                if dominates(&f[t as usize][..m], fs) {
                    return true;
                }
                t = next[t as usize];
            }
            false
        };
        // First front (lo) whose members do not dominate s; monotone in j.
        let (mut lo, mut hi) = (0usize, fronts);
        while lo < hi {
            let mid = (lo + hi) / 2;
            if dominated_by(mid, head, next) {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        if lo == fronts {
            head[fronts] = NONE;
            fronts += 1;
        }
        next[s] = head[lo];
        head[lo] = s as u32;
        rank[s] = lo as u32;
    }
    fronts
}

/// Weighted crowding distance (eq. 10-12): per front and objective `j`, sorted by
/// `f_j`, the two ends get `boundary` and inner solutions get
/// `sum_j W_j (f_j[next] - f_j[prev]) / (f_j,max - f_j,min)` (a zero span adds nothing).
///
/// `order` is a workspace of length `>= n`.
pub fn crowding_distance<const M: usize>(
    f: &[[f32; M]],
    m: usize,
    weights: &[f32],
    rank: &[u32],
    boundary: f32,
    crowd: &mut [f32],
    order: &mut [u32],
) {
    let n = f.len().min(rank.len()).min(crowd.len()).min(order.len());
    let m = m.min(M).min(weights.len());
    for c in crowd[..n].iter_mut() {
        *c = 0.0;
    }
    for j in 0..m {
        for (i, o) in order[..n].iter_mut().enumerate() {
            *o = i as u32;
        }
        order[..n].sort_unstable_by(|&a, &b| {
            rank[a as usize].cmp(&rank[b as usize]).then(
                f[a as usize][j]
                    .partial_cmp(&f[b as usize][j])
                    .unwrap_or(core::cmp::Ordering::Equal),
            )
        });
        let mut s = 0usize;
        while s < n {
            let r = rank[order[s] as usize];
            let mut e = s;
            while e < n && rank[order[e] as usize] == r {
                e += 1;
            }
            let lo = f[order[s] as usize][j];
            let hi = f[order[e - 1] as usize][j];
            let span = hi - lo;
            crowd[order[s] as usize] = boundary;
            crowd[order[e - 1] as usize] = boundary;
            if span > 0.0 {
                for k in s + 1..e.saturating_sub(1) {
                    let i = order[k] as usize;
                    if crowd[i] < boundary {
                        let d = f[order[k + 1] as usize][j] - f[order[k - 1] as usize][j];
                        crowd[i] += weights[j] * d / span;
                    }
                }
            }
            s = e;
        }
    }
}

/// PSO settings (eq. 8-9, 18-19 and the stop rule).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PsoConfig {
    /// Generations run every frame, `gen` (paper: 10). §3.1: "after the iteration count
    /// is reached, the fitness threshold is the final condition for ending the
    /// optimisation", so the threshold is checked only once `gen` generations ran.
    pub generations: usize,
    /// After `generations`, continue while the swarm's mean best-objective fitness is
    /// below this, `Th_pso` (0.7).
    pub threshold: f32,
    /// Hard cap on generations per frame (ours: bounded work per frame; the paper has
    /// none). Values below `generations` are treated as `generations`.
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
    /// Half width (m) of the uniform mutation increments.
    pub mutation: f32,
    /// Number of measurement-derived points `Z_m` (objectives), at most the capacity `M`.
    pub points: usize,
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
        }
    }
}

/// Swarm workspace for up to `S / 2` particles (parents plus children fill `S`) and `M`
/// objectives. Memory is O(S M).
#[derive(Debug, Clone)]
pub struct Swarm<const S: usize, const M: usize> {
    /// Position (x, y) per entry.
    pub pos: [[f32; 2]; S],
    vel: [[f32; 2]; S],
    pbest: [[f32; 2]; S],
    pbest_fit: [f32; S],
    /// Objective values per entry.
    pub fit: [[f32; M]; S],
    /// PHD weight carried from parent to child.
    pub weight: [f32; S],
    /// Filter particle each entry descends from.
    pub src: [u32; S],
    /// Selection group of each entry (the caller's target group; children inherit it).
    group: [u16; S],
    rank: [u32; S],
    crowd: [f32; S],
    order: [u32; S],
    next: [u32; S],
    head: [u32; S],
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

impl<const S: usize, const M: usize> Default for Swarm<S, M> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const S: usize, const M: usize> Swarm<S, M> {
    /// Zeroed workspace.
    pub const fn new() -> Self {
        Self {
            pos: [[0.0; 2]; S],
            vel: [[0.0; 2]; S],
            pbest: [[0.0; 2]; S],
            pbest_fit: [0.0; S],
            fit: [[0.0; M]; S],
            weight: [0.0; S],
            src: [0; S],
            group: [0; S],
            rank: [0; S],
            crowd: [0.0; S],
            order: [0; S],
            next: [0; S],
            head: [0; S],
            len: 0,
        }
    }

    /// Parent capacity `S / 2`.
    pub const fn capacity() -> usize {
        S / 2
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
        if self.len >= S / 2 {
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
    fn evaluate(&mut self, i: usize, points: &[[f32; 2]], inv_two_s2: f32, floor: f32) -> f32 {
        let p = self.pos[i];
        let mut total = 0.0;
        for (m, z) in points.iter().enumerate().take(M) {
            let dx = p[0] - z[0];
            let dy = p[1] - z[1];
            let v = math::exp(-(dx * dx + dy * dy) * inv_two_s2);
            // Values below the floor are set to 0: far points then tie exactly, so the
            // sort decomposes per point (few, short fronts instead of one huge one).
            let v = if v < floor { 0.0 } else { v };
            self.fit[i][m] = v;
            total += v;
        }
        if !points.is_empty() {
            total /= points.len().min(M) as f32;
        }
        if total > self.pbest_fit[i] {
            self.pbest_fit[i] = total;
            self.pbest[i] = p;
        }
        total
    }

    /// Best objective index and value of entry `i`.
    #[inline]
    pub fn best_objective(&self, i: usize, m: usize) -> (usize, f32) {
        let mut best = (0usize, f32::NEG_INFINITY);
        for (j, &v) in self.fit[i][..m.min(M)].iter().enumerate() {
            if v > best.1 {
                best = (j, v);
            }
        }
        best
    }

    /// Runs the multi-objective PSO on the parents `0..len` towards `points`:
    /// per generation, children by eq. 8-9 plus mutation (entry `i % 3`: 0 unchanged,
    /// 1 one common uniform increment, 2 an own uniform increment), fitness eq. 18-19,
    /// merge, non-dominated sort, weighted crowding, keep the best `len` by
    /// (front, crowding). Runs `generations`, then continues while the mean
    /// best-objective fitness is below `threshold`, at most `max_generations` in all. Weights ride along; the caller renormalises.
    pub fn run(&mut self, cfg: &PsoConfig, points: &[[f32; 2]], rng: &mut Rng) -> SwarmReport {
        let n = self.len;
        let m = points.len().min(M);
        if n == 0 || m == 0 {
            return SwarmReport::default();
        }
        let inv_two_s2 = 1.0 / (2.0 * cfg.fitness_scale * cfg.fitness_scale);
        let mut mean_best = 0.0f32;
        for i in 0..n {
            self.evaluate(i, points, inv_two_s2, cfg.gate);
            mean_best += self.best_objective(i, m).1;
        }
        mean_best /= n as f32;
        let obj_w = [1.0f32 / m as f32; M];
        let mut gens = 0usize;
        let cap = cfg.max_generations.max(cfg.generations);
        while gens < cap && (gens < cfg.generations || mean_best < cfg.threshold) {
            gens += 1;
            // Leaders: per objective, the front-0 entry with the highest value.
            let fronts = non_dominated_sort(
                &self.fit[..n],
                m,
                &mut self.rank[..n],
                &mut self.order[..n],
                &mut self.next[..n],
                &mut self.head[..n],
            );
            let _ = fronts;
            let mut leader = [0usize; M];
            let mut lval = [f32::NEG_INFINITY; M];
            for i in 0..n {
                if self.rank[i] == 0 {
                    for j in 0..m {
                        if self.fit[i][j] > lval[j] {
                            lval[j] = self.fit[i][j];
                            leader[j] = i;
                        }
                    }
                }
            }
            let common = [
                rng.uniform_range(-cfg.mutation, cfg.mutation),
                rng.uniform_range(-cfg.mutation, cfg.mutation),
            ];
            for i in 0..n {
                let c = n + i;
                let g = self.pos[leader[self.best_objective(i, m).0]];
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
                self.evaluate(c, points, inv_two_s2, cfg.gate);
            }
            // Elitist selection over parents + children.
            let tot = 2 * n;
            non_dominated_sort(
                &self.fit[..tot],
                m,
                &mut self.rank[..tot],
                &mut self.order[..tot],
                &mut self.next[..tot],
                &mut self.head[..tot],
            );
            crowding_distance(
                &self.fit[..tot],
                m,
                &obj_w[..m],
                &self.rank[..tot],
                f32::MAX,
                &mut self.crowd[..tot],
                &mut self.order[..tot],
            );
            {
                let (rank, crowd, group) = (&self.rank, &self.crowd, &self.group);
                self.order[..tot].sort_unstable_by(|&a, &b| {
                    let (a, b) = (a as usize, b as usize);
                    group[a]
                        .cmp(&group[b])
                        .then(rank[a].cmp(&rank[b]))
                        .then(
                            crowd[b]
                                .partial_cmp(&crowd[a])
                                .unwrap_or(core::cmp::Ordering::Equal),
                        )
                        .then(a.cmp(&b))
                });
            }
            // Per group, keep the best `parents of the group` entries (a global cut
            // would keep the groups whose fronts are wide, i.e. targets near several
            // points, and drop the others' particles: measured, a target with one
            // point lost 99.9 % of its swarm entries in one frame). Every parent and
            // child of group g sits in the contiguous run of g in `order`, and the run
            // holds twice the group's parents, so `kept` ends at n.
            let mut kept = 0usize;
            let mut s0 = 0usize;
            while s0 < tot {
                let gi = self.group[self.order[s0] as usize];
                let mut e0 = s0;
                while e0 < tot && self.group[self.order[e0] as usize] == gi {
                    e0 += 1;
                }
                let keep = (e0 - s0) / 2;
                for t in s0..s0 + keep {
                    self.order[kept] = self.order[t];
                    kept += 1;
                }
                s0 = e0;
            }
            // Compacted in ascending index order (safe forward copy).
            self.order[..kept].sort_unstable();
            mean_best = 0.0;
            for k in 0..n {
                let s = self.order[k] as usize;
                self.pos[k] = self.pos[s];
                self.vel[k] = self.vel[s];
                self.pbest[k] = self.pbest[s];
                self.pbest_fit[k] = self.pbest_fit[s];
                self.fit[k] = self.fit[s];
                self.weight[k] = self.weight[s];
                self.src[k] = self.src[s];
                self.group[k] = self.group[s];
                mean_best += self.best_objective(k, m).1;
            }
            mean_best /= n as f32;
        }
        SwarmReport {
            generations: gens,
            mean_fitness: mean_best,
        }
    }
}
