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
//! Memory ([`arnold_bytes`](super::arnold_bytes)): `M^2 sizeof(C)` merits, `9 M 4`
//! bytes of row keys, `8 M` of row buffers, `4 W = (L - 1) ceil(M^2 b / 32) 4` bytes of
//! back-pointers (`b = 4` for `q_B = 9`: 8 KiB per frame at `M = 128`) and the fixed
//! fields: `M^2 c + 44 M + 4 W + 144` bytes.

use super::{
    begin, bits_for, check_shape, detection, finish, radius_of, read_bits, BitWriter, DpConfig,
    DpReport, DpTrack, Ends, MeritCell, Method, Quant, Tally, TrackEnd, STATE,
};
use crate::detect::{Detection, Detector, ScoreKind};
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

/// First-order DP-TBD on `M x M` images with a `q_B = QB` window (9, 25 or 49), tracks
/// recoverable over `L` frames, `W = arnold_words(M, QB, L)` back-pointer words, merits
/// stored as `C`.
///
/// Build small instances with [`ArnoldDp::new`]; large ones zeroed in a `static` (or a
/// `Box`) with [`ArnoldDp::unconfigured`] and then [`Detector::configure`].
#[derive(Debug, Clone)]
pub struct ArnoldDp<
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
    merit: [[C; M]; M],
    hring: [[i32; M]; RING + 1],
    kbuf: [i32; M],
    zrow: [i32; M],
    ptr: [u32; W],
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell>
    ArnoldDp<M, QB, L, W, C>
{
    const R: usize = radius_of(QB);
    const PB: u32 = if Self::R <= 1 { 2 } else { 3 };
    const SH: u32 = 2 * Self::PB;
    const PM: usize = (1 << Self::PB) - 1;
    const BITS: u32 = ptr_bits(QB);
    const WF: usize = (M * M * Self::BITS as usize).div_ceil(32);
    const LP: usize = L.saturating_sub(1);
    const SHAPE: () = assert!(
        W == Self::LP * Self::WF,
        "W must be dp::arnold_words(M, QB, L)"
    );

    /// A detector for `cfg` (validated here). Large shapes: see the type docs.
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
            cfg: DpConfig::dim_point(Method::Arnold, 1),
            configured: false,
            quant: Quant::zero(),
            tally: Tally::new(),
            ends: Ends::new(),
            merit: [[C::ZERO; M]; M],
            hring: [[0; M]; RING + 1],
            kbuf: [0; M],
            zrow: [0; M],
            ptr: [0; W],
        }
    }

    /// The distinct track ends of the last frame, best first ([`DpConfig::top_k`]).
    pub fn ends(&self) -> &[TrackEnd] {
        self.ends.as_slice()
    }

    #[inline]
    fn raw(&self, x: usize, y: usize) -> Option<i32> {
        self.merit.get(y)?.get(x).map(|c| c.get())
    }

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

    /// The recursion on one frame (checked).
    fn run(&mut self, frame: &[f32], slow: bool) {
        let k = self.tally.frames + 1;
        let sub = if k == 1 { 0 } else { self.tally.best_raw };
        let mut clamped = 0u32;
        let mut best = i32::MIN;
        let mut bxy = (0u16, 0u16);
        if k == 1 {
            for (y, (row, src)) in self.merit.iter_mut().zip(frame.chunks_exact(M)).enumerate() {
                clamped += self.quant.row(src, 0, slow, &mut self.zrow);
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
            self.hring[RING] = [FLOOR_KEY; M];
            for rr in 0..r.min(M) {
                let (src, dst) = (&self.merit[rr], &mut self.hring[rr & (RING - 1)]);
                Self::h_row(src, rr, dst, &mut self.kbuf);
            }
            let slot = ((k - 2) as usize) % Self::LP.max(1);
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
                    clamped += self.quant.row(src, sub, true, &mut self.zrow);
                    Self::col_row(&rows, &self.zrow, |&q| q, y, row, &mut bw)
                } else {
                    let quant = self.quant;
                    Self::col_row(&rows, src, |&z| quant.fast(z, base), y, row, &mut bw)
                };
                if rb > best {
                    best = rb;
                    bxy = (rx as u16, y as u16);
                }
            }
            bw.finish();
        }
        self.tally.advance(sub, best, bxy, clamped);
    }
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell> Detector
    for ArnoldDp<M, QB, L, W, C>
{
    type Frame = [f32];
    type Config = DpConfig;
    type Report = DpReport;
    const STATE: &'static [&'static str] = STATE;
    const SCORE: ScoreKind = ScoreKind::Merit;

    /// Checks `cfg` (method `Arnold`, `L >= 1`, a 9/25/49 window no larger than the
    /// image) and restarts in place. No random numbers: `seed` is unused.
    fn configure(&mut self, cfg: &DpConfig, _seed: u64) -> Result<()> {
        let () = Self::SHAPE;
        check_shape(cfg, Method::Arnold, M, Self::R, L)?;
        let quant = Quant::new(cfg.lsb, C::ZMAX)?;
        self.cfg = *cfg;
        self.quant = quant;
        self.configured = true;
        self.reset(0);
        Ok(())
    }

    fn config(&self) -> &DpConfig {
        &self.cfg
    }

    /// Restarts from frame 0 (merits and back-pointers are overwritten before use).
    fn reset(&mut self, _seed: u64) {
        self.tally = Tally::new();
        self.ends = Ends::new();
    }

    /// One `M x M` frame, row-major.
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
    for ArnoldDp<M, QB, L, W, C>
{
    const SIDE: usize = M;
    const HISTORY: usize = L;

    fn frames(&self) -> u32 {
        self.tally.frames
    }

    fn merit(&self, x: usize, y: usize) -> Option<f32> {
        self.tally.merit_of(self.raw(x, y), self.cfg.lsb)
    }

    fn track(&self, x: usize, y: usize, out: &mut [[u16; 2]]) -> usize {
        let k = self.tally.frames as usize;
        if x >= M || y >= M || k == 0 {
            return 0;
        }
        let n = out.len().min(L).min(k);
        let (mut x, mut y) = (x, y);
        for (j, o) in out.iter_mut().take(n).enumerate() {
            if j > 0 {
                // back-pointer of frame f = k - j + 1 >= 2
                let f = k - j + 1;
                let slot = (f - 2) % Self::LP.max(1);
                let bit = (slot * Self::WF) * 32 + (y * M + x) * Self::BITS as usize;
                let code = read_bits(&self.ptr, bit, Self::BITS);
                (x, y) = Self::pred(x, y, code);
            }
            *o = [x as u16, y as u16];
        }
        n
    }

    fn best(&self) -> Option<TrackEnd> {
        self.ends.as_slice().first().copied()
    }
}
