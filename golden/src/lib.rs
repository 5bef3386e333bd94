//! # faint-golden
//!
//! Deterministic outputs of `faint-core` from fixed seeds, computed the same way on the
//! host (x86_64, `cargo run -q -p faint-golden --example golden`) and on the Cortex-M4F
//! firmware (`cd firmware && cargo run --profile firmware`). Each case prints one line
//!
//! ```text
//! golden <name> <word> <word> ...
//! ```
//!
//! of 32-bit words in hex (`f32` results as their bits, indices as integers, long outputs
//! folded by FNV-1a with [`Fold`]). `.ci/run` diffs the two sets of lines: any difference
//! means host and target disagree bit for bit, i.e. a host-side Monte Carlo result would
//! not carry over to the firmware.
//!
//! ## Adding a case (detector helpers)
//!
//! 1. Add a file `golden/src/<name>.rs` with
//!    `pub(crate) fn cases(emit: &mut dyn FnMut(&str, &[u32]))` that builds its inputs
//!    from fixed seeds ([`SEED`] and `Rng::from_stream(SEED, k)`), runs the detector a few
//!    frames and emits its report fields (`f32::to_bits`, counts, indices) under names
//!    starting with `<name>.`. Keep stack use small (a few KiB; the firmware runs it on
//!    its normal stack) and the run short (well under 10^8 instructions).
//! 2. Add `mod <name>;` and one call `<name>::cases(emit);` at the end of [`cases`].
//!
//! Nothing else is needed: the firmware and the host example both print every case.
//! Errors are emitted as the single word [`ERR`] (a `Result` that is `Err` on one side
//! only still shows up as a diff).
//!
//! ## The shared fixtures
//!
//! The crate is also the one home of the deterministic inputs that host and target must
//! draw alike: the detector scenes of the golden cases (which the firmware's instruction
//! table and the host tests also run), their windows, and the soak's plausible frames and
//! reduced configurations ([`soak`]). It depends on `faint-core` alone and is `no_std`
//! without allocation, so the host (`faint-host`), this crate's golden cases and the
//! firmware all use it as it is; a copy kept bit-identical by hand is what it replaces.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

use core::fmt;

pub mod cbmember;
pub mod crpf;
pub mod dp;
pub mod phd;
pub mod soak;

use faint_core::existence::ExistenceMarkov;
use faint_core::math;
use faint_core::particles::{self, Scheme};
use faint_core::rng::Rng;

pub mod mht;

/// Master seed of every golden case.
pub const SEED: u64 = 0x00FA_1A7F_601D_E115;

/// The word emitted in place of a result when a call returned `Err`.
pub const ERR: u32 = 0xEEEE_EEEE;

/// FNV-1a (32-bit) over the little-endian bytes of a sequence of words.
#[derive(Debug, Clone, Copy)]
pub struct Fold(u32);

impl Default for Fold {
    fn default() -> Self {
        Self::new()
    }
}

impl Fold {
    /// The FNV-1a offset basis.
    pub const fn new() -> Self {
        Self(0x811C_9DC5)
    }

    /// Folds one word in.
    pub fn push(&mut self, word: u32) {
        for b in word.to_le_bytes() {
            self.0 ^= b as u32;
            self.0 = self.0.wrapping_mul(0x0100_0193);
        }
    }

    /// Folds `f32` bits in.
    pub fn push_f32(&mut self, x: f32) {
        self.push(x.to_bits());
    }

    /// The hash so far.
    pub const fn value(self) -> u32 {
        self.0
    }
}

/// Writes one line (without the newline): `golden <name>` then ` {word:08x}` per word.
/// Host and firmware both format through this function.
pub fn write_line(w: &mut dyn fmt::Write, name: &str, words: &[u32]) -> fmt::Result {
    write!(w, "golden {name}")?;
    for word in words {
        write!(w, " {word:08x}")?;
    }
    Ok(())
}

/// Runs every golden case in a fixed order, calling `emit(name, words)` once per case.
pub fn cases(emit: &mut dyn FnMut(&str, &[u32])) {
    rng_cases(emit);
    math_cases(emit);
    weight_cases(emit);
    resample_cases(emit);
    existence_cases(emit);
    mht::cases(emit);
    crpf::cases(emit);
    phd::cases(emit);
    cbmember::cases(emit);
    dp::cases(emit);
}

