//! Second-order DP over state pairs (Wang, Zhang 2016, §2, eq. 12-17).
//!
//! A state is a pair `(t, t')` of the positions at frames `k` and `k-1` with
//! `t' in R_B(t)`, stored at pixel `t` as the displacement `d = t - t'` (index
//! `(dy + R)(2R+1) + (dx + R)`, `q_B` states per pixel). With `e = t'' - (2 t' - t)`,
//! the offset of `t''` from the back-extrapolated position (eq. 15):
//!
//! ```text
//! I_1(t, .) = T(z_1(t)),  I_2(t, t') = T(z_2(t)) + T(z_1(t'))           (§2.3 step 1)
//! I_k(t, t') = T(z_k(t)) + J_k(t', d),                                   k >= 3
//! J_k(t', d) = max_{e in [-1,1]^2, d - e in R_B} [I_{k-1}(t', t' - (d - e)) + g(e)]   (eq. 14)
//! ```
//!
//! `J_k(t', .)` depends only on the states stored at pixel `t'`, so it is computed per
//! pixel (a 2-D optimisation over the `q_I = 9` candidates of each of the `q_B` states)
//! and then scattered: `I_k(t' + d, d) = T(z_k(t' + d)) + J_k(t', d)`. Each candidate is
//! one integer key `(I + g) << 4 | j` (`j` the candidate's index among the state's
//! `n_d` valid ones, ascending `e = (ey + 1) 3 + (ex + 1)`): one compare-select per
//! candidate, ties to the larger `j`. The back-pointer of state `(t', d)` is that `j`;
//! the `q_B` pointers of a pixel are one mixed-radix code
//! `(..(j_0 n_1 + j_1) n_2 + ..) + j_last` of `ceil(log2 prod n_d)` bits (22 bits for
//! `q_B = 9`: `n_d` is 9 in the centre, 6 on the edges, 4 in the corners; 70 bits in
//! three chunks below 2^32 for `q_B = 25`), packed into a bit stream per frame.
//!
//! When the transition table is separable, `g(e) = gx(ex) + gy(ey)` (the preset's
//! Gaussian after rounding, and the hard window), the max over the 9 candidates runs as
//! row maxima shared by the states, then column maxima, on keys with the code
//! `(ey + 1) << 2 | (ex + 1)`, which ascends with `j`: the same winners and pointers, 24
//! compare-selects per pixel instead of 40. Otherwise the candidates are compared directly.
//!
//! For `q_B = 9` with a separable `g`, from frame 3, `J` is written directly at the target
//! pixels, in three padded target rows held in the `J` rows' memory, and the new merits
//! read one contiguous cell per pixel (`run_fast`); on the Cortex-M4 both passes are
//! `asm!` rows whose portable twins give the same merits and pointers.
//!
//! Memory ([`second_order_bytes`](super::second_order_bytes)): `M^2 q_B sizeof(C)`
//! merits, `5 M q_B sizeof(C)` bytes of `J` rows, `4 M` of a row buffer, 64 of transition
//! keys, `4 W = (L - 2) ceil(M^2 b / 32) 4` bytes of back-pointers and 144 of fixed
//! fields. For `M = 128`, `q_B = 9`, `L = 8`: `C = i16` 294 912 + 11 520 + 512 + 64 +
//! 270 336 + 144 = 577 488 B (564 KiB); `C = i8` 147 456 + 5 760 + 512 + 64 + 270 336 +
//! 144 = 424 272 B (414 KiB, within 512 KiB).

use super::{
    begin, check_shape, detection, finish, radius_of, read_bits, transition_table, BitWriter,
    DpConfig, DpReport, DpTrack, Ends, MeritCell, Method, Quant, Tally, TrackEnd, STATE,
};
use crate::detect::{Detection, Detector, ScoreKind};
use crate::Result;

/// Largest supported `q_B` (5x5).
pub(crate) const MAXQ: usize = 25;
/// Rows of `J` kept (`2R + 1 <= 5`).
const JROWS: usize = 5;
const FLOOR_KEY: i32 = i32::MIN / 2;

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

/// Pointer-code tables of the Cortex-M4 `J` row ([`j_row_asm`], `q_B = 9`): the code is
/// the sum of `jterm[d][c_d]` over the states, looked up as `jterm[8]` (16 words) and the
/// pairs `(0, 1)`, `(3, 4)`, `(6, 7)`, `(2, 5)` (256 words each, index `c_a | c_b << 4`).
#[cfg_attr(not(faint_m4_asm), allow(dead_code))]
static ATAB: [u32; 16 + 4 * 256] = atab();

const fn atab() -> [u32; 16 + 4 * 256] {
    let l = layout(9);
    let mut t = [0u32; 16 + 4 * 256];
    let mut c = 0;
    while c < 16 {
        t[c] = l.jterm[8][c];
        c += 1;
    }
    let pairs = [(0, 1), (3, 4), (6, 7), (2, 5)];
    let mut p = 0;
    while p < 4 {
        let (a, b) = pairs[p];
        let mut c = 0;
        while c < 256 {
            t[16 + 256 * p + c] = l.jterm[a][c & 15] + l.jterm[b][c >> 4];
            c += 1;
        }
        p += 1;
    }
    t
}

