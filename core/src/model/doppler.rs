//! Observation and motion model of the sky-wave OTHR scenario (Lu, Wang, Zhang 2017, §3).
//!
//! State `x = [fd, fda, A]`: Doppler (Hz), Doppler rate (Hz/s), amplitude.
//!
//! ```text
//! x_k = F x_{k-1} + G v_{k-1},  F = [[1, dT, 0], [0, 1, 0], [0, 0, 1]],
//!                               G = [[dT^2/2, 0], [dT, 0], [0, dT]]         (eq. 16)
//! z_k = DFT_W(A_k exp(j 2 pi fd_k n ts) + wbar_k),  n = 0..m-1               (eq. 17)
//! ```
//!
//! # The observation `h_k(x)` without an FFT per particle
//! With `z_b = sum_n w_n s_n exp(-j 2 pi b n / m)` and `nu = fd ts` (cycles per sample),
//! the target's response in bin `b` is `h_b = A W(nu - b/m)`, where
//! `W(theta) = sum_n w_n exp(j 2 pi theta n)` is the window's DTFT. Writing
//! `fd ts m = b0 + delta` (`b0` the nearest bin, `|delta| <= 1/2`), bin `b0 + j` sees
//! `A W((delta - j)/m)`. The model keeps a table of `W(u/m)` for
//! `u in [-(J + 1/2), J + 1/2]`, [`TABLE_STEPS`] points per bin, computed once in `f64`,
//! and evaluates only the `2J + 1` bins around the peak ([`SPAN`] = 5, `J = 2`) by linear
//! interpolation (all five bins share one interpolation fraction). A particle's cost then
//! needs only
//!
//! ```text
//! ||z - h||^2 = ||z||^2 - 2 Re <z, h> + ||h||^2,   <z, h> = sum_b conj(z_b) h_b
//! ```
//!
//! over those five bins ([`DopplerModel::project`]). Within one frame the five-bin sums
//! of a table row are linear in the interpolation fraction `f`:
//! `<z, h> / A = sum_j conj(z_j) a_j + f sum_j conj(z_j) d_j` (`a_j`, `d_j` the row's
//! points and slopes) and `||h||^2 / A^2 = H0 + f (H1 + f H2)` (per row, computed once in
//! `f64`), so [`DopplerModel::project_cached`] keeps the two complex sums per (first bin,
//! row) in a [`ProjectionCache`] filled on first use in each frame.
//!
//! # Approximation error (stated bound, checked by `tests/crpf_model.rs`)
//! Two sources: (1) the window's energy outside the five bins nearest the peak (the
//! symmetric 32-point Hamming window's side lobes summed over the other 27 bins; worst
//! when the target sits half-way between bins and one of the two bins 2.5 bins away is
//! left out), and (2) the linear interpolation of the table (step 1/128 bin, the phase
//! of `W` turns by about pi per bin, so the chord error is about
//! `(pi/128)^2 / 8 = 8e-5` of the value). Against the exact windowed DFT over all `m`
//! bins computed in `f64`, the relative error `||h_approx - h_exact|| / ||h_exact||` is
//! below [`RESPONSE_ERROR_BOUND`] = 3e-2 for every Doppler in the band (Hamming, `m = 32`;
//! measured maximum 2.65e-2, i.e. at most 7e-4 = -31 dB of the target's energy is left
//! out); the test scans 20 000 Doppler values. In a cost this is a bias of at most
//! `2 ||z|| ||h|| 3e-2` on `||z - h||^2`.

use crate::math;
use crate::rng::Rng;
use crate::{Complex32, Error, Result};

/// Largest frame length (bins) the fixed-size buffers hold.
pub const MAX_BINS: usize = 64;
/// Half-width `J` of the evaluated bin span.
pub const HALF_SPAN: usize = 2;
/// Bins evaluated per particle: `2J + 1`.
pub const SPAN: usize = 2 * HALF_SPAN + 1;
/// Table points per bin of the window's DTFT.
pub const TABLE_STEPS: usize = 128;
const TABLE_LEN: usize = SPAN * TABLE_STEPS + 1;
/// One interpolation row: for each of the [`SPAN`] bins, `[a.re, a.im, (b - a).re,
/// (b - a).im]` with `a`, `b` the two table points around the bin's position.
type Row = [[f32; 4]; SPAN];
/// `0.5 - f32::EPSILON / 4`: `trunc(x + copysign(HALF_DOWN, x))` is `roundf(x)`.
const HALF_DOWN: f32 = 0.5 - 0.25 * f32::EPSILON;
/// Below this magnitude (2^22) a table position is rounded inline.
const LARGE: f32 = 4_194_304.0;
/// Stated bound on `||h_approx - h_exact|| / ||h_exact||` for the Hamming window, `m = 32`
/// (measured maximum 2.65e-2, dominated by the side-lobe energy left out).
pub const RESPONSE_ERROR_BOUND: f64 = 3e-2;

