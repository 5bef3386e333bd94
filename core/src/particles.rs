//! Particle machinery shared by every particle filter: resampling into a caller-provided
//! ancestor buffer, in-place gather of states, effective sample size.
//!
//! Resampling works in exact integer arithmetic: weights are quantised once to
//! `q_i = floor(w_i * 2^31 / sum w)` (so `T = sum q_i < 2^32`), and every comparison
//! `position < cumulative` is done on `u64` numerators. The result is the same on every
//! target, has no floating-point drift over thousands of particles, and systematic and
//! residual counts are provably within one of `M q_i / T`. A weight below `2^-31` of the
//! total is quantised to zero (it would get a copy with probability below `M 2^-31`).
//!
//! All schemes write **sorted** ancestor indices (`a_0 <= a_1 <= ...`), which is what
//! lets [`gather_in_place`] reorder the states without a second buffer.

use crate::math::{self, KahanSum};
use crate::rng::Rng;
use crate::{Error, Result};

/// An integer type that can hold a particle index (`u16` halves the RAM of `u32`).
pub trait ParticleIndex: Copy + Default + core::fmt::Debug {
    /// `Some(i)` if `i` fits.
    fn from_usize(i: usize) -> Option<Self>;
    /// The index as `usize`.
    fn to_usize(self) -> usize;
}

macro_rules! impl_index {
    ($($t:ty),*) => {$(
        impl ParticleIndex for $t {
            #[inline]
            fn from_usize(i: usize) -> Option<Self> {
                <$t>::try_from(i).ok()
            }
            #[inline]
            fn to_usize(self) -> usize {
                self as usize
            }
        }
    )*};
}
impl_index!(u16, u32, usize);

/// Resampling scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Scheme {
    /// One uniform offset, `M` evenly spaced positions (lowest variance in practice).
    #[default]
    Systematic,
    /// One uniform per stratum `[j/M, (j+1)/M)`.
    Stratified,
    /// `floor(M w_i)` deterministic copies, the rest systematically from the residuals.
    Residual,
    /// `M` independent draws from the categorical distribution (sorted by generating
    /// uniform order statistics from exponential spacings, no extra memory).
    Multinomial,
}

/// Quantised weights: the `2^31 / sum` scale and the integer total `T`.
struct Quantised {
    scale: f32,
    total: u64,
}

#[inline]
fn quantise(w: f32, scale: f32) -> u64 {
    // w >= 0 and finite (checked); w * scale <= 2^31 (1 + eps) fits a u32, and the
    // f32 -> u32 conversion is one instruction on the M4 (f32 -> u64 is a libcall).
    (w * scale) as u32 as u64
}

fn prepare(weights: &[f32]) -> Result<Quantised> {
    let sum = math::checked_weight_sum(weights)?;
    let mut scale = 2_147_483_648.0f32 / sum;
    if !scale.is_finite() {
        // Subnormal sum: quantise relative to the largest weight instead.
        return Err(Error::DegenerateWeights);
    }
    // Guard the rounding of `sum` so that T stays below 2^32.
    scale *= 1.0 - 4.0 * f32::EPSILON;
    let mut total = 0u64;
    for &w in weights {
        total += quantise(w, scale);
    }
    if total == 0 {
        return Err(Error::DegenerateWeights);
    }
    Ok(Quantised { scale, total })
}

