//! Divide-and-conquer non-dominated sorting for many objectives and large fronts
//! (Jensen 2003, "Reducing the run-time complexity of multiobjective EAs: the NSGA-II and
//! other algorithms", IEEE TEVC 7(5); with the tie handling of Fortin, Grenier, Parizeau
//! 2013, "Generalizing the improved run-time complexity algorithm for non-dominated
//! sorting", GECCO, and Buzdalov, Shalyto 2014, PPSN).
//!
//! ENS-BS ([`super::pso::non_dominated_sort`]) compares a solution with every member of a
//! front it is not dominated by, so a front of `F` members costs `O(N F)`; with three or
//! more objectives the swarm's fronts hold most of a group (every particle inside the
//! triangle of three points is non-dominated), measured ~640 of ~980 entries per group.
//! This algorithm is `O(N log^(k-1) N)` whatever the front sizes, in `O(N)` memory
//! (four caller arrays, recursion depth `O(k log N)`), and gives the same ranks.
//!
//! Objectives are **maximised**. Solutions are addressed by their position `p` in the
//! caller's lexicographically descending order (so no solution dominates an earlier one);
//! duplicates (equal vectors) get the rank of their first copy.
//! `rank(s) = 1 + max { rank(t) : t dominates s }` (0 if none) is computed with:
//! - `helper_a(S, k)`: ranks within `S`, whose objectives `>= k` are constant: split `S`
//!   at the median of objective `k - 1` into the better half `B` and the worse `W`, then
//!   `helper_a(B, k)`, `helper_b(B, W, k - 1)`, `helper_a(W, k)`;
//! - `helper_b(L, H, k)`: ranks of `H` raised by the (final) ranks of `L`, where every
//!   `l` is `>=` every `h` on objectives `>= k`: split both at a common median of
//!   objective `k - 1` and recurse on (upper L, upper H, k), (upper L, lower H, k - 1),
//!   (lower L, lower H, k);
//! - two objectives: a sweep in objective 0 with a Fenwick tree (prefix maximum of rank)
//!   over the ranks of objective 1.
//!
//! Every helper leaves its index lists in ascending position order on return (stable
//! partitions, merged back), so sub-lists stay lexicographically sorted.

/// Below this many pairs, `helper_b` compares all pairs; below this many solutions,
/// `helper_a` does.
const SMALL: usize = 8;

/// The `u32` workspaces of [`rank_sorted`], each of length `>= n` (shorter slices
/// restrict `n`); their contents on entry do not matter.
#[derive(Debug)]
pub struct Workspace<'a> {
    /// Index lists of the recursion.
    pub work: &'a mut [u32],
    /// Partitions, merges, pivots.
    pub scratch: &'a mut [u32],
    /// Dense descending rank of objective 1 per position.
    pub order1: &'a mut [u32],
    /// Fenwick tree of the two-objective sweeps.
    pub fenwick: &'a mut [u32],
}

/// Ranks (front index, 0 = non-dominated) of `n` solutions given in lexicographically
/// descending order of their objective vectors `val(p, 0..k)` (position 0 first).
///
/// Writes `rank[..n]` (by position) and returns the number of fronts. Values must be
/// finite.
pub fn rank_sorted<V: Fn(usize, usize) -> f32>(
    n: usize,
    k: usize,
    val: V,
    rank: &mut [u32],
    ws: Workspace<'_>,
) -> usize {
    let Workspace {
        work,
        scratch,
        order1,
        fenwick,
    } = ws;
    let n = n
        .min(rank.len())
        .min(work.len())
        .min(scratch.len())
        .min(order1.len())
        .min(fenwick.len());
    if n == 0 {
        return 0;
    }
    let equal_prev = |p: usize| (0..k).all(|j| val(p, j) == val(p - 1, j));
    // Dense descending rank of objective 1 (0 = largest), the sweeps' Fenwick index.
    if k >= 2 {
        let sc = &mut scratch[..n];
        for (p, x) in sc.iter_mut().enumerate() {
            *x = p as u32;
            order1[p] = !ordered_bits(val(p, 1));
        }
        // Ties by position: a total order (the dense ranks do not depend on it).
        crate::sort::sort_unstable_by_key(sc, |&p| {
            (order1.get(p as usize).copied().unwrap_or(u32::MAX), p)
        });
        // Keys to dense ranks in place (the previous key is kept before overwriting).
        let mut d = 0u32;
        let mut prev = order1[sc[0] as usize];
        for &p in sc.iter() {
            let key = order1[p as usize];
            if key != prev {
                d += 1;
                prev = key;
            }
            order1[p as usize] = d;
        }
    }
    // Unique vectors only; duplicates copy their first copy's rank afterwards.
    let mut u = 0usize;
    for p in 0..n {
        rank[p] = 0;
        fenwick[p] = 0;
        if p == 0 || !equal_prev(p) {
            work[u] = p as u32;
            u += 1;
        }
    }
    let mut ctx = Ctx {
        val: &val,
        rank: &mut rank[..n],
        scratch: &mut scratch[..n],
        order1: &order1[..n],
        fenwick: &mut fenwick[..n],
    };
    ctx.helper_a(&mut work[..u], k);
    let mut fronts = 0u32;
    for p in 0..n {
        if p > 0 && equal_prev(p) {
            rank[p] = rank[p - 1];
        }
        fronts = fronts.max(rank[p] + 1);
    }
    fronts as usize
}