/// Analysis window of the windowed DFT.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub enum Window {
    /// `w_n = 1`.
    Rectangular,
    /// Symmetric Hamming, `w_n = 0.54 - 0.46 cos(2 pi n / (m - 1))` (the preset).
    #[default]
    Hamming,
    /// Symmetric Hann, `w_n = 0.5 - 0.5 cos(2 pi n / (m - 1))`.
    Hann,
}

impl Window {
    /// Coefficient `w_n` of an `m`-point window, in `f64`.
    pub fn coefficient(self, n: usize, m: usize) -> f64 {
        let c = if m > 1 {
            libm::cos(2.0 * core::f64::consts::PI * n as f64 / (m - 1) as f64)
        } else {
            1.0
        };
        match self {
            Window::Rectangular => 1.0,
            Window::Hamming => 0.54 - 0.46 * c,
            Window::Hann => 0.5 - 0.5 * c,
        }
    }
}

/// `<z, h>` and `||h||^2` of one hypothesised target against one frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Projection {
    /// `sum_b conj(z_b) h_b` over the evaluated bins.
    pub zh: Complex32,
    /// `sum_b |h_b|^2` over the evaluated bins.
    pub hh: f32,
}

impl Projection {
    /// `||z - h||^2 = zz - 2 Re<z,h> + ||h||^2`, floored at `f32::MIN_POSITIVE` so its
    /// logarithm is finite (an exact fit or an all-zero frame).
    #[inline]
    pub fn residual_norm2(&self, zz: f32) -> f32 {
        let d = zz - 2.0 * self.zh.re + self.hh;
        if d > f32::MIN_POSITIVE {
            d
        } else {
            f32::MIN_POSITIVE
        }
    }

    /// Gaussian log likelihood ratio `ln p(z|x)/p(z|0) = (2 Re<z,h> - ||h||^2) / s2` for
    /// independent complex Gaussian bins of variance `s2`.
    #[inline]
    pub fn log_lr(&self, inv_var: f32) -> f32 {
        (2.0 * self.zh.re - self.hh) * inv_var
    }
}

/// The windowed-DFT response of a complex exponential, tabulated (see the module docs).
#[derive(Debug, Clone)]
pub struct DopplerModel {
    m: usize,
    /// `m as f32` (converted once, not per particle).
    m_f32: f32,
    ts: f32,
    window: Window,
    /// `rows[i0][j]`: the table points `t = i0 + (SPAN - 1 - j) S` and `t + 1` of bin `j`
    /// (`S` = [`TABLE_STEPS`]), so one fractional table position serves all five bins
    /// with one bounds check and no index arithmetic in the hot loop.
    rows: [Row; TABLE_STEPS],
    /// `U = fd u_scale + u_off` is `128 (pos + 1/2 + m)` (`pos = fd ts m`): `U >> 7` is the
    /// nearest bin plus `m`, `U & 127` the row, the rest the fraction.
    u_scale: f32,
    u_off: f32,
    /// `first_of[q] = (q - m - J) mod m` for `q = U >> 7 < 2m`.
    first_of: [u8; 2 * MAX_BINS],
    /// `[H0, H1, H2]` of each row: `sum_j |a_j + f d_j|^2 = H0 + f (H1 + f H2)`.
    hq: [[f32; 3]; TABLE_STEPS],
    window_sum: f32,
    window_energy: f32,
}

