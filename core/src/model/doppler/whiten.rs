//! Whitening of a windowed frame by the known bin covariance: the window-aware Gaussian
//! likelihood of the comparators (PF-TBD, JOTT, PF-LRT).
//!
//! With white time-domain noise of variance `s2` and `z = F W s` (`W = diag(w_n)`, `F`
//! the `m`-point DFT), the bins are correlated: `C = E[z z^H] = s2 F W^2 F^H` (circulant;
//! Hamming, `m = 32`: `|rho| ~ 0.65` between neighbours). A square root of its inverse is
//! `C^(-1/2) = F W^(-1) F^(-1) / sqrt(m s2)`, so
//!
//! ```text
//! z' = F W^(-1) F^(-1) z           (the rectangular-window DFT of the samples)
//! 2 Re(h^H C^-1 z) - h^H C^-1 h = (2 Re<z', h'> - ||h'||^2) / (m s2),   h' = F s_target
//! ```
//!
//! i.e. the exact Gaussian log likelihood ratio under the window's covariance is the
//! independent-bin one of `z'` with the rectangular window's response and per-bin
//! variance `m s2`. A detector configured with `Window::Rectangular` and variance
//! `m s2`, fed `z'`, uses it (over the five bins its response table spans: the exact
//! likelihood of those bins of `z'`, which are independent).

use super::{check_frame, Window, MAX_BINS};
use crate::{Complex32, Error, Result};

/// Replaces the windowed frame `z` (`z_b = sum_n w_n s_n exp(-j 2 pi b n / m)`) by the
/// rectangular-window DFT of the same samples, `z' = F W^(-1) F^(-1) z` (module doc),
/// in `f64`. Errors, before any change: the errors of [`check_frame`] (`m = z.len()`),
/// `InvalidConfig` for `m` outside `1..=MAX_BINS` or a window coefficient below `1e-6`
/// (e.g. the symmetric Hann window's end points: its covariance is singular).
pub fn unwindow(z: &mut [Complex32], window: Window) -> Result<()> {
    let m = z.len();
    if !(1..=MAX_BINS).contains(&m) {
        return Err(Error::InvalidConfig("bins per frame (1..=512)"));
    }
    check_frame(z, m)?;
    let mut inv_w = [0.0f64; MAX_BINS];
    for (n, iw) in inv_w.iter_mut().enumerate().take(m) {
        let w = window.coefficient(n, m);
        if !(w.is_finite() && w >= 1e-6) {
            return Err(Error::InvalidConfig("window has a zero coefficient"));
        }
        *iw = 1.0 / w;
    }
    // tw[t] = exp(-j 2 pi t / m)
    let mut tw = [(0.0f64, 0.0f64); MAX_BINS];
    for (t, v) in tw.iter_mut().enumerate().take(m) {
        let ph = -2.0 * core::f64::consts::PI * t as f64 / m as f64;
        *v = (libm::cos(ph), libm::sin(ph));
    }
    // samples s_n = (1 / (m w_n)) sum_b z_b exp(+j 2 pi b n / m)
    let mut s = [(0.0f64, 0.0f64); MAX_BINS];
    // `(b * n) % m < m <= MAX_BINS`: every `tw` lookup hits (the `get`s only show the
    // optimiser so).
    let twiddle = |i: usize| tw.get(i % m).copied().unwrap_or((1.0, 0.0));
    for (n, (sn, &iw)) in s.iter_mut().zip(inv_w.iter()).enumerate().take(m) {
        let (mut re, mut im) = (0.0f64, 0.0f64);
        for (b, zb) in z.iter().enumerate() {
            let (c, si) = twiddle(b * n);
            let (zr, zi) = (f64::from(zb.re), f64::from(zb.im));
            // z_b conj(tw)
            re += zr * c + zi * si;
            im += zi * c - zr * si;
        }
        let k = iw / m as f64;
        *sn = (re * k, im * k);
    }
    for (b, zb) in z.iter_mut().enumerate() {
        let (mut re, mut im) = (0.0f64, 0.0f64);
        for (n, &(sr, si)) in s.iter().enumerate().take(m) {
            let (c, sn) = twiddle(b * n);
            re += sr * c - si * sn;
            im += sr * sn + si * c;
        }
        *zb = Complex32::new(re as f32, im as f32);
    }
    Ok(())
}

