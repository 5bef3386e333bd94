//! Property tests of the core primitives: resampling invariants and unbiasedness,
//! log-weight normalisation, determinism.

use faint::math;
use faint::particles::{gather_in_place, resample, Scheme};
use faint::rng::Rng;
use proptest::prelude::*;

const SCHEMES: [Scheme; 4] = [
    Scheme::Systematic,
    Scheme::Stratified,
    Scheme::Residual,
    Scheme::Multinomial,
];

fn weights() -> impl Strategy<Value = Vec<f32>> {
    // Mixtures of zeros, tiny and large weights, 1..200 particles.
    prop::collection::vec(
        prop_oneof![Just(0.0f32), 1e-30f32..1e-20, 0.0f32..1.0, 1.0f32..1e6],
        1..200,
    )
    .prop_filter("not all zero", |w| w.iter().any(|&x| x > 1e-25))
}

fn counts(idx: &[u32], n: usize) -> Vec<usize> {
    let mut c = vec![0; n];
    for &i in idx {
        c[i as usize] += 1;
    }
    c
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(300))]

    #[test]
    fn counts_sum_to_m_sorted_in_range(w in weights(), m in 1usize..500, seed: u64) {
        let mut rng = Rng::seed_from_u64(seed);
        for s in SCHEMES {
            let mut out = vec![0u32; m];
            resample(s, &w, &mut out, &mut rng).unwrap();
            prop_assert!(out.windows(2).all(|p| p[0] <= p[1]));
            prop_assert!(out.iter().all(|&i| (i as usize) < w.len()));
            let c = counts(&out, w.len());
            prop_assert_eq!(c.iter().sum::<usize>(), m);
            for (i, &ci) in c.iter().enumerate() {
                prop_assert!(w[i] > 0.0 || ci == 0, "{:?} copied a zero weight", s);
            }
        }
    }

    #[test]
    fn systematic_and_residual_within_one(w in weights(), m in 1usize..500, seed: u64) {
        // Both schemes give floor(M w_i) or ceil(M w_i) copies; the tolerance 1 + 1e-3
        // absorbs the 2^-31 quantisation of the weights (documented in particles.rs).
        let total: f64 = w.iter().map(|&x| x as f64).sum();
        let mut rng = Rng::seed_from_u64(seed);
        for s in [Scheme::Systematic, Scheme::Residual] {
            let mut out = vec![0u32; m];
            resample(s, &w, &mut out, &mut rng).unwrap();
            for (i, &c) in counts(&out, w.len()).iter().enumerate() {
                let e = m as f64 * w[i] as f64 / total;
                prop_assert!((c as f64 - e).abs() < 1.0 + 1e-3, "{:?} i={} c={} e={}", s, i, c, e);
            }
        }
    }

    #[test]
    fn normalisation_sums_to_one(logs in prop::collection::vec(-1e4f32..1e4, 1..300)) {
        let mut w = vec![0.0f32; logs.len()];
        let lse = math::normalize_log_weights(&logs, &mut w).unwrap();
        prop_assert!(lse.is_finite());
        prop_assert!(w.iter().all(|x| x.is_finite() && *x >= 0.0 && *x <= 1.0));
        // Kahan sum of values each rounded once: error a few ulps of 1.
        prop_assert!((math::sum(&w) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn normalisation_never_nan(logs in prop::collection::vec(
        prop_oneof![Just(f32::NEG_INFINITY), Just(f32::INFINITY), Just(f32::NAN), -1e30f32..1e30], 0..50)) {
        let mut w = vec![0.0f32; logs.len()];
        if math::normalize_log_weights(&logs, &mut w).is_ok() {
            prop_assert!(w.iter().all(|x| x.is_finite()));
            prop_assert!((math::sum(&w) - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn deterministic(w in weights(), seed: u64) {
        for s in SCHEMES {
            let mut a = vec![0u16; 64];
            let mut b = vec![0u16; 64];
            resample(s, &w, &mut a, &mut Rng::seed_from_u64(seed)).unwrap();
            resample(s, &w, &mut b, &mut Rng::seed_from_u64(seed)).unwrap();
            prop_assert_eq!(&a, &b);
        }
    }

    #[test]
    fn gather_equals_out_of_place_copy(w in weights(), seed: u64) {
        let n = w.len();
        let mut anc = vec![0u32; n];
        resample(Scheme::Systematic, &w, &mut anc, &mut Rng::seed_from_u64(seed)).unwrap();
        let old: Vec<usize> = (0..n).collect();
        let mut s = old.clone();
        gather_in_place(&mut s, &anc).unwrap();
        for j in 0..n {
            prop_assert_eq!(s[j], old[anc[j] as usize]);
        }
    }
}

/// Unbiasedness: over R independent resamplings, the mean number of copies of particle i
/// must be M w_i. The tolerance is 5 standard errors of that mean; the per-draw variance
/// is bounded by the multinomial one, M w_i (1 - w_i), for all four schemes (systematic,
/// stratified and residual have lower variance), so the bound is conservative.
#[test]
fn resampling_is_unbiased() {
    let w = [0.05f32, 0.31, 0.0, 0.12, 0.02, 0.5];
    let m = 37usize;
    let reps = 20_000usize;
    for s in SCHEMES {
        let mut rng = Rng::seed_from_u64(2024);
        let mut sum = [0f64; 6];
        let mut out = vec![0u32; m];
        for _ in 0..reps {
            resample(s, &w, &mut out, &mut rng).unwrap();
            for (i, c) in counts(&out, 6).iter().enumerate() {
                sum[i] += *c as f64;
            }
        }
        for i in 0..6 {
            let wi = w[i] as f64;
            let mean = sum[i] / reps as f64;
            let se = (m as f64 * wi * (1.0 - wi) / reps as f64).sqrt();
            assert!(
                (mean - m as f64 * wi).abs() <= 5.0 * se + 1e-9,
                "{s:?} particle {i}: mean {mean} expected {}",
                m as f64 * wi
            );
        }
    }
}
