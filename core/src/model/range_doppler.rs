//! Range-Doppler maps of a rotor UAV: the joint Doppler / micro-Doppler measurement model
//! of *Weak targets detection and estimation based on joint use of Doppler and
//! micro-Doppler* (Journal of Radars, 2023; "the rotor-UAV paper" below), eq. 13 and
//! 17-22, with the corrections of the project's specification.
//!
//! **Map.** `n_range x n_velocity` pixels, row-major (`index = i_r * n_velocity + j_v`),
//! pixel `(i, j)` centred at `r_i = range_start + (i + 0.5) range_bin`,
//! `v_j = velocity_start + (j + 0.5) velocity_bin`. A map is borrowed as complex pixels
//! `&[Complex32]`, as a precomputed power map `|y|^2` (`&[f32]`), or quantised (`&[u8]`,
//! see [`Dequant`]); it is never copied ([`PowerMap`]).
//!
//! **Points (eq. 17, eq. 13 sign).** A state `[r, v, rho, V, omega, theta, B]` lights
//! `B + 1` points at range `r`: the body at `v`, blade `b = 1..B` at
//! `v - V sin(theta + 2 pi (b - 1) / B)` ([`point_velocities`]; the Doppler-only model
//! keeps the body only).
//!
//! **Pixels (eq. 18-21, power reading).** Point `p` spreads
//! `g_p = exp(-(r_i - r)^2 / zeta_r^2 - (v_j - v_p)^2 / zeta_v^2)` over its support
//! `|r_i - r| <= kappa zeta_r`, `|v_j - v_p| <= kappa zeta_v`, `kappa = sqrt(ln 100)`
//! (the spread is truncated where one axis factor falls below 0.01). A pixel of the union
//! of the supports `T(x)` (eq. 20) is complex Gaussian with per-component variance
//! `zeta_s^2 (1 + a)`, `a = A sum_p g_p`, `A = k_s rho / (2 r^4 zeta_s^2)` the peak SNR
//! of eq. 19 (the signal *power* `d = k_s rho g / r^4`, so eq. 18's `d^2` reads `d`);
//! every other pixel has variance `zeta_s^2` (eq. 21). Overlapping points add powers.
//!
//! **Log likelihood ratio (eq. 22).** With `z = |y|^2 / (2 zeta_s^2)`,
//! ```text
//! ln g(x) = sum_{(i,j) in T(x)} [ z_ij a_ij / (1 + a_ij) - ln(1 + a_ij) ]
//! ```
//! All points share the range, so `a_ij = A g_r(i) h_j` with `h_j = sum_p g_v(v_j - v_p)`.
//! [`log_lr_exact`] evaluates this over the pixels of `T(x)` only (never the whole map);
//! [`log_lr_blocked`] is the fast form used by the filter: the map is pre-summed once per
//! frame over blocks of `M` velocity bins ([`BlockMap`], a per-frame box pre-filter of
//! `|y|^2`), and `a` is evaluated at the block centre:
//! ```text
//! ln g(x) ~ sum_i sum_m [ Z_im a_im / (1 + a_im) - M ln(1 + a_im) ],  Z_im = sum_{j in m} z_ij
//! ```
//! (error measured in `tests/cbmember`). Logs of products: `sum ln(1 + a)` is taken as
//! the log of running products, folded before they could overflow.

use crate::math;
use crate::rng::Rng;
use crate::{Complex32, Error, Result};

/// Most points a state lights (body plus at most 4 blades).
pub const MAX_POINTS: usize = 5;
/// Most blades of a rotor.
pub const MAX_BLADES: usize = MAX_POINTS - 1;
/// Largest supported `n_velocity` (size of the per-particle velocity scratch).
pub const MAX_VELOCITY_BINS: usize = 1024;
/// Truncation factor `kappa = sqrt(ln 100)`: one axis factor of the spread is at least
/// 0.01 inside the support.
pub const KAPPA: f32 = 2.145_966;
/// Number of entries of the quantised-map lookup table ([`Dequant`]).
pub const QUANT_LEVELS: usize = 256;

/// Axes of the range-Doppler map.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct RdGeometry {
    /// Range bins (rows) `N_r`.
    pub n_range: usize,
    /// Velocity bins (columns) `N_v`, at most [`MAX_VELOCITY_BINS`].
    pub n_velocity: usize,
    /// Lower edge of range bin 0 (m).
    pub range_start: f32,
    /// Range bin size (m).
    pub range_bin: f32,
    /// Lower edge of velocity bin 0 (m/s, positive = receding).
    pub velocity_start: f32,
    /// Velocity bin size (m/s).
    pub velocity_bin: f32,
}

impl RdGeometry {
    /// Number of pixels `N_r N_v`.
    pub const fn len(&self) -> usize {
        self.n_range * self.n_velocity
    }

