//! Capacities: the back-pointer words `W` a DP detector's type carries (computed here,
//! named through [`dp_tbd!`](crate::dp_tbd)), and the static RAM of each detector.

use super::bits::{bits_for, words};
use super::{arnold, second};

/// Back-pointer words `W` of an [`ArnoldDp<M, QB, L, W>`](super::ArnoldDp):
/// `(L - 1) ceil(M^2 b / 32)`, `b = 4` bits for `q_B = 9`, 5 for 25, 6 for 49.
pub const fn arnold_words(m: usize, qb: usize, l: usize) -> usize {
    words(m, arnold::ptr_bits(qb) as usize, l.saturating_sub(1))
}

/// Back-pointer words `W` of a [`PulfordDp<M, QB, L, W>`](super::PulfordDp):
/// `(L - 1) ceil(M^2 b / 32)`, `b = ceil(log2(q_B + 1))` (4 bits for 9, 5 for 25).
pub const fn pulford_words(m: usize, qb: usize, l: usize) -> usize {
    words(m, bits_for(qb + 1) as usize, l.saturating_sub(1))
}

/// Back-pointer words `W` of a [`SecondOrderDp<M, QB, L, W>`](super::SecondOrderDp):
/// `(L - 2) ceil(M^2 b / 32)`, `b` the bits of one pixel's mixed-radix code (22 for
/// `q_B = 9`, 70 for 25; see [`SecondOrderDp`](super::SecondOrderDp)).
pub const fn second_order_words(m: usize, qb: usize, l: usize) -> usize {
    words(m, second::code_bits(qb) as usize, l.saturating_sub(2))
}

/// Bytes of the fixed fields every DP detector carries (configuration, quantiser,
/// running merit offset, reported ends), the same on 32- and 64-bit targets.
pub const FIXED_BYTES: usize = 144;

/// Static RAM (bytes) of an [`ArnoldDp<M, QB, L, W, C>`](super::ArnoldDp), `c = size_of::<C>()`:
/// `M^2 c` merits + `44 M` row keys and buffers + `4 W` back-pointers + [`FIXED_BYTES`]
/// (`M` a multiple of 4), rounded up to a multiple of 8 (the alignment). `M = 128`,
/// `q_B = 9`, `L = 8`: 95 888 B (`i16`), 79 504 B (`i8`).
pub const fn arnold_bytes(m: usize, qb: usize, l: usize, c: usize) -> usize {
    (m * m * c + 44 * m + 4 * arnold_words(m, qb, l) + FIXED_BYTES).next_multiple_of(8)
}

/// Static RAM (bytes) of a [`PulfordDp<M, QB, L, W, C>`](super::PulfordDp):
/// `(M^2 + 4 M)(c + 24)` merits and Kalman filters (current and 4 delayed rows) + `5 M`
/// row buffers + 264 B of gains + `4 W` back-pointers + [`FIXED_BYTES`] (`M` a multiple
/// of 4), rounded up to a multiple of 8. `M = 128`, `q_B = 9`, `L = 8`, `i16`: 497 688 B.
pub const fn pulford_bytes(m: usize, qb: usize, l: usize, c: usize) -> usize {
    ((m * m + 4 * m) * (c + 24) + 5 * m + 264 + 4 * pulford_words(m, qb, l) + FIXED_BYTES)
        .next_multiple_of(8)
}

/// Static RAM (bytes) of a [`SecondOrderDp<M, QB, L, W, C>`](super::SecondOrderDp):
/// `(M^2 + 5 M) q_B c` state merits and `J` rows + `4 M` row buffer + 64 B of transition
/// keys + `4 W` back-pointers + [`FIXED_BYTES`] (`M` a multiple of 4), rounded up to a
/// multiple of 8. `M = 128`,
/// `q_B = 9`, `L = 8`: 577 488 B (564 KiB) with `i16`, 424 272 B (414 KiB) with `i8`; the
/// back-pointers are `(L - 2) 45 056` B, so within 512 KiB: `i16` merits up to `L = 6`
/// (487 376 B), `i8` merits up to `L = 10` (514 384 B).
pub const fn second_order_bytes(m: usize, qb: usize, l: usize, c: usize) -> usize {
    ((m * m + 5 * m) * qb * c + 4 * m + 64 + 4 * second_order_words(m, qb, l) + FIXED_BYTES)
        .next_multiple_of(8)
}

/// Names a DP-TBD detector type from its method and capacities, computing the
/// back-pointer storage `W` (`dp::arnold_words`, `dp::pulford_words`,
/// `dp::second_order_words`) so that no user writes it:
///
/// ```
/// use faint_core::detect::dp::DpTrack;
/// type Dp = faint_core::dp_tbd!(SecondOrder, 64, 9, 8); // SIDE, WINDOW (q_B), HISTORY (L)
/// type Dp8 = faint_core::dp_tbd!(Arnold, 64, 9, 8, i8); // an `i8` merit cell
/// assert_eq!(<Dp as DpTrack>::SIDE, 64);
/// let _ = Dp8::new_unconfigured();
/// ```
///
/// The method is `Arnold`, `Pulford` or `SecondOrder`; the capacities are constant
/// expressions.
#[macro_export]
macro_rules! dp_tbd {
    (Arnold, $side:expr, $window:expr, $history:expr $(, $cell:ty)? $(,)?) => {
        $crate::detect::dp::ArnoldDp<
            { $side },
            { $window },
            { $history },
            { $crate::detect::dp::arnold_words($side, $window, $history) }
            $(, $cell)?
        >
    };
    (Pulford, $side:expr, $window:expr, $history:expr $(, $cell:ty)? $(,)?) => {
        $crate::detect::dp::PulfordDp<
            { $side },
            { $window },
            { $history },
            { $crate::detect::dp::pulford_words($side, $window, $history) }
            $(, $cell)?
        >
    };
    (SecondOrder, $side:expr, $window:expr, $history:expr $(, $cell:ty)? $(,)?) => {
        $crate::detect::dp::SecondOrderDp<
            { $side },
            { $window },
            { $history },
            { $crate::detect::dp::second_order_words($side, $window, $history) }
            $(, $cell)?
        >
    };
}
