//! The Cortex-M4 kernels of the second-order fast frame (`q_B = 9`, separable `g`): the
//! `J` row and the new merits of a row, in DSP assembly. Each has a portable twin in
//! `portable.rs` / `mod.rs` that gives the same merits and pointers (compared on the
//! target by the golden lines).

#[cfg(faint_m4_asm)]
use super::layout::code_bits;
use super::layout::layout;
#[cfg(faint_m4_asm)]
use crate::detect::dp::bits::BitWriter;
#[cfg(faint_m4_asm)]
use crate::detect::dp::quant::MeritCell;

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

/// One `J` row of `SecondOrderRecursion::jrow_fast` in Cortex-M4 assembly (`q_B = 9`,
/// `rr mod 3 = ROT`), the arithmetic of `SecondOrderRecursion::j_cell_sep`: per column `dx`
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
pub(super) fn j_row_asm<C: MeritCell, const QB: usize, const M: usize, const ROT: usize>(
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
/// arithmetic of `SecondOrderRecursion::run_fast`'s portable loop: `I(x, s) = sat(zq(x) +
/// J(x, s))` for the `M` pixels (`ring` from row `y`'s cell of pixel 0, every third
/// cell), two states per register, the row's largest merit kept per halfword
/// (`ssub16`/`sel`); returns it. `i16`: `qadd16` (exact when every `zq` is an `i16`,
/// `q16` true; else `None`); `i8`: `qadd8`, four states per register, when every `zq`
/// is an `i8` (`q16` true), else `sxtb16`, `sadd16`, `ssat16 #8` (always exact).
#[cfg(faint_m4_asm)]
#[allow(unsafe_code)]
#[inline(always)]
pub(super) fn scatter_asm<C: MeritCell, const QB: usize, const M: usize>(
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
