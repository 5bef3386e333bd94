//! The shared DP-TBD detector: [`DpTbd`] holds what the three recursions have in common
//! (configuration, quantiser, running merit offset, reported ends) and implements
//! [`Detector`] and [`DpTrack`] once; a [`Recursion`] is the per-method part (its merit
//! and back-pointer storage, one frame of its recursion, one step of its track recovery).
//!
//! Why a generic struct over a kernel rather than a trait each detector implements: the
//! shared fields then exist once, so the configuration order (checks, then state),
//! `step` (checks, recursion, ends), the detections and the track-recovery loop are one
//! piece of code, and a kernel cannot forget or reorder a part of the contract. (A
//! trait would leave each detector its own copy of those fields and their handling.) Each
//! `DpTbd<ArnoldRecursion<..>>` is monomorphic and inlines its kernel.

use super::config::{DpConfig, Method, MAX_ENDS};
use super::quant::Quant;
use crate::detect::{Detection, Detector, ScoreKind, TrackInfo, Validate};
use crate::{Error, Result};

/// The end of a track: pixel and merit.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct TrackEnd {
    /// Column.
    pub x: u16,
    /// Row.
    pub y: u16,
    /// Merit of the best track ending here (intensity units).
    pub merit: f32,
}

/// What one DP step returns.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct DpReport {
    /// Frames processed since `configure`/`reset`, this one included.
    pub frame: u32,
    /// The best track end of this frame (ties: the first in row-major order).
    pub best: TrackEnd,
    /// Pixels of this frame clamped to `+-ZMAX` LSB.
    pub clamped: u32,
}

/// What the three DP detectors offer beyond [`Detector`]: merits at any pixel and track
/// recovery.
pub trait DpTrack: Detector<Frame = [f32], Config = DpConfig, Report = DpReport> {
    /// Image side `M`.
    const SIDE: usize;
    /// Recoverable track length `L` (frames).
    const HISTORY: usize;
    /// The unconfigured detector (all-zero bits; `step` returns
    /// `Error::InvalidConfig("unconfigured")` until [`Detector::configure`] succeeds), for
    /// generic code such as `Box::new(D::new_unconfigured())`.
    fn new_unconfigured() -> Self
    where
        Self: Sized;
    /// Frames processed since `configure`/`reset`.
    fn frames(&self) -> u32;
    /// Merit of the best track ending at pixel `(x, y)` (`None` outside the image or
    /// before the first frame).
    fn merit(&self, x: usize, y: usize) -> Option<f32>;
    /// Recovers the best track ending at `(x, y)` into `out`, newest position first
    /// (`out[0] = (x, y)` at the last frame, `out[1]` one frame earlier, ...). Returns
    /// the number of positions written: `min(out.len(), L, frames)`, 0 outside the image.
    fn track(&self, x: usize, y: usize, out: &mut [[u16; 2]]) -> usize;
    /// The best end of the last frame.
    fn best(&self) -> Option<TrackEnd>;
    /// The best track end within Chebyshev distance `radius` of `(x, y)` (ties: first in
    /// row-major order), for the track-level detection test.
    fn best_within(&self, x: usize, y: usize, radius: usize) -> Option<TrackEnd> {
        let m = Self::SIDE;
        if x >= m || y >= m {
            return None;
        }
        let mut best: Option<TrackEnd> = None;
        for yy in y.saturating_sub(radius)..=(y + radius).min(m - 1) {
            for xx in x.saturating_sub(radius)..=(x + radius).min(m - 1) {
                if let Some(v) = self.merit(xx, yy) {
                    if best.is_none_or(|b| v > b.merit) {
                        best = Some(TrackEnd {
                            x: xx as u16,
                            y: yy as u16,
                            merit: v,
                        });
                    }
                }
            }
        }
        best
    }
}

/// Checks the frame length against `M x M`.
pub(crate) fn check_len(frame: &[f32], m: usize) -> Result<()> {
    if frame.len() != m * m {
        return Err(Error::LengthMismatch {
            expected: m * m,
            got: frame.len(),
        });
    }
    Ok(())
}