    /// True if the map has no pixel.
    pub const fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Checks sizes and extents.
    pub fn validate(&self) -> Result<()> {
        if self.n_range == 0 || self.n_velocity == 0 {
            return Err(Error::InvalidConfig("geometry: map dimensions"));
        }
        if self.n_velocity > MAX_VELOCITY_BINS || self.n_range > u32::MAX as usize / 4096 {
            return Err(Error::InvalidConfig("geometry: map too large"));
        }
        let pos = |v: f32| v.is_finite() && v > 0.0;
        if !pos(self.range_bin) || !pos(self.velocity_bin) {
            return Err(Error::InvalidConfig("geometry: bin sizes"));
        }
        if !self.range_start.is_finite() || !self.velocity_start.is_finite() {
            return Err(Error::InvalidConfig("geometry: axis starts"));
        }
        Ok(())
    }

    /// Centre of range bin `i` (m).
    #[inline]
    pub fn range_centre(&self, i: usize) -> f32 {
        self.range_start + (i as f32 + 0.5) * self.range_bin
    }

    /// Centre of velocity bin `j` (m/s).
    #[inline]
    pub fn velocity_centre(&self, j: usize) -> f32 {
        self.velocity_start + (j as f32 + 0.5) * self.velocity_bin
    }
}

/// Spread of a measurement point (eq. 18): `zeta_r` (m), `zeta_v` (m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct RdSpread {
    /// Range spread `zeta_r` (m).
    pub zeta_r: f32,
    /// Velocity spread `zeta_v` (m/s).
    pub zeta_v: f32,
}

impl RdSpread {
    /// The spread of a point target on a map made by pulse compression in range and a
    /// windowed slow-time DFT of `n_velocity` pulses in velocity (one velocity ambiguity
    /// `Va = n_velocity velocity_bin` across the map), matched to the map's response at
    /// its peak.
    ///
    /// Velocity: a constant-velocity target offset by `x` bins from a pixel centre gives
    /// the power response of the window `w_n` (`N = n_velocity`, `phi = 2 pi x / N`):
    /// ```text
    /// R(x) = |sum_n w_n exp(j phi n)|^2 / (sum w)^2
    ///      = 1 - phi^2 s_w^2 + O(phi^4),   s_w^2 = sum w_n (n - n_bar)^2 / sum w_n
    /// ```
    /// (expand `cos(phi (n - m))` in the double sum; `n_bar` the window's centroid).
    /// The model's factor `exp(-dv^2 / zeta_v^2) = 1 - x^2 velocity_bin^2 / zeta_v^2 + ..`
    /// has the same curvature when
    /// ```text
    /// zeta_v0 = velocity_bin N / (2 pi s_w)
    /// ```
    /// (rectangular: `s_w^2 = (N^2 - 1) / 12`, `zeta_v0 = 0.551` bins; Hamming:
    /// `s_w = 0.2004 N`, `zeta_v0 = 0.794` bins, half-power half-width `0.661` bins
    /// against the window's `0.65`). A scatterer whose velocity sweeps uniformly over
    /// `smear` m/s within the CPI (a rotor blade: `V omega CPI |cos(theta)|`) spreads the
    /// power over that interval; matching second moments (a power Gaussian
    /// `exp(-dv^2 / zeta^2)` has variance `zeta^2 / 2`, the uniform `smear^2 / 12`):
    /// ```text
    /// zeta_v^2 = zeta_v0^2 + smear^2 / 6
    /// ```
    /// Range: a compressed pulse `sinc(dr / dR)` (`dR = range_resolution`, a rectangular
    /// spectrum) has power `sinc^2(u) = 1 - pi^2 u^2 / 3 + O(u^4)`, so
    /// `zeta_r = sqrt(3) dR / pi = 0.551 dR`.
    ///
    /// Returns `None` if the geometry, `range_resolution` or `smear` is invalid (the
    /// result always validates otherwise).
    pub fn from_geometry(
        g: &RdGeometry,
        window: super::doppler::Window,
        range_resolution: f32,
        smear: f32,
    ) -> Option<Self> {
        g.validate().ok()?;
        let ok = range_resolution.is_finite()
            && range_resolution > 0.0
            && smear.is_finite()
            && smear >= 0.0;
        if !ok {
            return None;
        }
        let n = g.n_velocity;
        let (mut s0, mut s1, mut s2) = (0.0f64, 0.0f64, 0.0f64);
        for k in 0..n {
            let w = window.coefficient(k, n);
            let t = k as f64;
            s0 += w;
            s1 += w * t;
            s2 += w * t * t;
        }
        let var = if s0 > 0.0 {
            s2 / s0 - (s1 / s0) * (s1 / s0)
        } else {
            0.0
        };
        // One pulse (or a degenerate window): no curvature, one bin.
        let zeta_v0 = if var > 0.0 {
            f64::from(g.velocity_bin) * n as f64 / (2.0 * core::f64::consts::PI * libm::sqrt(var))
        } else {
            f64::from(g.velocity_bin)
        };
        let sm = f64::from(smear);
        let zeta_v = libm::sqrt(zeta_v0 * zeta_v0 + sm * sm / 6.0) as f32;
        let zeta_r = (libm::sqrt(3.0) * f64::from(range_resolution) / core::f64::consts::PI) as f32;
        let s = Self { zeta_r, zeta_v };
        s.validate().ok()?;
        Some(s)
    }

