//! The windowed-DFT response `h_k(x)` of a target: the analysis [`Window`], the table of
//! its DTFT and the direct five-bin [`Projection`] of a frame (see the parent module for
//! the method and its error bound).

use crate::math;
use crate::{Complex32, Error, Result};

/// Largest frame length (bins) the fixed-size buffers hold.
pub const MAX_BINS: usize = 512;
/// Half-width `J` of the evaluated bin span.
pub const HALF_SPAN: usize = 2;
/// Bins evaluated per particle: `2J + 1`.
pub const SPAN: usize = 2 * HALF_SPAN + 1;
/// Table points per bin of the window's DTFT.
pub const TABLE_STEPS: usize = 128;
pub(super) const TABLE_LEN: usize = SPAN * TABLE_STEPS + 1;
/// One interpolation row: for each of the [`SPAN`] bins, `[a.re, a.im, (b - a).re,
/// (b - a).im]` with `a`, `b` the two table points around the bin's position.
pub(super) type Row = [[f32; 4]; SPAN];
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

    /// `sum_n w_n^2` of an `m`-point window, in `f64`: the bin variance of unit-variance
    /// white time-domain noise.
    pub fn energy(self, m: usize) -> f64 {
        (0..m)
            .map(|n| {
                let w = self.coefficient(n, m);
                w * w
            })
            .sum()
    }
}

/// The target's carrier phase at the start of each frame, as the observation model
/// assumes it (the detectors' [`ModelConfig::phase`](super::ModelConfig::phase)).
///
/// ```text
/// Zero:     z = DFT_W(A exp(j 2 pi fd n ts)) + noise, A real           (eq. 17)
///           cost ||z - h||^2 = ||z||^2 - 2 Re<z,h> + ||h||^2
///           log-LR (2 Re<z,h> - ||h||^2) / s2
/// Unknown:  the same with A exp(j phi), phi uniform and independent per frame
///           cost min_phi ||z - h e^{j phi}||^2 = ||z||^2 - 2 |<z,h>| + ||h||^2
///           log-LR ln E_phi[LR] = ln I0(2 |<z,h>| / s2) - ||h||^2 / s2    (Rician)
/// ```
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "kebab-case")
)]
pub enum Phase {
    /// Zero at every frame's start: a real amplitude (eq. 17 of Lu, Wang, Zhang 2017),
    /// the paper's model and the presets' (`ModelConfig::othr`). The default, and what a
    /// configuration without the key means (the model of every file written before the
    /// option existed).
    #[default]
    Zero,
    /// Unknown and independent from frame to frame (independent dwells, the real echo):
    /// CRPF-TBD minimises its cost over the phase, the Gaussian comparators average
    /// their likelihood ratio over it.
    Unknown,
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
        floored(zz - 2.0 * self.zh.re + self.hh)
    }

    /// Gaussian log likelihood ratio `ln p(z|x)/p(z|0) = (2 Re<z,h> - ||h||^2) / s2` for
    /// independent complex Gaussian bins of variance `s2`.
    #[inline]
    pub fn log_lr(&self, inv_var: f32) -> f32 {
        (2.0 * self.zh.re - self.hh) * inv_var
    }

    /// `min_phi ||z - h e^{j phi}||^2 = zz - 2 |<z,h>| + ||h||^2`, floored at
    /// `f32::MIN_POSITIVE` as [`residual_norm2`](Self::residual_norm2) (needs `Im <z,h>`:
    /// a full projection).
    #[inline]
    pub fn residual_norm2_unknown_phase(&self, zz: f32) -> f32 {
        floored(zz - 2.0 * math::hypot(self.zh.re, self.zh.im) + self.hh)
    }

    /// The log likelihood ratio averaged over a uniform phase (Rician):
    /// `ln I0(2 |<z,h>| / s2) - ||h||^2 / s2`, computed as
    /// `(2 |<z,h>| - ||h||^2) / s2 + ln(e^-x I0(x))`, `x = 2 |<z,h>| / s2` (clamped to
    /// `f32::MAX`), so no intermediate overflows where the zero-phase form does not
    /// (needs `Im <z,h>`: a full projection).
    #[inline]
    pub fn log_lr_unknown_phase(&self, inv_var: f32) -> f32 {
        let r = math::hypot(self.zh.re, self.zh.im);
        let x = 2.0 * r * inv_var;
        let x = if x < f32::MAX { x } else { f32::MAX };
        (2.0 * r - self.hh) * inv_var + math::ln_i0e(x)
    }

    /// The cost of the phase model: [`residual_norm2`](Self::residual_norm2) or
    /// [`residual_norm2_unknown_phase`](Self::residual_norm2_unknown_phase).
    #[inline(always)]
    pub fn cost(&self, zz: f32, phase: Phase) -> f32 {
        match phase {
            Phase::Zero => self.residual_norm2(zz),
            Phase::Unknown => self.residual_norm2_unknown_phase(zz),
        }
    }

    /// The log likelihood ratio of the phase model: [`log_lr`](Self::log_lr) or
    /// [`log_lr_unknown_phase`](Self::log_lr_unknown_phase).
    #[inline(always)]
    pub fn log_lr_for(&self, inv_var: f32, phase: Phase) -> f32 {
        match phase {
            Phase::Zero => self.log_lr(inv_var),
            Phase::Unknown => self.log_lr_unknown_phase(inv_var),
        }
    }
}