/// Common configuration checks of a detector of side `m`, window radius `r`
/// (0 = invalid window) and history `l`.
pub(crate) fn check_shape(
    cfg: &DpConfig,
    method: Method,
    m: usize,
    r: usize,
    l: usize,
) -> Result<()> {
    cfg.validate()?;
    if cfg.method != method {
        return Err(Error::InvalidConfig("method"));
    }
    if l == 0 {
        return Err(Error::InvalidConfig("L"));
    }
    if m == 0 || m > 4096 {
        return Err(Error::InvalidConfig("M"));
    }
    if r == 0 {
        return Err(Error::InvalidConfig("q_b"));
    }
    if 2 * r + 1 > m {
        return Err(Error::InvalidConfig("window larger than the image"));
    }
    Ok(())
}

/// Running merit bookkeeping shared by the three recursions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tally {
    /// Frames processed.
    pub(crate) frames: u32,
    /// Stored merit + `offset` = merit in LSB.
    pub(crate) offset: i64,
    /// Best stored merit of the last frame (subtracted from the next frame's).
    pub(crate) best_raw: i32,
    /// Where it is.
    pub(crate) best_xy: (u16, u16),
    /// Pixels clamped in the last frame.
    pub(crate) clamped: u32,
}

impl Tally {
    pub(crate) const fn new() -> Self {
        Self {
            frames: 0,
            offset: 0,
            best_raw: 0,
            best_xy: (0, 0),
            clamped: 0,
        }
    }

    /// Merit (intensity) of a stored value.
    #[inline]
    pub(crate) fn merit(&self, raw: i32, lsb: f32) -> f32 {
        (i64::from(raw) + self.offset) as f32 * lsb
    }

    /// Merit of a stored value, `None` before the first frame or without a value.
    pub(crate) fn merit_of(&self, raw: Option<i32>, lsb: f32) -> Option<f32> {
        if self.frames == 0 {
            return None;
        }
        raw.map(|v| self.merit(v, lsb))
    }

    /// Ends a frame: stored merits were re-centred by `sub`; `best` at `xy` is the best.
    pub(crate) fn advance(&mut self, sub: i32, best: i32, xy: (u16, u16), clamped: u32) {
        self.offset += i64::from(sub);
        self.best_raw = best;
        self.best_xy = xy;
        self.clamped = clamped;
        self.frames = self.frames.wrapping_add(1);
    }
}

/// The checks before a detector's recursion runs on `frame` (configured, length `m x m`,
/// finite): whether the frame needs the clamping path ([`Quant::check`]).
pub(crate) fn begin(configured: bool, quant: &Quant, frame: &[f32], m: usize) -> Result<bool> {
    if !configured {
        return Err(Error::InvalidConfig("unconfigured"));
    }
    check_len(frame, m)?;
    quant.check(frame)
}

/// The report of the frame just run, after refilling `ends` (best merit at `raw(x, y)`).
pub(crate) fn finish(
    cfg: &DpConfig,
    t: &Tally,
    ends: &mut Ends,
    m: usize,
    raw: impl Fn(usize, usize) -> Option<i32>,
) -> DpReport {
    let lsb = cfg.lsb;
    ends.fill(
        m,
        usize::from(cfg.top_k),
        usize::from(cfg.separation),
        t.best_xy,
        t,
        lsb,
        |x, y| raw(x, y).unwrap_or(i32::MIN),
    );
    DpReport {
        frame: t.frames,
        best: TrackEnd {
            x: t.best_xy.0,
            y: t.best_xy.1,
            merit: t.merit(t.best_raw, lsb),
        },
        clamped: t.clamped,
    }
}

/// The distinct track ends of the last frame, best first.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ends {
    /// Number of ends (`u32`, so the detectors' sizes are the same on 32- and 64-bit targets).
    pub(crate) n: u32,
    pub(crate) ends: [TrackEnd; MAX_ENDS],
}

