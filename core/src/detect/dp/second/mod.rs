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
//! Files: `layout.rs` the state and pointer layout, `portable.rs` the portable `J`
//! kernels, `m4.rs` the Cortex-M4 assembly kernels, this file the recursion of a frame
//! and the track recovery.
//!
//! Memory ([`second_order_bytes`](super::second_order_bytes)): `M^2 q_B sizeof(C)`
//! merits, `5 M q_B sizeof(C)` bytes of `J` rows, `4 M` of a row buffer, 64 of transition
//! keys, `4 W = (L - 2) ceil(M^2 b / 32) 4` bytes of back-pointers and 144 of fixed
//! fields. For `M = 128`, `q_B = 9`, `L = 8`: `C = i16` 294 912 + 11 520 + 512 + 64 +
//! 270 336 + 144 = 577 488 B (564 KiB); `C = i8` 147 456 + 5 760 + 512 + 64 + 270 336 +
//! 144 = 424 272 B (414 KiB, within 512 KiB).

mod layout;
mod m4;
mod portable;
#[cfg(test)]
mod tests;

pub(crate) use layout::code_bits;
use layout::{layout, Layout};
use portable::separable;

use super::bits::{read_bits, BitWriter};
use super::config::{transition_table, DpConfig, Method};
use super::detector::{DpTbd, Recursion, Tally};
use super::quant::{MeritCell, Quant};
use crate::Result;

/// Rows of `J` kept (`2R + 1 <= 5`).
const JROWS: usize = 5;
const FLOOR_KEY: i32 = i32::MIN / 2;

/// Second-order DP-TBD on `M x M` images with `q_B = QB` (9 or 25) state pairs per pixel
/// and `q_I = 9`, tracks over `L` frames, `W = second_order_words(M, QB, L)`
/// back-pointer words, merits stored as `C`: a [`DpTbd`] over a
/// [`SecondOrderRecursion`]. Name an instance with
/// [`dp_tbd!`](crate::dp_tbd)`(SecondOrder, SIDE, WINDOW, HISTORY)` (which computes `W`).
pub type SecondOrderDp<
    const SIDE: usize,
    const WINDOW: usize,
    const HISTORY: usize,
    const WORDS: usize,
    C = i16,
> = DpTbd<SecondOrderRecursion<SIDE, WINDOW, HISTORY, WORDS, C>>;

/// The state merits, `J` rows and back-pointers of [`SecondOrderDp`] (`M = SIDE`,
/// `q_B = WINDOW`, `L = HISTORY`, `W = WORDS`).
#[derive(Debug, Clone)]
pub struct SecondOrderRecursion<
    const M: usize,
    const QB: usize,
    const L: usize,
    const W: usize,
    C: MeritCell = i16,