/// A squared residual floored at `f32::MIN_POSITIVE`, so its logarithm is finite (NaN
/// becomes the floor too).
#[inline(always)]
fn floored(d: f32) -> f32 {
    if d > f32::MIN_POSITIVE {
        d
    } else {
        f32::MIN_POSITIVE
    }
}

/// The windowed-DFT response of a complex exponential, tabulated (see the module docs).
#[derive(Debug, Clone)]
pub struct DopplerModel {
    pub(super) m: usize,
    /// `m as f32` (converted once, not per particle).
    pub(super) m_f32: f32,
    pub(super) ts: f32,
    pub(super) window: Window,
    /// `rows[i0][j]`: the table points `t = i0 + (SPAN - 1 - j) S` and `t + 1` of bin `j`
    /// (`S` = [`TABLE_STEPS`]), so one fractional table position serves all five bins
    /// with one bounds check and no index arithmetic in the hot loop.
    pub(super) rows: [Row; TABLE_STEPS],
    /// `U = fd u_scale + u_off` is `128 (pos + 1/2 + m)` (`pos = fd ts m`): `U >> 7` is the
    /// nearest bin plus `m`, `U & 127` the row, the rest the fraction.
    pub(super) u_scale: f32,
    pub(super) u_off: f32,
    /// `first_of[q] = (q - m - J) mod m` for `q = U >> 7 < 2m`.
    pub(super) first_of: [u16; 2 * MAX_BINS],
    /// `[H0, H1, H2]` of each row: `sum_j |a_j + f d_j|^2 = H0 + f (H1 + f H2)`.
    pub(super) hq: [[f32; 3]; TABLE_STEPS],
    pub(super) window_sum: f32,
    pub(super) window_energy: f32,
}

impl DopplerModel {
    /// A model of no bins (every projection is zero): the value a `static` starts from
    /// before [`build_into`](Self::build_into) sets it up in place (all zero bits, so the
    /// `static` lands in `.bss`).
    pub const fn new_empty() -> Self {
        Self {
            m: 0,
            m_f32: 0.0,
            ts: 0.0,
            window: Window::Rectangular,
            rows: [[[0.0; 4]; SPAN]; TABLE_STEPS],
            u_scale: 0.0,
            u_off: 0.0,
            first_of: [0; 2 * MAX_BINS],
            hq: [[0.0; 3]; TABLE_STEPS],
            window_sum: 0.0,
            window_energy: 0.0,
        }
    }