impl Ends {
    pub(crate) const fn new() -> Self {
        Self {
            n: 0,
            ends: [TrackEnd {
                x: 0,
                y: 0,
                merit: 0.0,
            }; MAX_ENDS],
        }
    }

    pub(crate) fn as_slice(&self) -> &[TrackEnd] {
        self.ends.get(..self.n as usize).unwrap_or(&[])
    }

    /// Fills the ends: the best (`best`), then up to `k - 1` more, each the best pixel
    /// (by `raw(x, y)`, ties first in row-major order) farther than `sep` (Chebyshev)
    /// from all chosen so far.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn fill(
        &mut self,
        m: usize,
        k: usize,
        sep: usize,
        best: (u16, u16),
        tally: &Tally,
        lsb: f32,
        raw: impl Fn(usize, usize) -> i32,
    ) {
        let mut chosen = [(0usize, 0usize, 0i32); MAX_ENDS];
        chosen[0] = (
            usize::from(best.0),
            usize::from(best.1),
            raw(usize::from(best.0), usize::from(best.1)),
        );
        let mut n = 1usize;
        let k = k.min(MAX_ENDS);
        while n < k {
            let mut cand: Option<(usize, usize, i32)> = None;
            for y in 0..m {
                for x in 0..m {
                    let v = raw(x, y);
                    if cand.is_some_and(|c| v <= c.2) {
                        continue;
                    }
                    let far = chosen
                        .iter()
                        .take(n)
                        .all(|c| c.0.abs_diff(x) > sep || c.1.abs_diff(y) > sep);
                    if far {
                        cand = Some((x, y, v));
                    }
                }
            }
            match (cand, chosen.get_mut(n)) {
                (Some(c), Some(slot)) => *slot = c,
                _ => break,
            }
            n += 1;
        }
        self.n = n as u32;
        for (e, c) in self.ends.iter_mut().zip(chosen.iter().take(n)) {
            *e = TrackEnd {
                x: c.0 as u16,
                y: c.1 as u16,
                merit: tally.merit(c.2, lsb),
            };
        }
    }
}

/// Least-squares velocity (px/frame) of a track given newest first.
pub(crate) fn velocity(track: &[[u16; 2]]) -> (f32, f32) {
    let n = track.len();
    if n < 2 {
        return (0.0, 0.0);
    }
    // time t_j = -j; slope = sum (t - tbar)(p - pbar) / sum (t - tbar)^2
    let tbar = -((n - 1) as f32) / 2.0;
    let (mut sx, mut sy, mut st) = (0.0f32, 0.0f32, 0.0f32);
    let (mut mx, mut my) = (0.0f32, 0.0f32);
    for p in track {
        mx += f32::from(p[0]);
        my += f32::from(p[1]);
    }
    mx /= n as f32;
    my /= n as f32;
    for (j, p) in track.iter().enumerate() {
        let dt = -(j as f32) - tbar;
        sx += dt * (f32::from(p[0]) - mx);
        sy += dt * (f32::from(p[1]) - my);
        st += dt * dt;
    }
    (sx / st, sy / st)
}

/// Names of a DP detection's state.
pub(crate) const STATE: &[&str] = &["x_px", "y_px", "vx_px_per_frame", "vy_px_per_frame"];

