//! Deterministic random streams: a thin layer over Xoshiro128++ (`rand_xoshiro`).
//!
//! Xoshiro128++ works on four `u32` words, so it is as fast on a Cortex-M4 as on a PC,
//! and every sampler here uses only integer operations and `libm`-backed `f32` math
//! (see [`crate::math`]): the same seed gives the same numbers, bit for bit, on x86_64
//! and on `thumbv7em-none-eabihf`.
//!
//! Streams: [`Rng::seed_from_u64`] for one stream; [`Rng::from_stream`] for the
//! independent stream number `i` of a master seed (per trial, per component), derived by
//! SplitMix64 hashing of `(master, i)`; [`Rng::jump`] advances by 2^64 draws when
//! provably disjoint sub-sequences are wanted.

use rand_core::{Rng as _, SeedableRng};
use rand_xoshiro::Xoshiro128PlusPlus;

use crate::math;

#[allow(clippy::excessive_precision)]
#[path = "rng_ziggurat_tables.rs"]
mod tables;
use tables::{ZIG_F, ZIG_K, ZIG_W};

/// Ziggurat base-strip edge `r` (Marsaglia & Tsang 2000, 128 layers).
const ZIG_R: f32 = 3.442_62;
/// `2^-24`.
const TWO_M24: f32 = 1.0 / 16_777_216.0;

/// SplitMix64 finaliser: a bijective 64-bit mix (Steele, Lea, Flood 2014).
#[inline]
pub const fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Seed of stream `index` of `master`: `splitmix64(splitmix64(master) ^ index)`-style
/// hashing, so neighbouring indices give unrelated seeds. Used by the host's Monte Carlo
/// runner for trial `i` and by detectors for their sub-components.
#[inline]
pub const fn derive_seed(master: u64, index: u64) -> u64 {
    splitmix64(splitmix64(master) ^ splitmix64(index.wrapping_add(0x6A09_E667_F3BC_C909)))
}

/// A seeded random stream with the samplers the detectors need.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Rng {
    inner: Xoshiro128PlusPlus,
}

impl Rng {
    /// One stream from a 64-bit seed (expanded to 128 bits of state by PCG32, as
    /// `rand_core::SeedableRng::seed_from_u64` does on every platform).
    pub fn seed_from_u64(seed: u64) -> Self {
        Self {
            inner: Xoshiro128PlusPlus::seed_from_u64(seed),
        }
    }

    /// Stream `index` of a master seed; see [`derive_seed`].
    pub fn from_stream(master: u64, index: u64) -> Self {
        Self::seed_from_u64(derive_seed(master, index))
    }

    /// Advances the stream by 2^64 draws (disjoint sub-sequences).
    pub fn jump(&mut self) {
        self.inner.jump();
    }

    /// A new stream for a sub-component: this stream's next 64 bits hashed with `tag`.
    pub fn fork(&mut self, tag: u64) -> Self {
        let s = self.next_u64();
        Self::seed_from_u64(derive_seed(s, tag))
    }

