//! First-order DP over a hard `q_B` window (Barniv 1985; Arnold, Shaw, Pasternack 1993).
//!
//! ```text
//! I_1(t) = T(z_1(t)),   I_k(t) = T(z_k(t)) + max_{t' in R_B(t)} I_{k-1}(t')   (eq. 8-9)
//! ```
//!
//! The max over the `(2R+1) x (2R+1)` window is separable: a row pass (max over
//! `x - R..=x + R` of the previous frame's merits) and a column pass over `2R + 1` row
//! results. Each candidate is compared as one integer key
//! `merit << 2b | (y' mod 2^b) << b | (x' mod 2^b)` (`b = 2` bits for `R = 1`, 3 above),
//! so a single compare-select per candidate also carries the predecessor's position;
//! among equal merits the larger code wins (a fixed, position-based order). The code of
//! the winner is the back-pointer: 4 bits as is for `q_B = 9`, re-coded to the
//! `ceil(log2 q_B)`-bit window index for larger windows.
//!
//! For `q_B = 9`, even `M` and a frame that needs no clamping, one column pass computes
//! two output rows: the row maxima of four rows are held interleaved per pixel (in the
//! row-key buffer), two new rows per pass, and the middle pair of the two columns is
//! shared. On the Cortex-M4 that pass is DSP assembly; the portable code gives the same
//! merits and back-pointers.
//!
//! Memory ([`arnold_bytes`](super::arnold_bytes)): `M^2 sizeof(C)` merits, `9 M 4`
//! bytes of row keys, `8 M` of row buffers, `4 W = (L - 1) ceil(M^2 b / 32) 4` bytes of
//! back-pointers (`b = 4` for `q_B = 9`: 8 KiB per frame at `M = 128`) and the fixed
//! fields: `M^2 c + 44 M + 4 W + 144` bytes.

use super::bits::{bits_for, code_at, radius_of, BitWriter};
use super::config::{DpConfig, Method};
use super::detector::{DpTbd, Recursion, Tally};
use super::quant::{MeritCell, Quant, MAGIC, MAGIC_BITS};
use crate::Result;

/// Bits of one back-pointer for a `q_B`-pixel window.
pub(crate) const fn ptr_bits(qb: usize) -> u32 {
    match radius_of(qb) {
        0 | 1 => 4,
        _ => bits_for(qb),
    }
}

const FLOOR_KEY: i32 = i32::MIN / 2;
/// Ring slots of row keys (row `r` in slot `r & 7`) and the floor row.
const RING: usize = 8;

#[inline(always)]
fn max_i32(a: i32, b: i32) -> i32 {
    if b > a {
        b
    } else {
        a
    }
}

/// `round(z * inv)` (halves to even) for `|z * inv| < 2^22`.
#[inline(always)]
fn round_q(z: f32, inv: f32) -> i32 {
    ((z * inv + MAGIC).to_bits() as i32).wrapping_sub(MAGIC_BITS)
}

/// One pixel pair of the 3x3 column pass (`ArnoldRecursion::col3`), portable; `best` a plain
/// maximum, the back-pointers into nibble `i` of `acc0`, `acc1`.
#[inline(always)]
fn px3<C: MeritCell, const ROT: bool>(
    cell: &[i32],
    (za, zb): (f32, f32),
    inv: f32,
    (oa, ob): (&mut C, &mut C),
    best: &mut i32,
    (acc0, acc1): (&mut u32, &mut u32),
    i: usize,
) {
    let [s0, s1, s2, s3] = *<&[i32; 4]>::try_from(cell).unwrap_or(&[FLOOR_KEY; 4]);
    let (a, b, c, d) = if ROT {
        (s1, s2, s3, s0)
    } else {
        (s3, s0, s1, s2)
    };
    let pm = max_i32(b, c);
    let v0 = max_i32(a, pm);
    let v1 = max_i32(pm, d);
    let na = C::sat(round_q(za, inv) + (v0 >> 4));
    let nb = C::sat(round_q(zb, inv) + (v1 >> 4));
    *oa = na;
    *ob = nb;
    *best = max_i32(*best, max_i32(na.get(), nb.get()));
    let sh = 4 * (i as u32 & 7);
    let mask = 15u32 << sh;
    *acc0 = (*acc0 & !mask) | (((v0 as u32) << sh) & mask);
    *acc1 = (*acc1 & !mask) | (((v1 as u32) << sh) & mask);
}