struct Ctx<'a, V> {
    val: &'a V,
    rank: &'a mut [u32],
    scratch: &'a mut [u32],
    order1: &'a [u32],
    /// All zero between sweeps (each sweep clears what it set).
    fenwick: &'a mut [u32],
}

impl<V: Fn(usize, usize) -> f32> Ctx<'_, V> {
    #[inline]
    fn v(&self, p: u32, j: usize) -> f32 {
        (self.val)(p as usize, j)
    }

    /// `a >= b` on objectives `0..k` (with distinct vectors and the helpers'
    /// preconditions on the others: `a` dominates `b`).
    #[inline]
    fn weakly(&self, a: u32, b: u32, k: usize) -> bool {
        (0..k).all(|j| self.v(a, j) >= self.v(b, j))
    }

    #[inline]
    fn raise(&mut self, h: u32, from: u32) {
        let r = self.rank[from as usize] + 1;
        let t = &mut self.rank[h as usize];
        if r > *t {
            *t = r;
        }
    }

    fn helper_a(&mut self, s: &mut [u32], k: usize) {
        let n = s.len();
        if n < 2 {
            return;
        }
        if k <= 1 || n <= SMALL {
            // Position order: every earlier solution's rank is final when used.
            for i in 1..n {
                for j in 0..i {
                    if self.weakly(s[j], s[i], k) {
                        self.raise(s[i], s[j]);
                    }
                }
            }
            return;
        }
        if k == 2 {
            self.sweep(s, s, true);
            return;
        }
        let o = k - 1;
        let (mn, mx) = self.range(s, o);
        if mn == mx {
            self.helper_a(s, k - 1);
            return;
        }
        let (p, ge) = self.pivot(s, &[], o, mx);
        let nb = self.partition(s, o, p, ge);
        {
            let (b, w) = s.split_at_mut(nb);
            self.helper_a(b, k);
            self.helper_b(b, w, k - 1);
            self.helper_a(w, k);
        }
        self.merge(s, nb);
    }

    fn helper_b(&mut self, l: &mut [u32], h: &mut [u32], k: usize) {
        if l.is_empty() || h.is_empty() {
            return;
        }
        if k <= 1 || l.len() * h.len() <= SMALL * SMALL {
            for &hh in h.iter() {
                for &ll in l.iter() {
                    if self.weakly(ll, hh, k) {
                        self.raise(hh, ll);
                    }
                }
            }
            return;
        }
        if k == 2 {
            self.sweep(l, h, false);
            return;
        }
        let o = k - 1;
        let (mnl, mxl) = self.range(l, o);
        let (mnh, mxh) = self.range(h, o);
        if mnl >= mxh {
            self.helper_b(l, h, k - 1);
            return;
        }
        if mxl < mnh {
            return;
        }
        let (p, ge) = self.pivot(l, h, o, if mxl > mxh { mxl } else { mxh });
        let nl = self.partition(l, o, p, ge);
        let nh = self.partition(h, o, p, ge);
        {
            let (l1, l2) = l.split_at_mut(nl);
            let (h1, h2) = h.split_at_mut(nh);
            self.helper_b(l1, h1, k);
            self.helper_b(l1, h2, k - 1);
            self.helper_b(l2, h2, k);
        }
        self.merge(l, nl);
        self.merge(h, nh);
    }

    /// Two objectives. `same`: `l` and `h` are one list (ranks within it, `helper_a`);
    /// otherwise the ranks of `h` are raised from `l`. Walks in objective 0 (position
    /// order, `l` before `h` at ties) with a Fenwick tree of `rank + 1` indexed by the
    /// dense descending rank of objective 1, so `val1(t) >= val1(h)` is a prefix.
    fn sweep(&mut self, l: &[u32], h: &[u32], same: bool) {
        let mut next_l = 0usize;
        for &hh in h {
            if !same {
                let x0 = self.v(hh, 0);
                while next_l < l.len() && self.v(l[next_l], 0) >= x0 {
                    let p = l[next_l] as usize;
                    fenwick_set(self.fenwick, self.order1[p] as usize, self.rank[p] + 1);
                    next_l += 1;
                }
            }
            // In one lexicographic list every earlier solution has objective 0 `>=`.
            let at = self.order1[hh as usize] as usize;
            let best = fenwick_max(self.fenwick, at + 1);
            if best > self.rank[hh as usize] {
                self.rank[hh as usize] = best;
            }
            if same {
                fenwick_set(self.fenwick, at, self.rank[hh as usize] + 1);
            }
        }
        let inserted = if same { h } else { &l[..next_l] };
        for &p in inserted {
            fenwick_clear(self.fenwick, self.order1[p as usize] as usize);
        }
    }

    fn range(&self, s: &[u32], o: usize) -> (f32, f32) {
        let mut mn = f32::INFINITY;
        let mut mx = f32::NEG_INFINITY;
        for &p in s {
            let x = self.v(p, o);
            if x < mn {
                mn = x;
            }
            if x > mx {
                mx = x;
            }
        }
        (mn, mx)
    }

    /// Pivot on objective `o` over `a` and `b`: the median (up to 64 values) or the median
    /// of 15 evenly spaced values, and whether the split must be `>=` (nothing above
    /// the pivot) so that both sides are non-empty.
    fn pivot(&mut self, a: &[u32], b: &[u32], o: usize, mx: f32) -> (f32, bool) {
        let n = a.len() + b.len();
        let take = if n <= 64 { n } else { 15 };
        for t in 0..take {
            let i = t * n / take;
            let p = if i < a.len() { a[i] } else { b[i - a.len()] };
            self.scratch[t] = ordered_bits(self.v(p, o));
        }
        let mid = take / 2;
        let m = match self.scratch.get_mut(..take) {
            Some(sc) => {
                crate::sort::select_nth_unstable(sc, mid);
                sc.get(mid).copied().unwrap_or(0)
            }
            None => 0,
        };
        let m = from_ordered_bits(m);
        (m, mx <= m)
    }

    /// Stable partition of `s`: objective `o` above `p` (or `>= p`) first; returns the
    /// size of the first part.
    fn partition(&mut self, s: &mut [u32], o: usize, p: f32, ge: bool) -> usize {
        let mut w = 0usize;
        let mut c = 0usize;
        for i in 0..s.len() {
            let x = self.v(s[i], o);
            if x > p || (ge && x >= p) {
                s[w] = s[i];
                w += 1;
            } else {
                self.scratch[c] = s[i];
                c += 1;
            }
        }
        s[w..].copy_from_slice(&self.scratch[..c]);
        w
    }

    /// Merges the ascending runs `s[..mid]` and `s[mid..]`.
    fn merge(&mut self, s: &mut [u32], mid: usize) {
        self.scratch[..mid].copy_from_slice(&s[..mid]);
        let (mut i, mut j, mut o) = (0usize, mid, 0usize);
        while i < mid {
            if j < s.len() && s[j] < self.scratch[i] {
                s[o] = s[j];
                j += 1;
            } else {
                s[o] = self.scratch[i];
                i += 1;
            }
            o += 1;
        }
    }
}