    /// 32 uniform bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        self.inner.next_u32()
    }

    /// 64 uniform bits (two `u32` draws, low word first).
    #[inline]
    pub fn next_u64(&mut self) -> u64 {
        let lo = self.next_u32() as u64;
        let hi = self.next_u32() as u64;
        lo | (hi << 32)
    }

    /// Uniform on `[0, 1)` with 24 bits of resolution: `(u32 >> 8) * 2^-24`.
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * TWO_M24
    }

    /// Uniform on `(0, 1]`: safe to take the logarithm of.
    #[inline]
    pub fn uniform_open0(&mut self) -> f32 {
        ((self.next_u32() >> 8) + 1) as f32 * TWO_M24
    }

    /// Uniform on `[lo, hi)`.
    #[inline]
    pub fn uniform_range(&mut self, lo: f32, hi: f32) -> f32 {
        lo + (hi - lo) * self.uniform()
    }

    /// Uniform integer in `0..n` (Lemire's multiply-shift; bias below `n / 2^32`).
    /// Returns 0 when `n == 0`.
    #[inline]
    pub fn below(&mut self, n: u32) -> u32 {
        ((self.next_u32() as u64 * n as u64) >> 32) as u32
    }

    /// `true` with probability `p` (`p` outside `[0, 1]` saturates).
    #[inline]
    pub fn bernoulli(&mut self, p: f32) -> bool {
        self.uniform() < p
    }

    /// Exponential with rate 1: `-ln(U)`, `U` on `(0, 1]`.
    #[inline]
    pub fn exponential(&mut self) -> f32 {
        -math::ln(self.uniform_open0())
    }

    /// Standard normal by the Ziggurat method (Marsaglia & Tsang 2000, 128 layers).
    ///
    /// One `u32` per draw on the fast path (about 98.8 % of draws): the low 7 bits pick
    /// the layer, the top 25 bits are a signed 24-bit magnitude (disjoint bits, unlike
    /// the original, so layer and magnitude are independent). Slow paths: the wedge test
    /// `f_i + U (f_{i-1} - f_i) < exp(-x^2/2)`, and Marsaglia's tail method beyond `r`.
    #[inline]
    pub fn normal(&mut self) -> f32 {
        let u = self.next_u32();
        let i = (u & 0x7f) as usize;
        let j = (u as i32) >> 7;
        if j.unsigned_abs() < ZIG_K[i] {
            return j as f32 * ZIG_W[i];
        }
        self.normal_slow(i, j)
    }

    #[cold]
    fn normal_slow(&mut self, mut i: usize, mut j: i32) -> f32 {
        loop {
            let x = j as f32 * ZIG_W[i];
            if i == 0 {
                // Tail beyond r: x = -ln(U1)/r, accept if -2 ln(U2) > x^2.
                loop {
                    let xt = -math::ln(self.uniform_open0()) * (1.0 / ZIG_R);
                    let y = -math::ln(self.uniform_open0());
                    if y + y >= xt * xt {
                        return if j > 0 { ZIG_R + xt } else { -ZIG_R - xt };
                    }
                }
            }
            let f_lo = ZIG_F[i];
            let f_hi = ZIG_F[i - 1];
            if f_lo + self.uniform() * (f_hi - f_lo) < math::exp(-0.5 * x * x) {
                return x;
            }
            let u = self.next_u32();
            i = (u & 0x7f) as usize;
            j = (u as i32) >> 7;
            if j.unsigned_abs() < ZIG_K[i] {
                return j as f32 * ZIG_W[i];
            }
        }
    }

    /// Normal with mean `mu` and standard deviation `sigma`.
    #[inline]
    pub fn gaussian(&mut self, mu: f32, sigma: f32) -> f32 {
        mu + sigma * self.normal()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::vec::Vec;

    #[test]
    fn ziggurat_tables_match_recipe() {
        // Recompute the Marsaglia-Tsang tables in f64 and compare each f32 entry within
        // 2 ulp (the generator ran on another libm), each u32 within 1.
        let m1 = 16_777_216.0f64;
        let mut dn = 3.442619855899f64;
        let mut tn = dn;
        let vn = 9.91256303526217e-3f64;
        let mut k = [0u32; 128];
        let mut w = [0f64; 128];
        let mut f = [0f64; 128];
        let q = vn / (-0.5 * dn * dn).exp();
        k[0] = ((dn / q) * m1) as u32;
        w[0] = q / m1;
        w[127] = dn / m1;
        f[0] = 1.0;
        f[127] = (-0.5 * dn * dn).exp();
        for i in (1..=126).rev() {
            dn = (-2.0 * (vn / dn + (-0.5 * dn * dn).exp()).ln()).sqrt();
            k[i + 1] = ((dn / tn) * m1) as u32;
            tn = dn;
            f[i] = (-0.5 * dn * dn).exp();
            w[i] = dn / m1;
        }
        for i in 0..128 {
            assert!(k[i].abs_diff(ZIG_K[i]) <= 1, "K[{i}]");
            let rel = |a: f64, b: f32| ((a as f32 - b) / b).abs();
            assert!(rel(w[i], ZIG_W[i]) < 3e-7, "W[{i}]");
            assert!(rel(f[i], ZIG_F[i]) < 3e-7, "F[{i}]");
        }
    }

    #[test]
    fn same_seed_same_stream() {
        let mut a = Rng::seed_from_u64(42);
        let mut b = Rng::seed_from_u64(42);
        for _ in 0..1000 {
            assert_eq!(a.normal().to_bits(), b.normal().to_bits());
        }
        let mut c = Rng::from_stream(1, 0);
        let mut d = Rng::from_stream(1, 1);
        assert_ne!(c.next_u32(), d.next_u32());
    }

    #[test]
    fn golden_values() {
        // Pinned outputs: a change here breaks reproducibility of every published run
        // (and the host-versus-target golden check). Update only on purpose.
        let mut r = Rng::seed_from_u64(0);
        let u: Vec<u32> = (0..4).map(|_| r.next_u32()).collect();
        assert_eq!(u, [1179900579, 1938959192, 3089844957, 3657088315]);
        let mut r = Rng::seed_from_u64(0);
        let n: Vec<u32> = (0..4).map(|_| r.normal().to_bits()).collect();
        assert_eq!(n, [1059052133, 1071241460, 3213722536, 3202277732]);
    }

    #[test]
    fn uniform_bounds() {
        let mut r = Rng::seed_from_u64(3);
        for _ in 0..100_000 {
            let u = r.uniform();
            assert!((0.0..1.0).contains(&u));
            let o = r.uniform_open0();
            assert!(o > 0.0 && o <= 1.0);
            assert!(r.below(7) < 7);
        }
        assert_eq!(r.below(0), 0);
    }
}
