//! The state and pointer layout of the second-order recursion: for each `q_B`, the valid
//! candidates of each state and the mixed-radix pointer code of a pixel (compile-time
//! tables).

use crate::detect::dp::bits::radius_of;

/// Largest supported `q_B` (5x5).
pub(crate) const MAXQ: usize = 25;
/// The state and pointer layout of one `q_B` (compile-time tables).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Layout {
    /// Window radius (0: unsupported `q_B`).
    pub(crate) r: usize,
    /// Valid candidates `n_d` per state.
    pub(crate) nopt: [u8; MAXQ],
    /// Candidate `j` of state `d`: its `e` index `(ey + 1) 3 + (ex + 1)`.
    pub(crate) opt_e: [[u8; 9]; MAXQ],
    /// Candidate `j` of state `d`: the predecessor state `d - e`.
    pub(crate) opt_s: [[u8; 9]; MAXQ],
    /// Bit offset, in a pixel's code, of the chunk holding state `d`.
    pub(crate) chunk_bit: [u16; MAXQ],
    /// Bits of that chunk.
    pub(crate) chunk_bits: [u8; MAXQ],
    /// State `d` is the last of its chunk.
    pub(crate) chunk_last: [bool; MAXQ],
    /// Product of `n` over the later states of the chunk (the radix of `j_d`).
    pub(crate) suffix: [u32; MAXQ],
    /// Bits of one pixel's code.
    pub(crate) bits: u32,
    /// State `d`'s share of its chunk's code, `j suffix[d]`, by the separable key code
    /// `(ey + 1) << 2 | (ex + 1)` of its winner (0 for codes that cannot win).
    pub(crate) jterm: [[u32; 16]; MAXQ],
    /// States `2i - 1` and `2i` together (same chunk): `jterm` of both, by the codes
    /// `c_{2i-1} | c_{2i} << 4`.
    pub(crate) jpair: [[u32; 256]; MAXQ / 2],
}

const fn bits_u64(n: u64) -> u32 {
    let mut b = 0;
    while b < 64 && (1u64 << b) < n {
        b += 1;
    }
    b
}

/// The layout of `q_B = qb` (radius 1 or 2; anything else gives `r = 0`).
pub(crate) const fn layout(qb: usize) -> Layout {
    let mut l = Layout {
        r: 0,
        nopt: [0; MAXQ],
        opt_e: [[0; 9]; MAXQ],
        opt_s: [[0; 9]; MAXQ],
        chunk_bit: [0; MAXQ],
        chunk_bits: [0; MAXQ],
        chunk_last: [false; MAXQ],
        suffix: [1; MAXQ],
        bits: 0,
        jterm: [[0; 16]; MAXQ],
        jpair: [[0; 256]; MAXQ / 2],
    };
    let r = radius_of(qb);
    if r == 0 || r > 2 {
        return l;
    }
    l.r = r;
    let n = 2 * r + 1;
    let ri = r as i32;
    let mut s = 0;
    while s < qb {
        let dx = (s % n) as i32 - ri;
        let dy = (s / n) as i32 - ri;
        let mut c = 0;
        let mut ei = 0;
        while ei < 9 {
            let ex = ei % 3 - 1;
            let ey = ei / 3 - 1;
            let (px, py) = (dx - ex, dy - ey);
            if px >= -ri && px <= ri && py >= -ri && py <= ri {
                l.opt_e[s][c] = ei as u8;
                l.opt_s[s][c] = ((py + ri) as usize * n + (px + ri) as usize) as u8;
                c += 1;
            }
            ei += 1;
        }
        l.nopt[s] = c as u8;
        s += 1;
    }
    // chunks: consecutive states whose radix product stays below 2^32
    let mut off = 0u32;
    let mut s = 0;
    while s < qb {
        let start = s;
        let mut prod = 1u64;
        while s < qb && prod * (l.nopt[s] as u64) < (1u64 << 32) {
            prod *= l.nopt[s] as u64;
            s += 1;
        }
        let bits = bits_u64(prod);
        let mut t = start;
        while t < s {
            l.chunk_bit[t] = off as u16;
            l.chunk_bits[t] = bits as u8;
            let mut suf = 1u32;
            let mut u = t + 1;
            while u < s {
                suf *= l.nopt[u] as u32;
                u += 1;
            }
            l.suffix[t] = suf;
            t += 1;
        }
        l.chunk_last[s - 1] = true;
        off += bits;
    }
    l.bits = off;
    // jterm: candidate j = (cy - cy_min) n_x + (cx - cx_min) of code cy << 2 | cx
    let mut d = 0;
    while d < qb {
        let (dxi, dyi) = (d % n, d / n);
        let cxmin = (dxi + 1).saturating_sub(2 * r);
        let cymin = (dyi + 1).saturating_sub(2 * r);
        let cxmax = if dxi + 1 < 2 { dxi + 1 } else { 2 };
        let cymax = if dyi + 1 < 2 { dyi + 1 } else { 2 };
        let nx = cxmax + 1 - cxmin;
        let mut c = 0;
        while c < 16 {
            let (cx, cy) = (c & 3, c >> 2);
            if cx >= cxmin && cx <= cxmax && cy >= cymin && cy <= cymax {
                let j = (cy - cymin) * nx + (cx - cxmin);
                l.jterm[d][c] = j as u32 * l.suffix[d];
            }
            c += 1;
        }
        d += 1;
    }
    let mut i = 1;
    while 2 * i < qb {
        let (a, b) = (2 * i - 1, 2 * i);
        let mut c = 0;
        while c < 256 {
            l.jpair[i - 1][c] = l.jterm[a][c & 15] + l.jterm[b][c >> 4];
            c += 1;
        }
        i += 1;
    }
    l
}

/// Bits of one pixel's pointer code for `q_B = qb` (0 if unsupported).
pub(crate) const fn code_bits(qb: usize) -> u32 {
    layout(qb).bits
}
