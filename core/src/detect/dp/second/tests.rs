//! The second order's fast frames against its general path.

use super::SecondOrderDp;
use crate::detect::dp::{second_order_words, DpConfig, MeritCell, Method, Transition};
use crate::detect::Detector;
use crate::rng::Rng;

/// The fast frames (separable `g`, `J` at the target pixels) equal the general 2-D
/// path exactly: merits, back-pointer words and the best pixel, over frames with
/// saturating and clamped values.
fn fast_equals_general<C: MeritCell, const M: usize, const W: usize>(
    lsb: f32,
    seed: u64,
) -> crate::Result<()> {
    for transition in [Transition::Gaussian, Transition::Hard] {
        let mut cfg = DpConfig::dim_point(Method::SecondOrder, 1);
        cfg.transition = transition;
        cfg.lsb = lsb;
        let mut a = SecondOrderDp::<M, 9, 5, W, C>::new(cfg)?;
        let mut b = a.clone();
        assert!(a.kernel.sep.is_some());
        b.kernel.sep = None;
        let mut rng = Rng::seed_from_u64(seed);
        let mut z = [0f32; 4096];
        for k in 0..9 {
            for v in z.iter_mut().take(M * M) {
                *v = 1.5 * rng.normal();
                if rng.bernoulli(0.05) {
                    *v *= 40.0;
                }
                if k == 4 && rng.bernoulli(0.02) {
                    *v = if rng.bernoulli(0.5) { 1e30 } else { -1e30 };
                }
            }
            let ra = a.step(&z[..M * M]);
            let rb = b.step(&z[..M * M]);
            assert_eq!(ra.is_ok(), rb.is_ok());
            assert!(a.kernel.s == b.kernel.s, "merits, frame {k}");
            assert!(a.kernel.ptr == b.kernel.ptr, "pointers, frame {k}");
            assert_eq!(a.tally.best_raw, b.tally.best_raw, "frame {k}");
            assert_eq!(a.tally.best_xy, b.tally.best_xy, "frame {k}");
        }
    }
    Ok(())
}

#[test]
fn fast_frames_equal_the_general_path() -> crate::Result<()> {
    for seed in 0..3 {
        fast_equals_general::<i16, 12, { second_order_words(12, 9, 5) }>(0.0625, seed)?;
        fast_equals_general::<i8, 12, { second_order_words(12, 9, 5) }>(0.0625, seed)?;
        fast_equals_general::<i16, 7, { second_order_words(7, 9, 5) }>(0.0625, seed)?;
        fast_equals_general::<i8, 16, { second_order_words(16, 9, 5) }>(0.5, seed)?;
        fast_equals_general::<i16, 16, { second_order_words(16, 9, 5) }>(0.001, seed)?;
        fast_equals_general::<i16, 3, { second_order_words(3, 9, 5) }>(0.0625, seed)?;
    }
    Ok(())
}
