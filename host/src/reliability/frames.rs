//! Hostile frames: what a recorder, a broken front end or a bit flip can hand a detector.
//!
//! Each frame is drawn in one [`Mode`]; most are plausible (noise at the preset's level,
//! sometimes with a strong return), the rest carry arbitrary bits, extremes, a constant,
//! a single NaN/inf, or the wrong length. The plausible values and scans are
//! `faint_golden::soak`'s, the generator the firmware's soak draws its frames with.

use faint_core::detect::cbmember::CbmemberConfig;
use faint_core::detect::phd::PhdConfig;
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;
use faint_core::Complex32;
use faint_golden::soak::{plausible as one_plausible, plot_count, plot_inside};

/// How a frame is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// Noise at the preset's scale, 1 in 8 values with a strong return added.
    Plausible,
    /// Noise at a scale from `1e-30` to `1e30`.
    Scaled,
    /// Every value from random bits (NaN, inf and subnormals included).
    Bits,
    /// Values from `{0, -0, +-MIN_POSITIVE, +-1e30, +-f32::MAX}`.
    Extreme,
    /// One value everywhere.
    Constant,
    /// A plausible frame with one NaN or infinity.
    OneBad,
    /// A plausible frame of the wrong length.
    WrongLength,
}

impl Mode {
    /// Every mode.
    pub const ALL: [Mode; 7] = [
        Mode::Plausible,
        Mode::Scaled,
        Mode::Bits,
        Mode::Extreme,
        Mode::Constant,
        Mode::OneBad,
        Mode::WrongLength,
    ];

    /// A mode: plausible half the time, the others equally often.
    pub fn draw(rng: &mut Rng) -> Mode {
        if rng.below(2) == 0 {
            Mode::Plausible
        } else {
            Mode::ALL[1 + rng.below(6) as usize]
        }
    }

    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Mode::Plausible => "plausible",
            Mode::Scaled => "scaled",
            Mode::Bits => "bits",
            Mode::Extreme => "extreme",
            Mode::Constant => "constant",
            Mode::OneBad => "one-bad",
            Mode::WrongLength => "wrong-length",
        }
    }
}

/// Extreme finite values a frame can carry.
pub const EXTREMES: [f32; 8] = [
    0.0,
    -0.0,
    f32::MIN_POSITIVE,
    -f32::MIN_POSITIVE,
    1e30,
    -1e30,
    f32::MAX,
    -f32::MAX,
];
/// The non-finite values.
pub const BAD: [f32; 3] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY];

/// `len` reals in `mode`; `scale` is the preset's noise level, `positive` makes the
/// plausible values powers (`|x|^2`) rather than signed amplitudes.
pub fn reals(rng: &mut Rng, len: usize, mode: Mode, scale: f32, positive: bool) -> Vec<f32> {
    let plausible = |rng: &mut Rng, s: f32| one_plausible(rng, s, positive);
    match mode {
        Mode::Plausible => (0..len).map(|_| plausible(rng, scale)).collect(),
        Mode::Scaled => {
            let s = 10f32.powi(rng.below(61) as i32 - 30);
            (0..len).map(|_| plausible(rng, s)).collect()
        }
        Mode::Bits => (0..len).map(|_| f32::from_bits(rng.next_u32())).collect(),
        Mode::Extreme => (0..len).map(|_| EXTREMES[rng.below(8) as usize]).collect(),
        Mode::Constant => {
            let c = if rng.below(2) == 0 {
                EXTREMES[rng.below(8) as usize]
            } else {
                plausible(rng, scale)
            };
            vec![c; len]
        }
        Mode::OneBad => {
            let mut v: Vec<f32> = (0..len).map(|_| plausible(rng, scale)).collect();
            if !v.is_empty() {
                let i = rng.below(v.len() as u32) as usize;
                v[i] = BAD[rng.below(3) as usize];
            }
            v
        }
        Mode::WrongLength => {
            let n = match rng.below(4) {
                0 => 0,
                1 => len.saturating_sub(1),
                2 => len + 1,
                _ => rng.below(2 * len as u32 + 2) as usize,
            };
            let n = if n == len { len + 1 } else { n };
            (0..n).map(|_| plausible(rng, scale)).collect()
        }
    }
}

/// `len` complex bins in `mode` (wrong-length frames change the bin count).
pub fn complex(rng: &mut Rng, len: usize, mode: Mode, scale: f32) -> Vec<Complex32> {
    let flat = reals(rng, 2 * len, mode, scale, false);
    let mut out: Vec<Complex32> = flat
        .chunks_exact(2)
        .map(|c| Complex32::new(c[0], c[1]))
        .collect();
    if mode == Mode::WrongLength && out.len() == len {
        out.push(Complex32::new(0.0, 0.0));
    }
    out
}

/// A scan of plots in `mode`, inside `area = [x0, x1, y0, y1]` when plausible; the count
/// runs from 0 to twice `capacity` (over-capacity lists are expected input).
pub fn plots(rng: &mut Rng, area: [f32; 4], capacity: usize, mode: Mode) -> Vec<Plot> {
    let n = plot_count(rng, capacity);
    let inside = |rng: &mut Rng| plot_inside(rng, area);
    match mode {
        Mode::Plausible | Mode::Constant | Mode::WrongLength => {
            (0..n).map(|_| inside(rng)).collect()
        }
        Mode::Scaled => {
            let s = 10f32.powi(rng.below(61) as i32 - 30);
            (0..n)
                .map(|_| Plot::new(s * rng.uniform(), s * rng.normal(), s * rng.normal()))
                .collect()
        }
        Mode::Bits => (0..n)
            .map(|_| {
                Plot::new(
                    f32::from_bits(rng.next_u32()),
                    f32::from_bits(rng.next_u32()),
                    f32::from_bits(rng.next_u32()),
                )
            })
            .collect(),
        Mode::Extreme => (0..n)
            .map(|_| {
                let e = |rng: &mut Rng| EXTREMES[rng.below(8) as usize];
                Plot::new(e(rng), e(rng), e(rng))
            })
            .collect(),
        Mode::OneBad => {
            let mut v: Vec<Plot> = (0..n.max(1)).map(|_| inside(rng)).collect();
            let i = rng.below(v.len() as u32) as usize;
            v[i].x = BAD[rng.below(3) as usize];
            v
        }
    }
}

/// The frame length `n`, or a short frame of 16 when `n` overflowed or exceeds `max` (a
/// configuration asking for more than a generator draws gets short frames).
pub fn len_or_short(n: Option<usize>, max: usize) -> usize {
    match n {
        Some(n) if n <= max => n,
        _ => 16,
    }
}

/// A power cube for a PHD-family configuration: `range x doppler x azimuth` cells.
pub fn cube(rng: &mut Rng, c: &PhdConfig, mode: Mode, max: usize) -> Vec<f32> {
    let g = c.geometry;
    let n = g
        .n_range
        .checked_mul(g.n_doppler)
        .and_then(|x| x.checked_mul(g.n_azimuth));
    reals(rng, len_or_short(n, max), mode, 1.0, true)
}

/// A range-velocity map for a CBMeMBer configuration.
pub fn map(rng: &mut Rng, c: &CbmemberConfig, mode: Mode, max: usize) -> Vec<f32> {
    let g = c.geometry;
    reals(
        rng,
        len_or_short(g.n_range.checked_mul(g.n_velocity), max),
        mode,
        1.0,
        true,
    )
}