/// One `J` row of [`SecondOrderDp::jrow_fast`] in Cortex-M4 assembly (`q_B = 9`,
/// `rr mod 3 = ROT`), the arithmetic of [`SecondOrderDp::j_cell_sep`]: per column `dx`
/// of the states, the row maxima `Hx(p_y, dx)` over `ex` (keys `I << 4 + GX`), then the
/// three states' maxima over `ey` (`+ GY`), `ssat(key >> 4)` stored at the target cells,
/// the key nibbles summed through [`ATAB`] into the pixel's pointer code, appended to
/// `bw` as [`BitWriter::push`] does. Returns `false`, having done nothing, if the
/// writer lacks the words the row completes.
/// Registers: `r0` source, `r1` ring cell `3 x`, `r2`-`r7` `GX`, `GY`, `r8`-`r10`
/// `Hx` then keys, `r11`, `r12` scratch, `lr` the nibbles of states 0, 1, 3, 4, 6, 7.
#[cfg(faint_m4_asm)]
#[allow(unsafe_code)]
#[inline(always)]
fn j_row_asm<C: MeritCell, const QB: usize, const M: usize, const ROT: usize>(
    src: &[[C; QB]; M],
    ring: &mut [[C; QB]],
    gk: &[i32; 6],
    bw: &mut BitWriter<'_>,
) -> bool {
    const BITS: u32 = code_bits(9);
    let (words, acc, fill) = bw.parts();
    // (the words this row completes)
    let need = (*fill as usize + M * BITS as usize) / 32;
    if QB != 9 || ring.len() < 3 * (M + 2) || M == 0 || words.len() < need || BITS != 22 {
        return false;
    }
    let sz = core::mem::size_of::<C>();
    let src_p = src.as_ptr() as usize;
    let w0 = words.as_mut_ptr() as u32;
    // [GX0..2, GY0..2, tables, source end, (unused), source, ring, word, acc, fill]
    let mut par: [u32; 14] = [
        gk[0] as u32,
        gk[1] as u32,
        gk[2] as u32,
        gk[3] as u32,
        gk[4] as u32,
        gk[5] as u32,
        ATAB.as_ptr() as u32,
        (src_p + M * 9 * sz) as u32,
        0,
        src_p as u32,
        ring.as_mut_ptr() as u32,
        w0,
        *acc,
        *fill,
    ];
    macro_rules! row {
        ($ld:literal, $st:literal) => {
            // SAFETY: the block reads the `M` source cells (`9 M` values) and `ATAB`,
            // writes the writer's next `need` words and ring cells `0 .. 3 (M + 2)` (state offsets below
            // `27 sizeof(C)` from cell `3 x`, checked above), and restores r4-r11 and lr.
            unsafe {
                core::arch::asm!(
                    "push {{r4-r11, lr}}",
                    "push {{{par}}}",
                    "ldr r0, [{par}, #36]",
                    "ldr r1, [{par}, #40]",
                    "ldm {par}, {{r2-r7}}",
                    "2:",
                    // column dx = -1: Hx(py) = max(I(py,1) + GX0, I(py,0) + GX1)
                    concat!($ld, " r8, [r0, #{i1}]"), "add r8, r2, r8, lsl #4",
                    concat!($ld, " r11, [r0, #{i0}]"), "add r11, r3, r11, lsl #4",
                    "cmp r8, r11", "it lt", "movlt r8, r11",
                    concat!($ld, " r9, [r0, #{i4}]"), "add r9, r2, r9, lsl #4",
                    concat!($ld, " r11, [r0, #{i3}]"), "add r11, r3, r11, lsl #4",
                    "cmp r9, r11", "it lt", "movlt r9, r11",
                    concat!($ld, " r10, [r0, #{i7}]"), "add r10, r2, r10, lsl #4",
                    concat!($ld, " r11, [r0, #{i6}]"), "add r11, r3, r11, lsl #4",
                    "cmp r10, r11", "it lt", "movlt r10, r11",
                    // states (dy 0, -1, +1): max over ey
                    "add r11, r10, r5", "add r12, r9, r6", "cmp r11, r12", "it lt", "movlt r11, r12",
                    "add r12, r8, r7", "cmp r11, r12", "it lt", "movlt r11, r12",
                    "ssat r12, #{bits}, r11, asr #4", concat!($st, " r12, [r1, #{o3}]"),
                    "bfi lr, r11, #8, #4",
                    "add r8, r8, r6", "add r12, r9, r5", "cmp r8, r12", "it lt", "movlt r8, r12",
                    "ssat r12, #{bits}, r8, asr #4", concat!($st, " r12, [r1, #{o0}]"),
                    "bfi lr, r8, #0, #4",
                    "add r10, r10, r6", "add r9, r9, r7", "cmp r10, r9", "it lt", "movlt r10, r9",
                    "ssat r12, #{bits}, r10, asr #4", concat!($st, " r12, [r1, #{o6}]"),
                    "bfi lr, r10, #16, #4",
                    // column dx = 0: max(I(py,2) + GX0, I(py,1) + GX1, I(py,0) + GX2)
                    concat!($ld, " r8, [r0, #{i2}]"), "add r8, r2, r8, lsl #4",
                    concat!($ld, " r11, [r0, #{i1}]"), "add r11, r3, r11, lsl #4",
                    "cmp r8, r11", "it lt", "movlt r8, r11",
                    concat!($ld, " r11, [r0, #{i0}]"), "add r11, r4, r11, lsl #4",
                    "cmp r8, r11", "it lt", "movlt r8, r11",
                    concat!($ld, " r9, [r0, #{i5}]"), "add r9, r2, r9, lsl #4",
                    concat!($ld, " r11, [r0, #{i4}]"), "add r11, r3, r11, lsl #4",
                    "cmp r9, r11", "it lt", "movlt r9, r11",
                    concat!($ld, " r11, [r0, #{i3}]"), "add r11, r4, r11, lsl #4",
                    "cmp r9, r11", "it lt", "movlt r9, r11",
                    concat!($ld, " r10, [r0, #{i8}]"), "add r10, r2, r10, lsl #4",
                    concat!($ld, " r11, [r0, #{i7}]"), "add r11, r3, r11, lsl #4",
                    "cmp r10, r11", "it lt", "movlt r10, r11",
                    concat!($ld, " r11, [r0, #{i6}]"), "add r11, r4, r11, lsl #4",
                    "cmp r10, r11", "it lt", "movlt r10, r11",
                    "add r11, r10, r5", "add r12, r9, r6", "cmp r11, r12", "it lt", "movlt r11, r12",
                    "add r12, r8, r7", "cmp r11, r12", "it lt", "movlt r11, r12",
                    "ssat r12, #{bits}, r11, asr #4", concat!($st, " r12, [r1, #{o4}]"),
                    "bfi lr, r11, #12, #4",
                    "add r8, r8, r6", "add r12, r9, r5", "cmp r8, r12", "it lt", "movlt r8, r12",
                    "ssat r12, #{bits}, r8, asr #4", concat!($st, " r12, [r1, #{o1}]"),
                    "bfi lr, r8, #4, #4",
                    "add r10, r10, r6", "add r9, r9, r7", "cmp r10, r9", "it lt", "movlt r10, r9",
                    "ssat r12, #{bits}, r10, asr #4", concat!($st, " r12, [r1, #{o7}]"),
                    "bfi lr, r10, #20, #4",
                    // column dx = +1: max(I(py,2) + GX1, I(py,1) + GX2)
                    concat!($ld, " r8, [r0, #{i2}]"), "add r8, r3, r8, lsl #4",
                    concat!($ld, " r11, [r0, #{i1}]"), "add r11, r4, r11, lsl #4",
                    "cmp r8, r11", "it lt", "movlt r8, r11",
                    concat!($ld, " r9, [r0, #{i5}]"), "add r9, r3, r9, lsl #4",
                    concat!($ld, " r11, [r0, #{i4}]"), "add r11, r4, r11, lsl #4",
                    "cmp r9, r11", "it lt", "movlt r9, r11",
                    concat!($ld, " r10, [r0, #{i8}]"), "add r10, r3, r10, lsl #4",
                    concat!($ld, " r11, [r0, #{i7}]"), "add r11, r4, r11, lsl #4",
                    "cmp r10, r11", "it lt", "movlt r10, r11",
                    "add r11, r10, r5", "add r12, r9, r6", "cmp r11, r12", "it lt", "movlt r11, r12",
                    "add r12, r8, r7", "cmp r11, r12", "it lt", "movlt r11, r12",
                    "ssat r12, #{bits}, r11, asr #4", concat!($st, " r12, [r1, #{o5}]"),
                    "add r8, r8, r6", "add r12, r9, r5", "cmp r8, r12", "it lt", "movlt r8, r12",
                    "ssat r12, #{bits}, r8, asr #4", concat!($st, " r12, [r1, #{o2}]"),
                    "add r10, r10, r6", "add r9, r9, r7", "cmp r10, r9", "it lt", "movlt r10, r9",
                    "ssat r12, #{bits}, r10, asr #4", concat!($st, " r12, [r1, #{o8}]"),
                    // the pointer code: keys of states 8 (r10), 2 (r8), 5 (r11), nibbles in lr
                    "ldr r12, [sp]",
                    "ldr r3, [r12, #24]",
                    "and r4, r10, #15",
                    "ldr r4, [r3, r4, lsl #2]",
                    "ubfx r5, lr, #0, #8", "add r5, r3, r5, lsl #2", "ldr r5, [r5, #64]", "add r4, r5",
                    "ubfx r5, lr, #8, #8", "add r5, r3, r5, lsl #2", "ldr r5, [r5, #1088]", "add r4, r5",
                    "ubfx r5, lr, #16, #8", "add r5, r3, r5, lsl #2", "ldr r5, [r5, #2112]", "add r4, r5",
                    "and r5, r8, #15", "bfi r5, r11, #4, #4",
                    "add r5, r3, r5, lsl #2", "ldr r5, [r5, #3136]", "add r4, r5",
                    // append the code's 22 bits to the writer (`BitWriter::push`)
                    "ldr r5, [r12, #52]",
                    "ldr r3, [r12, #48]",
                    "lsl r6, r4, r5",
                    "orr r3, r3, r6",
                    "adds r5, r5, #22",
                    "cmp r5, #32",
                    "blo 3f",
                    "ldr r6, [r12, #44]",
                    "str r3, [r6], #4",
                    "str r6, [r12, #44]",
                    "subs r5, r5, #32",
                    "rsb r6, r5, #22",
                    "lsr r3, r4, r6",
                    "3:",
                    "str r5, [r12, #52]",
                    "str r3, [r12, #48]",
                    "add r0, r0, #{csz}",
                    "add r1, r1, #{rsz}",
                    "ldr r5, [r12, #28]",
                    "cmp r0, r5",
                    "ldm r12, {{r2-r7}}",
                    "bne 2b",
                    "add sp, sp, #4",
                    "pop {{r4-r11, lr}}",
                    par = in(reg) par.as_mut_ptr(),
                    i0 = const 0, i1 = const core::mem::size_of::<C>(), i2 = const 2 * core::mem::size_of::<C>(), i3 = const 3 * core::mem::size_of::<C>(),
                    i4 = const 4 * core::mem::size_of::<C>(), i5 = const 5 * core::mem::size_of::<C>(), i6 = const 6 * core::mem::size_of::<C>(), i7 = const 7 * core::mem::size_of::<C>(),
                    i8 = const 8 * core::mem::size_of::<C>(),
                    o0 = const off::<ROT>(0, core::mem::size_of::<C>()), o1 = const off::<ROT>(1, core::mem::size_of::<C>()),
                    o2 = const off::<ROT>(2, core::mem::size_of::<C>()), o3 = const off::<ROT>(3, core::mem::size_of::<C>()),
                    o4 = const off::<ROT>(4, core::mem::size_of::<C>()), o5 = const off::<ROT>(5, core::mem::size_of::<C>()),
                    o6 = const off::<ROT>(6, core::mem::size_of::<C>()), o7 = const off::<ROT>(7, core::mem::size_of::<C>()),
                    o8 = const off::<ROT>(8, core::mem::size_of::<C>()),
                    bits = const 8 * core::mem::size_of::<C>(),
                    csz = const 9 * core::mem::size_of::<C>(),
                    rsz = const 27 * core::mem::size_of::<C>(),
                    out("r0") _, out("r1") _, out("r2") _, out("r3") _, out("r12") _, out("lr") _,
                );
            }
        };
    }
    if sz == 2 {
        row!("ldrsh", "strh");
    } else {
        row!("ldrsb", "strb");
    }
    let (w1, a1, f1) = (par[11], par[12], par[13]);
    *acc = a1;
    *fill = f1;
    bw.skip((w1.wrapping_sub(w0) / 4) as usize);
    true
}