impl DopplerModel {
    /// Builds the table for `m` bins (`SPAN <= m <= MAX_BINS`) and sample interval `ts`.
    pub fn new(m: usize, ts: f32, window: Window) -> Result<Self> {
        if !(SPAN..=MAX_BINS).contains(&m) {
            return Err(Error::InvalidConfig("bins per frame (5..=64)"));
        }
        if !(ts.is_finite() && ts > 0.0) {
            return Err(Error::InvalidConfig("sample interval ts"));
        }
        let mut table = [Complex32::new(0.0, 0.0); TABLE_LEN];
        for (t, slot) in table.iter_mut().enumerate() {
            let u = -(HALF_SPAN as f64 + 0.5) + t as f64 / TABLE_STEPS as f64;
            let (re, im) = dtft(window, m, u / m as f64);
            *slot = Complex32::new(re as f32, im as f32);
        }
        let mut rows = [[[0.0f32; 4]; SPAN]; TABLE_STEPS];
        for (i0, row) in rows.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                let t = i0 + (SPAN - 1 - j) * TABLE_STEPS;
                let (a, b) = match (table.get(t), table.get(t + 1)) {
                    (Some(&a), Some(&b)) => (a, b),
                    _ => (Complex32::new(0.0, 0.0), Complex32::new(0.0, 0.0)),
                };
                *cell = [a.re, a.im, b.re - a.re, b.im - a.im];
            }
        }
        let mut first_of = [0u8; 2 * MAX_BINS];
        for (q, f) in first_of.iter_mut().enumerate() {
            *f = (q as i64 - m as i64 - HALF_SPAN as i64).rem_euclid(m as i64) as u8;
        }
        let mut hq = [[0.0f32; 3]; TABLE_STEPS];
        for (h, row) in hq.iter_mut().zip(rows.iter()) {
            let (mut h0, mut h1, mut h2) = (0.0f64, 0.0f64, 0.0f64);
            for c in row.iter() {
                let (ar, ai, dr, di) = (c[0] as f64, c[1] as f64, c[2] as f64, c[3] as f64);
                h0 += ar * ar + ai * ai;
                h1 += 2.0 * (ar * dr + ai * di);
                h2 += dr * dr + di * di;
            }
            *h = [h0 as f32, h1 as f32, h2 as f32];
        }
        let mut s = 0.0f64;
        let mut s2 = 0.0f64;
        for n in 0..m {
            let w = window.coefficient(n, m);
            s += w;
            s2 += w * w;
        }
        Ok(Self {
            m,
            m_f32: m as f32,
            ts,
            window,
            rows,
            u_scale: (ts as f64 * m as f64 * TABLE_STEPS as f64) as f32,
            u_off: (TABLE_STEPS / 2 + TABLE_STEPS * m) as f32,
            first_of,
            hq,
            window_sum: s as f32,
            window_energy: s2 as f32,
        })
    }

    /// Bins per frame `m`.
    pub fn bins(&self) -> usize {
        self.m
    }

    /// Sample interval `ts` (s).
    pub fn ts(&self) -> f32 {
        self.ts
    }

    /// Frame time `dT = m ts` (s).
    pub fn frame_time(&self) -> f32 {
        self.m as f32 * self.ts
    }

    /// The window.
    pub fn window(&self) -> Window {
        self.window
    }

    /// `sum_n w_n = |W(0)|`, the peak gain of a bin-centred target.
    pub fn window_sum(&self) -> f32 {
        self.window_sum
    }

    /// `sum_n w_n^2`: a white time-domain noise of variance `s2` has per-bin variance
    /// `s2 * window_energy` after the windowed DFT.
    pub fn window_energy(&self) -> f32 {
        self.window_energy
    }

    /// Unambiguous Doppler band `[-1/(2 ts), 1/(2 ts))` (Hz).
    pub fn band(&self) -> (f32, f32) {
        let h = 0.5 / self.ts;
        (-h, h)
    }

    /// Nearest bin `b0` and interpolation position: the first of the [`SPAN`] bins is
    /// `b0 - J (mod m)`; returns `(first_bin, interpolation row, fraction)`.
    #[inline]
    fn locate(&self, fd: f32) -> (usize, &Row, f32) {
        let (first, i0, frac) = self.locate_i(fd);
        (first, self.row(i0), frac)
    }

    /// Interpolation row `i0` (`i0 < TABLE_STEPS` by construction; row 0 otherwise).
    #[inline(always)]
    fn row(&self, i0: usize) -> &Row {
        match self.rows.get(i0) {
            Some(r) => r,
            None => &self.rows[0],
        }
    }

    /// [`locate`](Self::locate) with the row index.
    #[inline(always)]
    fn locate_i(&self, fd: f32) -> (usize, usize, f32) {
        let pos = fd * self.ts * self.m_f32;
        let pos = if pos.is_finite() { pos } else { 0.0 };
        let (b, bi) = if pos > -LARGE && pos < LARGE {
            // libm's roundf, trunc(x + copysign(0.5 - eps/4, x)), inlined.
            let h = if pos < 0.0 { -HALF_DOWN } else { HALF_DOWN };
            let bi = (pos + h) as i32;
            (bi as f32, bi)
        } else {
            // Out of any band; `i32::MAX` sends `first` to the exact path below.
            let b = math::round(pos);
            (b, i32::MAX)
        };
        let delta = pos - b; // in [-0.5, 0.5]
        let p0 = (delta + 0.5) * TABLE_STEPS as f32;
        let mut i0 = p0 as usize; // p0 >= 0
        if i0 >= TABLE_STEPS {
            i0 = TABLE_STEPS - 1;
        }
        let frac = p0 - i0 as f32;
        // b - J (mod m) without a 64-bit division in the usual case |b| < m.
        let m = self.m as i32;
        let mut first = bi - HALF_SPAN as i32;
        if first < 0 {
            first += m;
        }
        if !(0..m).contains(&first) {
            first = (b as i64 - HALF_SPAN as i64).rem_euclid(m as i64) as i32;
        }
        (first as usize, i0, frac)
    }

    /// `[Re A, Im A, Re D, Im D]`, `A = sum_j conj(z_{first+j}) a_j`, `D` the same with
    /// `d_j = b_j - a_j`, over row `i0` (bins wrap mod `m`).
    fn sums(&self, z: &[Complex32], first: usize, i0: usize) -> [f32; 4] {
        let row = self.row(i0);
        let mut out = [0.0f32; 4];
        let mut b = first;
        for c in row.iter() {
            if let Some(zb) = z.get(b) {
                out[0] += zb.re * c[0] + zb.im * c[1];
                out[1] += zb.re * c[1] - zb.im * c[0];
                out[2] += zb.re * c[2] + zb.im * c[3];
                out[3] += zb.re * c[3] - zb.im * c[2];
            }
            b += 1;
            if b == self.m {
                b = 0;
            }
        }
        out
    }

    /// [`project`](Self::project) through a per-frame cache of the row sums `A`, `D` (see
    /// [`ProjectionCache`]): `<z, h> = amp (A + frac D)`, `||h||^2 = amp^2 (H0 + frac (H1 +
    /// frac H2))`; the same values up to rounding (relative difference below 4e-6, test
    /// `crpf_model`). `IM = false`: `Im <z, h>` is 0. The table position comes from
    /// `U = 128 (fd ts m + 1/2 + m)`: `U >> 7` the nearest bin (plus `m`), `U & 127` the
    /// row, `U - floor(U)` the fraction. Not finite or outside the band, or `m > 32`:
    /// the direct [`project`](Self::project). `cache` must be valid for `z`:
    /// [`ProjectionCache::new_frame`] once before a frame's first call (a new cache too).
    #[inline(always)]
    pub fn project_cached<const IM: bool>(
        &self,
        cache: &mut ProjectionCache,
        z: &[Complex32],
        fd: f32,
        amp: f32,
    ) -> Projection {
        let u = fd * self.u_scale + self.u_off;
        // In the band, 0 <= U < 256 m; NaN and anything else go to the direct path.
        if !(u >= 0.0 && u < self.u_off * 2.0) {
            return self.project_direct::<IM>(z, fd, amp);
        }
        let iu = u as u32;
        let frac = u - iu as f32;
        let i0 = (iu as usize) & (TABLE_STEPS - 1);
        let first = match self.first_of.get((iu >> 7) as usize) {
            Some(&f) => f as usize,
            None => return self.project_direct::<IM>(z, fd, amp),
        };
        let key = first * TABLE_STEPS + i0;
        let slot = key & (CACHE_LEN - 1);
        let tag = cache.cur * CACHE_KEYS + key as u32;
        let (Some(e), Some(t), Some(h)) = (
            cache.sums.get_mut(slot),
            cache.tag.get_mut(slot),
            self.hq.get(i0),
        ) else {
            return self.project_direct::<IM>(z, fd, amp);
        };
        if key >= CACHE_KEYS as usize {
            return self.project_direct::<IM>(z, fd, amp);
        }
        if *t != tag {
            *e = self.sums(z, first, i0);
            *t = tag;
        }
        let zr = e[0] + frac * e[2];
        let zi = if IM { e[1] + frac * e[3] } else { 0.0 };
        let hh = h[0] + frac * (h[1] + frac * h[2]);
        Projection {
            zh: Complex32::new(zr * amp, zi * amp),
            hh: hh * amp * amp,
        }
    }

    /// The evaluated response: `out[j] = h_{first + j (mod m)}` for `j = 0..SPAN`;
    /// returns `first`. Bins outside the span are taken as zero.
    pub fn response(&self, fd: f32, amp: f32, out: &mut [Complex32; SPAN]) -> usize {
        let (first, row, frac) = self.locate(fd);
        for (o, c) in out.iter_mut().zip(row.iter()) {
            let a = Complex32::new(c[0], c[1]);
            let d = Complex32::new(c[2], c[3]);
            *o = (a + d * frac) * amp;
        }
        first
    }

    /// `<z, h(fd, amp)>` and `||h||^2` over the evaluated bins. `z` must hold `m` bins
    /// (not checked here: the detectors check each frame once; a shorter `z` reads its
    /// missing bins as zero).
    #[inline]
    pub fn project(&self, z: &[Complex32], fd: f32, amp: f32) -> Projection {
        self.project_impl::<true>(z, fd, amp)
    }

    /// [`project`](Self::project) without `Im <z, h>` (returned as 0): all a cost
    /// `||z - h||^2` or a Gaussian likelihood ratio needs; bit-identical otherwise.
    #[inline]
    pub fn project_re(&self, z: &[Complex32], fd: f32, amp: f32) -> Projection {
        self.project_impl::<false>(z, fd, amp)
    }

    #[cold]
    #[inline(never)]
    fn project_direct<const IM: bool>(&self, z: &[Complex32], fd: f32, amp: f32) -> Projection {
        self.project_impl::<IM>(z, fd, amp)
    }

    #[inline(always)]
    fn project_impl<const IM: bool>(&self, z: &[Complex32], fd: f32, amp: f32) -> Projection {
        let (first, row, frac) = self.locate(fd);
        let (zr, zi, hh) = match z
            .get(first..first + SPAN)
            .and_then(|s| <&[Complex32; SPAN]>::try_from(s).ok())
        {
            // The five bins do not wrap (27 of 32 positions for m = 32).
            Some(zs) => kernel::<IM>(row, zs, frac),
            None => {
                let mut zs = [Complex32::new(0.0, 0.0); SPAN];
                let mut b = first;
                for o in zs.iter_mut() {
                    if let Some(&v) = z.get(b) {
                        *o = v;
                    }
                    b += 1;
                    if b == self.m {
                        b = 0;
                    }
                }
                kernel::<IM>(row, &zs, frac)
            }
        };
        Projection {
            zh: Complex32::new(zr * amp, zi * amp),
            hh: hh * amp * amp,
        }
    }
}