/// Eight pixel pairs of the 3x3 column pass ([`px3`]): `zs`, `os` from the chunk's first
/// pixel of row `y` (row `y + 1` at `+ M`); returns the two rows' back-pointer words.
#[inline(always)]
fn chunk3_port<C: MeritCell, const ROT: bool, const M: usize>(
    c: &[i32; 32],
    zs: &[f32],
    os: &mut [C],
    inv: f32,
    best: &mut i32,
) -> (u32, u32) {
    let (mut acc0, mut acc1) = (0u32, 0u32);
    let (o0, o1) = os.split_at_mut(M.min(os.len()));
    for (i, cell) in c.chunks_exact(4).enumerate() {
        let (Some(&za), Some(&zb), Some(oa), Some(ob)) =
            (zs.get(i), zs.get(M + i), o0.get_mut(i), o1.get_mut(i))
        else {
            continue;
        };
        px3::<C, ROT>(
            cell,
            (za, zb),
            inv,
            (oa, ob),
            best,
            (&mut acc0, &mut acc1),
            i,
        );
    }
    (acc0, acc1)
}

/// [`chunk3_port`] (the assembly is the Cortex-M4's).
#[cfg(not(faint_m4_asm))]
#[inline(always)]
fn chunk3<C: MeritCell, const ROT: bool, const M: usize>(
    c: &[i32; 32],
    zs: &[f32],
    os: &mut [C],
    inv: f32,
    best: &mut i32,
) -> (u32, u32) {
    chunk3_port::<C, ROT, M>(c, zs, os, inv, best)
}

/// Eight pixel pairs of the 3x3 column pass in Cortex-M4 assembly, the same arithmetic
/// as [`chunk3_port`]: `zs`, `os` from the chunk's first pixel of row `y` (row `y + 1` at `+ M`),
/// `best` two halfword maxima (`ssub16`/`sel`); returns the two rows' back-pointer words.
/// `vcvtr` rounds to nearest even in the default FPSCR mode, as [`round_q`].
#[cfg(faint_m4_asm)]
#[allow(unsafe_code)]
#[inline(always)]
fn chunk3<C: MeritCell, const ROT: bool, const M: usize>(
    c: &[i32; 32],
    zs: &[f32],
    os: &mut [C],
    inv: f32,
    best: &mut i32,
) -> (u32, u32) {
    if zs.len() < M + 8 || os.len() < M + 8 || M > 255 {
        return (0, 0);
    }
    let (mut cp, mut zp, mut op) = (c.as_ptr(), zs.as_ptr(), os.as_mut_ptr());
    let (acc0, acc1): (u32, u32);
    macro_rules! lanes {
        ($a:literal, $b:literal, $c:literal, $d:literal, $st:literal) => {
            // SAFETY: the block reads the 32 keys of `c`, `zs[0..8]` and `zs[M..M + 8]`,
            // writes `os[0..8]` and `os[M..M + 8]` (lengths checked above), and restores
            // the FPU registers it uses (`vpush`/`vpop`).
            unsafe {
                core::arch::asm!(
                    "vpush {{s0-s2}}",
                    "vmov s2, {acc0}",
                    ".irp sh, 0, 4, 8, 12, 16, 20, 24, 28",
                    "ldm {cp}!, {{r0-r3}}",
                    concat!("cmp ", $b, ", ", $c),
                    "it lt",
                    concat!("movlt ", $b, ", ", $c),
                    concat!("cmp ", $a, ", ", $b),
                    "it lt",
                    concat!("movlt ", $a, ", ", $b),
                    concat!("cmp ", $d, ", ", $b),
                    "it lt",
                    concat!("movlt ", $d, ", ", $b),
                    "vldmia {zp}!, {{s0}}",
                    "vldr s1, [{zp}, #{zoff}]",
                    "vmul.f32 s0, s0, s2",
                    "vmul.f32 s1, s1, s2",
                    "vcvtr.s32.f32 s0, s0",
                    "vcvtr.s32.f32 s1, s1",
                    concat!("vmov ", $c, ", ", $b, ", s0, s1"),
                    concat!("add ", $c, ", ", $c, ", ", $a, ", asr #4"),
                    concat!("add ", $b, ", ", $b, ", ", $d, ", asr #4"),
                    concat!("ssat ", $c, ", #{bits}, ", $c),
                    concat!("ssat ", $b, ", #{bits}, ", $b),
                    concat!($st, " ", $b, ", [{op}, #{ooff}]"),
                    concat!($st, " ", $c, ", [{op}], #{step}"),
                    concat!("pkhbt ", $c, ", ", $c, ", ", $b, ", lsl #16"),
                    concat!("ssub16 ", $b, ", ", $c, ", {best}"),
                    concat!("sel {best}, ", $c, ", {best}"),
                    concat!("bfi {acc0}, ", $a, ", #\\sh, #4"),
                    concat!("bfi {acc1}, ", $d, ", #\\sh, #4"),
                    ".endr",
                    "vpop {{s0-s2}}",
                    cp = inout(reg) cp,
                    zp = inout(reg) zp,
                    op = inout(reg) op,
                    best = inout(reg) *best,
                    acc0 = inout(reg) inv.to_bits() => acc0,
                    acc1 = out(reg) acc1,
                    zoff = const 4 * M - 4,
                    ooff = const M * core::mem::size_of::<C>(),
                    step = const core::mem::size_of::<C>(),
                    bits = const 8 * core::mem::size_of::<C>(),
                    out("r0") _,
                    out("r1") _,
                    out("r2") _,
                    out("r3") _,
                );
            }
        };
    }
    match (ROT, core::mem::size_of::<C>()) {
        // y mod 4 = 0: h(y - 1), h(y), h(y + 1), h(y + 2) in slots 3, 0, 1, 2
        (false, 2) => lanes!("r3", "r0", "r1", "r2", "strh"),
        (false, _) => lanes!("r3", "r0", "r1", "r2", "strb"),
        // y mod 4 = 2: in slots 1, 2, 3, 0
        (true, 2) => lanes!("r1", "r2", "r3", "r0", "strh"),
        (true, _) => lanes!("r1", "r2", "r3", "r0", "strb"),
    }
    let _ = (cp, zp, op);
    (acc0, acc1)
}

