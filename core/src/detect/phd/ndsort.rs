//! Non-dominated sorting, exact and in O(N) memory (no N^2 domination lists), for the
//! PSO step ([`super::pso`]), objectives **maximised**:
//!
//! - [`non_dominated_sort`] (any number of objectives): ENS-BS (Zhang, Tian, Cheng, Jin,
//!   "An efficient approach to nondominated sorting for evolutionary multiobjective
//!   optimization", IEEE TEVC 2015): solutions are visited in lexicographic order (so
//!   none can be dominated by a later one), and each is placed by binary search over the
//!   fronts found so far, checking the members of a front newest first; fronts are
//!   linked lists through one `next` array. Worst case O(M N^2); with at most two
//!   objectives only the newest member of a front needs checking, O(N log N).
//! - [`rank_sorted`]: divide-and-conquer sorting for many objectives and large fronts
//!   (Jensen 2003, "Reducing the run-time complexity of multiobjective EAs: the NSGA-II and
//!   other algorithms", IEEE TEVC 7(5); with the tie handling of Fortin, Grenier, Parizeau
//!   2013, "Generalizing the improved run-time complexity algorithm for non-dominated
//!   sorting", GECCO, and Buzdalov, Shalyto 2014, PPSN).
//!
//! ENS-BS ([`non_dominated_sort`]) compares a solution with every member of a
//! front it is not dominated by, so a front of `F` members costs `O(N F)`; with three or
//! more objectives the swarm's fronts hold most of a group (every particle inside the
//! triangle of three points is non-dominated), measured ~640 of ~980 entries per group.
//! [`rank_sorted`] is `O(N log^(k-1) N)` whatever the front sizes, in `O(N)` memory
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

use crate::sort;

/// The end of a front's linked list in [`ens_bs`].
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
/// With `m <= 2` only each front's newest member is checked (see `ens_bs`), so the
/// sort is O(N log N) whatever the front sizes.
pub fn non_dominated_sort<const OBJECTIVES: usize>(
    f: &[[f32; OBJECTIVES]],
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
    let m = m.min(OBJECTIVES);
    for (i, o) in order[..n].iter_mut().enumerate() {
        *o = i as u32;
    }
    sort::sort_unstable_by(&mut order[..n], |&a, &b| {
        match (f.get(a as usize), f.get(b as usize)) {
            (Some(fa), Some(fb)) => lex_desc(&fa[..m], &fb[..m]),
            _ => core::cmp::Ordering::Equal,
        }
        .then(a.cmp(&b))
    });
    ens_bs(&order[..n], m <= 2, rank, next, head, |a, b| {
        match (f.get(a), f.get(b)) {
            (Some(fa), Some(fb)) => dominates(&fa[..m], &fb[..m]),
            _ => false,
        }
    })
}

