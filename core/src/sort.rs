//! Panic-free in-place unstable sort of `Copy` elements (introsort, Musser 1997).
//!
//! `core`'s `sort_unstable*` may panic when the comparator is not a total order, so a
//! detector covered by a panic-never link check sorts with [`sort_unstable_by`] or
//! [`sort_unstable_by_key`] instead. Every element access is a checked `get` or a swap
//! behind an explicit bounds test, and the loops are iterative, so no panic path and no
//! recursion remain, whatever the comparator does.
//!
//! Algorithm: quicksort with Hoare's partition around the median of the first, middle and
//! last elements (Sedgewick 1978); ranges of at most 16 elements are insertion-sorted; a
//! range still large after `2 floor(log2 n) + 2` partitions is heapsorted. Pending ranges
//! live on a fixed stack of `usize::BITS` entries: the larger part is pushed and the
//! smaller one sorted next, so at most `log2 n` are pending.
//!
//! Cost: `O(n log n)` comparisons and moves in the worst case, about `1.2 n log2 n`
//! comparisons on random input; no memory beyond the range stack (`usize::BITS` entries,
//! 384 B on a 32-bit target).
//!
//! Result: when the comparator is a total order without ties (e.g. keys broken by index),
//! the output is the unique sorted permutation, identical to `sort_by`'s. With ties, the
//! order of equal elements is unspecified (deterministic for a given input). With an
//! inconsistent comparator the output is some permutation of the input; it never panics.
//! The elements are `Copy` (indices, keys) so that the insertion sort and the partition
//! move values instead of swapping.

use core::cmp::Ordering;

/// Ranges of at most this many elements are insertion-sorted.
const SMALL: usize = 16;

/// Capacity of the pending-range stack (at most `log2 n < usize::BITS` are pending).
const STACK: usize = usize::BITS as usize;

/// Sorts `v` in place by `cmp` (unstable; see the module doc for ties and inconsistent
/// comparators). `O(n log n)` worst case, no allocation, no panic.
pub fn sort_unstable_by<T: Copy, F>(v: &mut [T], mut cmp: F)
where
    F: FnMut(&T, &T) -> Ordering,
{
    introsort(v, &mut |a: &T, b: &T| cmp(a, b) == Ordering::Less);
}

/// Sorts `v` in place by the key `key` (unstable, the key is computed per comparison).
pub fn sort_unstable_by_key<T: Copy, K, F>(v: &mut [T], mut key: F)
where
    K: Ord,
    F: FnMut(&T) -> K,
{
    introsort(v, &mut |a: &T, b: &T| key(a) < key(b));
}

/// Sorts `v` in place by its `Ord` (unstable).
pub fn sort_unstable<T: Copy + Ord>(v: &mut [T]) {
    introsort(v, &mut |a: &T, b: &T| a < b);
}

/// Reorders `v` so that `v[k]` is the element a sort by `cmp` would put there, with
/// `v[..k] <= v[k] <= v[k + 1..]` (introselect: quickselect with the sort's partition,
/// heapsort of a range still large after `2 floor(log2 n) + 2` partitions). Does nothing
/// when `k >= v.len()`. With a total order without ties the set `v[..k]` is the unique
/// `k` smallest, as with `core`'s `select_nth_unstable_by`. `O(n)` expected, `O(n log n)`
/// worst case, no allocation, no panic.
pub fn select_nth_unstable_by<T: Copy, F>(v: &mut [T], k: usize, mut cmp: F)
where
    F: FnMut(&T, &T) -> Ordering,
{
    introselect(v, k, &mut |a: &T, b: &T| cmp(a, b) == Ordering::Less);
}

/// [`select_nth_unstable_by`] by `Ord`.
pub fn select_nth_unstable<T: Copy + Ord>(v: &mut [T], k: usize) {
    introselect(v, k, &mut |a: &T, b: &T| a < b);
}

fn introselect<T: Copy, F: FnMut(&T, &T) -> bool>(v: &mut [T], k: usize, is_less: &mut F) {
    let mut depth = 2 * (usize::BITS - v.len().leading_zeros());
    let (mut lo, mut hi) = (0usize, v.len());
    // invariant: lo <= k < hi, and v[..lo] <= v[lo..hi] <= v[hi..]
    while k >= lo && k < hi {
        let Some(s) = v.get_mut(lo..hi) else {
            return;
        };
        if s.len() <= SMALL {
            insertion_sort(s, is_less);
            return;
        }
        if depth == 0 {
            heapsort(s, is_less);
            return;
        }
        depth -= 1;
        // s[..p] <= s[p] <= s[p + 1..]
        let p = lo + partition(s, is_less);
        if k < p {
            hi = p;
        } else {
            lo = p + 1;
        }
    }
}

/// Swaps `v[i]` and `v[j]` when both are in range (always, for the callers below).
#[inline(always)]
fn swap<T>(v: &mut [T], i: usize, j: usize) {
    if i < v.len() && j < v.len() {
        v.swap(i, j);
    }
}

