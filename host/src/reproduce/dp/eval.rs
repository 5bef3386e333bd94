//! One run of the `dim-point` scene through the three DP detectors: what every frame
//! shows (the best merit near the truth, the global best and where it is) and the
//! tracking error after the last frame.

use anyhow::{anyhow, Result};
use faint_core::detect::dp::{DpConfig, DpTrack, Method, Transition};
use faint_core::dp_tbd;
use faint_core::rng::Rng;
use serde::Serialize;

use crate::simulate::dp::{boxed, qb_for, with_dp, DimPoint, Run, Truth, HISTORY, METHODS, SIDE};

/// The second order with `i8` merit cells (`--second-bits 8`), `q_B = 9`: the merit
/// memory of the STM32H743's `dp-second:128:8` image (which keeps `L = 8` frames of
/// back-pointers; `L` changes only the recoverable track, not the merits).
pub type Second9I8 = dp_tbd!(SecondOrder, SIDE, 9, HISTORY, i8);
/// The same at `q_B = 25` (2 px/frame).
pub type Second25I8 = dp_tbd!(SecondOrder, SIDE, 25, HISTORY, i8);

/// The input LSB of `i8` merits (intensity units): an `i8` cell holds pixels up to
/// `+-63` LSB, so the preset's `1/16` would clip them at 3.9 (2.6 sigma); the firmware's
/// `i8` rows and board images use 0.25 (pixels up to 15.75, 10.5 sigma).
pub const I8_LSB: f32 = 0.25;

/// What one detector showed on one target run, frame by frame (index `n - 1` after `n`
/// frames).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Trace {
    /// Best merit of a track ending within `near_px` (Chebyshev) of the true pixel.
    pub near: Vec<f32>,
    /// The global best merit.
    pub best: Vec<f32>,
    /// Where the global best track ends (pixel).
    pub best_xy: Vec<[u16; 2]>,
    /// The global best end lies within `near_px` of the true pixel.
    pub best_hit: Vec<bool>,
    /// `errT` (px) after the last frame of the track recovered from the best end near the
    /// truth (`None` when nothing was recovered).
    pub err_near: Option<f64>,
    /// `errT` (px) after the last frame of the track recovered from the global best end.
    pub err_best: Option<f64>,
}

/// `errT`: RMS over the recovered frames of the Euclidean distance between the
/// recovered pixel centres (newest first, as `DpTrack::track` gives them) and the true
/// positions, the newest at frame `last` (0-based).
pub fn track_error(track: &[[u16; 2]], truth: &Truth, last: usize) -> Option<f64> {
    if track.is_empty() {
        return None;
    }
    let mut s = 0.0;
    for (j, p) in track.iter().enumerate() {
        let t = truth.position(last.checked_sub(j)?);
        let dx = f64::from(p[0]) + 0.5 - t[0];
        let dy = f64::from(p[1]) + 0.5 - t[1];
        s += dx * dx + dy * dy;
    }
    Some((s / track.len() as f64).sqrt())
}

fn recovered<D: DpTrack>(det: &D, x: usize, y: usize, truth: &Truth, last: usize) -> Option<f64> {
    let mut buf = [[0u16; 2]; HISTORY];
    let n = det.track(x, y, &mut buf);
    track_error(buf.get(..n).unwrap_or(&[]), truth, last)
}

/// Runs `det` over a target run.
pub fn trace<D: DpTrack>(det: &mut D, sc: &DimPoint, run: &Run) -> Result<Trace> {
    let truth = run
        .truth
        .ok_or_else(|| anyhow!("a target run needs a truth"))?;
    let r = sc.near_px;
    let n = run.frames.len();
    let mut t = Trace {
        near: Vec::with_capacity(n),
        best: Vec::with_capacity(n),
        best_xy: Vec::with_capacity(n),
        best_hit: Vec::with_capacity(n),
        err_near: None,
        err_best: None,
    };
    let mut near_end = None;
    for (k, f) in run.frames.iter().enumerate() {
        let rep = det.step(f).map_err(|e| anyhow!("frame {k}: {e}"))?;
        let (x, y) = truth.pixel(k);
        let near = det.best_within(x, y, r);
        near_end = near;
        t.near.push(near.map_or(f32::NEG_INFINITY, |e| e.merit));
        let b = rep.best;
        t.best.push(b.merit);
        t.best_xy.push([b.x, b.y]);
        t.best_hit
            .push(usize::from(b.x).abs_diff(x) <= r && usize::from(b.y).abs_diff(y) <= r);
    }
    let last = n.saturating_sub(1);
    if let Some(e) = near_end {
        t.err_near = recovered(det, usize::from(e.x), usize::from(e.y), &truth, last);
    }
    if let Some(b) = det.best() {
        t.err_best = recovered(det, usize::from(b.x), usize::from(b.y), &truth, last);
    }
    Ok(t)
}