/// Writes the low `n` bits (`1..=32`) of `v` at bit `bit` of `words` (outside: dropped).
#[inline(always)]
fn put_bits(words: &mut [u32], bit: usize, v: u32, n: u32) {
    let w = bit >> 5;
    let sh = (bit & 31) as u32;
    if sh == 0 && n == 32 {
        if let Some(d) = words.get_mut(w) {
            *d = v;
        }
        return;
    }
    let mask = if n >= 32 { u32::MAX } else { (1u32 << n) - 1 };
    let v = v & mask;
    if let Some(d) = words.get_mut(w) {
        *d = (*d & !(mask << sh)) | (v << sh);
    }
    if sh + n > 32 {
        let s2 = 32 - sh;
        if let Some(d) = words.get_mut(w + 1) {
            *d = (*d & !(mask >> s2)) | (v >> s2);
        }
    }
}

/// First-order DP-TBD on `M x M` images with a `q_B = QB` window (9, 25 or 49), tracks
/// recoverable over `L` frames, `W = arnold_words(M, QB, L)` back-pointer words, merits
/// stored as `C`: a [`DpTbd`] over an [`ArnoldRecursion`]. Name an instance with
/// [`dp_tbd!`](crate::dp_tbd)`(Arnold, SIDE, WINDOW, HISTORY)` (which computes `W`).
pub type ArnoldDp<
    const SIDE: usize,
    const WINDOW: usize,
    const HISTORY: usize,
    const WORDS: usize,
    C = i16,
> = DpTbd<ArnoldRecursion<SIDE, WINDOW, HISTORY, WORDS, C>>;

/// The merits and back-pointers of [`ArnoldDp`] (`M = SIDE`, `q_B = WINDOW`,
/// `L = HISTORY`, `W = WORDS`).
#[derive(Debug, Clone)]
pub struct ArnoldRecursion<
    const M: usize,
    const QB: usize,
    const L: usize,
    const W: usize,
    C: MeritCell = i16,