/// The new merits of one row from the ring in Cortex-M4 assembly (`q_B = 9`), the
/// arithmetic of [`SecondOrderDp::run_fast`]'s portable loop: `I(x, s) = sat(zq(x) +
/// J(x, s))` for the `M` pixels (`ring` from row `y`'s cell of pixel 0, every third
/// cell), two states per register, the row's largest merit kept per halfword
/// (`ssub16`/`sel`); returns it. `i16`: `qadd16` (exact when every `zq` is an `i16`,
/// `q16` true; else `None`); `i8`: `qadd8`, four states per register, when every `zq`
/// is an `i8` (`q16` true), else `sxtb16`, `sadd16`, `ssat16 #8` (always exact).
#[cfg(faint_m4_asm)]
#[allow(unsafe_code)]
#[inline(always)]
fn scatter_asm<C: MeritCell, const QB: usize, const M: usize>(
    ring: &[[C; QB]],
    row: &mut [[C; QB]; M],
    zrow: &[i32; M],
    q16: bool,
) -> Option<i32> {
    let sz = core::mem::size_of::<C>();
    if QB != 9 || ring.len() < 3 * M || M == 0 || (sz == 2 && !q16) {
        return None;
    }
    let mut rp = ring.as_ptr();
    let mut op = row.as_mut_ptr();
    let mut zp = zrow.as_ptr();
    let end = zp.wrapping_add(M);
    let (mut mx, mut m8) = if sz == 1 && q16 {
        (0x8080_8080u32, 0x8080_8080u32)
    } else {
        (0x8000_8000u32, 0x8000_8000u32)
    };
    if sz == 2 {
        // SAFETY: reads `ring` cells `0, 3, .., 3 (M - 1)` (18 bytes each, checked above)
        // and `zrow`, writes the `M` cells of `row`; no stack, flags only.
        unsafe {
            core::arch::asm!(
                "2:",
                "ldr {z}, [{zp}], #4",
                "pkhbt {z}, {z}, {z}, lsl #16",
                "ldr {a}, [{rp}], #54",
                "qadd16 {a}, {a}, {z}",
                "str {a}, [{op}], #18",
                "ssub16 {t}, {a}, {mx}",
                "sel {mx}, {a}, {mx}",
                ".irp o, 4, 8, 12",
                "ldr {a}, [{rp}, #(\\o - 54)]",
                "qadd16 {a}, {a}, {z}",
                "str {a}, [{op}, #(\\o - 18)]",
                "ssub16 {t}, {a}, {mx}",
                "sel {mx}, {a}, {mx}",
                ".endr",
                "ldrsh {a}, [{rp}, #-38]",
                "qadd16 {a}, {a}, {z}",
                "strh {a}, [{op}, #-2]",
                "ssub16 {t}, {a}, {m8}",
                "sel {m8}, {a}, {m8}",
                "cmp {zp}, {end}",
                "bne 2b",
                zp = inout(reg) zp,
                rp = inout(reg) rp,
                op = inout(reg) op,
                mx = inout(reg) mx,
                m8 = inout(reg) m8,
                end = in(reg) end,
                z = out(reg) _,
                a = out(reg) _,
                t = out(reg) _,
                options(nostack),
            );
        }
    } else if q16 {
        // SAFETY: reads `ring` cells `0, 3, .., 3 (M - 1)` (9 bytes each, checked above)
        // and `zrow`, writes the `M` cells of `row`; no stack, flags only.
        unsafe {
            core::arch::asm!(
                "2:",
                "ldr {z}, [{zp}], #4",
                "uxtb {z}, {z}",
                "orr {z}, {z}, {z}, lsl #8",
                "orr {z}, {z}, {z}, lsl #16",
                "ldr {a}, [{rp}], #27",
                "qadd8 {a}, {a}, {z}",
                "str {a}, [{op}], #9",
                "ssub8 {t}, {a}, {mx}",
                "sel {mx}, {a}, {mx}",
                "ldr {a}, [{rp}, #-23]",
                "qadd8 {a}, {a}, {z}",
                "str {a}, [{op}, #-5]",
                "ssub8 {t}, {a}, {mx}",
                "sel {mx}, {a}, {mx}",
                "ldrb {a}, [{rp}, #-19]",
                "qadd8 {a}, {a}, {z}",
                "strb {a}, [{op}, #-1]",
                "ssub8 {t}, {a}, {m8}",
                "sel {m8}, {a}, {m8}",
                "cmp {zp}, {end}",
                "bne 2b",
                zp = inout(reg) zp,
                rp = inout(reg) rp,
                op = inout(reg) op,
                mx = inout(reg) mx,
                m8 = inout(reg) m8,
                end = in(reg) end,
                z = out(reg) _,
                a = out(reg) _,
                t = out(reg) _,
                options(nostack),
            );
        }
        let _ = (rp, op, zp);
        let b = |v: u32| i32::from(v as u8 as i8);
        return Some(
            b(mx)
                .max(b(mx >> 8))
                .max(b(mx >> 16))
                .max(b(mx >> 24))
                .max(b(m8)),
        );
    } else {
        // SAFETY: reads `ring` cells `0, 3, .., 3 (M - 1)` (9 bytes each, checked above)
        // and `zrow`, writes the `M` cells of `row`; no stack, flags only.
        unsafe {
            core::arch::asm!(
                "2:",
                "ldr {z}, [{zp}], #4",
                "pkhbt {zz}, {z}, {z}, lsl #16",
                "ldr {w}, [{rp}], #27",
                ".irp o, 0, 4",
                ".if \\o",
                "ldr {w}, [{rp}, #(\\o - 27)]",
                ".endif",
                "sxtb16 {a}, {w}",
                "sxtb16 {b}, {w}, ror #8",
                "sadd16 {a}, {a}, {zz}",
                "sadd16 {b}, {b}, {zz}",
                "ssat16 {a}, #8, {a}",
                "ssat16 {b}, #8, {b}",
                "ssub16 {w}, {a}, {mx}",
                "sel {mx}, {a}, {mx}",
                "ssub16 {w}, {b}, {mx}",
                "sel {mx}, {b}, {mx}",
                "and {a}, {a}, #0x00FF00FF",
                "and {b}, {b}, #0x00FF00FF",
                "orr {a}, {a}, {b}, lsl #8",
                ".if \\o",
                "str {a}, [{op}, #(\\o - 9)]",
                ".else",
                "str {a}, [{op}], #9",
                ".endif",
                ".endr",
                "ldrsb {a}, [{rp}, #-19]",
                "add {a}, {a}, {z}",
                "ssat {a}, #8, {a}",
                "strb {a}, [{op}, #-1]",
                "ssub16 {w}, {a}, {m8}",
                "sel {m8}, {a}, {m8}",
                "cmp {zp}, {end}",
                "bne 2b",
                zp = inout(reg) zp,
                rp = inout(reg) rp,
                op = inout(reg) op,
                mx = inout(reg) mx,
                m8 = inout(reg) m8,
                end = in(reg) end,
                z = out(reg) _,
                zz = out(reg) _,
                w = out(reg) _,
                a = out(reg) _,
                b = out(reg) _,
                options(nostack),
            );
        }
    }
    let _ = (rp, op, zp);
    let h = |v: u32| i32::from(v as u16 as i16);
    Some(h(mx).max(h(mx >> 16)).max(h(m8)))
}

