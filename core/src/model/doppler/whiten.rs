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