/// Front assignment of ENS-BS. `order` lists solution ids best first in lexicographic
/// order (so no solution is dominated by a later one); `dom(a, b)`: `a` dominates `b`.
/// `rank` and `next` are indexed by solution id, `head[..order.len()]` by front; fronts
/// are linked lists (newest first) through `next`. Returns the number of fronts.
///
/// `newest_only` (valid for at most two objectives): in lexicographic order the members
/// of one front have non-increasing `f_1` and non-decreasing `f_2`, so a later solution
/// is dominated by some member iff it is dominated by the newest one.
pub(crate) fn ens_bs(
    order: &[u32],
    newest_only: bool,
    rank: &mut [u32],
    next: &mut [u32],
    head: &mut [u32],
    dom: impl Fn(usize, usize) -> bool,
) -> usize {
    let mut fronts = 0usize;
    for &s in order {
        let s = s as usize;
        // Is s dominated by some member of front `j`?
        let dominated_by = |j: usize, head: &[u32], next: &[u32]| {
            let mut t = head.get(j).copied().unwrap_or(NONE);
            while t != NONE {
                if dom(t as usize, s) {
                    return true;
                }
                if newest_only {
                    return false;
                }
                t = next.get(t as usize).copied().unwrap_or(NONE);
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
            if let Some(h) = head.get_mut(fronts) {
                *h = NONE;
            }
            fronts += 1;
        }
        if let (Some(h), Some(nx)) = (head.get_mut(lo), next.get_mut(s)) {
            *nx = *h;
            *h = s as u32;
        }
        if let Some(r) = rank.get_mut(s) {
            *r = lo as u32;
        }
    }
    fronts
}

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
/// Writes `rank[..n]` (by position) and returns the number of fronts. Values should be
/// finite; a NaN gives some ranks, never an unbounded recursion (a split that separates
/// nothing falls back to comparing all pairs).
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
        for (p, (x, o)) in sc.iter_mut().zip(order1.iter_mut()).enumerate() {
            *x = p as u32;
            *o = !ordered_bits(val(p, 1));
        }
        // Ties by position: a total order (the dense ranks do not depend on it).
        crate::sort::sort_unstable_by_key(sc, |&p| {
            (order1.get(p as usize).copied().unwrap_or(u32::MAX), p)
        });
        // Keys to dense ranks in place (the previous key is kept before overwriting).
        let mut d = 0u32;
        let mut prev = sc
            .first()
            .and_then(|&p| order1.get(p as usize))
            .copied()
            .unwrap_or(0);
        for &p in sc.iter() {
            if let Some(o) = order1.get_mut(p as usize) {
                if *o != prev {
                    d += 1;
                    prev = *o;
                }
                *o = d;
            }
        }
    }
    // Unique vectors only; duplicates copy their first copy's rank afterwards.
    let mut u = 0usize;
    for (p, (r, f)) in rank.iter_mut().zip(fenwick.iter_mut()).take(n).enumerate() {
        *r = 0;
        *f = 0;
        if p == 0 || !equal_prev(p) {
            if let Some(w) = work.get_mut(u) {
                *w = p as u32;
            }
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
    ctx.helper_a(work.get_mut(..u).unwrap_or(&mut []), k);
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
        let Some(&r) = self.rank.get(from as usize) else {
            return;
        };
        if let Some(t) = self.rank.get_mut(h as usize) {
            if r + 1 > *t {
                *t = r + 1;
            }
        }
    }

    /// Ranks of `h` raised from `l` by comparing all pairs; `l == h` (one list, in
    /// position order) ranks within it: every earlier solution's rank is final when used.
    fn all_pairs(&mut self, l: &[u32], h: &[u32], k: usize) {
        let same = core::ptr::eq(l, h);
        for (i, &hh) in h.iter().enumerate() {
            let from = if same { l.get(..i).unwrap_or(&[]) } else { l };
            for &ll in from {
                if self.weakly(ll, hh, k) {
                    self.raise(hh, ll);
                }
            }
        }
    }

    fn helper_a(&mut self, s: &mut [u32], k: usize) {
        let n = s.len();
        if n < 2 {
            return;
        }
        if k <= 1 || n <= SMALL {
            self.all_pairs(s, s, k);
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
        if nb == 0 || nb >= n {
            // No split (only with NaN values: a finite pivot always separates the
            // maximum from a sampled value): the stable partition left `s` as it was;
            // all pairs, so the recursion always shrinks.
            self.all_pairs(s, s, k);
            return;
        }
        if let Some((b, w)) = s.split_at_mut_checked(nb) {
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
            self.all_pairs(l, h, k);
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
        if (nl == 0 && nh == 0) || (nl >= l.len() && nh >= h.len()) {
            // No split (NaN values only): both lists are unchanged; all pairs.
            self.all_pairs(l, h, k);
            return;
        }
        if let (Some((l1, l2)), Some((h1, h2))) =
            (l.split_at_mut_checked(nl), h.split_at_mut_checked(nh))
        {
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
                while let Some(&lp) = l.get(next_l).filter(|&&lp| self.v(lp, 0) >= x0) {
                    let p = lp as usize;
                    if let (Some(&o), Some(&r)) = (self.order1.get(p), self.rank.get(p)) {
                        fenwick_set(self.fenwick, o as usize, r + 1);
                    }
                    next_l += 1;
                }
            }
            // In one lexicographic list every earlier solution has objective 0 `>=`.
            let (Some(&at), Some(r)) =
                (self.order1.get(hh as usize), self.rank.get_mut(hh as usize))
            else {
                continue;
            };
            let at = at as usize;
            let best = fenwick_max(self.fenwick, at + 1);
            if best > *r {
                *r = best;
            }
            if same {
                let r = *r;
                fenwick_set(self.fenwick, at, r + 1);
            }
        }
        let inserted = if same {
            h
        } else {
            l.get(..next_l).unwrap_or(l)
        };
        for &p in inserted {
            if let Some(&o) = self.order1.get(p as usize) {
                fenwick_clear(self.fenwick, o as usize);
            }
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
            let p = match a.get(i) {
                Some(&p) => p,
                None => b.get(i - a.len()).copied().unwrap_or(0),
            };
            let x = ordered_bits(self.v(p, o));
            if let Some(slot) = self.scratch.get_mut(t) {
                *slot = x;
            }
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
            let si = s[i];
            let x = self.v(si, o);
            if x > p || (ge && x >= p) {
                // w <= i
                if let Some(d) = s.get_mut(w) {
                    *d = si;
                }
                w += 1;
            } else {
                if let Some(d) = self.scratch.get_mut(c) {
                    *d = si;
                }
                c += 1;
            }
        }
        // w + c == s.len()
        if let (Some(d), Some(src)) = (s.get_mut(w..), self.scratch.get(..c)) {
            if d.len() == src.len() {
                d.copy_from_slice(src);
            }
        }
        w
    }

    /// Merges the ascending runs `s[..mid]` and `s[mid..]`.
    fn merge(&mut self, s: &mut [u32], mid: usize) {
        let (Some(dst), Some(src)) = (self.scratch.get_mut(..mid), s.get(..mid)) else {
            return;
        };
        dst.copy_from_slice(src);
        let (mut i, mut j, mut o) = (0usize, mid, 0usize);
        while let Some(&x) = self.scratch.get(i).filter(|_| i < mid) {
            let v = match s.get(j) {
                Some(&y) if y < x => {
                    j += 1;
                    y
                }
                _ => {
                    i += 1;
                    x
                }
            };
            // o < j <= s.len()
            if let Some(d) = s.get_mut(o) {
                *d = v;
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
        if let Some(&x) = t.get(i - 1) {
            m = m.max(x);
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
    let mut i = at.saturating_add(1);
    // i >= 1 and strictly increasing
    while i <= t.len() {
        if let Some(x) = t.get_mut(i - 1) {
            *x = 0;
        }
        i += i & i.wrapping_neg();
    }
}

/// Raises entry `at` of a Fenwick prefix-maximum tree to at least `v`.
#[inline]
fn fenwick_set(t: &mut [u32], at: usize, v: u32) {
    let mut i = at.saturating_add(1);
    // i >= 1 and strictly increasing
    while i <= t.len() {
        if let Some(x) = t.get_mut(i - 1) {
            if *x < v {
                *x = v;
            }
        }
        i += i & i.wrapping_neg();
    }
}
