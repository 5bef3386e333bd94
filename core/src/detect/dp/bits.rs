//! Bit-packed back-pointers: fixed-width codes appended to and read from `u32` words, and
//! the window and storage arithmetic behind them.

/// `ceil(log2(n))` for `n >= 1` (bits to hold `0..n`).
pub(crate) const fn bits_for(n: usize) -> u32 {
    let mut b = 0;
    while (1usize << b) < n {
        b += 1;
    }
    b
}

/// Window radius of a `q`-pixel square window (`q = (2R+1)^2`), 0 if `q` is not one.
pub(crate) const fn radius_of(q: usize) -> usize {
    let mut r = 1;
    while r <= 3 {
        if (2 * r + 1) * (2 * r + 1) == q {
            return r;
        }
        r += 1;
    }
    0
}

/// `u32` words of `frames` frames of `bits`-bit codes per pixel of an `m x m` image.
pub(crate) const fn words(m: usize, bits: usize, frames: usize) -> usize {
    frames * (m * m * bits).div_ceil(32)
}

/// Appends fixed-width codes to a word slice, least significant bit first (words past
/// the slice are dropped, never written).
pub(crate) struct BitWriter<'a> {
    words: &'a mut [u32],
    next: usize,
    acc: u32,
    fill: u32,
}

impl<'a> BitWriter<'a> {
    pub(crate) fn new(words: &'a mut [u32]) -> Self {
        Self {
            words,
            next: 0,
            acc: 0,
            fill: 0,
        }
    }

    /// Appends the low `bits` bits of `v` (`1 <= bits <= 32`, `v < 2^bits`).
    #[inline(always)]
    pub(crate) fn push(&mut self, v: u32, bits: u32) {
        self.acc |= v.wrapping_shl(self.fill);
        let total = self.fill + bits;
        if total >= 32 {
            if let Some(w) = self.words.get_mut(self.next) {
                *w = self.acc;
            }
            self.next += 1;
            self.acc = if self.fill == 0 {
                0
            } else {
                v.wrapping_shr(32 - self.fill)
            };
            self.fill = total - 32;
        } else {
            self.fill = total;
        }
    }

    /// For a writer outside (the second order's Cortex-M4 `J` row): the unwritten
    /// words, the pending bits and their count; [`Self::skip`] then counts the words
    /// it wrote.
    #[cfg_attr(not(faint_m4_asm), allow(dead_code))]
    pub(crate) fn parts(&mut self) -> (&mut [u32], &mut u32, &mut u32) {
        let words = self.words.get_mut(self.next..).unwrap_or(&mut []);
        (words, &mut self.acc, &mut self.fill)
    }

    /// `n` more words written (see [`Self::parts`]).
    #[cfg_attr(not(faint_m4_asm), allow(dead_code))]
    pub(crate) fn skip(&mut self, n: usize) {
        self.next += n;
    }

    /// Writes a partly filled last word.
    pub(crate) fn finish(self) {
        if self.fill > 0 {
            if let Some(w) = self.words.get_mut(self.next) {
                *w = self.acc;
            }
        }
    }
}

/// The `bits`-bit code at bit offset `bit` of `words` (0 past the end).
#[inline]
pub(crate) fn read_bits(words: &[u32], bit: usize, bits: u32) -> u32 {
    let w = bit >> 5;
    let sh = (bit & 31) as u32;
    let lo = words.get(w).copied().unwrap_or(0).wrapping_shr(sh);
    let hi = if sh != 0 && sh + bits > 32 {
        words.get(w + 1).copied().unwrap_or(0).wrapping_shl(32 - sh)
    } else {
        0
    };
    let v = lo | hi;
    if bits >= 32 {
        v
    } else {
        v & ((1u32 << bits) - 1)
    }
}

/// The `bits`-bit code of pixel `pixel` in slot `slot` of a back-pointer store of
/// `frame_words` words per frame.
#[inline]
pub(crate) fn code_at(
    words: &[u32],
    slot: usize,
    frame_words: usize,
    pixel: usize,
    bits: u32,
) -> u32 {
    read_bits(words, slot * frame_words * 32 + pixel * bits as usize, bits)
}
