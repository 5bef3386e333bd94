//! First-order DP with a Kalman velocity gate (Pulford, La Scala 2010; Tonissen, Evans
//! 1996), as Wang, Zhang 2016 (§1.2, Fig. 2) describe it.
//!
//! Every state `t'` carries a constant-velocity Kalman filter along its best track. The
//! predecessor set of `t` is `R_B(t)` narrowed to the `t'` whose gate `R_t'(k-1)` (the
//! `(2g+1)^2` pixels around the rounded one-step prediction `x + v`) contains `t`:
//!
//! ```text
//! I_k(t) = T(z_k(t)) + max_{t' in R_B(t), t in R_t'(k-1)} I_{k-1}(t')
//! per axis: x^- = x + v,  nu = t - x^-,  x = x^- + K1 nu,  v = v + K2 nu
//! P^- = F P F^T + q G G^T,  K = P^- H^T / (H P^- H^T + R),  F = [1 1; 0 1], G = [1/2; 1]
//! ```
//!
//! A state without velocity yet (frame 1, or a restarted track) gates nothing: the first
//! transition is the plain `R_B` window, and sets `x = t`, `v = t - t'` (velocity from
//! the first two states) with `P0 = p0 I`. The covariance, hence the gain, depends only
//! on the filter's age (updates since that start), so the gains are a table by age
//! (constant after 32 updates, where they have converged to f32 precision). If no
//! predecessor gates `t`, its track restarts there: merit `T(z_k(t))` alone, no velocity
//! (the paper: predecessors whose region excludes `t` "are no longer considered").
//! Ties: the larger window index `(dy + R)(2R+1) + (dx + R)` wins.
//!
//! Memory ([`pulford_bytes`](super::pulford_bytes)): `M^2 (sizeof(C) + 24)` bytes of
//! merits and filters, `4 M (sizeof(C) + 24)` of delayed rows, `5 M` of row buffers,
//! 264 of gains, `4 W = (L - 1) ceil(M^2 b / 32) 4` of back-pointers,
//! `b = ceil(log2(q_B + 1))` (the window index or "restart"), and 144 of fixed fields.

use super::bits::{bits_for, code_at, radius_of, BitWriter};
use super::config::{DpConfig, Method};
use super::detector::{DpTbd, Recursion, Tally};
use super::quant::{MeritCell, Quant, MAGIC, MAGIC_BITS};
use crate::{Error, Result};

/// Ages with their own gain; older filters use the last one.
const AGES: usize = 32;
/// Rows of delayed output (`R + 1 <= 4`).
const DELAY: usize = 4;
const FLOOR_KEY: i32 = i32::MIN / 2;

/// One state's Kalman filter (pixel-index units; pixel `i`'s centre is `i`).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Kf {
    x: f32,
    y: f32,
    vx: f32,
    vy: f32,
    /// Rounded prediction `x + v` for the next frame.
    px: i16,
    py: i16,
    /// Updates since the track's start (0: no velocity yet).
    age: u8,
}

impl Kf {
    const ZERO: Kf = Kf {
        x: 0.0,
        y: 0.0,
        vx: 0.0,
        vy: 0.0,
        px: 0,
        py: 0,
        age: 0,
    };

    fn start(x: usize, y: usize) -> Self {
        Kf {
            x: x as f32,
            y: y as f32,
            age: 0,
            ..Kf::ZERO
        }
    }

    #[inline]
    fn predict(&mut self) {
        self.px = round_i16(self.x + self.vx);
        self.py = round_i16(self.y + self.vy);
    }
}

/// Nearest integer (halves to even), clamped to `+-16384`.
#[inline]
fn round_i16(v: f32) -> i16 {
    let v = v.clamp(-16384.0, 16384.0);
    ((v + MAGIC).to_bits() as i32).wrapping_sub(MAGIC_BITS) as i16
}

/// Velocity-gated first-order DP-TBD on `M x M` images with a `q_B = QB` window (9, 25
/// or 49), tracks over `L` frames, `W = pulford_words(M, QB, L)` back-pointer words: a
/// [`DpTbd`] over a [`PulfordRecursion`]. Name an instance with
/// [`dp_tbd!`](crate::dp_tbd)`(Pulford, SIDE, WINDOW, HISTORY)` (which computes `W`).
pub type PulfordDp<
    const SIDE: usize,
    const WINDOW: usize,
    const HISTORY: usize,
    const WORDS: usize,
    C = i16,
> = DpTbd<PulfordRecursion<SIDE, WINDOW, HISTORY, WORDS, C>>;

/// The merits, Kalman filters and back-pointers of [`PulfordDp`] (`M = SIDE`,
/// `q_B = WINDOW`, `L = HISTORY`, `W = WORDS`).
#[derive(Debug, Clone)]
pub struct PulfordRecursion<
    const M: usize,
    const QB: usize,
    const L: usize,
    const W: usize,
    C: MeritCell = i16,