/// The per-method part of a [`DpTbd`]: the merits and back-pointers of one recursion,
/// one frame of it, and one step back along a recovered track. Sealed: implemented by
/// [`ArnoldRecursion`](super::ArnoldRecursion),
/// [`PulfordRecursion`](super::PulfordRecursion) and
/// [`SecondOrderRecursion`](super::SecondOrderRecursion).
pub trait Recursion: Clone + core::fmt::Debug {
    /// Image side `M`.
    const SIDE: usize;
    /// Recoverable track length `L` (frames).
    const HISTORY: usize;
    #[doc(hidden)]
    const METHOD: Method;
    /// Largest quantised pixel magnitude of the merit cell ([`MeritCell::ZMAX`](super::MeritCell::ZMAX)).
    #[doc(hidden)]
    const ZMAX: i32;
    /// Window radius `R` (`q_B = (2R + 1)^2`; 0: unsupported `q_B`).
    #[doc(hidden)]
    const RADIUS: usize;
    /// The unconfigured state, all-zero bits.
    #[doc(hidden)]
    const UNCONFIGURED: Self;
    /// A track buffer of `L` positions.
    #[doc(hidden)]
    type Track: AsMut<[[u16; 2]]>;
    #[doc(hidden)]
    const NO_TRACK: Self::Track;
    /// Builds the method's tables for `cfg` (already checked by the detector); on an
    /// error nothing has changed.
    #[doc(hidden)]
    fn configure(&mut self, cfg: &DpConfig) -> Result<()>;
    /// One frame (length and values checked; `slow`: some pixel needs clamping): new
    /// merits and back-pointers, the frame's best into `tally` ([`Tally::advance`]).
    #[doc(hidden)]
    fn recurse(
        &mut self,
        frame: &[f32],
        slow: bool,
        cfg: &DpConfig,
        quant: &Quant,
        tally: &mut Tally,
    );
    /// Stored merit of the best state at pixel `(x, y)`.
    #[doc(hidden)]
    fn raw(&self, x: usize, y: usize) -> Option<i32>;
    /// Starts a track at pixel `(x, y)` (inside the image, `frames >= 1`): the state
    /// the track carries besides its position (the second order's pair state `d`).
    #[doc(hidden)]
    fn trace_start(&self, _x: usize, _y: usize) -> Option<usize> {
        Some(0)
    }
    /// Position `j >= 1` of the track (`p`, `t`: position `j - 1` and its state) after
    /// `frames` frames; `None` where the track ends (it began at position `j - 1`).
    #[doc(hidden)]
    fn trace_back(
        &self,
        frames: usize,
        j: usize,
        p: (usize, usize),
        t: usize,
    ) -> Option<((usize, usize), usize)>;
}

/// A DP-TBD detector: the shared part and the recursion `R`. Name one through the
/// aliases [`ArnoldDp`](super::ArnoldDp), [`PulfordDp`](super::PulfordDp),
/// [`SecondOrderDp`](super::SecondOrderDp) with [`dp_tbd!`](crate::dp_tbd) (which
/// computes the storage size) or a [`preset`](super::preset).
///
/// Build small instances with [`DpTbd::new`]; large ones in a `static` (or a `Box`) with
/// [`DpTbd::new_unconfigured`] and then [`Detector::configure`].
#[derive(Debug, Clone)]
pub struct DpTbd<R: Recursion> {
    pub(super) cfg: DpConfig,
    configured: bool,
    quant: Quant,
    pub(super) tally: Tally,
    ends: Ends,
    pub(super) kernel: R,
}

impl<R: Recursion> DpTbd<R> {
    /// A detector for `cfg` (validated here). Large shapes: see the type docs.
    pub fn new(cfg: DpConfig) -> Result<Self> {
        let mut d = Self::new_unconfigured();
        d.configure(&cfg, 0)?;
        Ok(d)
    }

    /// The unconfigured detector, one constant (all-zero bits), so that copying it into a
    /// `Box` or a `static` is a zero fill with no temporary on the stack.
    const UNCONFIGURED: Self = Self {
        cfg: DpConfig::UNSET,
        configured: false,
        quant: Quant::zero(),
        tally: Tally::new(),
        ends: Ends::new(),
        kernel: R::UNCONFIGURED,
    };

    /// The unconfigured detector (all-zero bits, so a `static` of it lands in `.bss`);
    /// `step` returns `Error::InvalidConfig("unconfigured")` until
    /// [`Detector::configure`] succeeds.
    #[inline(always)]
    pub const fn new_unconfigured() -> Self {
        Self::UNCONFIGURED
    }

