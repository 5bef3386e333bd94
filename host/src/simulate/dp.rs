//! Scenario preset `dim-point` (Wang, Zhang 2016, §4): one point target, smaller than a
//! pixel, in `128 x 128` intensity images of i.i.d. Gaussian noise, for the three DP-TBD
//! recursions of `faint_core::detect::dp`.
//!
//! Values and choices (all also in [`DimPoint::describe`]):
//! - **Image**: `128 x 128` pixels; pixel `(x, y)` = (column, row) of the row-major image
//!   covers `[x, x+1) x [y, y+1)`. Noise `N(0, 1.5^2)` i.i.d. per pixel and frame.
//! - **Target**: its whole amplitude `a` goes into the one pixel holding its continuous
//!   position, `z = a + n` there; `SNR = a / sigma` (linear amplitude ratio, eq. 29),
//!   swept 1.6 to 2.5.
//! - **Motion**: straight and uniform at 1 or 2 px/frame; start uniform in
//!   `[0, 128)^2`, heading uniform in `[0, 2 pi)`, redrawn (rejection) until the position
//!   at the last frame is inside too (the path is a segment, so every frame is inside).
//! - **Frames**: 40. **Run streams**: run `i` at speed `s` draws its truth and then its
//!   frames, row-major, from `Rng::from_stream(derive_seed(seed, s), i)` whatever the SNR
//!   (common random numbers across SNR and across the three methods); noise-only runs use
//!   `derive_seed(seed, 1000 + s)` (threshold calibration) and `derive_seed(seed, 2000 + s)`
//!   (the independent false-alarm check).
//! - **Detectors** ([`DpConfig::dim_point`]): `q_B = 9` at 1 px/frame and 25 at 2 px/frame
//!   (Arnold and the second order; Pulford uses the same `R_B`), `q_I = 9`, Gaussian
//!   transition with `sigma_I = 0.5`, Pulford `P0 = speed^2 E`; merits kept over
//!   `L = 40` frames, so the whole track is recovered.

use anyhow::{anyhow, bail, ensure, Result};
use faint_core::detect::dp::{DpConfig, DpTrack, Method};
use faint_core::dp_tbd;
use faint_core::rng::{derive_seed, Rng};
use serde::Serialize;

pub use faint_core::detect::dp::preset::{
    Arnold25, Arnold9, Pulford25, Pulford9, Second25, Second9, HISTORY, SIDE,
};

/// Image sides `M` of the host detectors of `faint detect dp-*`, smallest first: an
/// `H x W` image runs on the smallest that holds `max(H, W)`, padded (see
/// [`pad_image`]). [`SIDE`] is the preset's.
pub const CAPACITIES: [usize; 3] = [SIDE, 256, 512];

/// The side `M` of [`CAPACITIES`] an `h x w` image runs on (`None`: larger than the
/// largest, or empty).
pub fn capacity(h: usize, w: usize) -> Option<usize> {
    if h == 0 || w == 0 {
        return None;
    }
    CAPACITIES.iter().copied().find(|&m| h.max(w) <= m)
}

/// Defines the larger host detectors (only ever built in place by [`boxed`]: they are
/// larger than a thread's stack).
macro_rules! sized {
    ($($name:ident = $method:ident, $m:literal, $q:literal;)*) => {$(
        #[doc = concat!("`", stringify!($method), "` at `M = ", stringify!($m), "`, `q_B = ", stringify!($q), "`.")]
        pub type $name = dp_tbd!($method, $m, $q, HISTORY);
    )*};
}

sized! {
    Arnold9At256 = Arnold, 256, 9;
    Arnold25At256 = Arnold, 256, 25;
    Pulford9At256 = Pulford, 256, 9;
    Pulford25At256 = Pulford, 256, 25;
    Second9At256 = SecondOrder, 256, 9;
    Second25At256 = SecondOrder, 256, 25;
    Arnold9At512 = Arnold, 512, 9;
    Arnold25At512 = Arnold, 512, 25;
    Pulford9At512 = Pulford, 512, 9;
    Pulford25At512 = Pulford, 512, 25;
    Second9At512 = SecondOrder, 512, 9;
    Second25At512 = SecondOrder, 512, 25;
}