    /// Checks both spreads are positive and finite.
    pub fn validate(&self) -> Result<()> {
        if !(self.zeta_r.is_finite()
            && self.zeta_r > 0.0
            && self.zeta_v.is_finite()
            && self.zeta_v > 0.0)
        {
            return Err(Error::InvalidConfig("spread: zeta_r / zeta_v"));
        }
        Ok(())
    }
}

/// Which points a state lights.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "snake_case")
)]
pub enum PointModel {
    /// Body and `B` blades (joint Doppler / micro-Doppler).
    #[default]
    Joint,
    /// Body only (the Doppler-only baseline).
    DopplerOnly,
}

/// Velocities of the points lit by a state (eq. 17 with eq. 13's sign): body `v`, blade
/// `b = 1..B`: `v - V sin(theta + 2 pi (b - 1) / B)`. Writes `out` and returns how many
/// (`1` for [`PointModel::DopplerOnly`], `B + 1` otherwise, `B` clamped to
/// `1..=MAX_BLADES`).
pub fn point_velocities(
    model: PointModel,
    v: f32,
    blade_speed: f32,
    theta: f32,
    blades: u32,
    out: &mut [f32; MAX_POINTS],
) -> usize {
    out[0] = v;
    if model == PointModel::DopplerOnly {
        return 1;
    }
    let b = blades.clamp(1, MAX_BLADES as u32);
    let step = 2.0 * math::PI / b as f32;
    for (k, o) in out.iter_mut().skip(1).take(b as usize).enumerate() {
        *o = v - blade_speed * math::sin(theta + step * k as f32);
    }
    1 + b as usize
}

/// Dequantisation of a map: `z = |y|^2 scale` for complex and power maps, and the
/// 256-entry table `z = table[q]` of a quantised `u8` map (normalised power of each code).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dequant {
    /// `1 / (2 zeta_s^2)`.
    pub scale: f32,
    /// Normalised power of each `u8` code.
    pub table: [f32; QUANT_LEVELS],
}

impl Dequant {
    /// `scale = 1 / (2 noise_var)` and the linear table `table[q] = q step` (normalised
    /// power units). [`quantise`] is its inverse.
    pub fn new(noise_var: f32, step: f32) -> Self {
        let mut table = [0.0; QUANT_LEVELS];
        for (q, t) in table.iter_mut().enumerate() {
            *t = q as f32 * step;
        }
        Self {
            scale: 0.5 / noise_var,
            table,
        }
    }
}

/// The `u8` code of normalised power `z` for a linear quantiser of step `step`:
/// `round(z / step)`, saturating at 255 (NaN gives 0).
pub fn quantise(z: f32, step: f32) -> u8 {
    let q = math::round(z / step);
    if q >= 255.0 {
        255
    } else if q > 0.0 {
        q as u8
    } else {
        0
    }
}

/// A borrowed range-Doppler map whose pixels yield normalised power
/// `z = |y|^2 / (2 zeta_s^2)`.
pub trait PowerMap {
    /// Number of pixels.
    fn pixel_count(&self) -> usize;
    /// Checks every pixel (finite, non-negative power): [`Error::NonFinite`],
    /// [`Error::NegativeWeight`].
    fn check(&self) -> Result<()>;
    /// Calls `f(k, z_{start + k})` for the pixels `start..start + len` that exist.
    fn for_each(&self, dq: &Dequant, start: usize, len: usize, f: impl FnMut(usize, f32));
}

impl PowerMap for [f32] {
    fn pixel_count(&self) -> usize {
        self.len()
    }
    fn check(&self) -> Result<()> {
        for &p in self {
            if !p.is_finite() {
                return Err(Error::NonFinite);
            }
            if p < 0.0 {
                return Err(Error::NegativeWeight);
            }
        }
        Ok(())
    }
    #[inline]
    fn for_each(&self, dq: &Dequant, start: usize, len: usize, mut f: impl FnMut(usize, f32)) {
        let end = start.saturating_add(len).min(self.len());
        if let Some(s) = self.get(start..end) {
            for (k, &p) in s.iter().enumerate() {
                f(k, p * dq.scale);
            }
        }
    }
}

impl PowerMap for [Complex32] {
    fn pixel_count(&self) -> usize {
        self.len()
    }
    fn check(&self) -> Result<()> {
        if self.iter().all(|c| c.re.is_finite() && c.im.is_finite()) {
            Ok(())
        } else {
            Err(Error::NonFinite)
        }
    }
    #[inline]
    fn for_each(&self, dq: &Dequant, start: usize, len: usize, mut f: impl FnMut(usize, f32)) {
        let end = start.saturating_add(len).min(self.len());
        if let Some(s) = self.get(start..end) {
            for (k, c) in s.iter().enumerate() {
                f(k, (c.re * c.re + c.im * c.im) * dq.scale);
            }
        }
    }
}

