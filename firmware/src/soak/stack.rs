//! The soak's peak stack: a window painted below the soak loop's frame, read after every
//! `step` ([`WINDOW`]), and the per-phase diagnostic of `phases=1` ([`phase`]).

use crate::harness::{lowest_touched, paint};

/// Stack window painted below the soak loop's frame (every detector's step measured so
/// far stays under 4.5 KiB; a row at `WINDOW` means at least that much).
pub const WINDOW: usize = 16 * 1024;

/// The deepest stack one phase of a frame reached and the first frame that reached it.
#[derive(Debug, Default, Clone, Copy)]
pub struct Peak {
    /// Bytes below the soak loop's stack pointer.
    pub bytes: usize,
    /// The first frame that reached them.
    pub frame: u64,
}

/// Runs one phase of frame `frame` on a freshly painted window `[lo, hi)` and raises
/// `peak` to its stack below `top` (`phases=1`).
pub fn phase<R>(
    top: usize,
    lo: usize,
    hi: usize,
    peak: &mut Peak,
    frame: u64,
    f: impl FnOnce() -> R,
) -> R {
    paint(lo, hi);
    let r = f();
    let bytes = top - lowest_touched(lo, hi);
    if bytes > peak.bytes {
        *peak = Peak { bytes, frame };
    }
    r
}