/// The DP detectors of the fuzzing targets (`reliability::guided`): small images, short
/// tracks, so a campaign runs many frames.
pub mod fuzz {
    use faint_core::dp_tbd;

    /// Image side `M`.
    pub const SIDE: usize = 32;
    /// Recoverable track length `L` (frames).
    pub const HISTORY: usize = 8;
    /// Arnold, `q_B = 9`.
    pub type Arnold9 = dp_tbd!(Arnold, SIDE, 9, HISTORY);
    /// Arnold, `q_B = 25`.
    pub type Arnold25 = dp_tbd!(Arnold, SIDE, 25, HISTORY);
    /// Pulford, `q_B = 9`.
    pub type Pulford9 = dp_tbd!(Pulford, SIDE, 9, HISTORY);
    /// Pulford, `q_B = 25`.
    pub type Pulford25 = dp_tbd!(Pulford, SIDE, 25, HISTORY);
    /// Second order, `q_B = 9`.
    pub type Second9 = dp_tbd!(SecondOrder, SIDE, 9, HISTORY);
    /// Second order, `q_B = 25`.
    pub type Second25 = dp_tbd!(SecondOrder, SIDE, 25, HISTORY);
}

/// A configured DP detector built on the heap, in place (the `q_B = 25` second order is
/// 6.2 MB, more than a thread's stack): the unconfigured detector (all-zero bits; an
/// optimised build writes it straight into the allocation), then configured with `cfg`.
pub fn boxed<D: DpTrack>(cfg: &DpConfig) -> Result<Box<D>> {
    let mut d = Box::new(D::new_unconfigured());
    d.configure(cfg, 0).map_err(|e| anyhow!("{e}"))?;
    Ok(d)
}

/// Runs `$body` with `$det: Box<_>` the host detector of `$method` and `$qb` (9 or 25),
/// configured with `$cfg`; another `q_B` is an error naming it.
macro_rules! with_dp {
    ($method:expr, $qb:expr, $cfg:expr, |$det:ident| $body:expr) => {{
        use faint_core::detect::dp::Method as M_;
        use $crate::simulate::dp as sdp;
        match ($method, $qb) {
            (M_::Arnold, 9) => {
                let $det = sdp::boxed::<sdp::Arnold9>($cfg)?;
                $body
            }
            (M_::Arnold, 25) => {
                let $det = sdp::boxed::<sdp::Arnold25>($cfg)?;
                $body
            }
            (M_::Pulford, 9) => {
                let $det = sdp::boxed::<sdp::Pulford9>($cfg)?;
                $body
            }
            (M_::Pulford, 25) => {
                let $det = sdp::boxed::<sdp::Pulford25>($cfg)?;
                $body
            }
            (M_::SecondOrder, 9) => {
                let $det = sdp::boxed::<sdp::Second9>($cfg)?;
                $body
            }
            (M_::SecondOrder, 25) => {
                let $det = sdp::boxed::<sdp::Second25>($cfg)?;
                $body
            }
            (_, q) => anyhow::bail!("q_b = {q}: must be 9 or 25"),
        }
    }};
}
pub(crate) use with_dp;