    /// Builds the table for `m` bins (`SPAN <= m <= MAX_BINS`) and sample interval `ts`
    /// (by value: [`build_into`](Self::build_into) builds it in place).
    pub fn new(m: usize, ts: f32, window: Window) -> Result<Self> {
        let mut s = Self::new_empty();
        s.build_into(m, ts, window)?;
        Ok(s)
    }

    /// [`DopplerModel::new`] in place: the table is written into `self`, with no
    /// temporary model (about 14 KB) on the stack, only the window's `m` coefficients.
    /// On error (the errors of [`new`](Self::new)) `self` is unchanged.
    pub fn build_into(&mut self, m: usize, ts: f32, window: Window) -> Result<()> {
        Self::check(m, ts)?;
        self.fill(m, ts, window);
        Ok(())
    }

    /// Whether `self` holds the table of `m` bins, `ts` (same bits) and `window`: the
    /// table depends on nothing else.
    pub(super) fn is_built_for(&self, m: usize, ts: f32, window: Window) -> bool {
        self.m == m && self.ts.to_bits() == ts.to_bits() && self.window == window
    }

    /// Writes the table of `m`, `ts`, `window` into `self` (checked by the caller with
    /// [`check`](Self::check)).
    ///
    /// The table holds `W(u/m)`, `u = -(J + 1/2) + t / S` (`S` = [`TABLE_STEPS`]), for
    /// `t = 0..=SPAN S`; cell `(i0, j)` of `rows` is `[a, b - a]` with `a` point
    /// `t = i0 + (SPAN - 1 - j) S` and `b` point `t + 1`. Each point `t < SPAN S` is the `a`
    /// of exactly one cell, so the points are written into the cells' `a` first, then
    /// each cell's `b` is read from the cell holding point `t + 1` (the next row, or row 0
    /// of the bin before, or the last point `t = SPAN S`): the same bits as a separate
    /// table of `TABLE_LEN` points.
    pub(super) fn fill(&mut self, m: usize, ts: f32, window: Window) {
        // The window's coefficients once, not once per table point (same bits).
        let mut w = [0.0f64; MAX_BINS];
        for (n, c) in w.iter_mut().enumerate().take(m) {
            *c = window.coefficient(n, m);
        }
        let w = w.get(..m).unwrap_or(&[]);
        let point = |t: usize| -> [f32; 2] {
            let u = -(HALF_SPAN as f64 + 0.5) + t as f64 / TABLE_STEPS as f64;
            let (re, im) = dtft_of(w.iter().copied(), u / m as f64);
            [re as f32, im as f32]
        };
        for (i0, row) in self.rows.iter_mut().enumerate() {
            for (j, cell) in row.iter_mut().enumerate() {
                let [re, im] = point(i0 + (SPAN - 1 - j) * TABLE_STEPS);
                *cell = [re, im, 0.0, 0.0];
            }
        }
        let last = point(TABLE_LEN - 1);
        for i0 in 0..TABLE_STEPS {
            for j in 0..SPAN {
                let next = if i0 + 1 < TABLE_STEPS {
                    self.rows.get(i0 + 1).and_then(|r| r.get(j))
                } else {
                    j.checked_sub(1)
                        .and_then(|jb| self.rows.first().and_then(|r| r.get(jb)))
                };
                let b = next.map_or(last, |c| [c[0], c[1]]);
                if let Some(cell) = self.rows.get_mut(i0).and_then(|r| r.get_mut(j)) {
                    cell[2] = b[0] - cell[0];
                    cell[3] = b[1] - cell[1];
                }
            }
        }
        // `m >= SPAN` (checked by the callers); `checked_` keeps the divide-by-zero panic out.
        for (q, f) in self.first_of.iter_mut().enumerate() {
            *f = (q as i64 - m as i64 - HALF_SPAN as i64)
                .checked_rem_euclid(m as i64)
                .unwrap_or(0) as u16;
        }
        for (h, row) in self.hq.iter_mut().zip(self.rows.iter()) {
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
        self.m = m;
        self.m_f32 = m as f32;
        self.ts = ts;
        self.window = window;
        self.u_scale = (ts as f64 * m as f64 * TABLE_STEPS as f64) as f32;
        self.u_off = (TABLE_STEPS / 2 + TABLE_STEPS * m) as f32;
        self.window_sum = s as f32;
        self.window_energy = s2 as f32;
    }

    /// Bins per frame `m`.
    pub fn bins(&self) -> usize {
        self.m
    }

    /// Sample interval `ts` (s).
    pub fn ts(&self) -> f32 {
        self.ts
    }

    /// The errors of [`DopplerModel::new`] for `m` bins and sample interval `ts`.
    pub(super) fn check(m: usize, ts: f32) -> Result<()> {
        if !(SPAN..=MAX_BINS).contains(&m) {
            return Err(Error::InvalidConfig("bins per frame (5..=512)"));
        }
        if !(ts.is_finite() && ts > 0.0) {
            return Err(Error::InvalidConfig("sample interval ts"));
        }
        Ok(())
    }

    /// [`DopplerModel::new`], or a copy of `old` when `old` was built for the same `m`,
    /// `ts` (same bits) and window: the table depends on nothing else, and building it
    /// costs `641 m` double-precision `sincos` (a reconfiguration that keeps the frame
    /// format skips them).
    pub fn new_reusing(m: usize, ts: f32, window: Window, old: &DopplerModel) -> Result<Self> {
        Self::check(m, ts)?;
        if old.is_built_for(m, ts, window) {
            Ok(old.clone())
        } else {
            Self::new(m, ts, window)
        }
    }

    /// Frame time `dT = m ts` (s).
    pub fn frame_time(&self) -> f32 {
        frame_time(self.m, self.ts)
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
        band(self.ts)
    }

    /// Nearest bin `b0` and interpolation position: the first of the [`SPAN`] bins is
    /// `b0 - J (mod m)`; returns `(first_bin, interpolation row, fraction)`.
    #[inline]
    pub(super) fn locate(&self, fd: f32) -> (usize, &Row, f32) {
        let (first, i0, frac) = self.locate_i(fd);
        (first, self.row(i0), frac)
    }

    /// Interpolation row `i0` (`i0 < TABLE_STEPS` by construction; row 0 otherwise).
    #[inline(always)]
    pub(super) fn row(&self, i0: usize) -> &Row {
        match self.rows.get(i0) {
            Some(r) => r,
            None => &self.rows[0],
        }
    }

    /// [`locate`](Self::locate) with the row index.
    #[inline(always)]
    pub(super) fn locate_i(&self, fd: f32) -> (usize, usize, f32) {
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
            // `m >= SPAN` (checked by `new`); the `max` only lets the optimiser see a
            // divisor that is not zero.
            first = (b as i64)
                .saturating_sub(HALF_SPAN as i64)
                .rem_euclid(i64::from(m).max(1)) as i32;
        }
        (first as usize, i0, frac)
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
    pub(super) fn project_direct<const IM: bool>(
        &self,
        z: &[Complex32],
        fd: f32,
        amp: f32,
    ) -> Projection {
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

/// Frame time `dT = m ts` (s) of `m` bins at sample interval `ts`.
pub(super) fn frame_time(m: usize, ts: f32) -> f32 {
    m as f32 * ts
}

/// Unambiguous Doppler band `[-1/(2 ts), 1/(2 ts))` (Hz).
pub(super) fn band(ts: f32) -> (f32, f32) {
    let h = 0.5 / ts;
    (-h, h)
}

/// `W(theta) = sum_n w_n exp(j 2 pi theta n)` in `f64`.
pub fn dtft(window: Window, m: usize, theta: f64) -> (f64, f64) {
    dtft_of((0..m).map(|n| window.coefficient(n, m)), theta)
}

/// [`dtft`] of the coefficients `w` (one `sincos` per sample: the same bits as `sin`
/// and `cos` apart, which share its argument reduction and kernels).
fn dtft_of(w: impl Iterator<Item = f64>, theta: f64) -> (f64, f64) {
    let mut re = 0.0;
    let mut im = 0.0;
    for (n, wn) in w.enumerate() {
        let ph = 2.0 * core::f64::consts::PI * theta * n as f64;
        let (s, c) = libm::sincos(ph);
        re += wn * c;
        im += wn * s;
    }
    (re, im)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::Rng;

    /// A frame of 32 bins: complex Gaussian noise plus a target at `fd` with amplitude
    /// `amp` and carrier phase `phi`.
    fn frame(model: &DopplerModel, fd: f32, amp: f32, phi: f32, seed: u64) -> [Complex32; 32] {
        let mut rng = Rng::seed_from_u64(seed);
        let mut z = [Complex32::new(0.0, 0.0); 32];
        for c in z.iter_mut() {
            *c = Complex32::new(rng.normal(), rng.normal());
        }
        let mut h = [Complex32::new(0.0, 0.0); SPAN];
        let first = model.response(fd, amp, &mut h);
        let rot = Complex32::new(math::cos(phi), math::sin(phi));
        for (j, v) in h.iter().enumerate() {
            if let Some(c) = z.get_mut((first + j) % 32) {
                *c += *v * rot;
            }
        }
        z
    }

    /// The unknown-phase cost and likelihood ratio depend on `|<z,h>|` only: rotating the
    /// whole frame by `e^{j phi}` leaves them unchanged (up to `f32` rounding), while the
    /// zero-phase cost moves.
    #[test]
    fn unknown_phase_observation_is_invariant_to_the_frame_phase() {
        let model = DopplerModel::new(32, 0.02, Window::Hamming).expect("valid model");
        for seed in 0..20u64 {
            let fd = -20.0 + 2.0 * seed as f32;
            let z = frame(&model, fd, 0.8, 0.3 * seed as f32, seed);
            let zz: f32 = z.iter().map(|c| c.norm_sqr()).sum();
            let base = model.project(&z, fd + 0.1, 0.7);
            let (c0, l0) = (
                base.residual_norm2_unknown_phase(zz),
                base.log_lr_unknown_phase(0.5),
            );
            let mut zero_costs = [0.0f32; 16];
            for (i, zc) in zero_costs.iter_mut().enumerate() {
                let phi = i as f32 * (2.0 * math::PI / 16.0);
                let rot = Complex32::new(math::cos(phi), math::sin(phi));
                let zr: [Complex32; 32] = core::array::from_fn(|b| z[b] * rot);
                let pr = model.project(&zr, fd + 0.1, 0.7);
                let c = pr.residual_norm2_unknown_phase(zz);
                let l = pr.log_lr_unknown_phase(0.5);
                assert!(
                    (c - c0).abs() <= 1e-5 * c0,
                    "seed {seed}, phi {phi}: {c} vs {c0}"
                );
                assert!((l - l0).abs() <= 1e-5 * (1.0 + l0.abs()), "{l} vs {l0}");
                assert!(
                    c <= pr.residual_norm2(zz) * (1.0 + 1e-6),
                    "the minimum over phi"
                );
                *zc = pr.residual_norm2(zz);
            }
            let (lo, hi) = zero_costs
                .iter()
                .fold((f32::MAX, 0.0f32), |(a, b), &c| (a.min(c), b.max(c)));
            assert!(hi - lo > 0.1, "the zero-phase cost depends on the phase");
        }
    }

    /// The Rician log-LR is the log of the zero-phase likelihood ratio averaged over a
    /// uniform phase, computed in `f64` (4096-point rule on the circle, exact to far
    /// below the tolerance for `x = 2 |<z,h>| / s2` up to the 6400 tested): absolute error below
    /// `1e-5 (1 + x)` (the `f32` rounding of `(2 |<z,h>| - ||h||^2) / s2`).
    #[test]
    fn rician_log_lr_is_the_phase_average_of_the_zero_phase_lr() {
        let mut rng = Rng::seed_from_u64(3);
        for i in 0..400 {
            let r = math::powf(10.0, rng.uniform_range(-4.0, 2.5));
            let th = rng.uniform_range(-math::PI, math::PI);
            let hh = r * rng.uniform_range(0.0, 3.0);
            let inv_var = math::powf(10.0, rng.uniform_range(-1.0, 1.0));
            let pr = Projection {
                zh: Complex32::new(r * math::cos(th), r * math::sin(th)),
                hh,
            };
            let got = pr.log_lr_unknown_phase(inv_var) as f64;
            let (zr, zi, hh, s) = (pr.zh.re as f64, pr.zh.im as f64, hh as f64, inv_var as f64);
            let n = 4096;
            let logs: [f64; 4096] = core::array::from_fn(|j| {
                let phi = 2.0 * core::f64::consts::PI * j as f64 / n as f64;
                // Re(e^{j phi} <z,h>), the zero-phase log-LR of the rotated target.
                let re = zr * libm::cos(phi) - zi * libm::sin(phi);
                (2.0 * re - hh) * s
            });
            let mx = logs.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let sum: f64 = logs.iter().map(|l| libm::exp(l - mx)).sum();
            let want = mx + libm::log(sum / n as f64);
            let x = 2.0 * libm::hypot(zr, zi) * s;
            assert!(
                (got - want).abs() <= 1e-5 * (1.0 + x),
                "case {i}: x = {x}, got {got}, want {want}"
            );
        }
    }

    /// The zero-phase cost and log-LR are the formulas they always were, bit for bit.
    #[test]
    fn zero_phase_observation_is_unchanged() {
        assert_eq!(Phase::default(), Phase::Zero);
        let pr = Projection {
            zh: Complex32::new(1.25, -0.5),
            hh: 0.75,
        };
        let zz = 3.0f32;
        assert_eq!(
            pr.cost(zz, Phase::Zero).to_bits(),
            (zz - 2.5 + 0.75f32).to_bits()
        );
        assert_eq!(pr.cost(zz, Phase::Zero), pr.residual_norm2(zz));
        assert_eq!(
            pr.log_lr_for(0.5, Phase::Zero).to_bits(),
            ((2.5f32 - 0.75) * 0.5).to_bits()
        );
        assert_eq!(pr.log_lr_for(0.5, Phase::Zero), pr.log_lr(0.5));
        let r = libm::hypotf(1.25, -0.5);
        let want = zz - 2.0 * r + 0.75;
        assert!((pr.cost(zz, Phase::Unknown) - want).abs() < 1e-6);
        // Both floored alike: z = j h (||h||^2 = 4) fits exactly at phase pi/2 only.
        let fit = Projection {
            zh: Complex32::new(0.0, 4.0),
            hh: 4.0,
        };
        assert_eq!(fit.cost(4.0, Phase::Unknown), f32::MIN_POSITIVE);
        assert_eq!(fit.cost(4.0, Phase::Zero), 8.0);
    }

    /// The table is built with one `sincos` per sample and the window's coefficients
    /// computed once; the reference below is the textbook form (a `cos`, a `sin` and the
    /// window's `cos` per sample). Every table value must have the same bits, for every
    /// window and bin count the model accepts.
    #[test]
    fn table_has_the_bits_of_separate_sin_and_cos() {
        fn reference(window: Window, m: usize, theta: f64) -> (f32, f32) {
            let (mut re, mut im) = (0.0f64, 0.0f64);
            for n in 0..m {
                let w = window.coefficient(n, m);
                let ph = 2.0 * core::f64::consts::PI * theta * n as f64;
                re += w * libm::cos(ph);
                im += w * libm::sin(ph);
            }
            (re as f32, im as f32)
        }
        for window in [Window::Rectangular, Window::Hamming, Window::Hann] {
            for m in SPAN..=MAX_BINS {
                let model = DopplerModel::new(m, 1e-3, window).expect("valid model");
                for (i0, row) in model.rows.iter().enumerate() {
                    for (j, cell) in row.iter().enumerate() {
                        let t = i0 + (SPAN - 1 - j) * TABLE_STEPS;
                        let u = -(HALF_SPAN as f64 + 0.5) + t as f64 / TABLE_STEPS as f64;
                        let (re, im) = reference(window, m, u / m as f64);
                        assert_eq!(
                            (cell[0].to_bits(), cell[1].to_bits()),
                            (re.to_bits(), im.to_bits()),
                            "{window:?}, m = {m}, t = {t}"
                        );
                    }
                }
            }
        }
    }

    /// The table as it was built before [`DopplerModel::build_into`]: a separate array of
    /// the `TABLE_LEN` points, then each row's cells `[a, b - a]` read from it.
    fn reference_rows(window: Window, m: usize) -> [Row; TABLE_STEPS] {
        let mut table = [[0.0f32; 2]; TABLE_LEN];
        for (t, slot) in table.iter_mut().enumerate() {
            let u = -(HALF_SPAN as f64 + 0.5) + t as f64 / TABLE_STEPS as f64;
            let (re, im) = dtft(window, m, u / m as f64);
            *slot = [re as f32, im as f32];
        }
        core::array::from_fn(|i0| {
            core::array::from_fn(|j| {
                let t = i0 + (SPAN - 1 - j) * TABLE_STEPS;
                let (a, b) = (table[t], table[t + 1]);
                [a[0], a[1], b[0] - a[0], b[1] - a[1]]
            })
        })
    }

    /// Every field of the model, as bits.
    fn bits(d: &DopplerModel) -> ([u32; 8], [[u32; 4]; 640], [u16; 2 * MAX_BINS], [u32; 384]) {
        let rows: [[u32; 4]; 640] =
            core::array::from_fn(|k| d.rows[k / SPAN][k % SPAN].map(f32::to_bits));
        let hq: [u32; 384] = core::array::from_fn(|k| d.hq[k / 3][k % 3].to_bits());
        let scalars = [
            d.m as u32,
            d.m_f32.to_bits(),
            d.ts.to_bits(),
            d.window as u32,
            d.u_scale.to_bits(),
            d.u_off.to_bits(),
            d.window_sum.to_bits(),
            d.window_energy.to_bits(),
        ];
        (scalars, rows, d.first_of, hq)
    }

    /// The table written in place (each cell's second point read from the cell that holds
    /// it) has the bits of the separate table it replaced, slopes included, for every
    /// window and for frame lengths at both ends and around the preset's; and building in
    /// place over a model of another frame format gives the bits of a new model, while a
    /// bad frame format leaves the model unchanged.
    #[test]
    fn table_built_in_place_has_the_bits_of_a_separate_table() {
        for window in [Window::Rectangular, Window::Hamming, Window::Hann] {
            for m in [SPAN, 6, 31, 32, 33, 100, MAX_BINS] {
                let d = DopplerModel::new(m, 0.02, window).expect("valid model");
                let want = reference_rows(window, m);
                for (i0, (row, want)) in d.rows.iter().zip(want.iter()).enumerate() {
                    for (j, (c, w)) in row.iter().zip(want.iter()).enumerate() {
                        assert_eq!(
                            c.map(f32::to_bits),
                            w.map(f32::to_bits),
                            "{window:?} m {m} ({i0}, {j})"
                        );
                    }
                }
                let mut other = DopplerModel::new(7, 0.5, Window::Hann).expect("valid model");
                other.build_into(m, 0.02, window).expect("valid model");
                assert_eq!(bits(&other), bits(&d), "{window:?}, m = {m}");
                assert!(other.build_into(4, 0.02, window).is_err());
                assert!(other.build_into(m, f32::NAN, window).is_err());
                assert_eq!(bits(&other), bits(&d), "unchanged after an error");
            }
        }
        let empty = DopplerModel::new_empty();
        assert_eq!(empty.bins(), 0);
        let z = [Complex32::new(1.0, 1.0); 32];
        assert_eq!(empty.project(&z, 3.0, 1.0), Projection::default());
    }
}