/// The Gaussian comparators' noise model of the bins (PF-TBD, JOTT, PF-LRT;
/// [`GaussConfig::likelihood`](crate::detect::pf_tbd::GaussConfig::likelihood)).
///
/// ```text
/// Independent: ln LR = (2 Re<z,h> - ||h||^2) / s2          bins of the windowed frame
///                                                           taken as independent
/// Window:      ln LR = (2 Re<z',h'> - ||h'||^2) / (m s2t)   z' = F W^-1 F^-1 z (module
///                                                           doc), h' the rectangular
///                                                           response, s2t = s2 / sum w^2
/// ```
/// `Window` is the exact Gaussian likelihood ratio of the bins `h'` spans under the
/// window's bin covariance; `Independent` is the approximation of Lu, Wang, Zhang (2017)
/// (exact only for a rectangular window, where the two coincide).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "kebab-case")
)]
pub enum Likelihood {
    /// Independent bins of the windowed frame: the paper's model and the presets'. The
    /// default, and what a configuration without the key means (the model of every file
    /// written before the option existed).
    #[default]
    Independent,
    /// The window's bin covariance taken into account: each frame whitened on the
    /// detector's path by [`Whitener`] (`m^2` complex multiply-adds per frame), the
    /// rectangular window's response. Needs every window coefficient `>= 1e-6` (not the
    /// symmetric Hann window, whose end points are zero).
    Window,
}

/// Smallest window coefficient [`Whitener`] accepts: `1 / w` must stay finite and the
/// whitened frame's energy within `f32` (module doc).
pub const MIN_WINDOW_COEFFICIENT: f64 = 1e-6;

/// The whitening operator of [`unwindow`] as a circulant kernel in the bin domain, and
/// the whitened frame:
///
/// ```text
/// z'_b = sum_k c_((b - k) mod m) z_k,   c_d = (1/m) sum_n (1/w_n) exp(-j 2 pi d n / m)
/// ```
///
/// (`F W^-1 F^-1` is diagonal in time, so circulant in frequency). The kernel is computed
/// once in `f64` and stored in `f32`; a frame costs `m^2` complex multiply-adds in `f32`
/// (`m = 32`: 1 024). Inactive (the frame passes through unchanged) for the independent
/// likelihood or a rectangular window, where `z' = z`.
#[derive(Debug, Clone)]
pub struct Whitener {
    /// Bins `m`; 0 when inactive.
    m: usize,
    kernel: [Complex32; MAX_BINS],
    out: [Complex32; MAX_BINS],
}

impl Whitener {
    /// An inactive whitener (every frame passes through).
    pub const fn inactive() -> Self {
        Self {
            m: 0,
            kernel: [Complex32::new(0.0, 0.0); MAX_BINS],
            out: [Complex32::new(0.0, 0.0); MAX_BINS],
        }
    }

    /// Builds the kernel for `likelihood` with an `m`-point `window` (inactive for
    /// [`Likelihood::Independent`] or [`Window::Rectangular`]). Errors
    /// ([`Error::InvalidConfig`]), before any change: `m` outside `1..=MAX_BINS`, a window
    /// coefficient below [`MIN_WINDOW_COEFFICIENT`].
    pub fn configure(&mut self, likelihood: Likelihood, window: Window, m: usize) -> Result<()> {
        if !Self::check_active(likelihood, window, m)? {
            self.m = 0;
            return Ok(());
        }
        self.build_kernel(window, m);
        Ok(())
    }