> {
    merit: [[C; M]; M],
    hring: [[i32; M]; RING + 1],
    kbuf: [i32; M],
    zrow: [i32; M],
    ptr: [u32; W],
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell>
    ArnoldRecursion<M, QB, L, W, C>
{
    const R: usize = radius_of(QB);
    const PB: u32 = if Self::R <= 1 { 2 } else { 3 };
    const SH: u32 = 2 * Self::PB;
    const PM: usize = (1 << Self::PB) - 1;
    const BITS: u32 = ptr_bits(QB);
    const WF: usize = (M * M * Self::BITS as usize).div_ceil(32);
    const LP: usize = L.saturating_sub(1);
    /// Whether the 3x3 column pass runs as Cortex-M4 assembly (`chunk3`; its offsets
    /// need `M <= 255`).
    const ASM3: bool = cfg!(faint_m4_asm) && M <= 255;
    const SHAPE: () = assert!(
        W == Self::LP * Self::WF,
        "W must be dp::arnold_words(M, QB, L)"
    );

    /// Row keys of merit row `r` into `dst` (max over the clipped row window).
    fn h_row(src: &[C; M], r: usize, dst: &mut [i32; M], kbuf: &mut [i32; M]) {
        let ycode = ((r & Self::PM) << Self::PB) as i32;
        if Self::R == 1 {
            Self::h_row3(src, ycode, dst);
            return;
        }
        for (x, (k, c)) in kbuf.iter_mut().zip(src.iter()).enumerate() {
            *k = (c.get() << Self::SH) | (x & Self::PM) as i32 | ycode;
        }
        let r = Self::R;
        let n = 2 * r + 1;
        // interior: full windows
        for (d, w) in dst.iter_mut().skip(r).zip(kbuf.windows(n)) {
            *d = w.iter().copied().fold(FLOOR_KEY, i32::max);
        }
        // edges: clipped windows
        for x in (0..r.min(M)).chain(M.saturating_sub(r).max(r)..M) {
            let lo = x.saturating_sub(r);
            let hi = (x + r + 1).min(M);
            if let (Some(d), Some(w)) = (dst.get_mut(x), kbuf.get(lo..hi)) {
                *d = w.iter().copied().fold(FLOOR_KEY, i32::max);
            }
        }
    }

    /// The 3x3 row pass: `h(x) = max(p(x - 1), p(x))`, `p(x) = max(k(x), k(x + 1))`
    /// (`k(-1) = k(M) = floor`), one pass, the keys built in registers (their code
    /// repeats every 4 pixels).
    #[inline]
    fn h_row3(src: &[C; M], ycode: i32, dst: &mut [i32; M]) {
        let key = |c: &C, x: i32| (c.get() << 4) | x | ycode;
        let Some((first, rest)) = src.split_first() else {
            return;
        };
        // k = k(x), pp = p(x - 1)
        let mut k = key(first, 0);
        let mut pp = k;
        let mut step = |d: &mut i32, c: &C, xn: i32| {
            let kn = key(c, xn);
            let p = if kn > k { kn } else { k };
            *d = if p > pp { p } else { pp };
            pp = p;
            k = kn;
        };
        let mut di = dst.chunks_exact_mut(4);
        let mut si = rest.chunks_exact(4);
        for (d, c) in di.by_ref().zip(si.by_ref()) {
            if let ([d0, d1, d2, d3], [c1, c2, c3, c4]) = (d, c) {
                step(d0, c1, 1);
                step(d1, c2, 2);
                step(d2, c3, 3);
                step(d3, c4, 0);
            }
        }
        // the last `(M - 1) % 4` pixels with a right neighbour, then the last pixel
        let done = (M - 1) / 4 * 4;
        let (dtail, stail) = (dst.get_mut(done..).unwrap_or(&mut []), si.remainder());
        let mut x = done;
        for (d, c) in dtail.iter_mut().zip(stail) {
            x += 1;
            step(d, c, (x & 3) as i32);
        }
        if let Some(d) = dst.last_mut() {
            *d = if k > pp { k } else { pp };
        }
    }

    /// The column pass of output row `y`: `v = max` over the `2R + 1` row keys, the new
    /// merits `q + (v >> SH)` into `out`, the back-pointers into `bw`; returns the row's
    /// best `(merit, x)` (ties: the first). `q(src[x])` is the quantised pixel.
    #[inline(always)]
    fn col_row<T>(
        rows: &[&[i32; M]; 7],
        src: &[T],
        q: impl Fn(&T) -> i32,
        y: usize,
        out: &mut [C; M],
        bw: &mut BitWriter<'_>,
    ) -> (i32, usize) {
        let n = 2 * Self::R + 1;
        let mask = (1i32 << Self::SH) - 1;
        let bits = Self::BITS;
        let mut best = i32::MIN;
        let mut bx = 0usize;
        let one = |x: usize, v: i32, s: &T, o: &mut C, best: &mut i32, bx: &mut usize| {
            let new = C::sat(q(s) + (v >> Self::SH));
            *o = new;
            let nv = new.get();
            if nv > *best {
                *best = nv;
                *bx = x;
            }
            Self::code(v & mask, x, y)
        };
        let floor8 = [FLOOR_KEY; 8];
        let mut x = 0usize;
        let mut oi = out.chunks_exact_mut(8);
        let mut si = src.chunks_exact(8);
        for (o8, s8) in oi.by_ref().zip(si.by_ref()) {
            let h8: [&[i32; 8]; 7] = core::array::from_fn(|j| {
                rows[j]
                    .get(x..x + 8)
                    .and_then(|h| <&[i32; 8]>::try_from(h).ok())
                    .unwrap_or(&floor8)
            });
            let mut acc = 0u64;
            for (i, (o, s)) in o8.iter_mut().zip(s8).enumerate() {
                // (the first row's key starts the max: every window holds a pixel)
                let mut v = h8[0][i & 7];
                for h in h8.iter().take(n).skip(1) {
                    let h = h[i & 7];
                    v = if h > v { h } else { v };
                }
                let c = one(x + i, v, s, o, &mut best, &mut bx);
                acc |= u64::from(c) << (bits as usize * i);
            }
            if Self::LP > 0 {
                bw.push(acc as u32, 32);
                if bits > 4 {
                    bw.push((acc >> 32) as u32, 8 * bits - 32);
                }
            }
            x += 8;
        }
        for (o, s) in oi.into_remainder().iter_mut().zip(si.remainder()) {
            let mut v = FLOOR_KEY;
            for rw in rows.iter().take(n) {
                let h = rw.get(x).copied().unwrap_or(FLOOR_KEY);
                v = if h > v { h } else { v };
            }
            let c = one(x, v, s, o, &mut best, &mut bx);
            if Self::LP > 0 {
                bw.push(c, bits);
            }
            x += 1;
        }
        (best, bx)
    }

    /// The back-pointer of the winning key code `code` (low `SH` bits) at `(x, y)`: as is
    /// for `q_B = 9`, else the window index `(dy + R)(2R + 1) + (dx + R)`.
    #[inline(always)]
    fn code(code: i32, x: usize, y: usize) -> u32 {
        if Self::R == 1 {
            return code as u32;
        }
        let r = Self::R as i32;
        let pm = Self::PM as i32;
        let cx = code & pm;
        let cy = code >> Self::PB;
        let half = 1 << (Self::PB - 1);
        let wrap = |c: i32, p: usize| {
            let d = (c - (p as i32 & pm)) & pm;
            if d >= half {
                d - (pm + 1)
            } else {
                d
            }
        };
        let n = 2 * r + 1;
        ((wrap(cx, x) + r) + n * (wrap(cy, y) + r)) as u32
    }

    /// Predecessor of pixel `(x, y)` from its back-pointer `code`.
    fn pred(x: usize, y: usize, code: u32) -> (usize, usize) {
        let r = Self::R as i32;
        let (dx, dy) = if Self::R == 1 {
            let cx = (code & 3) as usize;
            let cy = ((code >> 2) & 3) as usize;
            let dx = ((cx + 4 - (x & 3)) & 3) as i32;
            let dy = ((cy + 4 - (y & 3)) & 3) as i32;
            (if dx == 3 { -1 } else { dx }, if dy == 3 { -1 } else { dy })
        } else {
            let n = (2 * r + 1) as u32;
            ((code % n) as i32 - r, (code / n) as i32 - r)
        };
        (
            (x as i32 + dx).max(0) as usize,
            (y as i32 + dy).max(0) as usize,
        )
    }

    /// Row maxima of merit row `src` into slot `S` of the interleaved cells (pixel `x`'s
    /// four slots at `4 x ..`), keys `k(x) = merit << 4 + b + (x mod 4)`
    /// (`k(-1) = k(M) = floor`), two pixels at a time: `P = max(k(x), k(x + 1))`,
    /// `h(x) = max(k(x - 1), P)`, `h(x + 1) = max(P, k(x + 2))` (`M` even).
    #[inline(always)]
    fn h3<const S: usize>(src: &[C; M], b: i32, cells: &mut [i32]) {
        let key = |c: &C, x: i32| (c.get() << 4) + b + x;
        let Some(first) = src.first() else {
            return;
        };
        // km = k(x - 1), k = k(x)
        let (mut km, mut k) = (FLOOR_KEY, key(first, 0));
        let mut pair = |d0: &mut i32, d1: &mut i32, k1: i32, k2: i32| {
            let p = max_i32(k, k1);
            *d0 = max_i32(km, p);
            *d1 = max_i32(p, k2);
            km = k1;
            k = k2;
        };
        let rest = src.get(1..).unwrap_or(&[]);
        let mut si = rest.chunks_exact(4);
        for (d, c) in cells.chunks_exact_mut(16).zip(si.by_ref()) {
            if let (Ok(d), [c1, c2, c3, c4]) = (<&mut [i32; 16]>::try_from(d), c) {
                let (d01, d23) = d.split_at_mut(8);
                let (d0, d1) = d01.split_at_mut(4);
                let (d2, d3) = d23.split_at_mut(4);
                pair(&mut d0[S], &mut d1[S], key(c1, 1), key(c2, 2));
                pair(&mut d2[S], &mut d3[S], key(c3, 3), key(c4, 0));
            }
        }
        // the last pixel pairs (`k(M)` the floor)
        let mut x = (M - 1) / 4 * 4;
        while x + 1 < M {
            let k1 = rest
                .get(x)
                .map_or(FLOOR_KEY, |c| key(c, ((x + 1) & 3) as i32));
            let k2 = rest
                .get(x + 1)
                .map_or(FLOOR_KEY, |c| key(c, ((x + 2) & 3) as i32));
            let (lo, hi) = cells.split_at_mut((4 * (x + 1)).min(cells.len()));
            if let (Some(d0), Some(d1)) = (lo.get_mut(4 * x + S), hi.get_mut(S)) {
                pair(d0, d1, k1, k2);
            }
            x += 2;
        }
    }

    /// Fills slot `S` of the cells with the floor key (the row below the image).
    fn floor3<const S: usize>(cells: &mut [i32]) {
        for c in cells.chunks_exact_mut(4) {
            if let Some(c) = c.get_mut(S) {
                *c = FLOOR_KEY;
            }
        }
    }

    /// The column pass of output rows `y`, `y + 1` (`ROT`: `y mod 4 = 2`) from the cells,
    /// row `r`'s maxima in slot `r mod 4`: `v(y) = max(h(y - 1), h(y), h(y + 1))`,
    /// `v(y + 1) = max(h(y), h(y + 1), h(y + 2))` (the middle pair shared), the new merits
    /// `round(z / lsb) + (v >> 4)` into `oo` (the two rows, `2 M` cells; `zz` their `2 M`
    /// pixels) and the back-pointers `v mod 16` at bit `bit0` of `words` (row `y + 1` at
    /// `bit0 + 4 M`). Returns the largest new merit.
    #[inline(always)]
    fn col3<const ROT: bool>(
        cells: &[i32],
        zz: &[f32],
        oo: &mut [C],
        inv: f32,
        words: &mut [u32],
        bit0: usize,
    ) -> i32 {
        let store = |words: &mut [u32], bit: usize, acc: u32, n: u32| {
            if M.is_multiple_of(8) && n == 32 {
                if let Some(w) = words.get_mut(bit >> 5) {
                    *w = acc;
                }
            } else {
                put_bits(words, bit, acc, n);
            }
        };
        // (with the assembly: the two rows' maxima in the halfwords)
        let mut best = if Self::ASM3 {
            0x8000_8000u32 as i32
        } else {
            i32::MIN
        };
        let n8 = M / 8;
        let mut chunk = |ci: usize, c: &[i32]| {
            let x0 = 8 * ci;
            let (Ok(c), Some(zs), Some(os)) = (
                <&[i32; 32]>::try_from(c),
                zz.get(x0..x0 + M + 8),
                oo.get_mut(x0..x0 + M + 8),
            ) else {
                return (0, 0);
            };
            if Self::ASM3 {
                chunk3::<C, ROT, M>(c, zs, os, inv, &mut best)
            } else {
                chunk3_port::<C, ROT, M>(c, zs, os, inv, &mut best)
            }
        };
        let w = bit0 >> 5;
        match words.get_mut(w..w + M / 4) {
            // rows of whole words: stored in order
            Some(wr) if M.is_multiple_of(8) => {
                let (w0, w1) = wr.split_at_mut(M / 8);
                let it = cells
                    .chunks_exact(32)
                    .enumerate()
                    .zip(w0.iter_mut().zip(w1));
                for ((ci, c), (a0, a1)) in it {
                    (*a0, *a1) = chunk(ci, c);
                }
            }
            _ => {
                for (ci, c) in cells.chunks_exact(32).enumerate().take(n8) {
                    let (acc0, acc1) = chunk(ci, c);
                    store(words, bit0 + 32 * ci, acc0, 32);
                    store(words, bit0 + 4 * M + 32 * ci, acc1, 32);
                }
            }
        }
        if Self::ASM3 {
            best = max_i32(i32::from(best as i16), best >> 16);
        }
        let x0 = 8 * n8;
        if x0 < M {
            let (mut acc0, mut acc1) = (0u32, 0u32);
            let (o0, o1) = oo.split_at_mut(M);
            for x in x0..M {
                let (Some(c), Some(&za), Some(&zb), Some(oa), Some(ob)) = (
                    cells.get(4 * x..4 * x + 4),
                    zz.get(x),
                    zz.get(M + x),
                    o0.get_mut(x),
                    o1.get_mut(x),
                ) else {
                    continue;
                };
                px3::<C, ROT>(
                    c,
                    (za, zb),
                    inv,
                    (oa, ob),
                    &mut best,
                    (&mut acc0, &mut acc1),
                    x - x0,
                );
            }
            let n = 4 * (M - x0) as u32;
            store(words, bit0 + 4 * x0, acc0, n);
            store(words, bit0 + 4 * (M + x0), acc1, n);
        }
        best
    }

    /// The 3x3 recursion on a frame that needs no clamping, `M` even, two output rows
    /// per column pass. Its keys are those of [`Self::h_row3`] less `sub << 4` (so the
    /// winners and back-pointers are the same); the row maxima of four rows are held
    /// interleaved per pixel. Returns the best stored merit and its pixel.
    fn run3(&mut self, frame: &[f32], inv: f32, sub: i32, slot: usize) -> (i32, (u16, u16)) {
        let off = sub.wrapping_shl(4);
        let base = |r: usize| (((r & 3) << 2) as i32).wrapping_sub(off);
        let cells = self.hring.as_flattened_mut();
        let cells = cells.get_mut(..4 * M).unwrap_or(&mut []);
        if let Some(row) = self.merit.first() {
            Self::h3::<0>(row, base(0), cells);
        }
        Self::floor3::<3>(cells);
        let words = self
            .ptr
            .get_mut(slot * Self::WF..(slot + 1) * Self::WF)
            .unwrap_or(&mut []);
        let mut best = i32::MIN;
        let mut bxy = (0u16, 0u16);
        for (j, zz) in frame.chunks_exact(2 * M).enumerate() {
            let y = 2 * j;
            let rot = y & 2 != 0;
            // row maxima of rows y + 1, y + 2 (slots (y + 1) mod 4, (y + 2) mod 4)
            let (r1, r2) = (self.merit.get(y + 1), self.merit.get(y + 2));
            let (b1, b2) = (base(y + 1), base(y + 2));
            match (rot, r1, r2) {
                (false, Some(r1), Some(r2)) => {
                    Self::h3::<1>(r1, b1, cells);
                    Self::h3::<2>(r2, b2, cells);
                }
                (false, Some(r1), None) => {
                    Self::h3::<1>(r1, b1, cells);
                    Self::floor3::<2>(cells);
                }
                (true, Some(r1), Some(r2)) => {
                    Self::h3::<3>(r1, b1, cells);
                    Self::h3::<0>(r2, b2, cells);
                }
                (true, Some(r1), None) => {
                    Self::h3::<3>(r1, b1, cells);
                    Self::floor3::<0>(cells);
                }
                _ => {}
            }
            let Some(oo) = self.merit.get_mut(y..y + 2) else {
                continue;
            };
            let oo = oo.as_flattened_mut();
            let bit0 = y * M * 4;
            let b = if rot {
                Self::col3::<true>(cells, zz, oo, inv, words, bit0)
            } else {
                Self::col3::<false>(cells, zz, oo, inv, words, bit0)
            };
            if b > best {
                best = b;
                // the first pixel of the two rows (row-major) holding it
                let i = oo.iter().position(|c| c.get() == b).unwrap_or(0);
                bxy = ((i % M) as u16, (y + i / M) as u16);
            }
        }
        (best, bxy)
    }
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell> Recursion
    for ArnoldRecursion<M, QB, L, W, C>
{
    const SIDE: usize = M;
    const HISTORY: usize = L;
    const METHOD: Method = Method::Arnold;
    const ZMAX: i32 = C::ZMAX;
    const RADIUS: usize = Self::R;
    const UNCONFIGURED: Self = {
        let () = Self::SHAPE;
        Self {
            merit: [[C::ZERO; M]; M],
            hring: [[0; M]; RING + 1],
            kbuf: [0; M],
            zrow: [0; M],
            ptr: [0; W],
        }
    };
    type Track = [[u16; 2]; L];
    const NO_TRACK: Self::Track = [[0; 2]; L];

    fn configure(&mut self, _cfg: &DpConfig) -> Result<()> {
        let () = Self::SHAPE;
        Ok(())
    }

    fn recurse(
        &mut self,
        frame: &[f32],
        slow: bool,
        _cfg: &DpConfig,
        quant: &Quant,
        tally: &mut Tally,
    ) {
        let k = tally.frames + 1;
        let sub = if k == 1 { 0 } else { tally.best_raw };
        let mut clamped = 0u32;
        let mut best = i32::MIN;
        let mut bxy = (0u16, 0u16);
        if k == 1 {
            for (y, (row, src)) in self.merit.iter_mut().zip(frame.chunks_exact(M)).enumerate() {
                clamped += quant.row(src, 0, slow, &mut self.zrow);
                for (x, (c, &q)) in row.iter_mut().zip(self.zrow.iter()).enumerate() {
                    *c = C::sat(q);
                    let v = c.get();
                    if v > best {
                        best = v;
                        bxy = (x as u16, y as u16);
                    }
                }
            }
        } else {
            let r = Self::R;
            let slot = ((k - 2) as usize) % Self::LP.max(1);
            if !slow && r == 1 && M.is_multiple_of(2) {
                (best, bxy) = self.run3(frame, quant.inv_lsb, sub, slot);
                tally.advance(sub, best, bxy, clamped);
                return;
            }
            self.hring[RING] = [FLOOR_KEY; M];
            for rr in 0..r.min(M) {
                let (src, dst) = (&self.merit[rr], &mut self.hring[rr & (RING - 1)]);
                Self::h_row(src, rr, dst, &mut self.kbuf);
            }
            let words = self
                .ptr
                .get_mut(slot * Self::WF..(slot + 1) * Self::WF)
                .unwrap_or(&mut []);
            let mut bw = BitWriter::new(words);
            let base = Quant::base(sub);
            for (y, src) in frame.chunks_exact(M).enumerate() {
                if y + r < M {
                    let (src, dst) = (&self.merit[y + r], &mut self.hring[(y + r) & (RING - 1)]);
                    Self::h_row(src, y + r, dst, &mut self.kbuf);
                }
                let rows: [&[i32; M]; 7] = core::array::from_fn(|j| {
                    let yy = (y + j) as isize - r as isize;
                    if j < 2 * r + 1 && yy >= 0 && (yy as usize) < M {
                        &self.hring[(yy as usize) & (RING - 1)]
                    } else {
                        &self.hring[RING]
                    }
                });
                let Some(row) = self.merit.get_mut(y) else {
                    continue;
                };
                let (rb, rx) = if slow {
                    clamped += quant.row(src, sub, true, &mut self.zrow);
                    Self::col_row(&rows, &self.zrow, |&q| q, y, row, &mut bw)
                } else {
                    let quant = *quant;
                    Self::col_row(&rows, src, |&z| quant.fast(z, base), y, row, &mut bw)
                };
                if rb > best {
                    best = rb;
                    bxy = (rx as u16, y as u16);
                }
            }
            bw.finish();
        }
        tally.advance(sub, best, bxy, clamped);
    }

    #[inline]
    fn raw(&self, x: usize, y: usize) -> Option<i32> {
        self.merit.get(y)?.get(x).map(|c| c.get())
    }

    /// The back-pointer of frame `f = k - j + 1 >= 2` (slot `(f - 2) mod (L - 1)`) at
    /// position `j - 1`.
    fn trace_back(
        &self,
        k: usize,
        j: usize,
        (x, y): (usize, usize),
        _t: usize,
    ) -> Option<((usize, usize), usize)> {
        let slot = (k - j - 1) % Self::LP.max(1);
        let code = code_at(&self.ptr, slot, Self::WF, y * M + x, Self::BITS);
        Some((Self::pred(x, y, code), 0))
    }
}