/// Entries of the [`ProjectionCache`] (direct-mapped on `(first bin mod 8, table row)`).
const CACHE_LEN: usize = 1024;
/// Keys `first * 128 + row` the cache holds (`first < 32`; the other first bins of
/// larger frames project directly). An entry's tag is `frame * 4096 + key`.
const CACHE_KEYS: u32 = 4096;

/// Per-frame cache of the five-bin sums `A`, `D` of [`DopplerModel::project_cached`] for a
/// (first bin, table row): direct-mapped, 1024 entries, each tagged with its key and the
/// frame, filled on first use in a frame (20 KB). Call [`new_frame`](Self::new_frame)
/// before the first projection of every frame (also of a new or zeroed cache: its
/// frame stamp 0 is not valid).
#[derive(Debug, Clone)]
pub struct ProjectionCache {
    sums: [[f32; 4]; CACHE_LEN],
    /// `frame * 4096 + key` of each entry.
    tag: [u32; CACHE_LEN],
    /// Frame stamp (1-based; 0 marks empty entries).
    cur: u32,
}

impl Default for ProjectionCache {
    fn default() -> Self {
        Self {
            sums: [[0.0; 4]; CACHE_LEN],
            tag: [0; CACHE_LEN],
            cur: 0,
        }
    }
}