/// The global best merit after every frame of a run (noise-only runs).
pub fn best_merits<D: DpTrack>(det: &mut D, run: &Run) -> Result<Vec<f32>> {
    run.frames
        .iter()
        .enumerate()
        .map(|(k, f)| {
            det.step(f)
                .map(|r| r.best.merit)
                .map_err(|e| anyhow!("frame {k}: {e}"))
        })
        .collect()
}

/// The detectors of one evaluation: the preset's configuration with an ablation applied,
/// and `q_B` (`None`: the preset's for the speed).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Variant {
    /// Replaces the second order's transition term.
    pub transition: Option<Transition>,
    /// Replaces `q_B`.
    pub qb: Option<usize>,
    /// The second order with `i8` merit cells and the input LSB [`I8_LSB`] (the other
    /// methods unchanged).
    pub second_i8: bool,
}

impl Variant {
    /// `q_B` at `speed`.
    pub fn qb(&self, speed: u8) -> Result<usize> {
        self.qb.map_or_else(|| qb_for(speed), Ok)
    }

    /// The configuration of `method` at `speed`.
    pub fn config(&self, method: Method, speed: u8) -> DpConfig {
        let mut c = DpConfig::dim_point(method, speed);
        if let Some(t) = self.transition {
            c.transition = t;
        }
        if self.second_i8 && method == Method::SecondOrder {
            c.lsb = I8_LSB;
        }
        c
    }
}

/// Runs `$body` with `$det: Box<_>` the detector of `$method` and `$qb` configured with
/// `$cfg` under variant `$v`: the `i8` second order ([`Second9I8`], [`Second25I8`]) with
/// [`Variant::second_i8`], else the host's ([`with_dp!`]). The one place the variant
/// picks a detector type.
macro_rules! with_variant_dp {
    ($v:expr, $method:expr, $qb:expr, $cfg:expr, |$det:ident| $body:expr) => {{
        match ($v.second_i8 && $method == Method::SecondOrder, $qb) {
            (true, 9) => {
                let $det = boxed::<Second9I8>($cfg)?;
                $body
            }
            (true, 25) => {
                let $det = boxed::<Second25I8>($cfg)?;
                $body
            }
            (true, q) => anyhow::bail!("q_b = {q}: must be 9 or 25"),
            (false, _) => with_dp!($method, $qb, $cfg, |$det| $body),
        }
    }};
}

/// The three methods' traces on target run `i` at `snr` and `speed` (stream
/// `Rng::from_stream(DimPoint::target_seed(seed, speed), i)`, the same frames for all
/// three).
pub fn target_run(
    sc: &DimPoint,
    speed: u8,
    snr: f64,
    v: &Variant,
    rng: &mut Rng,
) -> Result<Vec<Trace>> {
    let run = sc.run(Some(snr), speed, rng)?;
    let qb = v.qb(speed)?;
    METHODS
        .iter()
        .map(|&m| {
            let cfg = v.config(m, speed);
            with_variant_dp!(v, m, qb, &cfg, |det| {
                let mut det = det;
                trace(det.as_mut(), sc, &run)
            })
        })
        .collect()
}

/// The three methods' best merits after every frame of a noise-only run.
pub fn noise_run(sc: &DimPoint, speed: u8, v: &Variant, rng: &mut Rng) -> Result<Vec<Vec<f32>>> {
    let run = sc.run(None, speed, rng)?;
    let qb = v.qb(speed)?;
    METHODS
        .iter()
        .map(|&m| {
            let cfg = v.config(m, speed);
            with_variant_dp!(v, m, qb, &cfg, |det| {
                let mut det = det;
                best_merits(det.as_mut(), &run)
            })
        })
        .collect()
}