/// Runs `$body` with `$det: Box<_>` the host detector of `$method`, `$qb` (9 or 25) and
/// image side `$side` (one of [`CAPACITIES`]), configured with `$cfg`; another `q_B` or
/// side is an error naming it.
macro_rules! with_dp_sized {
    ($method:expr, $qb:expr, $side:expr, $cfg:expr, |$det:ident| $body:expr) => {{
        use faint_core::detect::dp::Method as M_;
        use $crate::simulate::dp as sdp;
        match ($method, $qb, $side) {
            (M_::Arnold, 9, 128) => {
                let $det = sdp::boxed::<sdp::Arnold9>($cfg)?;
                $body
            }
            (M_::Arnold, 25, 128) => {
                let $det = sdp::boxed::<sdp::Arnold25>($cfg)?;
                $body
            }
            (M_::Pulford, 9, 128) => {
                let $det = sdp::boxed::<sdp::Pulford9>($cfg)?;
                $body
            }
            (M_::Pulford, 25, 128) => {
                let $det = sdp::boxed::<sdp::Pulford25>($cfg)?;
                $body
            }
            (M_::SecondOrder, 9, 128) => {
                let $det = sdp::boxed::<sdp::Second9>($cfg)?;
                $body
            }
            (M_::SecondOrder, 25, 128) => {
                let $det = sdp::boxed::<sdp::Second25>($cfg)?;
                $body
            }
            (M_::Arnold, 9, 256) => {
                let $det = sdp::boxed::<sdp::Arnold9At256>($cfg)?;
                $body
            }
            (M_::Arnold, 25, 256) => {
                let $det = sdp::boxed::<sdp::Arnold25At256>($cfg)?;
                $body
            }
            (M_::Pulford, 9, 256) => {
                let $det = sdp::boxed::<sdp::Pulford9At256>($cfg)?;
                $body
            }
            (M_::Pulford, 25, 256) => {
                let $det = sdp::boxed::<sdp::Pulford25At256>($cfg)?;
                $body
            }
            (M_::SecondOrder, 9, 256) => {
                let $det = sdp::boxed::<sdp::Second9At256>($cfg)?;
                $body
            }
            (M_::SecondOrder, 25, 256) => {
                let $det = sdp::boxed::<sdp::Second25At256>($cfg)?;
                $body
            }
            (M_::Arnold, 9, 512) => {
                let $det = sdp::boxed::<sdp::Arnold9At512>($cfg)?;
                $body
            }
            (M_::Arnold, 25, 512) => {
                let $det = sdp::boxed::<sdp::Arnold25At512>($cfg)?;
                $body
            }
            (M_::Pulford, 9, 512) => {
                let $det = sdp::boxed::<sdp::Pulford9At512>($cfg)?;
                $body
            }
            (M_::Pulford, 25, 512) => {
                let $det = sdp::boxed::<sdp::Pulford25At512>($cfg)?;
                $body
            }
            (M_::SecondOrder, 9, 512) => {
                let $det = sdp::boxed::<sdp::Second9At512>($cfg)?;
                $body
            }
            (M_::SecondOrder, 25, 512) => {
                let $det = sdp::boxed::<sdp::Second25At512>($cfg)?;
                $body
            }
            (_, q, m) => anyhow::bail!(
                "q_b = {q}, M = {m}: q_b must be 9 or 25, M one of {:?}",
                sdp::CAPACITIES
            ),
        }
    }};
}
pub(crate) use with_dp_sized;

/// `h x w` row-major frames (`frames` of them, back to back) copied into the top-left
/// corner of `m x m` frames, the rest `fill`. With `fill` far below every pixel
/// (`faint detect` uses `-(ZMAX - 1) lsb`, the lowest value that is not clamped), a
/// state in the padding is never a better predecessor than the in-image state of its
/// window unless that one lies `ZMAX` LSB below it (held near the merit floor, far
/// from every track that can matter), so the results inside are those of the
/// unpadded recursion (see the test `padding_does_not_change_a_128_run`).
pub fn pad_image(data: &[f32], frames: usize, h: usize, w: usize, m: usize, fill: f32) -> Vec<f32> {
    let mut out = vec![fill; frames * m * m];
    if h == 0 || w == 0 || h > m || w > m {
        return out;
    }
    for (src, dst) in data.chunks_exact(h * w).zip(out.chunks_exact_mut(m * m)) {
        for (s_row, d_row) in src.chunks_exact(w).zip(dst.chunks_exact_mut(m)) {
            d_row[..w].copy_from_slice(s_row);
        }
    }
    out
}

