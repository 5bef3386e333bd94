//! Stage 2, plot censoring (Bao et al. 2022, §3.1): modified single-frame Hough transform
//! (MSHT, eq. 4), M-scan sliding-window collinearity (eq. 5) and velocity gate (eq. 6).
//!
//! The rule implemented: a plot `s_{k,m}` joins the effective set `S_ep` when, for some
//! window of `M` consecutive scans `n-M+1..=n` containing `m`, there is a chain of plots
//! `p_{n-M+1}, ..., p_n` (one per scan of the window, `p_m = s_{k,m}`) such that
//! 1. all of them lie on one Hough cell `(rho, theta)` (the cell is hit in every scan of
//!    the window: `P_n(rho, theta) != 0`, eq. 5), and
//! 2. each consecutive pair passes the gate `|p_j - p_{j+1}| <= V_max T_scan` (eq. 6).
//!
//! This is the paper's censoring with the chain reading of "plot pairs of a surviving cell
//! between consecutive scans" (a plot must be linked through the whole window, not only to
//! one neighbour scan). The MSHT's per-cell plot sets (eq. 4, Algorithm 1) are not stored:
//! the plots of the last `M` scans are kept and cell membership is recomputed from their
//! coordinates. Evaluation order is gate first, then collinearity: gated pairs between
//! consecutive scans are found with an x-sorted sweep (`O(P log P)`), chains are grown
//! through them, and each complete chain is tested for a common cell over the `A` angles.
//! The output set is identical to "AND the `M` hit bitmaps, then gate the plots of each
//! surviving cell" (`tests/mht_core.rs` checks it against that brute force), at a small
//! fraction of its cost in dense clutter, where almost every cell is hit in every scan.

use super::geometry::Geometry;
use crate::model::plot::Plot;
use crate::sort;

/// Largest supported window `M`.
pub const MAX_M: usize = 8;

/// Flag bit: the plot is in the effective set `S_ep`.
pub const FLAG_EFFECTIVE: u8 = 1;

/// Counters of one censoring step.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct CensorStats {
    /// Gated pairs between the previous scan and this one.
    pub pairs: u32,
    /// Pairs dropped because the pair list (capacity `P`) was full.
    pub pair_overflow: u32,
    /// Complete chains tested for a common cell.
    pub chains: u32,
    /// Chains not tested because the per-scan chain budget (or the budget of partial
    /// chains visited, [`NODE_BUDGET_PER_PLOT`] per plot) was spent.
    pub chain_overflow: u32,
    /// Plots newly marked effective by this step's window.
    pub newly_effective: u32,
}

/// Partial chains a step may visit per plot of capacity: bounds the search when the
/// gate admits almost every pair (a gate larger than the area makes the chains of a
/// window up to `P^(m-1)`; with the preset's gate a scan visits far fewer).
pub const NODE_BUDGET_PER_PLOT: u32 = 64;

/// Working memory of the censoring stage for scans of at most `P` plots.
#[derive(Debug, Clone)]
pub struct Censor<const P: usize> {
    /// x-sorted plot indices of the scans, ring by scan index mod 2.
    order: [[u16; P]; 2],
    /// Sort keys of the current scan, `(total-order bits of x) << 32 | index`.
    keys: [u64; P],
    /// Gated pairs `(prev, cur)` between scan `s-1` and `s`, ring by `s mod MAX_M`,
    /// sorted by `prev`.
    pairs: [[(u16, u16); P]; MAX_M],
    npairs: [u16; MAX_M],
    /// Chain budget per step (`4 P`), bounds the worst-case cost.
    chain_budget: u32,
}

impl<const P: usize> Default for Censor<P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const P: usize> Censor<P> {
    /// Compile-time check: plot indices fit the `u16` order and pair lists.
    const SHAPE: () = assert!(P <= u16::MAX as usize, "at most 65535 plots per scan");