impl PowerMap for [u8] {
    fn pixel_count(&self) -> usize {
        self.len()
    }
    fn check(&self) -> Result<()> {
        Ok(())
    }
    #[inline]
    fn for_each(&self, dq: &Dequant, start: usize, len: usize, mut f: impl FnMut(usize, f32)) {
        let end = start.saturating_add(len).min(self.len());
        if let Some(s) = self.get(start..end) {
            for (k, &q) in s.iter().enumerate() {
                f(k, dq.table.get(q as usize).copied().unwrap_or(0.0));
            }
        }
    }
}

/// A Gaussian sampled on a regular grid by recurrence: `g_k = exp(-(u0 + k d)^2)` with
/// `g_{k+1} = g_k q_k`, `q_{k+1} = q_k exp(-2 d^2)`, re-anchored with two fresh `exp`
/// every [`ANCHOR`] steps (the relative error of the products grows as `k^2` ulps, so it
/// stays below about `1e-5`).
#[derive(Debug, Clone, Copy)]
struct GaussRun {
    g: f32,
    q: f32,
    c: f32,
    u0: f32,
    d: f32,
    k: u32,
}

/// Steps between re-anchors of a [`GaussRun`].
const ANCHOR: u32 = 16;

impl GaussRun {
    #[inline]
    fn new(u0: f32, d: f32, c: f32) -> Self {
        let mut r = Self {
            g: 0.0,
            q: 0.0,
            c,
            u0,
            d,
            k: 0,
        };
        r.anchor(u0);
        r
    }
    #[inline]
    fn anchor(&mut self, u: f32) {
        self.g = math::exp(-u * u);
        self.q = math::exp(-self.d * (2.0 * u + self.d));
    }
    #[inline]
    fn next(&mut self) -> f32 {
        let g = self.g;
        self.k += 1;
        // `%` by the constant, not `is_multiple_of`: on the Cortex-M4F the latter cost the
        // CBMeMBer steps 0.3-0.4 % more instructions (firmware table, measured).
        #[allow(clippy::manual_is_multiple_of)]
        if self.k % ANCHOR == 0 {
            self.anchor(self.u0 + self.k as f32 * self.d);
        } else {
            self.g *= self.q;
            self.q *= self.c;
        }
        g
    }
}

/// Per-configuration constants of the spread on the map's grid.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Kernel {
    /// `range_bin / zeta_r`.
    dr: f32,
    /// `exp(-2 dr^2)`.
    cr: f32,
    /// `kappa zeta_r / range_bin` (support half-width in range bins).
    half_r: f32,
    /// `velocity_bin / zeta_v`.
    dv: f32,
    /// `exp(-2 dv^2)`.
    cv: f32,
    /// `kappa zeta_v / velocity_bin`.
    half_v: f32,
    /// Velocity bins per block (1 for the exact form).
    block: usize,
    /// `block * dv`.
    db: f32,
    /// `exp(-2 db^2)`.
    cb: f32,
}

impl Kernel {
    /// The constants for a map geometry, a spread and a block of `block` velocity bins.
    pub fn new(g: &RdGeometry, s: &RdSpread, block: usize) -> Self {
        let dr = g.range_bin / s.zeta_r;
        let dv = g.velocity_bin / s.zeta_v;
        let block = block.max(1);
        let db = block as f32 * dv;
        Self {
            dr,
            cr: math::exp(-2.0 * dr * dr),
            half_r: KAPPA * s.zeta_r / g.range_bin,
            dv,
            cv: math::exp(-2.0 * dv * dv),
            half_v: KAPPA * s.zeta_v / g.velocity_bin,
            block,
            db,
            cb: math::exp(-2.0 * db * db),
        }
    }
}

/// Indices `lo..=hi` of grid points `k` with `|k - f| <= half`, clipped to `0..n`, or
/// `None` if there is none. `f` is a fractional grid coordinate.
#[inline]
fn span(f: f32, half: f32, n: usize) -> Option<(usize, usize)> {
    // Smallest integer >= f - half, largest <= f + half.
    let lo = -math::floor(half - f);
    let hi = math::floor(f + half);
    let lo = lo.max(0.0);
    let hi = hi.min(n as f32 - 1.0);
    if lo.is_nan() || hi.is_nan() || lo > hi {
        return None;
    }
    Some((lo as usize, hi as usize))
}

/// Peak SNR `A = k_s rho / (2 r^4 zeta_s^2)` (eq. 19) from `c0 = k_s / (2 zeta_s^2)`;
/// 0 for `rho <= 0` or a non-positive range.
#[inline]
pub fn peak_snr(c0: f32, rho: f32, range: f32) -> f32 {
    let r2 = range * range;
    let a = c0 * rho / (r2 * r2);
    if a > 0.0 && a.is_finite() {
        a
    } else {
        0.0
    }
}