/// The three methods in the order of every table.
pub const METHODS: [Method; 3] = [Method::Arnold, Method::Pulford, Method::SecondOrder];

/// The preset.
#[derive(Debug, Clone, Serialize)]
pub struct DimPoint {
    /// Image side (pixels).
    pub side: usize,
    /// Noise standard deviation `sigma`.
    pub sigma: f32,
    /// Frames per run.
    pub frames: usize,
    /// SNR grid of the paper's Fig. 6-7 (`a / sigma`, linear): `[from, to, step]`.
    pub snr_grid: [f64; 3],
    /// Target speeds (px/frame).
    pub speeds: [u8; 2],
    /// False-alarm probability of the detection thresholds.
    pub pfa: f64,
    /// Runs per point.
    pub runs: usize,
    /// Track-level detection: the best end within this Chebyshev distance (px) of the
    /// true pixel.
    pub near_px: usize,
}

impl Default for DimPoint {
    fn default() -> Self {
        Self {
            side: SIDE,
            sigma: 1.5,
            frames: HISTORY,
            snr_grid: [1.6, 2.5, 0.1],
            speeds: [1, 2],
            pfa: 0.01,
            runs: 100,
            near_px: 1,
        }
    }
}

/// A straight-line truth: the continuous position at frame `k` (0-based) is
/// `start + k velocity` (pixel units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Truth {
    /// Continuous position at the first frame.
    pub start: [f64; 2],
    /// Velocity (px/frame).
    pub velocity: [f64; 2],
}

impl Truth {
    /// Continuous position at frame `k` (0-based).
    pub fn position(&self, k: usize) -> [f64; 2] {
        let t = k as f64;
        [
            self.start[0] + t * self.velocity[0],
            self.start[1] + t * self.velocity[1],
        ]
    }

    /// The pixel `(x, y)` holding the position at frame `k`.
    pub fn pixel(&self, k: usize) -> (usize, usize) {
        let p = self.position(k);
        (p[0].floor() as usize, p[1].floor() as usize)
    }
}

/// The `q_B` of a speed: 9 at 1 px/frame, 25 at 2 px/frame.
pub fn qb_for(speed: u8) -> Result<usize> {
    match speed {
        1 => Ok(9),
        2 => Ok(25),
        s => bail!("speed {s} px/frame: the preset has 1 and 2"),
    }
}

impl DimPoint {
    /// The preset as JSON, with the detector configurations of both speeds.
    pub fn describe() -> serde_json::Value {
        let sc = Self::default();
        let mut v = serde_json::to_value(&sc).unwrap_or_default();
        let cfgs: Vec<serde_json::Value> = sc
            .speeds
            .iter()
            .flat_map(|&s| {
                METHODS.iter().map(move |&m| {
                    serde_json::json!({
                        "speed_px_per_frame": s,
                        "q_b": qb_for(s).unwrap_or(0),
                        "q_i": 9,
                        "history_frames": HISTORY,
                        "config": DpConfig::dim_point(m, s),
                    })
                })
            })
            .collect();
        if let Some(o) = v.as_object_mut() {
            o.insert("detectors".into(), serde_json::Value::Array(cfgs));
            o.insert(
                "motion".into(),
                serde_json::json!("straight, uniform; start uniform in [0, 128)^2, heading uniform in [0, 2 pi), redrawn until the last position is inside"),
            );
            o.insert(
                "target".into(),
                serde_json::json!(
                    "whole amplitude a = SNR sigma in the pixel holding the continuous position"
                ),
            );
            o.insert(
                "streams".into(),
                serde_json::json!("run i at speed s: Rng::from_stream(derive_seed(seed, s), i); noise-only calibration derive_seed(seed, 1000 + s), check derive_seed(seed, 2000 + s)"),
            );
        }
        v
    }