/// Resamples `out.len()` ancestors from `weights` (non-negative, need not be normalised).
///
/// `out` receives sorted indices into `weights`; `out.len()` may differ from
/// `weights.len()`. Errors leave `out` unspecified and are: [`Error::Empty`],
/// [`Error::NonFinite`], [`Error::NegativeWeight`], [`Error::DegenerateWeights`] (all
/// zero, or a subnormal sum), [`Error::IndexOutOfRange`] if `I` cannot index
/// `weights.len()` particles. The usual recovery for degenerate weights is to keep the
/// particles with uniform weights; the detectors document theirs.
pub fn resample<I: ParticleIndex>(
    scheme: Scheme,
    weights: &[f32],
    out: &mut [I],
    rng: &mut Rng,
) -> Result<()> {
    if weights.is_empty() {
        return Err(Error::Empty);
    }
    if I::from_usize(weights.len() - 1).is_none() {
        return Err(Error::IndexOutOfRange);
    }
    if out.is_empty() {
        return Ok(());
    }
    let q = prepare(weights)?;
    match scheme {
        Scheme::Systematic => {
            let a = (rng.next_u32() as u64 * q.total) >> 32;
            walk(weights, &q, out, |_| a)
        }
        Scheme::Stratified => walk(weights, &q, out, |_| {
            (rng.next_u32() as u64 * q.total) >> 32
        }),
        Scheme::Residual => residual(weights, &q, out, rng),
        Scheme::Multinomial => multinomial(weights, &q, out, rng),
    }
}

/// Shared walk of systematic and stratified resampling.
///
/// Position `j` is `(a_j + j T) / M` with `a_j in [0, T)`; with `C_i` the cumulative
/// quantised weight, `j` goes to the first `i` with `a_j + j T < M C_i`.
fn walk<I: ParticleIndex>(
    weights: &[f32],
    q: &Quantised,
    out: &mut [I],
    mut offset: impl FnMut(usize) -> u64,
) -> Result<()> {
    let m = out.len() as u64;
    let n = weights.len();
    let mut i = 0usize;
    let mut cum_m = m * quantise(weights[0], q.scale);
    for (j, slot) in out.iter_mut().enumerate() {
        let pos = offset(j) + j as u64 * q.total;
        while pos >= cum_m && i + 1 < n {
            i += 1;
            cum_m += m * quantise(weights[i], q.scale);
        }
        *slot = I::from_usize(i).ok_or(Error::IndexOutOfRange)?;
    }
    Ok(())
}

/// Residual resampling: `floor(M q_i / T)` copies of each particle, then the remaining
/// `M_r` by a systematic pass over the residuals `R_i = M q_i mod T` (whose total is
/// `M_r T`, so the systematic step is exactly `T`). One sorted pass.
fn residual<I: ParticleIndex>(
    weights: &[f32],
    q: &Quantised,
    out: &mut [I],
    rng: &mut Rng,
) -> Result<()> {
    let m = out.len() as u64;
    let t = q.total;
    let mut pos = (rng.next_u32() as u64 * t) >> 32;
    let mut cum_r = 0u64;
    let mut k = 0usize;
    let mut last_positive = 0usize;
    for (i, &w) in weights.iter().enumerate() {
        let mq = m * quantise(w, q.scale);
        if mq > 0 {
            last_positive = i;
        }
        let copies = mq / t;
        cum_r += mq % t;
        let mut emit = copies;
        while pos < cum_r {
            emit += 1;
            pos += t;
        }
        let idx = I::from_usize(i).ok_or(Error::IndexOutOfRange)?;
        for _ in 0..emit {
            if let Some(slot) = out.get_mut(k) {
                *slot = idx;
                k += 1;
            }
        }
    }
    // Exact arithmetic makes k == M; this only guards the unreachable remainder.
    let idx = I::from_usize(last_positive).ok_or(Error::IndexOutOfRange)?;
    for slot in out.iter_mut().skip(k) {
        *slot = idx;
    }
    Ok(())
}