> {
    gains: [[f32; 2]; AGES + 1],
    merit: [[C; M]; M],
    kf: [[Kf; M]; M],
    mring: [[C; M]; DELAY],
    kring: [[Kf; M]; DELAY],
    zrow: [i32; M],
    codes: [u8; M],
    ptr: [u32; W],
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell>
    DpTbd<PulfordRecursion<M, QB, L, W, C>>
{
    /// The Kalman estimate `[x, y, vx, vy]` (pixel-index units) of the best track ending
    /// at `(x, y)`, and its age (0: no velocity yet).
    pub fn filter(&self, x: usize, y: usize) -> Option<([f32; 4], u8)> {
        let k = self.kernel.kf.get(y)?.get(x)?;
        Some(([k.x, k.y, k.vx, k.vy], k.age))
    }
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell>
    PulfordRecursion<M, QB, L, W, C>
{
    const R: usize = radius_of(QB);
    const N: usize = 2 * Self::R + 1;
    const BITS: u32 = bits_for(QB + 1);
    const SH: u32 = Self::BITS;
    const WF: usize = (M * M * Self::BITS as usize).div_ceil(32);
    const LP: usize = L.saturating_sub(1);
    const SHAPE: () = assert!(
        W == Self::LP * Self::WF,
        "W must be dp::pulford_words(M, QB, L)"
    );

    /// Gains `[K1, K2]` by age `1..=AGES` (index 0 unused) for `P0 = p0 I`.
    fn gain_table(cfg: &DpConfig) -> [[f32; 2]; AGES + 1] {
        let mut t = [[0.0f32; 2]; AGES + 1];
        let (mut a, mut b, mut c) = (cfg.p0, 0.0f32, cfg.p0);
        let q = cfg.q;
        for g in t.iter_mut().skip(1) {
            let a1 = a + 2.0 * b + c + q / 4.0;
            let b1 = b + c + q / 2.0;
            let c1 = c + q;
            let s = a1 + cfg.r;
            let k1 = a1 / s;
            let k2 = b1 / s;
            *g = [k1, k2];
            a = (1.0 - k1) * a1;
            b = (1.0 - k1) * b1;
            c = c1 - k2 * b1;
        }
        t
    }
}

impl<const M: usize, const QB: usize, const L: usize, const W: usize, C: MeritCell> Recursion
    for PulfordRecursion<M, QB, L, W, C>
{
    const SIDE: usize = M;
    const HISTORY: usize = L;
    const METHOD: Method = Method::Pulford;
    const ZMAX: i32 = C::ZMAX;
    const RADIUS: usize = Self::R;
    const UNCONFIGURED: Self = {
        let () = Self::SHAPE;
        Self {
            gains: [[0.0; 2]; AGES + 1],
            merit: [[C::ZERO; M]; M],
            kf: [[Kf::ZERO; M]; M],
            mring: [[C::ZERO; M]; DELAY],
            kring: [[Kf::ZERO; M]; DELAY],
            zrow: [0; M],
            codes: [0; M],
            ptr: [0; W],
        }
    };
    type Track = [[u16; 2]; L];
    const NO_TRACK: Self::Track = [[0; 2]; L];

    /// Builds the gain table.
    fn configure(&mut self, cfg: &DpConfig) -> Result<()> {
        let () = Self::SHAPE;
        let gains = Self::gain_table(cfg);
        if gains.iter().flatten().any(|g| !g.is_finite()) {
            return Err(Error::InvalidConfig("p0"));
        }
        self.gains = gains;
        Ok(())
    }

    fn recurse(
        &mut self,
        frame: &[f32],
        slow: bool,
        cfg: &DpConfig,
        quant: &Quant,
        tally: &mut Tally,
    ) {
        let k = tally.frames + 1;
        let sub = if k == 1 { 0 } else { tally.best_raw };
        let mut clamped = 0u32;
        let mut best = i32::MIN;
        let mut bxy = (0u16, 0u16);
        if k == 1 {
            for (y, ((row, krow), src)) in self
                .merit
                .iter_mut()
                .zip(self.kf.iter_mut())
                .zip(frame.chunks_exact(M))
                .enumerate()
            {
                clamped += quant.row(src, 0, slow, &mut self.zrow);
                for (x, ((c, f), &q)) in row
                    .iter_mut()
                    .zip(krow.iter_mut())
                    .zip(self.zrow.iter())
                    .enumerate()
                {
                    *c = C::sat(q);
                    *f = Kf::start(x, y);
                    if c.get() > best {
                        best = c.get();
                        bxy = (x as u16, y as u16);
                    }
                }
            }
        } else {
            let r = Self::R;
            let n = Self::N;
            let g = i32::from(cfg.gate);
            let slot = ((k - 2) as usize) % Self::LP.max(1);
            let words = self
                .ptr
                .get_mut(slot * Self::WF..(slot + 1) * Self::WF)
                .unwrap_or(&mut []);
            let mut bw = BitWriter::new(words);
            let offset = tally.offset;
            let mask = (1i32 << Self::SH) - 1;
            for (y, src) in frame.chunks_exact(M).enumerate() {
                clamped += quant.row(src, sub, slow, &mut self.zrow);
                let ds = y & (DELAY - 1);
                for x in 0..M {
                    let mut v = FLOOR_KEY;
                    // candidates in window order j = dy n + dx (rows of the window: their
                    // merit and filter rows looked up once)
                    for dy in 0..n {
                        let yy = (y + dy).wrapping_sub(r);
                        let (Some(mrow), Some(krow)) = (self.merit.get(yy), self.kf.get(yy)) else {
                            continue;
                        };
                        for dx in 0..n {
                            let xx = (x + dx).wrapping_sub(r);
                            let (Some(c), Some(f)) = (mrow.get(xx), krow.get(xx)) else {
                                continue;
                            };
                            let ok = f.age == 0
                                || ((x as i32 - i32::from(f.px)).abs() <= g
                                    && (y as i32 - i32::from(f.py)).abs() <= g);
                            if ok {
                                let j = (dy * n + dx) as i32;
                                v = v.max((c.get() << Self::SH) | j);
                            }
                        }
                    }
                    let zq = self.zrow[x];
                    let (new, code, kf) = if v == FLOOR_KEY {
                        // restart: merit T(z) alone
                        let raw =
                            (i64::from(zq) - offset).clamp(i64::from(C::FLOOR), i64::from(C::ZMAX));
                        (C::sat(raw as i32), QB as u8, Kf::start(x, y))
                    } else {
                        let j = (v & mask) as usize;
                        let (dy, dx) = (j / n, j % n);
                        let (px, py) = ((x + dx).wrapping_sub(r), (y + dy).wrapping_sub(r));
                        let mut f = self
                            .kf
                            .get(py)
                            .and_then(|row| row.get(px))
                            .copied()
                            .unwrap_or(Kf::ZERO);
                        let (tx, ty) = (x as f32, y as f32);
                        if f.age == 0 {
                            f.vx = tx - f.x;
                            f.vy = ty - f.y;
                            f.x = tx;
                            f.y = ty;
                            f.age = 1;
                        } else {
                            let [k1, k2] = self.gains[usize::from(f.age).min(AGES)];
                            let (xm, ym) = (f.x + f.vx, f.y + f.vy);
                            let (nx, ny) = (tx - xm, ty - ym);
                            f.x = xm + k1 * nx;
                            f.y = ym + k1 * ny;
                            f.vx += k2 * nx;
                            f.vy += k2 * ny;
                            f.age = f.age.saturating_add(1).min(AGES as u8 + 1);
                        }
                        (C::sat(zq + (v >> Self::SH)), j as u8, f)
                    };
                    let mut kf = kf;
                    kf.predict();
                    self.mring[ds][x] = new;
                    self.kring[ds][x] = kf;
                    self.codes[x] = code;
                    if new.get() > best {
                        best = new.get();
                        bxy = (x as u16, y as u16);
                    }
                }
                if Self::LP > 0 {
                    for &c in self.codes.iter() {
                        bw.push(u32::from(c), Self::BITS);
                    }
                }
                // row y - R is no longer read: commit its new values
                if y >= r {
                    let yc = y - r;
                    if let (Some(m), Some(f)) = (self.merit.get_mut(yc), self.kf.get_mut(yc)) {
                        *m = self.mring[yc & (DELAY - 1)];
                        *f = self.kring[yc & (DELAY - 1)];
                    }
                }
            }
            for yc in M.saturating_sub(r)..M {
                self.merit[yc] = self.mring[yc & (DELAY - 1)];
                self.kf[yc] = self.kring[yc & (DELAY - 1)];
            }
            bw.finish();
        }
        tally.advance(sub, best, bxy, clamped);
    }

    #[inline]
    fn raw(&self, x: usize, y: usize) -> Option<i32> {
        self.merit.get(y)?.get(x).map(|c| c.get())
    }

    /// The back-pointer of frame `f = k - j + 1 >= 2` (slot `(f - 2) mod (L - 1)`);
    /// `None` at a restart (the track began there).
    fn trace_back(
        &self,
        k: usize,
        j: usize,
        (x, y): (usize, usize),
        _t: usize,
    ) -> Option<((usize, usize), usize)> {
        let slot = (k - j - 1) % Self::LP.max(1);
        let code = code_at(&self.ptr, slot, Self::WF, y * M + x, Self::BITS) as usize;
        if code >= QB {
            return None;
        }
        let r = Self::R;
        let x = (x + code % Self::N).saturating_sub(r);
        let y = (y + code / Self::N).saturating_sub(r);
        Some(((x, y), 0))
    }
}