> {
    g: [i32; 9],
    /// `Some` keys `[GX(ex), GY(ey)]` when `g(e) = gx(ex) + gy(ey)` (see `separable`).
    sep: Option<[i32; 6]>,
    s: [[[C; QB]; M]; M],
    jring: [[[C; QB]; M]; JROWS],
    zrow: [i32; M],
    ptr: [u32; W],
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell>
    DpTbd<SecondOrderRecursion<M, QB, L, W, C>>
{
    /// The transition term `g(e)` in LSB, index `(ey + 1) 3 + (ex + 1)`.
    pub fn transition(&self) -> [i32; 9] {
        self.kernel.g
    }

    /// Merit (intensity) of state `(t, t - d)` at pixel `t = (x, y)`, `d = (dx, dy)`.
    pub fn pair_merit(&self, x: usize, y: usize, dx: i32, dy: i32) -> Option<f32> {
        let r = SecondOrderRecursion::<M, QB, L, W, C>::R as i32;
        if self.tally.frames == 0 || dx.abs() > r || dy.abs() > r {
            return None;
        }
        let s = ((dy + r) * (2 * r + 1) + dx + r) as usize;
        let v = self.kernel.s.get(y)?.get(x)?.get(s)?.get();
        Some(self.tally.merit(v, self.cfg.lsb))
    }
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell>
    SecondOrderRecursion<M, QB, L, W, C>
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

    /// `J` of merit row `rr` (`q_B = 9`, separable `g`) written at the target pixels
    /// `t = t' + d` in the ring of [`Self::run_fast`] (state `d = (dx, dy)` of pixel `x`
    /// into cell `3 (x + 1 + dx) + (rr + dy) mod 3`); the pixels' pointer codes appended
    /// to `bw` (on the Cortex-M4 by `m4::j_row_asm`, else through `codes` with
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
                0 => m4::j_row_asm::<C, QB, M, 0>(src, ring, gk, w),
                1 => m4::j_row_asm::<C, QB, M, 1>(src, ring, gk, w),
                _ => m4::j_row_asm::<C, QB, M, 2>(src, ring, gk, w),
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
    #[allow(clippy::too_many_arguments)]
    fn run_fast(
        &mut self,
        frame: &[f32],
        quant: &Quant,
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
            let asm_rb = m4::scatter_asm::<C, QB, M>(cells, row, zrow, q16);
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
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell> Recursion
    for SecondOrderRecursion<M, QB, L, W, C>
{
    const SIDE: usize = M;
    const HISTORY: usize = L;
    const METHOD: Method = Method::SecondOrder;
    const ZMAX: i32 = C::ZMAX;
    const RADIUS: usize = Self::R;
    const UNCONFIGURED: Self = {
        let () = Self::SHAPE;
        Self {
            g: [0; 9],
            sep: None,
            s: [[[C::ZERO; QB]; M]; M],
            jring: [[[C::ZERO; QB]; M]; JROWS],
            zrow: [0; M],
            ptr: [0; W],
        }
    };
    type Track = [[u16; 2]; L];
    const NO_TRACK: Self::Track = [[0; 2]; L];

    /// Builds the transition table and its separable keys.
    fn configure(&mut self, cfg: &DpConfig) -> Result<()> {
        let () = Self::SHAPE;
        self.g = transition_table(cfg);
        self.sep = separable(&self.g);
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
            for (y, (row, src)) in self.s.iter_mut().zip(frame.chunks_exact(M)).enumerate() {
                clamped += quant.row(src, 0, slow, &mut self.zrow);
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
                let (b, xy, c) = self.run_fast(frame, quant, sub, slow, &gk, k);
                tally.advance(sub, b, xy, c);
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
        tally.advance(sub, best, bxy, clamped);
    }

    #[inline]
    fn raw(&self, x: usize, y: usize) -> Option<i32> {
        self.best_state(x, y).map(|b| b.1)
    }

    /// From the best state at `(x, y)` (ties: lowest state index).
    fn trace_start(&self, x: usize, y: usize) -> Option<usize> {
        self.best_state(x, y).map(|b| b.0)
    }

    /// Position `j` is `t_{j-1} - d`, `d` the state at position `j - 1`: from position 2
    /// on, the pointer of frame `f = k - j + 2 >= 3` at pixel `t_{j-1}`, state `d` of the
    /// step before, gives it. `None` where the predecessor leaves the image.
    fn trace_back(
        &self,
        k: usize,
        j: usize,
        (px, py): (usize, usize),
        d: usize,
    ) -> Option<((usize, usize), usize)> {
        let (r, nn) = (Self::R, Self::N);
        let lay = &Self::LAY;
        let mut d = d;
        if j >= 2 {
            let f = k - j + 2;
            let slot = (f - 3) % Self::LP.max(1);
            let pix = (slot * Self::WF) * 32 + (py * M + px) * Self::BITS;
            let (cb, cbits, suf, nopt) = (
                usize::from(lay.chunk_bit.get(d).copied().unwrap_or(0)),
                u32::from(lay.chunk_bits.get(d).copied().unwrap_or(1)),
                lay.suffix.get(d).copied().unwrap_or(1).max(1),
                u32::from(lay.nopt.get(d).copied().unwrap_or(1)).max(1),
            );
            let code = read_bits(&self.ptr, pix + cb, cbits);
            let jj = ((code / suf) % nopt) as usize;
            d = usize::from(*lay.opt_s.get(d).and_then(|o| o.get(jj))?);
        }
        // predecessor pixel t_{f-1} = t_f - d
        let qx = (px + r).wrapping_sub(d % nn);
        let qy = (py + r).wrapping_sub(d / nn);
        if qx >= M || qy >= M {
            return None;
        }
        Some(((qx, qy), d))
    }
}
