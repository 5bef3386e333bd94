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
//! Memory: `M^2 sizeof(C)` merits, `9 M 4` bytes of row keys, `M 5` bytes of row
//! buffers, and `4 W = (L - 1) ceil(M^2 b / 32) 4` bytes of back-pointers (`b = 4` for
//! `q_B = 9`: 8 KiB per frame at `M = 128`).

use super::{
    bits_for, check_len, check_shape, detection, radius_of, read_bits, BitWriter, DpConfig,
    DpReport, DpTrack, Ends, MeritCell, Method, Quant, Tally, TrackEnd, STATE,
};
use crate::detect::{Detection, Detector, ScoreKind};
use crate::{Error, Result};

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
    codes: [u8; M],
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
            codes: [0; M],
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
            let mask = (1i32 << Self::SH) - 1;
            for (y, src) in frame.chunks_exact(M).enumerate() {
                if y + r < M {
                    let (src, dst) = (&self.merit[y + r], &mut self.hring[(y + r) & (RING - 1)]);
                    Self::h_row(src, y + r, dst, &mut self.kbuf);
                }
                clamped += self.quant.row(src, sub, slow, &mut self.zrow);
                let rows: [&[i32; M]; 7] = core::array::from_fn(|j| {
                    let yy = (y + j) as isize - r as isize;
                    if j < 2 * r + 1 && yy >= 0 && (yy as usize) < M {
                        &self.hring[(yy as usize) & (RING - 1)]
                    } else {
                        &self.hring[RING]
                    }
                });
                let row = &mut self.merit[y];
                for x in 0..M {
                    let mut v = FLOOR_KEY;
                    for rw in rows.iter().take(2 * r + 1) {
                        v = v.max(rw[x]);
                    }
                    let new = C::sat(self.zrow[x] + (v >> Self::SH));
                    row[x] = new;
                    let nv = new.get();
                    if nv > best {
                        best = nv;
                        bxy = (x as u16, y as u16);
                    }
                    let code = v & mask;
                    self.codes[x] = if r == 1 {
                        code as u8
                    } else {
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
                        let n = (2 * r + 1) as i32;
                        ((wrap(cx, x) + r as i32) + n * (wrap(cy, y) + r as i32)) as u8
                    };
                }
                if Self::LP > 0 {
                    for &c in self.codes.iter() {
                        bw.push(u32::from(c), Self::BITS);
                    }
                }
            }
            bw.finish();
        }
        self.tally.offset += i64::from(sub);
        self.tally.best_raw = best;
        self.tally.best_xy = bxy;
        self.tally.clamped = clamped;
        self.tally.frames = k;
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
        if !self.configured {
            return Err(Error::InvalidConfig("unconfigured"));
        }
        check_len(frame, M)?;
        let slow = self.quant.check(frame)?;
        self.run(frame, slow);
        let t = self.tally;
        let lsb = self.cfg.lsb;
        let mut ends = self.ends;
        ends.fill(
            M,
            usize::from(self.cfg.top_k),
            usize::from(self.cfg.separation),
            t.best_xy,
            &t,
            lsb,
            |x, y| self.raw(x, y).unwrap_or(i32::MIN),
        );
        self.ends = ends;
        Ok(DpReport {
            frame: t.frames,
            best: TrackEnd {
                x: t.best_xy.0,
                y: t.best_xy.1,
                merit: t.merit(t.best_raw, lsb),
            },
            clamped: t.clamped,
        })
    }

    fn detection_count(&self) -> usize {
        self.ends.n
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
        if self.tally.frames == 0 {
            return None;
        }
        self.raw(x, y).map(|v| self.tally.merit(v, self.cfg.lsb))
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