/// Rows of a point at `range` and their range factors `g_r(i)` (written to `gr`, first
/// entry = row `i0`). Returns `(i0, rows)`.
#[inline]
fn range_rows(g: &RdGeometry, k: &Kernel, range: f32, gr: &mut [f32; 64]) -> (usize, usize) {
    let f = (range - g.range_start) / g.range_bin - 0.5;
    let Some((i0, i1)) = span(f, k.half_r, g.n_range) else {
        return (0, 0);
    };
    let n = (i1 - i0 + 1).min(gr.len());
    let mut run = GaussRun::new((i0 as f32 - f) * k.dr, k.dr, k.cr);
    for x in gr.iter_mut().take(n) {
        *x = run.next();
    }
    (i0, n)
}

/// Largest running product of `1 + a` factors kept before folding it into a log.
const FOLD: f32 = 1.0e30;

/// Number of factors `<= tmax` that can be multiplied without exceeding [`FOLD`].
#[inline]
fn fold_every(tmax: f32) -> usize {
    if tmax.is_nan() || tmax <= 1.0 {
        return usize::MAX;
    }
    let n = math::ln(FOLD) / math::ln(tmax);
    if n >= 1.0e6 {
        1_000_000
    } else if n >= 1.0 {
        n as usize
    } else {
        1
    }
}

/// The exact log likelihood ratio of eq. 22 over the pixels of `T(x)`: range `range`,
/// peak SNR `amp` ([`peak_snr`]), point velocities `vels`. `h` is a scratch of at least
/// `n_velocity` entries. Reads only the pixels of the union of the points' supports.
/// Rounding: `f32` sums (relative error of order `1e-6` per pixel), see `tests/cbmember`.
#[allow(clippy::too_many_arguments)]
pub fn log_lr_exact<M: PowerMap + ?Sized>(
    map: &M,
    dq: &Dequant,
    g: &RdGeometry,
    k: &Kernel,
    amp: f32,
    range: f32,
    vels: &[f32],
    h: &mut [f32],
) -> f32 {
    if amp.is_nan() || amp <= 0.0 || vels.is_empty() {
        return 0.0;
    }
    let mut gr = [0f32; 64];
    let (i0, nr) = range_rows(g, k, range, &mut gr);
    if nr == 0 {
        return 0.0;
    }
    let nv = g.n_velocity.min(h.len());
    // Union of the points' velocity spans, and h_j over it.
    let mut j_lo = usize::MAX;
    let mut j_hi = 0usize;
    let mut spans = [(0usize, 0usize, 0.0f32); MAX_POINTS];
    let mut np = 0usize;
    for (&vp, s) in vels.iter().zip(spans.iter_mut()) {
        let f = (vp - g.velocity_start) / g.velocity_bin - 0.5;
        if let Some((a, b)) = span(f, k.half_v, nv) {
            *s = (a, b, f);
            j_lo = j_lo.min(a);
            j_hi = j_hi.max(b);
            np += 1;
        } else {
            *s = (1, 0, f);
        }
    }
    if np == 0 || j_lo > j_hi {
        return 0.0;
    }
    let Some(hs) = h.get_mut(j_lo..=j_hi) else {
        return 0.0;
    };
    hs.iter_mut().for_each(|x| *x = 0.0);
    let mut hmax = 0.0f32;
    for &(a, b, f) in spans.iter().take(vels.len()) {
        if a > b {
            continue;
        }
        let mut run = GaussRun::new((a as f32 - f) * k.dv, k.dv, k.cv);
        if let Some(seg) = hs.get_mut(a - j_lo..=b - j_lo) {
            for x in seg.iter_mut() {
                *x += run.next();
            }
        }
    }
    for &x in hs.iter() {
        hmax = hmax.max(x);
    }
    let width = j_hi - j_lo + 1;
    let every = fold_every(1.0 + amp * hmax);
    let mut data = 0.0f32;
    let mut noise = 0.0f32;
    for (row, &grow) in gr.iter().take(nr).enumerate() {
        let s = amp * grow;
        let start = (i0 + row) * g.n_velocity + j_lo;
        let mut prod = 1.0f32;
        let mut since = 0usize;
        let mut d_row = 0.0f32;
        map.for_each(dq, start, width, |j, z| {
            let a = s * hs.get(j).copied().unwrap_or(0.0);
            let t = 1.0 + a;
            d_row += z * a / t;
            prod *= t;
            since += 1;
            if since >= every {
                noise += math::ln(prod);
                prod = 1.0;
                since = 0;
            }
        });
        noise += math::ln(prod);
        data += d_row;
    }
    data - noise
}

/// The map summed over blocks of `block` velocity bins, once per frame: `Z_im`, the
/// normalised power of range row `i` summed over velocity block `m` (a box pre-filter of
/// `|y|^2`), stored in a caller's buffer.
#[derive(Debug)]
pub struct BlockMap<'a> {
    sums: &'a [f32],
    blocks: usize,
}