    /// Master seed of the target runs at `speed` (run `i` is stream `i`).
    pub fn target_seed(seed: u64, speed: u8) -> u64 {
        derive_seed(seed, u64::from(speed))
    }

    /// Master seed of the noise-only calibration runs at `speed`.
    pub fn calibration_seed(seed: u64, speed: u8) -> u64 {
        derive_seed(seed, 1000 + u64::from(speed))
    }

    /// Master seed of the independent noise-only check runs at `speed`.
    pub fn check_seed(seed: u64, speed: u8) -> u64 {
        derive_seed(seed, 2000 + u64::from(speed))
    }

    /// Draws a truth at `speed` px/frame that stays inside for all frames.
    pub fn truth(&self, speed: f64, rng: &mut Rng) -> Result<Truth> {
        let m = self.side as f64;
        let last = self.frames.saturating_sub(1) as f64;
        ensure!(
            speed >= 0.0 && speed * last < m,
            "speed {speed} px/frame: the target cannot stay inside for {} frames",
            self.frames
        );
        for _ in 0..100_000 {
            let start = [m * f64::from(rng.uniform()), m * f64::from(rng.uniform())];
            let h = std::f64::consts::TAU * f64::from(rng.uniform());
            let velocity = [speed * h.cos(), speed * h.sin()];
            let t = Truth { start, velocity };
            let end = t.position(self.frames.saturating_sub(1));
            let inside = |v: f64| (0.0..m).contains(&v);
            if inside(end[0]) && inside(end[1]) {
                return Ok(t);
            }
        }
        bail!("no truth inside the image after 100000 draws")
    }

    /// Frame `k` into `out` (`side^2` values, row-major): noise, plus `amp` at the
    /// target's pixel when `truth` is given.
    pub fn frame(
        &self,
        truth: Option<&Truth>,
        amp: f32,
        k: usize,
        rng: &mut Rng,
        out: &mut Vec<f32>,
    ) {
        out.clear();
        out.extend((0..self.side * self.side).map(|_| self.sigma * rng.normal()));
        if let Some(t) = truth {
            let (x, y) = t.pixel(k);
            if let Some(v) = out.get_mut(y * self.side + x) {
                *v += amp;
            }
        }
    }

    /// One whole run: the truth (target runs) and every frame, from `rng` (see the module
    /// docs for the stream). `snr = None` gives a noise-only run.
    pub fn run(&self, snr: Option<f64>, speed: u8, rng: &mut Rng) -> Result<Run> {
        let truth = match snr {
            Some(_) => Some(self.truth(f64::from(speed), rng)?),
            None => None,
        };
        let amp = (snr.unwrap_or(0.0) * f64::from(self.sigma)) as f32;
        let mut frames = Vec::with_capacity(self.frames);
        for k in 0..self.frames {
            let mut f = Vec::new();
            self.frame(truth.as_ref(), amp, k, rng, &mut f);
            frames.push(f);
        }
        Ok(Run { truth, frames })
    }
}