/// `v[i] < v[j]`; false when either index is out of range (never, for the callers below).
#[inline(always)]
fn less_at<T, F: FnMut(&T, &T) -> bool>(v: &[T], i: usize, j: usize, is_less: &mut F) -> bool {
    match (v.get(i), v.get(j)) {
        (Some(a), Some(b)) => is_less(a, b),
        _ => false,
    }
}

fn introsort<T: Copy, F: FnMut(&T, &T) -> bool>(v: &mut [T], is_less: &mut F) {
    // 2 floor(log2 n) + 2 partitions before a range falls back to heapsort
    let limit = 2 * (usize::BITS - v.len().leading_zeros());
    let mut stack = [(0usize, 0usize, 0u32); STACK];
    let mut top = 0usize;
    let (mut lo, mut hi, mut depth) = (0usize, v.len(), limit);
    loop {
        if let Some(s) = v.get_mut(lo..hi) {
            let n = s.len();
            if n > SMALL && depth > 0 {
                depth -= 1;
                let p = partition(s, is_less);
                // s[..p] <= pivot = s[p] <= s[p + 1..], p < n
                let left = (lo, lo + p);
                let right = (lo + p + 1, hi);
                let (small, large) = if p < n - 1 - p {
                    (left, right)
                } else {
                    (right, left)
                };
                if let Some(slot) = stack.get_mut(top) {
                    *slot = (large.0, large.1, depth);
                    top += 1;
                } else if let Some(rest) = v.get_mut(large.0..large.1) {
                    // unreachable (at most log2 n ranges pending); still sorted
                    heapsort(rest, is_less);
                }
                (lo, hi) = small;
                continue;
            } else if n > SMALL {
                heapsort(s, is_less);
            } else {
                insertion_sort(s, is_less);
            }
        }
        if top == 0 {
            break;
        }
        top -= 1;
        match stack.get(top) {
            Some(&(a, b, d)) => (lo, hi, depth) = (a, b, d),
            None => break,
        }
    }
}

/// Hoare partition of `v` (length `>= 3`) around the median of its first, middle and
/// last elements (Sedgewick 1978): returns `p < n` with `v[..p] <= v[p] <= v[p + 1..]`
/// (for a consistent comparator; any comparator gives some `p < n`).
fn partition<T: Copy, F: FnMut(&T, &T) -> bool>(v: &mut [T], is_less: &mut F) -> usize {
    let n = v.len();
    if n < 3 {
        insertion_sort(v, is_less);
        return 0;
    }
    let (mid, last) = (n / 2, n - 1);
    // order v[0] <= v[mid] <= v[last], then the median goes to v[0]: the pivot stops the
    // right-to-left scan at 0 and the maximum at `last` the left-to-right one
    if less_at(v, mid, 0, is_less) {
        swap(v, 0, mid);
    }
    if less_at(v, last, mid, is_less) {
        swap(v, mid, last);
        if less_at(v, mid, 0, is_less) {
            swap(v, 0, mid);
        }
    }
    swap(v, 0, mid);
    let Some(&pivot) = v.first() else {
        return 0;
    };
    let (mut i, mut j) = (0usize, n);
    loop {
        // i: first index > previous i with !(v[i] < pivot) (or n)
        i += 1;
        while let Some(x) = v.get(i) {
            if !is_less(x, &pivot) {
                break;
            }
            i += 1;
        }
        // j: last index < previous j with !(pivot < v[j]) (or 0)
        while j > 0 {
            j -= 1;
            match v.get(j) {
                Some(x) if is_less(&pivot, x) => {}
                _ => break,
            }
        }
        if i >= j {
            break;
        }
        swap(v, i, j);
    }
    swap(v, 0, j);
    j
}

/// Insertion sort, `O(n^2)`: for the short ranges.
fn insertion_sort<T: Copy, F: FnMut(&T, &T) -> bool>(v: &mut [T], is_less: &mut F) {
    for i in 1..v.len() {
        let Some(&x) = v.get(i) else {
            return;
        };
        // shift the larger elements of v[..i] right by one, x into the hole
        let mut j = i;
        while j > 0 {
            match v.get(j - 1) {
                Some(&y) if is_less(&x, &y) => {
                    if let Some(h) = v.get_mut(j) {
                        *h = y;
                    }
                    j -= 1;
                }
                _ => break,
            }
        }
        if let Some(h) = v.get_mut(j) {
            *h = x;
        }
    }
}

/// Heapsort, `O(n log n)` worst case: the fallback of ranges that partition badly.
fn heapsort<T, F: FnMut(&T, &T) -> bool>(v: &mut [T], is_less: &mut F) {
    let n = v.len();
    for i in (0..n / 2).rev() {
        sift_down(v, i, is_less);
    }
    for end in (1..n).rev() {
        swap(v, 0, end);
        if let Some(heap) = v.get_mut(..end) {
            sift_down(heap, 0, is_less);
        }
    }
}