impl<'a> BlockMap<'a> {
    /// Fills `buf` (at least `n_range * n_velocity / block` entries) with the block sums
    /// of `map`, checking every pixel. Errors: [`Error::LengthMismatch`] (map or buffer),
    /// [`Error::NonFinite`], [`Error::NegativeWeight`], [`Error::InvalidConfig`] if
    /// `block` does not divide `n_velocity`.
    pub fn build<M: PowerMap + ?Sized>(
        map: &M,
        dq: &Dequant,
        g: &RdGeometry,
        block: usize,
        buf: &'a mut [f32],
    ) -> Result<Self> {
        if map.pixel_count() != g.len() {
            return Err(Error::LengthMismatch {
                expected: g.len(),
                got: map.pixel_count(),
            });
        }
        let block = block.max(1);
        if !g.n_velocity.is_multiple_of(block) {
            return Err(Error::InvalidConfig(
                "velocity_block must divide n_velocity",
            ));
        }
        let nb = g.n_velocity / block;
        let need = g.n_range * nb;
        let cap = buf.len();
        let Some(out) = buf.get_mut(..need) else {
            return Err(Error::Capacity {
                capacity: cap,
                requested: need,
            });
        };
        // One pass: the sums, and a flag for any pixel that is not a finite power >= 0
        // (NaN fails `z >= 0`, +inf makes a sum infinite); the rare bad map is then
        // classified by `check`.
        let mut ok = true;
        for (i, row) in out.chunks_exact_mut(nb.max(1)).enumerate() {
            for (m, x) in row.iter_mut().enumerate() {
                let mut acc = 0.0f32;
                let mut good = true;
                map.for_each(dq, i * g.n_velocity + m * block, block, |_, z| {
                    acc += z;
                    good &= z >= 0.0;
                });
                ok &= good && acc.is_finite();
                *x = acc;
            }
        }
        if !ok {
            map.check()?;
            return Err(Error::NonFinite);
        }
        Ok(Self {
            sums: &*out,
            blocks: nb,
        })
    }

    /// Blocks per row.
    pub fn blocks(&self) -> usize {
        self.blocks
    }
}

/// The blocked log likelihood ratio (module doc): like [`log_lr_exact`] with `a`
/// evaluated at the centre of each block of `k.block` velocity bins whose centre lies in
/// a point's support. `h` and `p` are scratches of at least `blocks` and `2 blocks`
/// entries.
#[allow(clippy::too_many_arguments)]
pub fn log_lr_blocked(
    bm: &BlockMap<'_>,
    g: &RdGeometry,
    k: &Kernel,
    amp: f32,
    range: f32,
    vels: &[f32],
    h: &mut [f32],
    p: &mut [f32],
) -> f32 {
    if amp.is_nan() || amp <= 0.0 || vels.is_empty() {
        return 0.0;
    }
    let mut gr = [0f32; 64];
    let (i0, nr) = range_rows(g, k, range, &mut gr);
    if nr == 0 {
        return 0.0;
    }
    let nb = bm.blocks.min(h.len()).min(p.len() / 2);
    let bsz = k.block as f32;
    let half = k.half_v / bsz;
    let mut m_lo = usize::MAX;
    let mut m_hi = 0usize;
    let mut spans = [(0usize, 0usize, 0.0f32); MAX_POINTS];
    let mut np = 0usize;
    for (&vp, s) in vels.iter().zip(spans.iter_mut()) {
        // Block m's centre is at bin coordinate m * block + (block - 1) / 2.
        let f = ((vp - g.velocity_start) / g.velocity_bin - 0.5 - 0.5 * (bsz - 1.0)) / bsz;
        if let Some((a, b)) = span(f, half, nb) {
            *s = (a, b, f);
            m_lo = m_lo.min(a);
            m_hi = m_hi.max(b);
            np += 1;
        } else {
            *s = (1, 0, f);
        }
    }
    if np == 0 || m_lo > m_hi {
        return 0.0;
    }
    let (Some(hs), Some(ps)) = (h.get_mut(m_lo..=m_hi), p.get_mut(..2 * (m_hi - m_lo + 1))) else {
        return 0.0;
    };
    hs.iter_mut().for_each(|x| *x = 0.0);
    for &(a, b, f) in spans.iter().take(vels.len()) {
        if a > b {
            continue;
        }
        let mut run = GaussRun::new((a as f32 - f) * k.db, k.db, k.cb);
        if let Some(seg) = hs.get_mut(a - m_lo..=b - m_lo) {
            for x in seg.iter_mut() {
                *x += run.next();
            }
        }
    }
    let hmax = hs.iter().fold(0.0f32, |m, &x| m.max(x));
    let every = fold_every(1.0 + amp * hmax);
    // Per-block accumulators (data sum in `ds`, running product of `1 + a` in `ps`):
    // element-wise, so the row loop vectorises; summed in a fixed order at the end.
    let width = hs.len();
    let Some((ps, rest)) = ps.split_at_mut_checked(width) else {
        return 0.0;
    };
    let Some(ds) = rest.get_mut(..width) else {
        return 0.0;
    };
    ps.iter_mut().for_each(|x| *x = 1.0);
    ds.iter_mut().for_each(|x| *x = 0.0);
    let mut noise = 0.0f32;
    let mut since = 0usize;
    for (row, &grow) in gr.iter().take(nr).enumerate() {
        let s = amp * grow;
        let start = (i0 + row) * bm.blocks + m_lo;
        let Some(zs) = bm.sums.get(start..start + width) else {
            continue;
        };
        for (((&zb, &hm), pm), dm) in zs
            .iter()
            .zip(hs.iter())
            .zip(ps.iter_mut())
            .zip(ds.iter_mut())
        {
            let a = s * hm;
            let t = 1.0 + a;
            *dm += zb * a / t;
            *pm *= t;
        }
        since += 1;
        if since >= every {
            for pm in ps.iter_mut() {
                noise += math::ln(*pm);
                *pm = 1.0;
            }
            since = 0;
        }
    }
    // The products of all blocks, folded into a log before they could overflow.
    let mut total = 1.0f32;
    for &pm in ps.iter() {
        let t = total * pm;
        if t > FOLD || !t.is_finite() {
            noise += math::ln(total) + math::ln(pm);
            total = 1.0;
        } else {
            total = t;
        }
    }
    noise += math::ln(total);
    let data = ds.iter().fold(0.0f32, |a, &d| a + d);
    data - bsz * noise
}

