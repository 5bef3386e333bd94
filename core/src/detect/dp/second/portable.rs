//! The portable kernels of the second-order recursion: `J` of a row (the 2-D max over the
//! candidates, or its separable form) and the separability test of the transition term.

use super::{SecondOrderRecursion, FLOOR_KEY, JROWS};
use crate::detect::dp::bits::BitWriter;
use crate::detect::dp::quant::MeritCell;

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell>
    SecondOrderRecursion<M, QB, L, W, C>
{
    /// `J` of merit row `rr` into its ring slot (`plain`: frame 2, `J = I`); with a
    /// writer, appends the pixels' pointer codes.
    pub(super) fn j_row(
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
    pub(super) fn j_cell_sep(
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