/// Multinomial resampling with sorted output and no extra memory: the `M` sorted
/// uniforms are `S_j / S_{M+1}` with `S` the partial sums of `M + 1` exponentials
/// (Devroye 1986, V.2). The exponentials are drawn twice from a cloned stream (once for
/// the total, once for the walk) so nothing is stored.
fn multinomial<I: ParticleIndex>(
    weights: &[f32],
    q: &Quantised,
    out: &mut [I],
    rng: &mut Rng,
) -> Result<()> {
    let m = out.len();
    let mut probe = rng.clone();
    let mut total = KahanSum::new();
    for _ in 0..=m {
        total.add(probe.exponential());
    }
    let total = total.value();
    let n = weights.len();
    let mut i = 0usize;
    let mut cum = quantise(weights[0], q.scale);
    let mut s = KahanSum::new();
    for slot in out.iter_mut() {
        s.add(rng.exponential());
        let u = (s.value() / total).min(1.0);
        // Position in quantised units; the min() keeps it inside [0, T).
        let pos = ((u as f64 * q.total as f64) as u64).min(q.total - 1);
        while pos >= cum && i + 1 < n {
            i += 1;
            cum += quantise(weights[i], q.scale);
        }
        *slot = I::from_usize(i).ok_or(Error::IndexOutOfRange)?;
    }
    // Consume the last exponential so the stream advances identically to `probe`.
    let _ = rng.exponential();
    Ok(())
}

/// Systematic resampling of `anc.len()` ancestors, the same result and the same single
/// draw as [`resample`]`(Scheme::Systematic, w, anc, rng)` (test
/// `systematic_with_sum_equals_resample`) for weights in `[0, 1]`, in
/// fewer passes: `sum` is the caller's compensated sum of `w` (a [`KahanSum`] in index
/// order, what `resample` computes), the quantised weights `q_i = floor(w_i 2^31 / sum)`
/// are computed once into `scratch` (as bits) instead of twice, and the checks of
/// `resample` for negative or non-finite weights are not repeated (a non-finite weight
/// makes `sum` non-finite). Returns `false`, with nothing drawn, where `resample` errs.
/// `scratch` must have `w.len()` entries. CRPF-TBD's resampler.
pub fn systematic_with_sum(
    w: &[f32],
    sum: f32,
    scratch: &mut [f32],
    anc: &mut [u32],
    rng: &mut Rng,
) -> bool {
    if !(sum > 0.0 && sum.is_finite()) || w.is_empty() || w.len() != scratch.len() {
        return false;
    }
    let mut scale = 2_147_483_648.0f32 / sum;
    if !scale.is_finite() {
        return false;
    }
    scale *= 1.0 - 4.0 * f32::EPSILON;
    let mut total = 0u64;
    for (q, &x) in scratch.iter_mut().zip(w.iter()) {
        // As `particles::quantise`: x * scale <= 2^31 (1 + eps) fits a u32.
        let v = (x * scale) as u32;
        *q = f32::from_bits(v);
        total += v as u64;
    }
    if total == 0 {
        return false;
    }
    // Position j is (a + j T) / M; j goes to the first i with a + j T < M C_i. The walk
    // keeps `gap = M C_i - (a + j T)` (exact in i64: both terms are below 2^45 for
    // M < 2^13, and below 2^63 for any M < 2^31) and advances i while `gap <= 0`.
    let m = anc.len() as u64;
    let a = (rng.next_u32() as u64 * total) >> 32;
    let mut qs = scratch.iter().map(|q| q.to_bits() as u64);
    let mut i = 0u32;
    let mut gap = (m * qs.next().unwrap_or(0)) as i64 - a as i64;
    let step_value = total as i64;
    // Read from memory by one `ldrd` per slot (opaque reference) instead of being
    // spilled and reloaded word by word.
    let step = core::hint::black_box(&step_value);
    for slot in anc.iter_mut() {
        while gap <= 0 {
            match qs.next() {
                Some(q) => {
                    i += 1;
                    gap += (m * q) as i64;
                }
                None => break,
            }
        }
        *slot = i;
        gap -= *step;
    }
    true
}

/// A particle state that [`gather_flagged`] moves field by field.
pub trait FlaggedState {
    /// Copies `from` into `self`; `all` is the gather's `ALL` (a caller may skip fields it
    /// reads only then).
    fn copy_from(&mut self, from: &Self, all: bool);
}