fn bits<const K: usize>(mut f: impl FnMut() -> f32) -> [u32; K] {
    let mut out = [0u32; K];
    for o in out.iter_mut() {
        *o = f().to_bits();
    }
    out
}

fn rng_cases(emit: &mut dyn FnMut(&str, &[u32])) {
    let mut rng = Rng::seed_from_u64(SEED);
    let mut words = [0u32; 8];
    for w in words.iter_mut() {
        *w = rng.next_u32();
    }
    emit("rng.u32", &words);

    let mut s = Rng::from_stream(SEED, 7);
    let mut f = s.fork(3);
    let mut j = s.clone();
    j.jump();
    emit(
        "rng.stream_fork_jump",
        &[s.next_u32(), f.next_u32(), j.next_u32()],
    );

    let mut rng = Rng::from_stream(SEED, 1);
    emit("rng.uniform", &bits::<8>(|| rng.uniform()));
    emit("rng.uniform_open0", &bits::<4>(|| rng.uniform_open0()));
    emit("rng.exponential", &bits::<8>(|| rng.exponential()));
    emit("rng.normal", &bits::<16>(|| rng.normal()));
    emit("rng.gaussian", &bits::<4>(|| rng.gaussian(3.0, 0.5)));
    let below = [
        rng.below(10),
        rng.below(1000),
        rng.below(0),
        rng.below(u32::MAX),
    ];
    emit("rng.below", &below);

    // 100 000 normals reach the wedge and tail paths of the Ziggurat many times.
    let mut rng = Rng::from_stream(SEED, 2);
    let mut fold = Fold::new();
    for _ in 0..100_000 {
        fold.push_f32(rng.normal());
    }
    emit("rng.normal_fold_100k", &[fold.value()]);
}

fn math_cases(emit: &mut dyn FnMut(&str, &[u32])) {
    const X: [f32; 8] = [-87.3, -10.5, -1.0, -0.1, 0.3, 1.0, 7.25, 80.0];
    const P: [f32; 8] = [1e-30, 1e-6, 0.1, 0.5, 1.0, 2.0, 1000.5, 3.0e30];
    let one = |f: fn(f32) -> f32, xs: &[f32; 8]| {
        let mut out = [0u32; 8];
        for (o, &x) in out.iter_mut().zip(xs) {
            *o = f(x).to_bits();
        }
        out
    };
    emit("math.exp", &one(math::exp, &X));
    emit("math.ln", &one(math::ln, &P));
    emit("math.sqrt", &one(math::sqrt, &P));
    emit("math.sin", &one(math::sin, &X));
    emit("math.cos", &one(math::cos, &X));
    emit("math.floor", &one(math::floor, &X));
    emit("math.round", &one(math::round, &X));
    emit("math.ln1p", &one(math::ln1p, &P));
    let mut two = [0u32; 8];
    for (k, o) in two.iter_mut().enumerate() {
        *o = math::atan2(X[k], X[7 - k]).to_bits();
    }
    emit("math.atan2", &two);
    for (k, o) in two.iter_mut().enumerate() {
        *o = math::powf(P[k], X[k] * 0.25).to_bits();
    }
    emit("math.powf", &two);
}

fn weight_cases(emit: &mut dyn FnMut(&str, &[u32])) {
    let mut rng = Rng::from_stream(SEED, 3);
    let mut logs = [0f32; 16];
    for l in logs.iter_mut() {
        *l = rng.gaussian(-40.0, 6.0);
    }
    emit(
        "math.sum_max_lse",
        &[
            math::sum(&logs).to_bits(),
            math::max_log(&logs).map_or(ERR, f32::to_bits),
            math::log_sum_exp(&logs).map_or(ERR, f32::to_bits),
        ],
    );
    let mut w = [0f32; 16];
    let lse = math::normalize_log_weights(&logs, &mut w);
    let mut words = [0u32; 17];
    words[0] = lse.map_or(ERR, f32::to_bits);
    for (o, x) in words[1..].iter_mut().zip(&w) {
        *o = x.to_bits();
    }
    emit("math.normalize_log_weights", &words);
    emit(
        "particles.ess",
        &[particles::effective_sample_size(&w).to_bits()],
    );
    let mut lin = [0f32; 16];
    for (l, &x) in lin.iter_mut().zip(&logs) {
        *l = math::exp(x + 40.0);
    }
    let old = math::normalize_weights(&mut lin);
    let mut words = [0u32; 17];
    words[0] = old.map_or(ERR, f32::to_bits);
    for (o, x) in words[1..].iter_mut().zip(&lin) {
        *o = x.to_bits();
    }
    emit("math.normalize_weights", &words);
}