impl ProjectionCache {
    /// Invalidates every entry (call once per new frame).
    pub fn new_frame(&mut self) {
        self.cur += 1;
        if self.cur >= u32::MAX / CACHE_KEYS {
            self.tag = [0; CACHE_LEN];
            self.cur = 1;
        }
    }
}

/// `sum_b conj(z_b) h_b / A` and `sum_b |h_b|^2 / A^2` over one interpolation row:
/// fixed-size arrays, fully unrolled, no bounds checks.
#[inline(always)]
fn kernel<const IM: bool>(row: &Row, zs: &[Complex32; SPAN], frac: f32) -> (f32, f32, f32) {
    // The sums start from the first bin's terms instead of 0.0 + them: the same values,
    // except that a sum of signed zeros may keep its sign (-0.0 instead of +0.0), which
    // no cost, gate or weight can tell apart (each is squared or added first).
    let (c, zb) = (&row[0], &zs[0]);
    let hr = c[0] + c[2] * frac;
    let hi = c[1] + c[3] * frac;
    let mut zr = zb.re * hr + zb.im * hi;
    let mut zi = if IM { zb.re * hi - zb.im * hr } else { 0.0 };
    let mut hh = hr * hr + hi * hi;
    for j in 1..SPAN {
        let (c, zb) = (&row[j], &zs[j]);
        let hr = c[0] + c[2] * frac;
        let hi = c[1] + c[3] * frac;
        // conj(z) h
        zr += zb.re * hr + zb.im * hi;
        if IM {
            zi += zb.re * hi - zb.im * hr;
        }
        hh += hr * hr + hi * hi;
    }
    (zr, zi, hh)
}