/// Byte offset, from ring cell `3 x`, of state `s = 3 (dy + 1) + dx + 1` of source pixel
/// `x` in row `rr` (`rr mod 3 = ROT`): cell `3 (x + dx + 1) + (rr + dy) mod 3`.
#[cfg(faint_m4_asm)]
const fn off<const ROT: usize>(s: usize, sz: usize) -> usize {
    let (dyi, dxi) = (s / 3, s % 3);
    ((3 * dxi + (ROT + dyi + 2) % 3) * 9 + s) * sz
}

/// Keys `[GX(-1..=1), GY(-1..=1)]` of a separable transition term
/// `g(ex, ey) = gx(ex) + gy(ey)`: `GX = gx << 4 | (ex + 1)`, `GY = gy << 4 | (ey + 1) << 2`
/// (`gx` the row `ey = 0`, `gy(ey) = g(0, ey) - g(0, 0)`); `None` if `g` is not separable
/// (the Gaussian of eq. 16 is, up to the rounding of the table; the hard window is).
pub(crate) fn separable(g: &[i32; 9]) -> Option<[i32; 6]> {
    let gx = [g[3], g[4], g[5]];
    let gy = [g[1] - g[4], 0, g[7] - g[4]];
    for (i, &v) in g.iter().enumerate() {
        if gx[i % 3] + gy[i / 3] != v {
            return None;
        }
    }
    Some([
        gx[0] << 4,
        (gx[1] << 4) | 1,
        (gx[2] << 4) | 2,
        gy[0] << 4,
        (gy[1] << 4) | 4,
        (gy[2] << 4) | 8,
    ])
}

/// Bits of one pixel's pointer code for `q_B = qb` (0 if unsupported).
pub(crate) const fn code_bits(qb: usize) -> u32 {
    layout(qb).bits
}

/// Second-order DP-TBD on `M x M` images with `q_B = QB` (9 or 25) state pairs per pixel
/// and `q_I = 9`, tracks over `L` frames, `W = second_order_words(M, QB, L)`
/// back-pointer words, merits stored as `C`.
#[derive(Debug, Clone)]
pub struct SecondOrderDp<
    const M: usize,
    const QB: usize,
    const L: usize,
    const W: usize,
    C: MeritCell = i16,