    /// Empty working memory.
    pub const fn new() -> Self {
        let () = Self::SHAPE;
        Self {
            order: [[0; P]; 2],
            keys: [0; P],
            pairs: [[(0, 0); P]; MAX_M],
            npairs: [0; MAX_M],
            chain_budget: 4 * P as u32,
        }
    }

    /// Process scan `s` of the block (`scans[s]` holds its plots): find gated pairs with
    /// scan `s-1`, then, when `s >= m-1`, the chains of the window `s-m+1..=s`, marking
    /// the plots of every collinear chain effective in `flags`.
    ///
    /// `m` is in `3..=MAX_M` and `gate >= 0` for a config that validates; any other `m`,
    /// a NaN gate, or fewer than `s + 1` rows of `flags` finds nothing (empty stats,
    /// `flags` untouched). Pairs found on earlier calls refer to the plots of the same
    /// `scans`; a chain whose plot is no longer there is skipped.
    pub fn step<const R: usize, const A: usize>(
        &mut self,
        geom: &Geometry<R, A>,
        scans: &[&[Plot]],
        flags: &mut [[u8; P]],
        s: usize,
        m: usize,
        gate: f32,
    ) -> CensorStats {
        let () = Self::SHAPE;
        let mut st = CensorStats::default();
        if !(3..=MAX_M).contains(&m) || gate.is_nan() || flags.len() <= s {
            return st;
        }
        let Some(cur) = scans.get(s) else {
            return st;
        };
        let n = cur.len().min(P);
        // x-order of this scan
        // by x (`f32::total_cmp`), ties by index: one u64 per plot, a total order
        let keys = &mut self.keys[..n];
        for (i, (k, p)) in keys.iter_mut().zip(cur.iter()).enumerate() {
            *k = (u64::from(total_order_bits(p.x)) << 32) | i as u64;
        }
        sort::sort_unstable(keys);
        let ord = &mut self.order[s % 2];
        for (o, &k) in ord.iter_mut().zip(keys.iter()) {
            *o = k as u16;
        }
        let slot = s % MAX_M;
        self.npairs[slot] = 0;
        if s == 0 {
            return st;
        }
        // gated pairs with the previous scan
        let prev = scans[s - 1];
        let np = prev.len().min(P);
        let pord = &self.order[(s - 1) % 2][..np];
        let g2 = gate * gate;
        let list = &mut self.pairs[slot];
        let mut k = 0usize;
        for (qi, q) in cur.iter().enumerate().take(n) {
            // the order holds indices of `prev` only (`np <= prev.len()`)
            let lo = pord
                .partition_point(|&i| prev.get(usize::from(i)).is_some_and(|p| p.x < q.x - gate));
            for &pi in &pord[lo..] {
                let Some(p) = prev.get(usize::from(pi)) else {
                    continue;
                };
                if p.x > q.x + gate {
                    break;
                }
                if p.dist2(q) <= g2 {
                    if k < P {
                        list[k] = (pi, qi as u16);
                        k += 1;
                    } else {
                        st.pair_overflow += 1;
                    }
                }
            }
        }
        // (prev, cur) pairs are distinct: the order is total
        if let Some(found) = list.get_mut(..k) {
            sort::sort_unstable(found);
        }
        self.npairs[slot] = k as u16;
        st.pairs = k as u32;
        if s + 1 < m {
            return st;
        }
        // chains through the window s0..=s
        let s0 = s + 1 - m;
        let mut chain = [0u16; MAX_M];
        let mut pts = [(0i32, 0i32); MAX_M];
        let first = (s0 + 1) % MAX_M;
        let nfirst = usize::from(self.npairs[first]);
        // (completed chains, partial chains visited) still allowed in this step.
        let mut budget = (
            self.chain_budget,
            NODE_BUDGET_PER_PLOT.saturating_mul(P as u32),
        );
        for &(a, b) in self.pairs[first].iter().take(nfirst) {
            chain[0] = a;
            chain[1] = b;
            self.grow(
                geom,
                scans,
                flags,
                s0,
                m,
                2,
                &mut chain,
                &mut pts,
                &mut budget,
                &mut st,
            );
        }
        st
    }