/// Weights `exp(N(0, 2^2))` (a spread like real likelihoods), deterministic.
fn weights<const N: usize>(stream: u64) -> [f32; N] {
    let mut rng = Rng::from_stream(SEED, stream);
    let mut w = [0f32; N];
    for x in w.iter_mut() {
        *x = math::exp(2.0 * rng.normal());
    }
    w
}

fn resample_cases(emit: &mut dyn FnMut(&str, &[u32])) {
    const SCHEMES: [(Scheme, &str, &str); 4] = [
        (
            Scheme::Systematic,
            "particles.systematic_32",
            "particles.systematic_1000_fold",
        ),
        (
            Scheme::Stratified,
            "particles.stratified_32",
            "particles.stratified_1000_fold",
        ),
        (
            Scheme::Residual,
            "particles.residual_32",
            "particles.residual_1000_fold",
        ),
        (
            Scheme::Multinomial,
            "particles.multinomial_32",
            "particles.multinomial_1000_fold",
        ),
    ];
    let w32 = weights::<32>(4);
    let w1000 = weights::<1000>(5);
    for (k, (scheme, short, long)) in SCHEMES.iter().enumerate() {
        let mut rng = Rng::from_stream(SEED, 10 + k as u64);
        let mut out = [0u16; 32];
        let mut words = [ERR; 32];
        if particles::resample(*scheme, &w32, &mut out, &mut rng).is_ok() {
            for (o, &a) in words.iter_mut().zip(&out) {
                *o = a as u32;
            }
        }
        emit(short, &words);

        // 1000 weights into 1500 ancestors (out.len() != weights.len()).
        let mut out = [0u16; 1500];
        let word = match particles::resample(*scheme, &w1000, &mut out, &mut rng) {
            Ok(()) => {
                let mut fold = Fold::new();
                out.iter().for_each(|&a| fold.push(a as u32));
                fold.value()
            }
            Err(_) => ERR,
        };
        // The stream position after resampling is part of the contract too.
        emit(long, &[word, rng.next_u32()]);
    }

    // Gather 32 states along systematic ancestors.
    let mut rng = Rng::from_stream(SEED, 20);
    let mut anc = [0u16; 32];
    let mut states = [0u32; 32];
    for (i, s) in states.iter_mut().enumerate() {
        *s = 3 * i as u32 + 1;
    }
    let ok = particles::resample(Scheme::Systematic, &w32, &mut anc, &mut rng)
        .and_then(|()| particles::gather_in_place(&mut states, &anc));
    if ok.is_err() {
        states = [ERR; 32];
    }
    emit("particles.gather_in_place_32", &states);
}

fn existence_cases(emit: &mut dyn FnMut(&str, &[u32])) {
    let Ok(chain) = ExistenceMarkov::new(0.1, 0.05) else {
        emit("existence", &[ERR]);
        return;
    };
    let mut rng = Rng::from_stream(SEED, 30);
    let mut existed = false;
    let mut mask = 0u32;
    for k in 0..32 {
        existed = chain.sample(existed, &mut rng).exists();
        mask |= (existed as u32) << k;
    }
    emit(
        "existence.sample_predict",
        &[
            mask,
            chain.predict(0.3).to_bits(),
            chain.predict(0.97).to_bits(),
        ],
    );
}

#[cfg(test)]
mod tests {
    extern crate std;
    use std::string::String;
    use std::vec::Vec;

    use super::*;

    #[test]
    fn line_format() {
        let mut s = String::new();
        write_line(&mut s, "a.b", &[0, 0xDEAD_BEEF]).unwrap();
        assert_eq!(s, "golden a.b 00000000 deadbeef");
    }

    #[test]
    fn case_names_unique_and_non_empty() {
        let mut names: Vec<String> = Vec::new();
        cases(&mut |name, words| {
            assert!(!words.is_empty(), "{name} emitted no words");
            assert!(!name.contains(' '), "{name}");
            names.push(name.into());
        });
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), n, "duplicate golden case names");
    }

    #[test]
    fn deterministic() {
        let mut a = Vec::new();
        let mut b = Vec::new();
        cases(&mut |_, w| a.extend_from_slice(w));
        cases(&mut |_, w| b.extend_from_slice(w));
        assert_eq!(a, b);
        // No case failed on the host.
        assert!(!a.contains(&ERR));
    }
}