/// One target as the map generator sees it: range, peak SNR `A` (eq. 19) and point
/// velocities.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LitTarget {
    /// Range `r` (m).
    pub range: f32,
    /// Peak SNR `A` (linear).
    pub amp: f32,
    /// Point velocities (first `n`).
    pub vels: [f32; MAX_POINTS],
    /// Points in use.
    pub n: usize,
}

/// The signal-to-noise ratio `a_ij` of every pixel of `target` (the map-model of the
/// module doc), added into `a` (length `g.len()`); the pixels outside `T(x)` are left.
pub fn add_signal(g: &RdGeometry, s: &RdSpread, target: &LitTarget, a: &mut [f32]) {
    let k = Kernel::new(g, s, 1);
    let mut gr = [0f32; 64];
    let (i0, nr) = range_rows(g, &k, target.range, &mut gr);
    let mut h = [0f32; MAX_VELOCITY_BINS];
    let nv = g.n_velocity.min(MAX_VELOCITY_BINS);
    for &vp in target.vels.iter().take(target.n) {
        let f = (vp - g.velocity_start) / g.velocity_bin - 0.5;
        if let Some((lo, hi)) = span(f, k.half_v, nv) {
            let mut run = GaussRun::new((lo as f32 - f) * k.dv, k.dv, k.cv);
            if let Some(seg) = h.get_mut(lo..=hi) {
                for x in seg.iter_mut() {
                    *x += run.next();
                }
            }
        }
    }
    for (row, &grow) in gr.iter().take(nr).enumerate() {
        let start = (i0 + row) * g.n_velocity;
        if let Some(dst) = a.get_mut(start..start + nv) {
            for (d, &hj) in dst.iter_mut().zip(h.iter()) {
                *d += target.amp * grow * hj;
            }
        }
    }
}

/// Draws a power map `|y|^2` from the model into `out` (length `g.len()`): pixel
/// `(i, j)` is complex Gaussian with per-component variance `noise_var (1 + a_ij)`, so
/// `|y|^2 = 2 noise_var (1 + a) E`, `E ~ Exp(1)` (one exponential per pixel, in pixel
/// order). `targets` may be empty (noise only). `out` is its own scratch.
pub fn simulate_power(
    g: &RdGeometry,
    s: &RdSpread,
    noise_var: f32,
    targets: &[LitTarget],
    rng: &mut Rng,
    out: &mut [f32],
) {
    out.iter_mut().for_each(|x| *x = 0.0);
    for t in targets {
        add_signal(g, s, t, out);
    }
    let two_s2 = 2.0 * noise_var;
    for o in out.iter_mut() {
        *o = two_s2 * (1.0 + *o) * rng.exponential();
    }
}