    #[allow(clippy::too_many_arguments)]
    fn grow<const R: usize, const A: usize>(
        &self,
        geom: &Geometry<R, A>,
        scans: &[&[Plot]],
        flags: &mut [[u8; P]],
        s0: usize,
        m: usize,
        len: usize,
        chain: &mut [u16; MAX_M],
        pts: &mut [(i32, i32); MAX_M],
        budget: &mut (u32, u32),
        st: &mut CensorStats,
    ) {
        if budget.1 == 0 {
            st.chain_overflow += 1;
            return;
        }
        budget.1 -= 1;
        if len == m {
            if budget.0 == 0 {
                st.chain_overflow += 1;
                return;
            }
            budget.0 -= 1;
            let flag = |flags: &[[u8; P]], j: usize| {
                flags
                    .get(s0 + j)
                    .and_then(|row| row.get(usize::from(chain[j])))
                    .copied()
            };
            // all already effective: nothing to learn
            if (0..m).all(|j| flag(flags, j).is_none_or(|f| f & FLAG_EFFECTIVE != 0)) {
                return;
            }
            st.chains += 1;
            for j in 0..m {
                let Some(p) = scans
                    .get(s0 + j)
                    .and_then(|sc| sc.get(usize::from(chain[j])))
                else {
                    return;
                };
                pts[j] = geom.quantise(p.x, p.y);
            }
            if geom.share_cell(&pts[..m]) {
                for (j, &c) in chain.iter().enumerate().take(m) {
                    let Some(f) = flags
                        .get_mut(s0 + j)
                        .and_then(|row| row.get_mut(usize::from(c)))
                    else {
                        continue;
                    };
                    if *f & FLAG_EFFECTIVE == 0 {
                        *f |= FLAG_EFFECTIVE;
                        st.newly_effective += 1;
                    }
                }
            }
            return;
        }
        // pairs between scan s0+len-1 and s0+len, starting at chain[len-1]
        let slot = (s0 + len) % MAX_M;
        let list = self.pairs[slot]
            .get(..usize::from(self.npairs[slot]))
            .unwrap_or(&[]);
        // 2 <= len < m <= MAX_M
        let (Some(&last), true) = (chain.get(len.wrapping_sub(1)), len < MAX_M) else {
            return;
        };
        let lo = list.partition_point(|&(a, _)| a < last);
        for &(a, b) in &list[lo..] {
            if a != last {
                break;
            }
            chain[len] = b;
            self.grow(geom, scans, flags, s0, m, len + 1, chain, pts, budget, st);
        }
    }
}

/// The bits of `x` mapped so that unsigned order is `f32::total_cmp` order (negative
/// values: all bits flipped; others: the sign bit set).
#[inline(always)]
fn total_order_bits(x: f32) -> u32 {
    let b = x.to_bits();
    b ^ ((((b as i32) >> 31) as u32) | 0x8000_0000)
}

#[cfg(test)]
mod tests {
    use super::total_order_bits;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn total_order_bits_is_total_cmp(a in any::<u32>(), b in any::<u32>()) {
            let (x, y) = (f32::from_bits(a), f32::from_bits(b));
            prop_assert_eq!(total_order_bits(x).cmp(&total_order_bits(y)), x.total_cmp(&y));
        }
    }

    #[test]
    fn total_order_bits_on_specials() {
        let v = [
            -f32::NAN,
            f32::NEG_INFINITY,
            -1.0,
            -0.0,
            0.0,
            1e-40,
            1.0,
            f32::INFINITY,
            f32::NAN,
        ];
        for w in v.windows(2) {
            assert!(total_order_bits(w[0]) < total_order_bits(w[1]), "{:?}", w);
        }
    }
}