> {
    cfg: DpConfig,
    configured: bool,
    quant: Quant,
    tally: Tally,
    ends: Ends,
    g: [i32; 9],
    /// `Some` keys `[GX(ex), GY(ey)]` when `g(e) = gx(ex) + gy(ey)` (see `separable`).
    sep: Option<[i32; 6]>,
    s: [[[C; QB]; M]; M],
    jring: [[[C; QB]; M]; JROWS],
    zrow: [i32; M],
    ptr: [u32; W],
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell>
    SecondOrderDp<M, QB, L, W, C>
{
    const LAY: Layout = layout(QB);
    const R: usize = Self::LAY.r;
    const N: usize = 2 * Self::R + 1;
    const BITS: usize = Self::LAY.bits as usize;
    const WF: usize = (M * M * Self::BITS).div_ceil(32);
    const LP: usize = L.saturating_sub(2);
    const SHAPE: () = assert!(
        W == Self::LP * Self::WF,
        "W must be dp::second_order_words(M, QB, L)"
    );

    /// A detector for `cfg` (validated here).
    pub fn new(cfg: DpConfig) -> Result<Self> {
        let mut d = Self::unconfigured();
        d.configure(&cfg, 0)?;
        Ok(d)
    }

    /// A zeroed detector for `static` storage; `step` returns
    /// `Error::InvalidConfig("unconfigured")` until [`Detector::configure`] succeeds.
    pub const fn unconfigured() -> Self {
        let () = Self::SHAPE;
        Self {
            cfg: DpConfig::dim_point(Method::SecondOrder, 1),
            configured: false,
            quant: Quant::zero(),
            tally: Tally::new(),
            ends: Ends::new(),
            g: [0; 9],
            sep: None,
            s: [[[C::ZERO; QB]; M]; M],
            jring: [[[C::ZERO; QB]; M]; JROWS],
            zrow: [0; M],
            ptr: [0; W],
        }
    }

    /// The distinct track ends of the last frame, best first.
    pub fn ends(&self) -> &[TrackEnd] {
        self.ends.as_slice()
    }

    /// The transition term `g(e)` in LSB, index `(ey + 1) 3 + (ex + 1)`.
    pub fn transition(&self) -> [i32; 9] {
        self.g
    }

    /// Merit (intensity) of state `(t, t - d)` at pixel `t = (x, y)`, `d = (dx, dy)`.
    pub fn pair_merit(&self, x: usize, y: usize, dx: i32, dy: i32) -> Option<f32> {
        let r = Self::R as i32;
        if self.tally.frames == 0 || dx.abs() > r || dy.abs() > r {
            return None;
        }
        let s = ((dy + r) * (2 * r + 1) + dx + r) as usize;
        let v = self.s.get(y)?.get(x)?.get(s)?.get();
        Some(self.tally.merit(v, self.cfg.lsb))
    }

    /// Best state at a pixel: `(state, stored merit)`, ties to the lowest state index.
    #[inline]
    fn best_state(&self, x: usize, y: usize) -> Option<(usize, i32)> {
        let cell = self.s.get(y)?.get(x)?;
        let mut b = (0usize, i32::MIN);
        for (i, c) in cell.iter().enumerate() {
            if c.get() > b.1 {
                b = (i, c.get());
            }
        }
        Some(b)
    }

    #[inline]
    fn raw(&self, x: usize, y: usize) -> Option<i32> {
        self.best_state(x, y).map(|b| b.1)
    }

    /// `J` of merit row `rr` into its ring slot (`plain`: frame 2, `J = I`); with a
    /// writer, appends the pixels' pointer codes.
    fn j_row(
        s: &[[[C; QB]; M]; M],
        jring: &mut [[[C; QB]; M]; JROWS],
        g: &[i32; 9],
        sep: &Option<[i32; 6]>,
        rr: usize,
        plain: bool,
        bw: &mut Option<BitWriter<'_>>,
    ) {
        let lay = &Self::LAY;
        let (Some(src), Some(dst)) = (s.get(rr), jring.get_mut(rr % JROWS)) else {
            return;
        };
        if plain {
            *dst = *src;
            return;
        }
        if let Some(gk) = sep {
            // (the writer in locals for the row, not behind the reference)
            match bw.take() {
                Some(mut w) => {
                    Self::j_row_sep(src, dst, gk, |c, b| w.push(c, b));
                    *bw = Some(w);
                }
                None => Self::j_row_sep(src, dst, gk, |_, _| {}),
            }
            return;
        }
        for (cell, out) in src.iter().zip(dst.iter_mut()) {
            let mut acc = 0u32;
            for (d, o) in out.iter_mut().enumerate() {
                let n = usize::from(lay.nopt.get(d).copied().unwrap_or(0));
                let (Some(oe), Some(os)) = (lay.opt_e.get(d), lay.opt_s.get(d)) else {
                    continue;
                };
                let mut v = FLOOR_KEY;
                for (j, (&e, &p)) in oe.iter().zip(os.iter()).take(n).enumerate() {
                    let (e, p) = (usize::from(e), usize::from(p));
                    let base = cell.get(p).map_or(C::FLOOR, |c| c.get());
                    let ge = g.get(e).copied().unwrap_or(0);
                    let key = ((base + ge) << 4) | j as i32;
                    v = v.max(key);
                }
                *o = C::sat(v >> 4);
                acc = acc * n as u32 + (v & 15) as u32;
                if lay.chunk_last.get(d).copied().unwrap_or(false) {
                    if let Some(w) = bw.as_mut() {
                        w.push(acc, u32::from(lay.chunk_bits.get(d).copied().unwrap_or(1)));
                    }
                    acc = 0;
                }
            }
        }
    }

    /// `J` of one row when `g` is separable ([`Self::j_cell_sep`] per pixel).
    #[inline(always)]
    fn j_row_sep(
        src: &[[C; QB]; M],
        dst: &mut [[C; QB]; M],
        gk: &[i32; 6],
        mut push: impl FnMut(u32, u32),
    ) {
        let gk = *gk;
        for (cell, out) in src.iter().zip(dst.iter_mut()) {
            Self::j_cell_sep(cell, &gk, out, &mut push);
        }
    }

    /// `J` of one pixel when `g` is separable: `J(d) = max_ey [GY(ey) + Hx(d - (0, ey), dx)]`,
    /// `Hx(p_y, dx) = max_ex [I(p) << 4 + GX(ex)]` (row maxima shared by the states). The
    /// keys carry `(ey + 1) << 2 | (ex + 1)`, ordered like the candidate index `j` (both
    /// ascend in `e`), so the winner and its pointer are those of the plain 2-D max.
    #[inline(always)]
    fn j_cell_sep(
        cell: &[C; QB],
        gk: &[i32; 6],
        out: &mut [C; QB],
        push: &mut impl FnMut(u32, u32),
    ) {
        let lay = &Self::LAY;
        let n = Self::N;
        // hx[p_y][dx] over ex with p_x = dx - ex inside the window
        let mut hx = [[FLOOR_KEY; 5]; 5];
        for (pyi, hrow) in hx.iter_mut().enumerate().take(n) {
            for (dxi, h) in hrow.iter_mut().enumerate().take(n) {
                // (`first`: the first candidate starts the max; constant once unrolled)
                let (mut v, mut first) = (FLOOR_KEY, true);
                for (cx, &gx) in gk.iter().enumerate().take(3) {
                    let pxi = (dxi + 1).wrapping_sub(cx);
                    if pxi < n {
                        let i = cell.get(pyi * n + pxi).map_or(C::FLOOR, |c| c.get());
                        let key = (i << 4) + gx;
                        v = if first || key > v { key } else { v };
                        first = false;
                    }
                }
                *h = v;
            }
        }
        let (mut acc, mut prev) = (0u32, 0i32);
        for (d, o) in out.iter_mut().enumerate() {
            let (dyi, dxi) = (d / n, d % n);
            let (mut v, mut first) = (FLOOR_KEY, true);
            for (cy, &gy) in gk.iter().skip(3).enumerate() {
                let pyi = (dyi + 1).wrapping_sub(cy);
                if pyi < n {
                    let h = hx
                        .get(pyi)
                        .and_then(|h| h.get(dxi))
                        .map_or(FLOOR_KEY, |&h| h);
                    let key = h + gy;
                    v = if first || key > v { key } else { v };
                    first = false;
                }
            }
            *o = C::sat(v >> 4);
            // the chunk's code, sum of j suffix[d] (the candidate index j of the
            // winner's code, from a table; states 2i - 1, 2i of one chunk as a pair)
            let last = lay.chunk_last.get(d).copied().unwrap_or(false);
            let paired = d % 2 == 1 && d + 1 < QB && !last;
            if d % 2 == 0 && d > 0 && !lay.chunk_last.get(d - 1).copied().unwrap_or(true) {
                let c = ((prev & 15) | ((v & 15) << 4)) as usize;
                let term = lay.jpair.get(d / 2 - 1).map_or(0, |t| t[c]);
                acc = acc.wrapping_add(term);
            } else if !paired {
                let term = lay.jterm.get(d).map_or(0, |t| t[(v & 15) as usize]);
                acc = acc.wrapping_add(term);
            }
            prev = v;
            if last {
                push(acc, u32::from(lay.chunk_bits.get(d).copied().unwrap_or(1)));
                acc = 0;
            }
        }
    }

    /// `J` of merit row `rr` (`q_B = 9`, separable `g`) written at the target pixels
    /// `t = t' + d` in the ring of [`Self::run_fast`] (state `d = (dx, dy)` of pixel `x`
    /// into cell `3 (x + 1 + dx) + (rr + dy) mod 3`); the pixels' pointer codes appended
    /// to `bw` (on the Cortex-M4 by [`j_row_asm`], else through `codes` with
    /// [`Self::j_cell_sep`]: the same).
    #[inline(always)]
    fn jrow_fast(
        states: &[[[C; QB]; M]; M],
        ring: &mut [[C; QB]],
        rr: usize,
        gk: &[i32; 6],
        codes: &mut [i32; M],
        bw: &mut Option<BitWriter<'_>>,
    ) {
        let Some(src) = states.get(rr) else {
            return;
        };
        if ring.len() < 3 * (M + 2) || QB != 9 {
            return;
        }
        #[cfg(faint_m4_asm)]
        if let Some(w) = bw.as_mut() {
            let done = match rr % 3 {
                0 => j_row_asm::<C, QB, M, 0>(src, ring, gk, w),
                1 => j_row_asm::<C, QB, M, 1>(src, ring, gk, w),
                _ => j_row_asm::<C, QB, M, 2>(src, ring, gk, w),
            };
            if done {
                return;
            }
        }
        let gk = *gk;
        let mut o = [C::ZERO; QB];
        for (x, (cell, code)) in src.iter().zip(codes.iter_mut()).enumerate() {
            let mut acc = 0u32;
            Self::j_cell_sep(cell, &gk, &mut o, &mut |c, _| acc = c);
            *code = acc as i32;
            let Some(t) = ring.get_mut(3 * x..3 * x + 9) else {
                continue;
            };
            for (s, &v) in o.iter().enumerate().take(9) {
                let (dyi, dxi) = (s / 3, s % 3);
                if let Some(c) = t
                    .get_mut(3 * dxi + (rr + dyi + 2) % 3)
                    .and_then(|c| c.get_mut(s))
                {
                    *c = v;
                }
            }
        }
        if let Some(w) = bw.as_mut() {
            for &c in codes.iter() {
                w.push(c as u32, Self::LAY.bits);
            }
        }
    }

    /// The fast frame (`q_B = 9`, separable `g`, `k >= 3`): `J` at the target pixels in
    /// a ring of three padded rows interleaved per pixel (target row `y`, pixel `x` in
    /// cell `3 (x + 1) + y mod 3` of `jring`), so the new merits read one contiguous cell
    /// per pixel. Sources outside the image stay at the floor (cells never written).
    /// Returns the best stored merit and its pixel, and the clamp count.
    fn run_fast(
        &mut self,
        frame: &[f32],
        sub: i32,
        slow: bool,
        gk: &[i32; 6],
        k: u32,
    ) -> (i32, (u16, u16), u32) {
        let floor = C::sat(C::FLOOR);
        let Self {
            s: states,
            jring,
            zrow,
            quant,
            ptr,
            ..
        } = self;
        let slot = (k.saturating_sub(3) as usize) % Self::LP.max(1);
        let words: &mut [u32] = ptr
            .get_mut(slot * Self::WF..(slot + 1) * Self::WF)
            .unwrap_or(&mut []);
        let mut bw = if words.is_empty() {
            None
        } else {
            Some(BitWriter::new(words))
        };
        let ring = jring.as_flattened_mut();
        let ring = ring.get_mut(..3 * (M + 2)).unwrap_or(&mut []);
        let fill = |ring: &mut [[C; QB]], cells: core::ops::Range<usize>, st: [usize; 3]| {
            for c in ring.iter_mut().take(cells.end).skip(cells.start) {
                for i in st {
                    if let Some(c) = c.get_mut(i) {
                        *c = floor;
                    }
                }
            }
        };
        // the cells no source writes: pixel 0's states dx = +1, pixel M - 1's dx = -1,
        // row 0's dy = +1
        fill(ring, 3..6, [2, 5, 8]);
        fill(ring, 3 * M..3 * M + 3, [0, 3, 6]);
        for x in 0..M {
            fill(ring, 3 * x + 3..3 * x + 4, [6, 7, 8]);
        }
        let mut clamped = 0;
        let (mut best, mut bxy) = (i32::MIN, (0u16, 0u16));
        // every zq = round(z / lsb) - sub, |round(z / lsb)| <= ZMAX, is a cell value
        #[cfg(faint_m4_asm)]
        let q16 = {
            let cmax = C::sat(i32::MAX).get();
            sub >= C::ZMAX - cmax && sub <= cmax + 1 - C::ZMAX
        };
        Self::jrow_fast(states, ring, 0, gk, zrow, &mut bw);
        for (y, src) in frame.chunks_exact(M).enumerate() {
            if y + 1 < M {
                Self::jrow_fast(states, ring, y + 1, gk, zrow, &mut bw);
            }
            clamped += quant.row(src, sub, slow, zrow);
            let sl = y % 3;
            if y + 1 == M {
                // the last row's states dy = -1
                for x in 0..M {
                    fill(ring, 3 * x + 3 + sl..3 * x + 4 + sl, [0, 1, 2]);
                }
            }
            let Some(row) = states.get_mut(y) else {
                continue;
            };
            let cells = ring.get(3 + sl..).unwrap_or(&[]);
            #[cfg(faint_m4_asm)]
            let asm_rb = scatter_asm::<C, QB, M>(cells, row, zrow, q16);
            #[cfg(not(faint_m4_asm))]
            let asm_rb: Option<i32> = None;
            let (rb, rx) = match asm_rb {
                // (the pixel only when the frame's best rises: the first holding it)
                Some(rb) => (rb, None),
                None => {
                    let (mut rb, mut rx) = (i32::MIN, 0usize);
                    let it = row.iter_mut().zip(zrow.iter()).zip(cells.iter().step_by(3));
                    for (x, ((cell, &zq), j)) in it.enumerate() {
                        let mut pb = i32::MIN;
                        for (c, jv) in cell.iter_mut().zip(j) {
                            *c = C::sat(zq + jv.get());
                            let v = c.get();
                            pb = if v > pb { v } else { pb };
                        }
                        if pb > rb {
                            rb = pb;
                            rx = x;
                        }
                    }
                    (rb, Some(rx))
                }
            };
            if rb > best {
                best = rb;
                let rx = rx.unwrap_or_else(|| {
                    row.iter()
                        .position(|c| c.iter().any(|v| v.get() == rb))
                        .unwrap_or(0)
                });
                bxy = (rx as u16, y as u16);
            }
        }
        if let Some(w) = bw {
            w.finish();
        }
        (best, bxy, clamped)
    }

    fn run(&mut self, frame: &[f32], slow: bool) {
        let k = self.tally.frames + 1;
        let sub = if k == 1 { 0 } else { self.tally.best_raw };
        let mut clamped = 0u32;
        let mut best = i32::MIN;
        let mut bxy = (0u16, 0u16);
        if k == 1 {
            for (y, (row, src)) in self.s.iter_mut().zip(frame.chunks_exact(M)).enumerate() {
                clamped += self.quant.row(src, 0, slow, &mut self.zrow);
                for (x, (cell, &q)) in row.iter_mut().zip(self.zrow.iter()).enumerate() {
                    let c = C::sat(q);
                    *cell = [c; QB];
                    if c.get() > best {
                        best = c.get();
                        bxy = (x as u16, y as u16);
                    }
                }
            }
        } else {
            let r = Self::R;
            let n = Self::N;
            let plain = k == 2;
            if let (Some(gk), true) = (self.sep, QB == 9 && !plain && M >= 3) {
                let (b, xy, c) = self.run_fast(frame, sub, slow, &gk, k);
                self.tally.advance(sub, b, xy, c);
                return;
            }
            let slot = if k >= 3 {
                ((k - 3) as usize) % Self::LP.max(1)
            } else {
                0
            };
            let Self {
                s: states,
                jring,
                ptr,
                zrow,
                quant,
                g,
                sep,
                ..
            } = self;
            let words: &mut [u32] = if plain || Self::LP == 0 {
                &mut []
            } else {
                ptr.get_mut(slot * Self::WF..(slot + 1) * Self::WF)
                    .unwrap_or(&mut [])
            };
            let mut bw = if words.is_empty() {
                None
            } else {
                Some(BitWriter::new(words))
            };
            for rr in 0..r.min(M) {
                Self::j_row(states, jring, g, sep, rr, plain, &mut bw);
            }
            for (y, src) in frame.chunks_exact(M).enumerate() {
                if y + r < M {
                    Self::j_row(states, jring, g, sep, y + r, plain, &mut bw);
                }
                clamped += quant.row(src, sub, slow, zrow);
                let Some(row) = states.get_mut(y) else {
                    continue;
                };
                let jring = &*jring;
                // a pixel with clipped windows: every state checked
                let edge =
                    |x: usize, cell: &mut [C; QB], zq: i32, best: &mut i32, bx: &mut usize| {
                        for (s, c) in cell.iter_mut().enumerate() {
                            let (dx, dy) = (s % Self::N, s / Self::N);
                            let qx = (x + Self::R).wrapping_sub(dx);
                            let qy = (y + Self::R).wrapping_sub(dy);
                            let j = if qx < M && qy < M {
                                jring
                                    .get(qy % JROWS)
                                    .and_then(|jr| jr.get(qx))
                                    .and_then(|jc| jc.get(s))
                                    .map_or(C::FLOOR, |v| v.get())
                            } else {
                                C::FLOOR
                            };
                            *c = C::sat(zq + j);
                            if c.get() > *best {
                                *best = c.get();
                                *bx = x;
                            }
                        }
                    };
                let (mut rb, mut rx) = (i32::MIN, 0usize);
                if y < r || y + r >= M {
                    for (x, (cell, &zq)) in row.iter_mut().zip(zrow.iter()).enumerate() {
                        edge(x, cell, zq, &mut rb, &mut rx);
                    }
                } else {
                    // interior rows: the J rows of the states' predecessors t' = t - d
                    let jr: [&[[C; QB]; M]; 5] = core::array::from_fn(|dy| {
                        let qy = (y + r).wrapping_sub(dy.min(n - 1));
                        &jring[qy % JROWS]
                    });
                    let lo = r.min(M);
                    let hi = M.saturating_sub(r).max(lo);
                    for (x, (cell, &zq)) in row.iter_mut().zip(zrow.iter()).enumerate() {
                        if x < lo || x >= hi {
                            edge(x, cell, zq, &mut rb, &mut rx);
                            continue;
                        }
                        // (the pixel's best first: the same first-in-row-major winner)
                        let mut pb = i32::MIN;
                        for (s, c) in cell.iter_mut().enumerate() {
                            let (dx, dy) = (s % n, s / n);
                            let j = jr[dy % 5]
                                .get((x + r).wrapping_sub(dx))
                                .and_then(|jc| jc.get(s))
                                .map_or(C::FLOOR, |v| v.get());
                            *c = C::sat(zq + j);
                            let v = c.get();
                            pb = if v > pb { v } else { pb };
                        }
                        if pb > rb {
                            rb = pb;
                            rx = x;
                        }
                    }
                }
                if rb > best {
                    best = rb;
                    bxy = (rx as u16, y as u16);
                }
            }
            if let Some(w) = bw {
                w.finish();
            }
        }
        self.tally.advance(sub, best, bxy, clamped);
    }
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell> Detector
    for SecondOrderDp<M, QB, L, W, C>
{
    type Frame = [f32];
    type Config = DpConfig;
    type Report = DpReport;
    const STATE: &'static [&'static str] = STATE;
    const SCORE: ScoreKind = ScoreKind::Merit;
    const UNCONFIGURED: Self = Self::unconfigured();

    /// Checks `cfg` (method `SecondOrder`, `L >= 1`, `q_B` 9 or 25 no larger than the
    /// image), builds the transition table and restarts in place. `seed` is unused.
    fn configure(&mut self, cfg: &DpConfig, _seed: u64) -> Result<()> {
        let () = Self::SHAPE;
        check_shape(cfg, Method::SecondOrder, M, Self::R, L)?;
        let quant = Quant::new(cfg.lsb, C::ZMAX)?;
        self.cfg = *cfg;
        self.quant = quant;
        self.g = transition_table(cfg);
        self.sep = separable(&self.g);
        self.configured = true;
        self.reset(0);
        Ok(())
    }

    fn config(&self) -> &DpConfig {
        &self.cfg
    }

    fn reset(&mut self, _seed: u64) {
        self.tally = Tally::new();
        self.ends = Ends::new();
    }

    fn step(&mut self, frame: &[f32]) -> Result<DpReport> {
        let slow = begin(self.configured, &self.quant, frame, M)?;
        self.run(frame, slow);
        let mut ends = self.ends;
        let r = finish(&self.cfg, &self.tally, &mut ends, M, |x, y| self.raw(x, y));
        self.ends = ends;
        Ok(r)
    }

    fn detection_count(&self) -> usize {
        self.ends.n as usize
    }

    fn detection(&self, i: usize) -> Option<Detection> {
        detection::<Self, L>(self, &self.ends, i)
    }
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell> DpTrack
    for SecondOrderDp<M, QB, L, W, C>
{
    const SIDE: usize = M;
    const HISTORY: usize = L;

    fn frames(&self) -> u32 {
        self.tally.frames
    }

    fn merit(&self, x: usize, y: usize) -> Option<f32> {
        self.tally.merit_of(self.raw(x, y), self.cfg.lsb)
    }

    /// From the best state at `(x, y)` (ties: lowest state index).
    fn track(&self, x: usize, y: usize, out: &mut [[u16; 2]]) -> usize {
        let k = self.tally.frames as usize;
        let Some((mut d, _)) = self.best_state(x, y) else {
            return 0;
        };
        if k == 0 {
            return 0;
        }
        let n = out.len().min(L).min(k);
        let (r, nn) = (Self::R, Self::N);
        let lay = &Self::LAY;
        // (px, py) = t_f, the newest position of the current pair state
        let (mut px, mut py) = (x, y);
        for j in 0..n {
            if j == 0 {
                if let Some(o) = out.get_mut(0) {
                    *o = [px as u16, py as u16];
                }
                continue;
            }
            // predecessor pixel t_{f-1} = t_f - d
            let qx = (px + r).wrapping_sub(d % nn);
            let qy = (py + r).wrapping_sub(d / nn);
            if qx >= M || qy >= M {
                return j;
            }
            if let Some(o) = out.get_mut(j) {
                *o = [qx as u16, qy as u16];
            }
            if j + 1 < n {
                // pointer of frame f = k - j + 1 >= 3 at pixel t_{f-1}, state d
                let f = k - j + 1;
                let slot = (f - 3) % Self::LP.max(1);
                let pix = (slot * Self::WF) * 32 + (qy * M + qx) * Self::BITS;
                let (cb, cbits, suf, nopt) = (
                    usize::from(lay.chunk_bit.get(d).copied().unwrap_or(0)),
                    u32::from(lay.chunk_bits.get(d).copied().unwrap_or(1)),
                    lay.suffix.get(d).copied().unwrap_or(1).max(1),
                    u32::from(lay.nopt.get(d).copied().unwrap_or(1)).max(1),
                );
                let code = read_bits(&self.ptr, pix + cb, cbits);
                let jj = ((code / suf) % nopt) as usize;
                let Some(&next) = lay.opt_s.get(d).and_then(|o| o.get(jj)) else {
                    return j + 1;
                };
                (px, py) = (qx, qy);
                d = usize::from(next);
            }
        }
        n
    }

    fn best(&self) -> Option<TrackEnd> {
        self.ends.as_slice().first().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::super::{second_order_words, DpConfig, Method, Transition};
    use super::{MeritCell, SecondOrderDp};
    use crate::detect::Detector;
    use crate::rng::Rng;

    /// The fast frames (separable `g`, `J` at the target pixels) equal the general 2-D
    /// path exactly: merits, back-pointer words and the best pixel, over frames with
    /// saturating and clamped values.
    fn fast_equals_general<C: MeritCell, const M: usize, const W: usize>(lsb: f32, seed: u64) {
        for transition in [Transition::Gaussian, Transition::Hard] {
            let mut cfg = DpConfig::dim_point(Method::SecondOrder, 1);
            cfg.transition = transition;
            cfg.lsb = lsb;
            let mut a = SecondOrderDp::<M, 9, 5, W, C>::new(cfg).unwrap_or_else(|_| unreachable!());
            let mut b = a.clone();
            assert!(a.sep.is_some());
            b.sep = None;
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
                assert!(a.s == b.s, "merits, frame {k}");
                assert!(a.ptr == b.ptr, "pointers, frame {k}");
                assert_eq!(a.tally.best_raw, b.tally.best_raw, "frame {k}");
                assert_eq!(a.tally.best_xy, b.tally.best_xy, "frame {k}");
            }
        }
    }

    #[test]
    fn fast_frames_equal_the_general_path() {
        for seed in 0..3 {
            fast_equals_general::<i16, 12, { second_order_words(12, 9, 5) }>(0.0625, seed);
            fast_equals_general::<i8, 12, { second_order_words(12, 9, 5) }>(0.0625, seed);
            fast_equals_general::<i16, 7, { second_order_words(7, 9, 5) }>(0.0625, seed);
            fast_equals_general::<i8, 16, { second_order_words(16, 9, 5) }>(0.5, seed);
            fast_equals_general::<i16, 16, { second_order_words(16, 9, 5) }>(0.001, seed);
            fast_equals_general::<i16, 3, { second_order_words(3, 9, 5) }>(0.0625, seed);
        }
    }
}