/// Maximum of `t[0..q]` in a Fenwick (binary indexed) prefix-maximum tree.
#[inline]
fn fenwick_max(t: &[u32], q: usize) -> u32 {
    let mut i = q.min(t.len());
    let mut m = 0u32;
    while i > 0 {
        if t[i - 1] > m {
            m = t[i - 1];
        }
        i &= i - 1;
    }
    m
}

/// `f32` to `u32` with the order of `f32::total_cmp`.
#[inline]
pub(crate) fn ordered_bits(x: f32) -> u32 {
    let b = x.to_bits();
    if b >> 31 == 1 {
        !b
    } else {
        b | 0x8000_0000
    }
}

/// Inverse of [`ordered_bits`].
#[inline]
fn from_ordered_bits(b: u32) -> f32 {
    f32::from_bits(if b >> 31 == 1 { b & 0x7FFF_FFFF } else { !b })
}

/// Zeroes the entries [`fenwick_set`] touched for index `at`.
#[inline]
fn fenwick_clear(t: &mut [u32], at: usize) {
    let mut i = at + 1;
    while i <= t.len() {
        t[i - 1] = 0;
        i += i & i.wrapping_neg();
    }
}

/// Raises entry `at` of a Fenwick prefix-maximum tree to at least `v`.
#[inline]
fn fenwick_set(t: &mut [u32], at: usize, v: u32) {
    let mut i = at + 1;
    while i <= t.len() {
        if t[i - 1] < v {
            t[i - 1] = v;
        }
        i += i & i.wrapping_neg();
    }
}