    /// The distinct track ends of the last frame, best first ([`DpConfig::top_k`]).
    pub fn ends(&self) -> &[TrackEnd] {
        self.ends.as_slice()
    }
}

impl<R: Recursion> Detector for DpTbd<R> {
    type Frame = [f32];
    type Config = DpConfig;
    type Report = DpReport;
    const STATE: &'static [&'static str] = STATE;
    const SCORE: ScoreKind = ScoreKind::Merit;
    const UNCONFIGURED: Self = Self::new_unconfigured();

    /// Checks `cfg` (the detector's method, `L >= 1`, a supported window no larger than
    /// the image, the method's tables), then restarts in place. No random numbers:
    /// `seed` is unused.
    fn configure(&mut self, cfg: &DpConfig, _seed: u64) -> Result<()> {
        check_shape(cfg, R::METHOD, R::SIDE, R::RADIUS, R::HISTORY)?;
        let quant = Quant::new(cfg.lsb, R::ZMAX)?;
        self.kernel.configure(cfg)?;
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
        let slow = begin(self.configured, &self.quant, frame, R::SIDE)?;
        self.kernel
            .recurse(frame, slow, &self.cfg, &self.quant, &mut self.tally);
        let mut ends = self.ends;
        let kernel = &self.kernel;
        let r = finish(&self.cfg, &self.tally, &mut ends, R::SIDE, |x, y| {
            kernel.raw(x, y)
        });
        self.ends = ends;
        Ok(r)
    }

    fn detection_count(&self) -> usize {
        self.ends.n as usize
    }

    /// Detection `i`: end `i` of [`DpTbd::ends`], state `[x + 0.5, y + 0.5, vx, vy]`
    /// (pixel centre, least-squares velocity of the recovered track), score = merit,
    /// track id `i` and the recovered length.
    fn detection(&self, i: usize) -> Option<Detection> {
        let e = self.ends.as_slice().get(i)?;
        let mut buf = R::NO_TRACK;
        let buf = buf.as_mut();
        let n = self.track(usize::from(e.x), usize::from(e.y), buf);
        let (vx, vy) = velocity(buf.get(..n).unwrap_or(&[]));
        Some(Detection::new(
            &[f32::from(e.x) + 0.5, f32::from(e.y) + 0.5, vx, vy],
            e.merit,
            Some(TrackInfo {
                id: i as u32,
                len: n as u32,
            }),
        ))
    }
}

impl<R: Recursion> DpTrack for DpTbd<R> {
    const SIDE: usize = R::SIDE;
    const HISTORY: usize = R::HISTORY;

    #[inline(always)]
    fn new_unconfigured() -> Self {
        DpTbd::new_unconfigured()
    }

    fn frames(&self) -> u32 {
        self.tally.frames
    }

    fn merit(&self, x: usize, y: usize) -> Option<f32> {
        self.tally.merit_of(self.kernel.raw(x, y), self.cfg.lsb)
    }

    /// Follows the back-pointers from `(x, y)`; stops early where the track began (a
    /// Pulford restart, a second-order predecessor outside the image).
    fn track(&self, x: usize, y: usize, out: &mut [[u16; 2]]) -> usize {
        let k = self.tally.frames as usize;
        if x >= R::SIDE || y >= R::SIDE || k == 0 {
            return 0;
        }
        let Some(mut t) = self.kernel.trace_start(x, y) else {
            return 0;
        };
        let n = out.len().min(R::HISTORY).min(k);
        let mut p = (x, y);
        for j in 0..n {
            if j > 0 {
                match self.kernel.trace_back(k, j, p, t) {
                    Some((q, u)) => (p, t) = (q, u),
                    None => return j,
                }
            }
            if let Some(o) = out.get_mut(j) {
                *o = [p.0 as u16, p.1 as u16];
            }
        }
        n
    }

    fn best(&self) -> Option<TrackEnd> {
        self.ends.as_slice().first().copied()
    }
}