/// `W(theta) = sum_n w_n exp(j 2 pi theta n)` in `f64`.
pub fn dtft(window: Window, m: usize, theta: f64) -> (f64, f64) {
    let mut re = 0.0;
    let mut im = 0.0;
    for n in 0..m {
        let w = window.coefficient(n, m);
        let ph = 2.0 * core::f64::consts::PI * theta * n as f64;
        re += w * libm::cos(ph);
        im += w * libm::sin(ph);
    }
    (re, im)
}

/// Axis-aligned box `I_x0` of births and initial particles, `x ~ U(I_x0)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct PriorBox {
    /// Doppler range (Hz).
    pub fd: (f32, f32),
    /// Doppler-rate range (Hz/s).
    pub fda: (f32, f32),
    /// Amplitude range (time-domain units).
    pub amp: (f32, f32),
}

impl PriorBox {
    /// Checks the ranges are finite with `lo <= hi` and a non-negative amplitude.
    pub fn validate(&self) -> Result<()> {
        for (lo, hi) in [self.fd, self.fda, self.amp] {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(Error::InvalidConfig("prior box range"));
            }
        }
        if self.amp.0 < 0.0 {
            return Err(Error::InvalidConfig("prior box amplitude"));
        }
        Ok(())
    }

    /// One draw from `U(I_x0)`.
    #[inline]
    pub fn sample(&self, rng: &mut Rng) -> [f32; 3] {
        [
            rng.uniform_range(self.fd.0, self.fd.1),
            rng.uniform_range(self.fda.0, self.fda.1),
            rng.uniform_range(self.amp.0, self.amp.1),
        ]
    }
}

/// The constant-Doppler-rate motion of eq. 16.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Frame time `dT` (s).
    pub dt: f32,
    /// Standard deviation of `v1`, the Doppler acceleration (Hz/s^2).
    pub accel_std: f32,
    /// Standard deviation of `v2`, the amplitude drift rate (1/s).
    pub amp_std: f32,
    /// Doppler band `[lo, hi)`; Doppler is wrapped into it (the DFT is periodic).
    pub band: (f32, f32),
}

impl Motion {
    /// Checks the values are finite, `dt > 0`, stds `>= 0`, band non-empty.
    pub fn validate(&self) -> Result<()> {
        if !(self.dt.is_finite() && self.dt > 0.0) {
            return Err(Error::InvalidConfig("frame time dT"));
        }
        if !(self.accel_std >= 0.0
            && self.accel_std.is_finite()
            && self.amp_std >= 0.0
            && self.amp_std.is_finite())
        {
            return Err(Error::InvalidConfig("process noise std"));
        }
        if !(self.band.0.is_finite() && self.band.1.is_finite() && self.band.0 < self.band.1) {
            return Err(Error::InvalidConfig("Doppler band"));
        }
        Ok(())
    }