/// The frames of one run and its truth (`None`: noise only).
#[derive(Debug, Clone)]
pub struct Run {
    /// The truth.
    pub truth: Option<Truth>,
    /// `frames x side^2` pixels.
    pub frames: Vec<Vec<f32>>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The larger detectors are built in place on the heap: all of them configure on a
    /// thread with a 256 KiB stack, smaller than each (a by-value construction would
    /// overflow it and abort the test binary). Prints each `size_of`, the numbers of
    /// docs/dp.md (`cargo test -p faint --lib -- larger_dp --nocapture`).
    #[test]
    fn larger_dp_detectors_build_in_place() {
        fn build<D: DpTrack>(method: Method, q: usize) -> (String, usize) {
            let cfg = DpConfig::dim_point(method, 1);
            let d = boxed::<D>(&cfg).unwrap();
            assert_eq!(d.frames(), 0);
            assert!(std::mem::size_of::<D>() > 256 << 10);
            let name = format!("{} q_B {q} M {}", method.name(), D::SIDE);
            (name, std::mem::size_of::<D>())
        }
        let sizes = std::thread::Builder::new()
            .stack_size(256 << 10)
            .spawn(|| {
                vec![
                    build::<Arnold9>(Method::Arnold, 9),
                    build::<Arnold25>(Method::Arnold, 25),
                    build::<Pulford9>(Method::Pulford, 9),
                    build::<Pulford25>(Method::Pulford, 25),
                    build::<Second9>(Method::SecondOrder, 9),
                    build::<Second25>(Method::SecondOrder, 25),
                    build::<Arnold9At256>(Method::Arnold, 9),
                    build::<Arnold25At256>(Method::Arnold, 25),
                    build::<Pulford9At256>(Method::Pulford, 9),
                    build::<Pulford25At256>(Method::Pulford, 25),
                    build::<Second9At256>(Method::SecondOrder, 9),
                    build::<Second25At256>(Method::SecondOrder, 25),
                    build::<Arnold9At512>(Method::Arnold, 9),
                    build::<Arnold25At512>(Method::Arnold, 25),
                    build::<Pulford9At512>(Method::Pulford, 9),
                    build::<Pulford25At512>(Method::Pulford, 25),
                    build::<Second9At512>(Method::SecondOrder, 9),
                    build::<Second25At512>(Method::SecondOrder, 25),
                ]
            })
            .unwrap()
            .join()
            .unwrap();
        for (name, bytes) in &sizes {
            println!("{name}: {bytes} B");
        }
        assert_eq!(capacity(128, 128), Some(128));
        assert_eq!(capacity(100, 300), Some(512));
        assert_eq!(capacity(129, 1), Some(256));
        assert_eq!(capacity(513, 2), None);
        assert_eq!(capacity(0, 5), None);
    }

    #[test]
    fn padding_keeps_the_image_top_left() {
        let img: Vec<f32> = (0..2 * 2 * 3).map(|i| i as f32).collect();
        let p = pad_image(&img, 2, 2, 3, 4, -9.0);
        assert_eq!(p.len(), 2 * 16);
        assert_eq!(&p[..8], &[0.0, 1.0, 2.0, -9.0, 3.0, 4.0, 5.0, -9.0]);
        assert_eq!(&p[8..16], &[-9.0; 8]);
        assert_eq!(&p[16..20], &[6.0, 7.0, 8.0, -9.0]);
    }

    #[test]
    fn truths_stay_inside_and_move_at_the_speed() {
        let sc = DimPoint::default();
        let mut rng = Rng::seed_from_u64(3);
        for speed in [1.0, 2.0] {
            for _ in 0..200 {
                let t = sc.truth(speed, &mut rng).unwrap();
                let v = (t.velocity[0].powi(2) + t.velocity[1].powi(2)).sqrt();
                assert!((v - speed).abs() < 1e-12);
                for k in 0..sc.frames {
                    let p = t.position(k);
                    assert!(p.iter().all(|c| (0.0..128.0).contains(c)));
                }
            }
        }
    }

    #[test]
    fn the_target_pixel_holds_the_amplitude() {
        let sc = DimPoint::default();
        let mut a = sc.run(Some(2.0), 1, &mut Rng::seed_from_u64(5)).unwrap();
        let b = sc.run(Some(0.0), 1, &mut Rng::seed_from_u64(5)).unwrap();
        let t = a.truth.unwrap();
        for k in 0..sc.frames {
            let (x, y) = t.pixel(k);
            let i = y * SIDE + x;
            assert!((a.frames[k][i] - b.frames[k][i] - 3.0).abs() < 1e-5);
            a.frames[k][i] = b.frames[k][i];
            assert_eq!(a.frames[k], b.frames[k]);
        }
    }
}