/// `parts[j] = old parts[anc[j]]`, `flags[j] = old flags[anc[j]]` in place for sorted
/// ancestors (what [`resample`] produces), like [`gather_in_place`] (same two passes:
/// ascending for `a > j`, descending for `a < j`; test `gather_flagged_equals_gather`)
/// but for a structure of arrays of states and flags, moving a state with
/// [`FlaggedState::copy_from`] and, unless `ALL`, only where its flag is set (a state
/// with a clear flag is never read: CRPF-TBD's absent particles when `lambda = 0`).
/// Out-of-range ancestors are skipped.
///
/// `ALL` is a constant so that each variant's loops carry no flag (it spilled).
pub fn gather_flagged<P: FlaggedState + Copy, const ALL: bool>(
    parts: &mut [P],
    flags: &mut [bool],
    anc: &[u32],
) {
    #[inline(always)]
    fn copy<P: FlaggedState + Copy>(
        parts: &mut [P],
        flags: &mut [bool],
        j: usize,
        a: usize,
        all: bool,
    ) {
        let e = match flags.get(a) {
            Some(&e) => e,
            None => return,
        };
        if let Some(d) = flags.get_mut(j) {
            *d = e;
        }
        if !(e || all) {
            return;
        }
        if let Some(&s) = parts.get(a) {
            if let Some(d) = parts.get_mut(j) {
                d.copy_from(&s, all);
            }
        }
    }
    for (j, &a) in anc.iter().enumerate() {
        if a as usize > j {
            copy(parts, flags, j, a as usize, ALL);
        }
    }
    for (j, &a) in anc.iter().enumerate().rev() {
        if (a as usize) < j {
            copy(parts, flags, j, a as usize, ALL);
        }
    }
}

/// Reorders `states` so that `states[j] = old states[ancestors[j]]`, in place and in
/// O(N), for **sorted** ancestors (what [`resample`] produces).
///
/// Two passes: ascending for the slots with `a_j >= j` (they read slots not yet
/// written), then descending for those with `a_j < j` (they read slots that were either
/// never written or only copied onto themselves). Errors: [`Error::LengthMismatch`],
/// [`Error::IndexOutOfRange`], [`Error::UnsortedAncestors`] (checked before any write).
pub fn gather_in_place<S: Copy, I: ParticleIndex>(states: &mut [S], ancestors: &[I]) -> Result<()> {
    if states.len() != ancestors.len() {
        return Err(Error::LengthMismatch {
            expected: states.len(),
            got: ancestors.len(),
        });
    }
    let n = states.len();
    let mut prev = 0usize;
    for a in ancestors {
        let a = a.to_usize();
        if a >= n {
            return Err(Error::IndexOutOfRange);
        }
        if a < prev {
            return Err(Error::UnsortedAncestors);
        }
        prev = a;
    }
    // `get` instead of indexing: the bounds were checked above, but this keeps the
    // function provably panic-free at link time (firmware `panic-never` check).
    for j in 0..n {
        let a = ancestors[j].to_usize();
        if let (true, Some(&s)) = (a >= j, states.get(a)) {
            states[j] = s;
        }
    }
    for j in (0..n).rev() {
        let a = ancestors[j].to_usize();
        if let (true, Some(&s)) = (a < j, states.get(a)) {
            states[j] = s;
        }
    }
    Ok(())
}