    /// Width of the Doppler band `W` (Hz).
    #[inline]
    pub fn band_width(&self) -> f32 {
        self.band.1 - self.band.0
    }

    /// The offset `fd - reference` brought into `[-W/2, W/2]` by one band width `width`
    /// (`W`, from [`band_width`](Self::band_width)): what a weighted Doppler mean
    /// averages, so that a cloud across the band edge is not split; the mean is then
    /// `wrap(reference + sum w d / sum w)`. Used by every Doppler-frame detector's
    /// estimate.
    #[inline(always)]
    pub fn wrap_offset(fd: f32, reference: f32, width: f32) -> f32 {
        let d = fd - reference;
        if d > 0.5 * width {
            d - width
        } else if d < -0.5 * width {
            d + width
        } else {
            d
        }
    }

    /// Wraps a Doppler into the band.
    #[inline]
    pub fn wrap(&self, fd: f32) -> f32 {
        let w = self.band.1 - self.band.0;
        if fd >= self.band.1 {
            fd - w
        } else if fd < self.band.0 {
            fd + w
        } else {
            fd
        }
    }

    /// `F x` (Doppler wrapped).
    #[inline]
    pub fn predict(&self, x: [f32; 3]) -> [f32; 3] {
        [self.wrap(x[0] + self.dt * x[1]), x[1], x[2]]
    }

    /// `F x + G v`, `v ~ N(0, diag(accel_std^2, amp_std^2))` (Doppler wrapped, amplitude
    /// kept non-negative by reflection).
    #[inline]
    pub fn propagate(&self, x: [f32; 3], rng: &mut Rng) -> [f32; 3] {
        let v1 = rng.normal() * self.accel_std;
        let v2 = rng.normal() * self.amp_std;
        let dt = self.dt;
        let a = x[2] + dt * v2;
        [
            self.wrap(x[0] + dt * x[1] + 0.5 * dt * dt * v1),
            x[1] + dt * v1,
            if a < 0.0 { -a } else { a },
        ]
    }
}

/// Validates a frame: `m` bins, all finite. Returns `||z||^2`.
pub fn check_frame(z: &[Complex32], m: usize) -> Result<f32> {
    if z.len() != m {
        return Err(Error::LengthMismatch {
            expected: m,
            got: z.len(),
        });
    }
    let mut zz = 0.0f32;
    for c in z {
        if !(c.re.is_finite() && c.im.is_finite()) {
            return Err(Error::NonFinite);
        }
        zz += c.re * c.re + c.im * c.im;
    }
    if !zz.is_finite() {
        return Err(Error::NonFinite);
    }
    Ok(zz)
}

/// Per-bin noise variance estimated from frames, `s2 = sum_k ||z_k||^2 / (K m)` (what the
/// Gaussian comparators assume when the statistics are "unknown"; the paper estimates it
/// from all K frames). Errors: [`Error::Empty`] for no frames, the errors of
/// [`check_frame`], and [`Error::InvalidConfig`] if the estimate is zero (all-zero frames).
pub fn estimate_noise_variance<'a>(
    frames: impl IntoIterator<Item = &'a [Complex32]>,
    m: usize,
) -> Result<f32> {
    let mut total = 0.0f32;
    let mut k = 0usize;
    for z in frames {
        total += check_frame(z, m)?;
        k += 1;
    }
    if k == 0 {
        return Err(Error::Empty);
    }
    let v = total / (k * m) as f32;
    if !(v.is_finite() && v > 0.0) {
        return Err(Error::InvalidConfig("noise variance estimate is zero"));
    }
    Ok(v)
}

/// The state-space model every OTHR detector shares (observation, motion, existence
/// chain, birth box). Built once from its values by [`ModelConfig::build`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct ModelConfig {
    /// Bins per frame `m`.
    pub bins: usize,
    /// Sample interval `ts` (s).
    pub ts: f32,
    /// DFT window.
    pub window: Window,
    /// Birth box `I_x0`.
    pub prior: PriorBox,
    /// Process noise: std of `v1` (Hz/s^2).
    pub accel_std: f32,
    /// Process noise: std of `v2` (1/s).
    pub amp_std: f32,
    /// `Pb = P(E_k = 1 | E_{k-1} = 0)` (eq. 9).
    pub birth: f32,
    /// `Pd = P(E_k = 0 | E_{k-1} = 1)` (eq. 9).
    pub death: f32,
    /// `P(E_0 = 1)` of the initial particles (and the initial existence of JOTT).
    pub initial_existence: f32,
}