/// Restores the max-heap property of `v` below `node`.
fn sift_down<T, F: FnMut(&T, &T) -> bool>(v: &mut [T], mut node: usize, is_less: &mut F) {
    loop {
        let Some(mut child) = node.checked_mul(2).and_then(|c| c.checked_add(1)) else {
            return;
        };
        if child >= v.len() {
            return;
        }
        if child + 1 < v.len() && less_at(v, child, child + 1, is_less) {
            child += 1;
        }
        if !less_at(v, node, child, is_less) {
            return;
        }
        swap(v, node, child);
        node = child;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::vec::Vec;

    fn check_u32(mut v: Vec<u32>) {
        let mut want = v.clone();
        want.sort();
        sort_unstable(&mut v);
        assert_eq!(v, want);
    }

    #[test]
    fn edge_cases() {
        check_u32(Vec::new());
        check_u32(std::vec![7]);
        check_u32(std::vec![2, 1]);
        check_u32((0..1000).collect());
        check_u32((0..1000).rev().collect());
        check_u32(std::vec![5; 1000]);
        check_u32((0..1000).map(|i| i % 3).collect());
        // organ pipe and sawtooth
        check_u32((0..500).chain((0..500).rev()).collect());
        check_u32((0..1000).map(|i| i % 17).collect());
    }

    #[test]
    fn select_edge_cases() {
        // k out of range: unchanged
        let mut v = std::vec![3u32, 1, 2];
        select_nth_unstable(&mut v, 3);
        assert_eq!(v, [3, 1, 2]);
        let mut e: [u32; 0] = [];
        select_nth_unstable(&mut e, 0);
        // an inconsistent comparator gives a permutation
        let mut v: Vec<u32> = (0..500).collect();
        let mut k = 7u32;
        select_nth_unstable_by(&mut v, 250, |_, _| {
            k = k.wrapping_mul(1_103_515_245).wrapping_add(12345);
            if k >> 31 == 0 {
                Ordering::Less
            } else {
                Ordering::Greater
            }
        });
        v.sort();
        assert_eq!(v, (0..500).collect::<Vec<_>>());
    }

    #[test]
    fn heapsort_alone_sorts() {
        let mut v: Vec<u32> = (0..300u32).map(|i| i.wrapping_mul(2_654_435_761)).collect();
        let mut want = v.clone();
        want.sort();
        heapsort(&mut v, &mut |a: &u32, b: &u32| a < b);
        assert_eq!(v, want);
    }

    #[test]
    fn inconsistent_comparator_gives_a_permutation() {
        let mut v: Vec<u32> = (0..500).collect();
        let mut k = 0u32;
        sort_unstable_by(&mut v, |_, _| {
            k = k.wrapping_mul(1_103_515_245).wrapping_add(12345);
            match k >> 30 {
                0 => Ordering::Less,
                1 => Ordering::Greater,
                _ => Ordering::Equal,
            }
        });
        v.sort();
        assert_eq!(v, (0..500).collect::<Vec<_>>());
    }

    proptest! {
        #[test]
        fn matches_std_on_total_orders(xs in proptest::collection::vec(-1000i32..1000, 0..600)) {
            // f32 keys with ties broken by index: a total order without ties
            let keys: Vec<f32> = xs.iter().map(|&x| x as f32 * 0.25).collect();
            let mut idx: Vec<u16> = (0..keys.len() as u16).collect();
            let mut want = idx.clone();
            let cmp = |a: &u16, b: &u16| {
                keys[*a as usize].total_cmp(&keys[*b as usize]).then(a.cmp(b))
            };
            want.sort_by(cmp);
            sort_unstable_by(&mut idx, cmp);
            prop_assert_eq!(&idx, &want);
            let mut by_key: Vec<u16> = (0..keys.len() as u16).rev().collect();
            sort_unstable_by_key(&mut by_key, |&i| (xs[i as usize], i));
            prop_assert_eq!(&by_key, &want);
        }

        #[test]
        fn select_matches_std(xs in proptest::collection::vec(-50i32..50, 1..300), k in 0usize..300) {
            let k = k % xs.len();
            let cmp = |a: &u16, b: &u16| xs[*a as usize].cmp(&xs[*b as usize]).then(a.cmp(b));
            let mut want: Vec<u16> = (0..xs.len() as u16).collect();
            want.select_nth_unstable_by(k, cmp);
            let mut got: Vec<u16> = (0..xs.len() as u16).rev().collect();
            select_nth_unstable_by(&mut got, k, cmp);
            prop_assert_eq!(got[k], want[k]);
            let (mut a, mut b) = (got[..k].to_vec(), want[..k].to_vec());
            a.sort();
            b.sort();
            prop_assert_eq!(a, b);
            let mut vals: Vec<i32> = xs.clone();
            select_nth_unstable(&mut vals, k);
            let mut sorted = xs.clone();
            sorted.sort();
            prop_assert_eq!(vals[k], sorted[k]);
        }

        #[test]
        fn sorts_with_ties(mut xs in proptest::collection::vec(0u8..8, 0..400)) {
            let mut want = xs.clone();
            want.sort();
            sort_unstable(&mut xs);
            prop_assert_eq!(xs, want);
        }
    }
}