/// [`gather_in_place`] when the particle count changes (a separate loop: the fixed-count one
/// keeps its bounds checks provably elided, 28 instructions per particle on the M4): the `n_old` old states are
/// `states[..n_old]`, and `states[j] = old states[ancestors[j]]` is written for
/// `j < ancestors.len()` (sorted ancestors below `n_old`; `states` holds at least
/// `max(n_old, ancestors.len())` entries). The same two passes are correct: a slot
/// `k = a_j < j` has `a_k <= k` (sorted), so the ascending pass left it unchanged, and slots
/// at or above `n_old` are never read. Errors as [`gather_in_place`].
pub fn gather_resized_in_place<S: Copy, I: ParticleIndex>(
    states: &mut [S],
    n_old: usize,
    ancestors: &[I],
) -> Result<()> {
    let n = ancestors.len();
    if states.len() < n_old.max(n) {
        return Err(Error::LengthMismatch {
            expected: n_old.max(n),
            got: states.len(),
        });
    }
    let mut prev = 0usize;
    for a in ancestors {
        let a = a.to_usize();
        if a >= n_old {
            return Err(Error::IndexOutOfRange);
        }
        if a < prev {
            return Err(Error::UnsortedAncestors);
        }
        prev = a;
    }
    // `get` instead of indexing: the bounds were checked above, but this keeps the
    // function provably panic-free at link time (firmware `panic-never` check).
    for (j, a) in ancestors.iter().enumerate() {
        let a = a.to_usize();
        if let (true, Some(&s)) = (a >= j, states.get(a)) {
            if let Some(d) = states.get_mut(j) {
                *d = s;
            }
        }
    }
    for (j, a) in ancestors.iter().enumerate().rev() {
        let a = a.to_usize();
        if let (true, Some(&s)) = (a < j, states.get(a)) {
            if let Some(d) = states.get_mut(j) {
                *d = s;
            }
        }
    }
    Ok(())
}

/// Effective sample size `(sum w)^2 / sum w^2` of non-negative weights (normalised or
/// not). Returns 0 for an empty or all-zero slice, and for NaN/inf inputs.
pub fn effective_sample_size(weights: &[f32]) -> f32 {
    let mut s = KahanSum::new();
    let mut s2 = KahanSum::new();
    for &w in weights {
        s.add(w);
        s2.add(w * w);
    }
    let (s, s2) = (s.value(), s2.value());
    if s2 > 0.0 && s.is_finite() && s2.is_finite() {
        s * s / s2
    } else {
        0.0
    }
}

/// Fixed-capacity particle storage: `N` states and their weights, with a sorted ancestor
/// buffer for resampling. `I` is the index type (`u16` for `N <= 65 536`).
#[derive(Debug, Clone)]
pub struct ParticleSet<S: Copy, I: ParticleIndex, const N: usize> {
    /// Particle states.
    pub states: [S; N],
    /// Particle weights (normalised after [`ParticleSet::normalize`]).
    pub weights: [f32; N],
    ancestors: [I; N],
}

impl<S: Copy, I: ParticleIndex, const N: usize> ParticleSet<S, I, N> {
    /// `N` copies of `init` with uniform weights `1/N`.
    pub fn new(init: S) -> Self {
        Self {
            states: [init; N],
            weights: [1.0 / N as f32; N],
            ancestors: [I::default(); N],
        }
    }

    /// Normalises the weights in place; returns their previous sum.
    pub fn normalize(&mut self) -> Result<f32> {
        math::normalize_weights(&mut self.weights)
    }

    /// Resamples `N` particles from `N` by `scheme`, sets the weights to `1/N`, and
    /// leaves the ancestor of each new particle in [`ParticleSet::ancestors`].
    /// On error the particles are untouched.
    pub fn resample(&mut self, scheme: Scheme, rng: &mut Rng) -> Result<()> {
        resample(scheme, &self.weights, &mut self.ancestors, rng)?;
        gather_in_place(&mut self.states, &self.ancestors)?;
        self.weights = [1.0 / N as f32; N];
        Ok(())
    }

    /// The ancestors written by the last [`ParticleSet::resample`].
    pub fn ancestors(&self) -> &[I; N] {
        &self.ancestors
    }