    /// The kernel of an active whitener (checked by the caller). Not inlined: its 4 KiB
    /// of window coefficients are on the stack only while it runs, not in the frame of
    /// every `configure` that may call it.
    #[inline(never)]
    fn build_kernel(&mut self, window: Window, m: usize) {
        let mut inv_w = [0.0f64; MAX_BINS];
        for (n, iw) in inv_w.iter_mut().enumerate().take(m) {
            *iw = 1.0 / window.coefficient(n, m);
        }
        for (d, c) in self.kernel.iter_mut().enumerate().take(m) {
            let (mut re, mut im) = (0.0f64, 0.0f64);
            for (n, &iw) in inv_w.iter().enumerate().take(m) {
                // (d n) mod m keeps the angle in [0, 2 pi): the same twiddles at any m.
                let ph = -2.0 * core::f64::consts::PI * ((d * n) % m) as f64 / m as f64;
                re += iw * libm::cos(ph);
                im += iw * libm::sin(ph);
            }
            *c = Complex32::new((re / m as f64) as f32, (im / m as f64) as f32);
        }
        self.m = m;
    }

    /// The errors of [`configure`](Self::configure), without building the kernel (or
    /// needing a whitener's 8 KiB).
    pub fn check(likelihood: Likelihood, window: Window, m: usize) -> Result<()> {
        Self::check_active(likelihood, window, m).map(|_| ())
    }

    /// Checks `m` and, when frames are whitened, every window coefficient; returns whether
    /// they are.
    fn check_active(likelihood: Likelihood, window: Window, m: usize) -> Result<bool> {
        if !(1..=MAX_BINS).contains(&m) {
            return Err(Error::InvalidConfig("bins per frame (1..=512)"));
        }
        if likelihood == Likelihood::Independent || window == Window::Rectangular {
            return Ok(false);
        }
        for n in 0..m {
            let w = window.coefficient(n, m);
            if !(w.is_finite() && w >= MIN_WINDOW_COEFFICIENT) {
                return Err(Error::InvalidConfig(
                    "likelihood window: the window has a zero coefficient",
                ));
            }
        }
        Ok(true)
    }

    /// Whether frames are whitened.
    pub fn is_active(&self) -> bool {
        self.m > 0
    }

    /// `z'` of a frame already checked by [`check_frame`] for this whitener's `m` bins:
    /// the whitened frame, or `z` itself when inactive. Errors: [`Error::LengthMismatch`]
    /// for a frame of another length, [`Error::Overflow`] if the whitened frame's energy
    /// overflows `f32` (an input within `1 / min w` of `f32::MAX`).
    pub fn apply<'a>(&'a mut self, z: &'a [Complex32]) -> Result<&'a [Complex32]> {
        let m = self.m;
        if m == 0 {
            return Ok(z);
        }
        if z.len() != m {
            return Err(Error::LengthMismatch {
                expected: m,
                got: z.len(),
            });
        }
        let kernel = self.kernel.get(..m).unwrap_or(&[]);
        let mut energy = 0.0f32;
        for (b, out) in self.out.iter_mut().enumerate().take(m) {
            // z'_b = sum_k c_((b - k) mod m) z_k: k = 0..=b uses c_b .. c_0, k > b uses
            // c_(m-1) .. c_(b+1).
            let (Some((head, tail)), Some((c_lo, c_hi))) =
                (z.split_at_checked(b + 1), kernel.split_at_checked(b + 1))
            else {
                continue; // b < m = z.len() = kernel.len(): never taken
            };
            let (mut re, mut im) = (0.0f32, 0.0f32);
            for (zk, c) in head.iter().zip(c_lo.iter().rev()) {
                re += c.re * zk.re - c.im * zk.im;
                im += c.re * zk.im + c.im * zk.re;
            }
            for (zk, c) in tail.iter().zip(c_hi.iter().rev()) {
                re += c.re * zk.re - c.im * zk.im;
                im += c.re * zk.im + c.im * zk.re;
            }
            *out = Complex32::new(re, im);
            energy += re * re + im * im;
        }
        if !energy.is_finite() {
            return Err(Error::Overflow);
        }
        Ok(self.out.get(..m).unwrap_or(&[]))
    }
}