impl ModelConfig {
    /// The OTHR preset of the spec: `m = 32`, `ts = 0.02 s`, Hamming window, Doppler band
    /// `[-25, 25)` Hz, `fda in [-0.5, 0.5]` Hz/s, amplitude box `[0.05, 1.5]` (unit time-domain
    /// noise variance: SNR about -13 dB to +17 dB by eq. 18), `v1` std 0.2 Hz/s^2, `v2` std
    /// 0.02 1/s, `Pb = Pd = 0.05`, `P(E_0 = 1) = 0.05`.
    pub fn othr() -> Self {
        Self {
            bins: 32,
            ts: 0.02,
            window: Window::Hamming,
            prior: PriorBox {
                fd: (-25.0, 25.0),
                fda: (-0.5, 0.5),
                amp: (0.05, 1.5),
            },
            accel_std: 0.2,
            amp_std: 0.02,
            birth: 0.05,
            death: 0.05,
            initial_existence: 0.05,
        }
    }

    /// Validates and builds the model.
    pub fn build(&self) -> Result<Model> {
        self.prior.validate()?;
        if !(0.0..=1.0).contains(&self.initial_existence) {
            return Err(Error::InvalidConfig("initial existence probability"));
        }
        let obs = DopplerModel::new(self.bins, self.ts, self.window)?;
        let motion = Motion {
            dt: obs.frame_time(),
            accel_std: self.accel_std,
            amp_std: self.amp_std,
            band: obs.band(),
        };
        motion.validate()?;
        let chain = crate::existence::ExistenceMarkov::new(self.birth, self.death)?;
        Ok(Model {
            obs,
            motion,
            chain,
            prior: self.prior,
            initial_existence: self.initial_existence,
        })
    }
}

/// A built [`ModelConfig`].
#[derive(Debug, Clone)]
pub struct Model {
    /// Observation model `h_k(x)`.
    pub obs: DopplerModel,
    /// Motion model (eq. 16).
    pub motion: Motion,
    /// Existence chain (eq. 9).
    pub chain: crate::existence::ExistenceMarkov,
    /// Birth box.
    pub prior: PriorBox,
    /// `P(E_0 = 1)`.
    pub initial_existence: f32,
}

/// What every Doppler-frame detector (CRPF-TBD, PF-TBD, JOTT, PF-LRT) reports per frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct DopplerReport {
    /// 1-based frame number.
    pub frame: u32,
    /// Existence probability of this frame (`P_E^k` for CRPF-TBD and PF-TBD, `q_k` for
    /// JOTT; for PF-LRT the per-frame evidence `1 / (1 + exp(-l_k))`, `l_k` this frame's
    /// log likelihood-ratio increment).
    pub existence: f32,
    /// Cumulative log likelihood ratio `ln p(Z_k|H1)/p(Z_k|H0)` (PF-LRT; 0 for the others).
    pub log_lr: f32,
    /// State estimate `[fd, fda, A]` (mean-cost for CRPF-TBD, posterior mean otherwise);
    /// `None` when no particle carries a target.
    pub estimate: Option<[f32; 3]>,
    /// Min-cost estimate (CRPF-TBD only, eq. 8).
    pub min_cost_estimate: Option<[f32; 3]>,
}

/// Names of the Doppler-frame state `[fd, fda, A]` ([`Detector::STATE`](crate::detect::Detector::STATE)).
pub const DOPPLER_STATE: &[&str] = &["fd_hz", "fda_hz_per_s", "amplitude"];

impl DopplerReport {
    /// The report as a [`Detection`](crate::detect::Detection): the estimate, scored by
    /// `existence` or by the cumulative `log_lr`; `None` without an estimate.
    pub fn detection(&self, score: crate::detect::ScoreKind) -> Option<crate::detect::Detection> {
        let x = self.estimate?;
        let s = match score {
            crate::detect::ScoreKind::LogLikelihoodRatio => self.log_lr,
            _ => self.existence,
        };
        Some(crate::detect::Detection::new(&x, s, None))
    }
}