    /// Effective sample size of the current weights.
    pub fn ess(&self) -> f32 {
        effective_sample_size(&self.weights)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec;
    use std::vec::Vec;

    fn counts(idx: &[u32], n: usize) -> Vec<usize> {
        let mut c = vec![0; n];
        for &i in idx {
            c[i as usize] += 1;
        }
        c
    }

    #[test]
    fn all_schemes_sorted_and_complete() {
        let w = [0.1f32, 0.0, 0.4, 0.2, 0.3];
        let mut rng = Rng::seed_from_u64(1);
        for s in [
            Scheme::Systematic,
            Scheme::Stratified,
            Scheme::Residual,
            Scheme::Multinomial,
        ] {
            let mut out = [0u32; 1000];
            resample(s, &w, &mut out, &mut rng).unwrap();
            assert!(out.windows(2).all(|p| p[0] <= p[1]), "{s:?}");
            let c = counts(&out, 5);
            assert_eq!(c[1], 0, "{s:?} picked a zero weight");
            assert_eq!(c.iter().sum::<usize>(), 1000);
        }
    }

    #[test]
    fn systematic_counts_within_one() {
        let w = [0.123f32, 0.377, 0.25, 0.05, 0.2];
        let mut rng = Rng::seed_from_u64(9);
        for m in [1usize, 7, 100, 6000] {
            let mut out = vec![0u32; m];
            resample(Scheme::Systematic, &w, &mut out, &mut rng).unwrap();
            for (i, c) in counts(&out, 5).iter().enumerate() {
                let e = m as f32 * w[i];
                assert!(
                    (*c as f32 - e).abs() < 1.0 + 1e-3,
                    "m={m} i={i} c={c} e={e}"
                );
            }
        }
    }

    #[test]
    fn gather_matches_copy() {
        let anc = [0u16, 0, 1, 4, 4, 4, 6, 7];
        let mut s = [10, 11, 12, 13, 14, 15, 16, 17];
        let old = s;
        gather_in_place(&mut s, &anc).unwrap();
        for j in 0..8 {
            assert_eq!(s[j], old[anc[j] as usize]);
        }
        assert_eq!(
            gather_in_place(&mut s, &[1u16, 0, 2, 3, 4, 5, 6, 7]),
            Err(Error::UnsortedAncestors)
        );
    }

    #[test]
    fn gather_resized_matches_copy() {
        for (n_old, anc) in [
            (8usize, &[0u16, 0, 1, 4, 4, 4, 6, 7, 7, 7, 7][..]),
            (8, &[2u16, 2, 5][..]),
            (3, &[0u16, 1, 1, 1, 2, 2][..]),
        ] {
            let mut s: Vec<u32> = (0..n_old.max(anc.len()) as u32).map(|i| 10 + i).collect();
            let old = s.clone();
            gather_resized_in_place(&mut s, n_old, anc).unwrap();
            for (j, &a) in anc.iter().enumerate() {
                assert_eq!(s[j], old[a as usize]);
            }
        }
        let mut s = [0u32; 4];
        assert_eq!(
            gather_resized_in_place(&mut s, 2, &[0u16, 2]),
            Err(Error::IndexOutOfRange)
        );
    }

    #[test]
    fn degenerate_weights_are_errors() {
        let mut rng = Rng::seed_from_u64(0);
        let mut out = [0u16; 4];
        let e =
            |w: &[f32], out: &mut [u16], rng: &mut Rng| resample(Scheme::Systematic, w, out, rng);
        assert_eq!(
            e(&[0.0; 4], &mut out, &mut rng),
            Err(Error::DegenerateWeights)
        );
        assert_eq!(
            e(&[1.0, f32::NAN], &mut out, &mut rng),
            Err(Error::NonFinite)
        );
        assert_eq!(
            e(&[1.0, -1.0], &mut out, &mut rng),
            Err(Error::NegativeWeight)
        );
        assert_eq!(e(&[], &mut out, &mut rng), Err(Error::Empty));
        assert_eq!(
            e(&[1e-45; 4], &mut out, &mut rng),
            Err(Error::DegenerateWeights)
        );
        let big = vec![1.0f32; 70_000];
        assert_eq!(e(&big, &mut out, &mut rng), Err(Error::IndexOutOfRange));
    }

    #[test]
    fn particle_set_resample() {
        let mut p: ParticleSet<f32, u16, 64> = ParticleSet::new(0.0);
        for i in 0..64 {
            p.states[i] = i as f32;
            p.weights[i] = if i == 10 { 1.0 } else { 0.0 };
        }
        let mut rng = Rng::seed_from_u64(5);
        p.resample(Scheme::Systematic, &mut rng).unwrap();
        assert!(p.states.iter().all(|&s| s == 10.0));
        assert!((p.ess() - 64.0).abs() < 1e-3);
    }

    #[test]
    fn systematic_with_sum_equals_resample() {
        // Weights like CRPF's: many equal (absent particles), a few larger, exact zeros.
        let mut rng = Rng::seed_from_u64(11);
        for n in [1usize, 2, 7, 64, 1000, 6000] {
            for trial in 0..20 {
                let w: Vec<f32> = (0..n)
                    .map(|i| match (i + trial) % 5 {
                        0 => rng.uniform(),
                        1 => 0.0,
                        _ => 1e-3 * (1 + trial % 3) as f32,
                    })
                    .collect();
                let mut sum = KahanSum::new();
                for &x in &w {
                    sum.add(x);
                }
                let mut a = std::vec![0u32; n];
                let mut b = std::vec![0u32; n];
                let mut scratch = std::vec![0.0f32; n];
                let mut r1 = rng.clone();
                let mut r2 = rng.clone();
                let ok1 = resample(Scheme::Systematic, &w, &mut a, &mut r1).is_ok();
                let ok2 = systematic_with_sum(&w, sum.value(), &mut scratch, &mut b, &mut r2);
                assert_eq!(ok1, ok2, "n {n} trial {trial}");
                if ok1 {
                    assert_eq!(a, b, "n {n} trial {trial}");
                }
                assert_eq!(r1, r2);
                rng.next_u32();
            }
        }
        // All zero: both refuse, nothing drawn.
        let w = [0.0f32; 4];
        let mut r = Rng::seed_from_u64(1);
        let before = r.clone();
        assert!(!systematic_with_sum(
            &w,
            0.0,
            &mut [0.0; 4],
            &mut [0; 4],
            &mut r
        ));
        assert_eq!(r, before);
    }

    #[test]
    fn gather_flagged_equals_gather() {
        #[derive(Debug, Clone, Copy, PartialEq, Default)]
        struct S([f32; 2]);
        impl FlaggedState for S {
            fn copy_from(&mut self, from: &Self, _all: bool) {
                *self = *from;
            }
        }
        let mut rng = Rng::seed_from_u64(5);
        for n in [1usize, 2, 9, 300] {
            let w: Vec<f32> = (0..n).map(|_| rng.uniform()).collect();
            let mut anc = std::vec![0u32; n];
            resample(Scheme::Systematic, &w, &mut anc, &mut rng).unwrap();
            let states: Vec<S> = (0..n).map(|i| S([i as f32, -(i as f32)])).collect();
            let flags: Vec<bool> = (0..n).map(|i| i % 3 != 0).collect();
            let mut want_s = states.clone();
            let mut want_f = flags.clone();
            gather_in_place(&mut want_s, &anc).unwrap();
            gather_in_place(&mut want_f, &anc).unwrap();
            // ALL: states and flags as gather_in_place.
            let (mut s, mut f) = (states.clone(), flags.clone());
            gather_flagged::<S, true>(&mut s, &mut f, &anc);
            assert_eq!((&s, &f), (&want_s, &want_f), "n {n}");
            // Not ALL: the flags, and the states where the flag is set.
            let (mut s, mut f) = (states.clone(), flags.clone());
            gather_flagged::<S, false>(&mut s, &mut f, &anc);
            assert_eq!(f, want_f);
            for j in 0..n {
                if f[j] {
                    assert_eq!(s[j], want_s[j], "n {n} j {j}");
                }
            }
        }
    }
}