/// Draws complex pixels from the model (two normals per pixel): `y = sqrt(noise_var
/// (1 + a)) (n_I + j n_Q)`. Arguments as [`simulate_power`].
pub fn simulate_complex(
    g: &RdGeometry,
    s: &RdSpread,
    noise_var: f32,
    targets: &[LitTarget],
    rng: &mut Rng,
    snr: &mut [f32],
    out: &mut [Complex32],
) {
    snr.iter_mut().for_each(|x| *x = 0.0);
    for t in targets {
        add_signal(g, s, t, snr);
    }
    for (o, &a) in out.iter_mut().zip(snr.iter()) {
        let sd = math::sqrt(noise_var * (1.0 + a));
        let re = sd * rng.normal();
        let im = sd * rng.normal();
        *o = Complex32::new(re, im);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn span_is_inclusive_and_clipped() {
        assert_eq!(span(5.0, 2.0, 100), Some((3, 7)));
        assert_eq!(span(5.5, 2.0, 100), Some((4, 7)));
        assert_eq!(span(-10.0, 2.0, 100), None);
        assert_eq!(span(1.0, 2.0, 100), Some((0, 3)));
        assert_eq!(span(99.0, 2.0, 100), Some((97, 99)));
    }

    #[test]
    fn gauss_run_matches_exp() {
        let mut r = GaussRun::new(-2.1, 0.015, libm::expf(-2.0 * 0.015 * 0.015));
        for k in 0..300 {
            let u = (-2.1f64 + 0.015f64 * k as f64) as f32;
            let want = libm::expf(-u * u);
            let got = r.next();
            assert!((got - want).abs() <= 1e-5 * want, "{k}: {got} {want}");
        }
    }

    /// The geometry spread against a brute-force f64 DFT of the window: the model's
    /// `exp(-x^2 dv^2 / zeta_v^2)` and the window's power response `R(x)` agree in
    /// curvature at the peak (`1 - R(x)` at `x = 0.02` bins within 0.1 %: the `x^4` term
    /// is `~x^2` smaller) and within 4 % of the peak out to the half-power point
    /// (`x = 0.5` bins; the rectangular window is farthest); rectangular
    /// `zeta_v = sqrt(12) / (2 pi)` bins, range
    /// `sqrt(3) dR / pi`; a blade sweep adds `smear^2 / 6`; bad inputs give `None`.
    #[test]
    fn geometry_spread_matches_the_window_response() {
        use crate::model::doppler::Window;
        let g = RdGeometry {
            n_range: 8,
            n_velocity: 512,
            range_start: 0.0,
            range_bin: 0.78125,
            velocity_start: -20.0,
            velocity_bin: 0.078125,
        };
        let resp = |w: Window, x: f64| {
            let n = g.n_velocity;
            let (mut re, mut im, mut s) = (0.0f64, 0.0f64, 0.0f64);
            for k in 0..n {
                let c = w.coefficient(k, n);
                let ph = 2.0 * core::f64::consts::PI * x * k as f64 / n as f64;
                re += c * libm::cos(ph);
                im += c * libm::sin(ph);
                s += c;
            }
            (re * re + im * im) / (s * s)
        };
        for w in [Window::Hamming, Window::Rectangular, Window::Hann] {
            let sp = RdSpread::from_geometry(&g, w, 0.78125, 0.0).unwrap();
            let z = f64::from(sp.zeta_v / g.velocity_bin);
            let x = 0.02;
            let model = 1.0 - libm::exp(-x * x / (z * z));
            assert!((1.0 - resp(w, x)) / model - 1.0 < 1e-3, "{w:?}");
            assert!(model / (1.0 - resp(w, x)) - 1.0 < 1e-3, "{w:?}");
            for x in [0.1, 0.25, 0.5] {
                let m = libm::exp(-x * x / (z * z));
                assert!((m - resp(w, x)).abs() < 0.04, "{w:?} x {x}");
            }
        }
        let rect = RdSpread::from_geometry(&g, Window::Rectangular, 2.0, 0.0).unwrap();
        let want = libm::sqrt(12.0) / (2.0 * core::f64::consts::PI) * 0.078125;
        assert!((f64::from(rect.zeta_v) / want - 1.0).abs() < 1e-3);
        let want_r = libm::sqrt(3.0) * 2.0 / core::f64::consts::PI;
        assert!((f64::from(rect.zeta_r) / want_r - 1.0).abs() < 1e-6);
        let blade = RdSpread::from_geometry(&g, Window::Rectangular, 2.0, 0.3).unwrap();
        let want_b = libm::sqrt(want * want + 0.09 / 6.0);
        assert!((f64::from(blade.zeta_v) / want_b - 1.0).abs() < 1e-5);
        assert!(RdSpread::from_geometry(&g, Window::Hamming, 0.0, 0.0).is_none());
        assert!(RdSpread::from_geometry(&g, Window::Hamming, 1.0, f32::NAN).is_none());
        assert!(RdSpread::from_geometry(&g, Window::Hamming, 1.0, -1.0).is_none());
    }

    #[test]
    fn blade_points_follow_eq_13() {
        let mut out = [0.0; MAX_POINTS];
        let n = point_velocities(PointModel::Joint, 1.0, 10.0, 0.5, 2, &mut out);
        assert_eq!(n, 3);
        assert!((out[1] - (1.0 - 10.0 * libm::sinf(0.5))).abs() < 1e-5);
        assert!((out[2] - (1.0 + 10.0 * libm::sinf(0.5))).abs() < 1e-4);
        assert_eq!(
            point_velocities(PointModel::DopplerOnly, 1.0, 10.0, 0.5, 2, &mut out),
            1
        );
    }
}
