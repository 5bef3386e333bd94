//! The one place that picks the `f32` math backend, plus log-domain helpers.
//!
//! Backends (cargo features of `faint-core`):
//! - `libm` (default): accurate, pure software, so the host build and the Cortex-M build
//!   produce bit-identical results. Use it whenever results are compared across targets.
//! - `micromath`: fast approximations (a few percent of relative error on `exp`/`ln`);
//!   for cycle-starved targets that accept the accuracy loss.
//!
//! Platform intrinsics that change results between targets (`f32::mul_add`, x87, fast
//! math) are never used: every function here is plain IEEE single precision.

#[cfg(any(feature = "libm", not(feature = "micromath")))]
mod backend {
    #[inline]
    /// `e^x`.
    pub fn exp(x: f32) -> f32 {
        libm::expf(x)
    }
    #[inline]
    /// Natural logarithm.
    pub fn ln(x: f32) -> f32 {
        libm::logf(x)
    }
    #[inline]
    /// Square root.
    pub fn sqrt(x: f32) -> f32 {
        libm::sqrtf(x)
    }
    #[inline]
    /// Sine (radians).
    pub fn sin(x: f32) -> f32 {
        libm::sinf(x)
    }
    #[inline]
    /// Cosine (radians).
    pub fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
    #[inline]
    /// Four-quadrant arctangent of `y/x`.
    pub fn atan2(y: f32, x: f32) -> f32 {
        libm::atan2f(y, x)
    }
    #[inline]
    /// `x^y`.
    pub fn powf(x: f32, y: f32) -> f32 {
        libm::powf(x, y)
    }
    #[inline]
    /// Largest integer not above `x`.
    pub fn floor(x: f32) -> f32 {
        libm::floorf(x)
    }
    #[inline]
    /// Nearest integer, half away from zero.
    pub fn round(x: f32) -> f32 {
        libm::roundf(x)
    }
    #[inline]
    /// `ln(1 + x)`, accurate near 0.
    pub fn ln1p(x: f32) -> f32 {
        libm::log1pf(x)
    }
}

#[cfg(all(feature = "micromath", not(feature = "libm")))]
mod backend {
    use micromath::F32Ext;
    #[inline]
    /// `e^x`.
    pub fn exp(x: f32) -> f32 {
        x.exp()
    }
    #[inline]
    /// Natural logarithm.
    pub fn ln(x: f32) -> f32 {
        x.ln()
    }
    #[inline]
    /// Square root.
    pub fn sqrt(x: f32) -> f32 {
        x.sqrt()
    }
    #[inline]
    /// Sine (radians).
    pub fn sin(x: f32) -> f32 {
        x.sin()
    }
    #[inline]
    /// Cosine (radians).
    pub fn cos(x: f32) -> f32 {
        x.cos()
    }
    #[inline]
    /// Four-quadrant arctangent of `y/x`.
    pub fn atan2(y: f32, x: f32) -> f32 {
        y.atan2(x)
    }
    #[inline]
    /// `x^y`.
    pub fn powf(x: f32, y: f32) -> f32 {
        x.powf(y)
    }
    #[inline]
    /// Largest integer not above `x`.
    pub fn floor(x: f32) -> f32 {
        x.floor()
    }
    #[inline]
    /// Nearest integer, half away from zero.
    pub fn round(x: f32) -> f32 {
        x.round()
    }
    #[inline]
    /// `ln(1 + x)`, accurate near 0.
    pub fn ln1p(x: f32) -> f32 {
        (1.0 + x).ln()
    }
}

pub use backend::{atan2, cos, exp, floor, ln, ln1p, powf, round, sin, sqrt};

use crate::{Error, Result};

/// `pi` in `f32`.
pub const PI: f32 = core::f32::consts::PI;

/// Compensated (Kahan) sum: deterministic, and its error does not grow with `N`, so
/// normalised weights of thousands of particles sum to 1 within a few ulps.
#[derive(Debug, Clone, Copy, Default)]
pub struct KahanSum {
    sum: f32,
    carry: f32,
}

impl KahanSum {
    /// An empty sum.
    pub const fn new() -> Self {
        Self {
            sum: 0.0,
            carry: 0.0,
        }
    }
    /// Adds one term.
    #[inline]
    pub fn add(&mut self, x: f32) {
        let y = x - self.carry;
        let t = self.sum + y;
        self.carry = (t - self.sum) - y;
        self.sum = t;
    }
    /// The sum so far.
    #[inline]
    pub fn value(&self) -> f32 {
        self.sum
    }
}

/// Compensated sum of a slice.
pub fn sum(xs: &[f32]) -> f32 {
    let mut s = KahanSum::new();
    for &x in xs {
        s.add(x);
    }
    s.value()
}

/// Largest value of a slice of log weights, skipping `-inf`.
///
/// Returns [`Error::Empty`] for an empty slice, [`Error::NonFinite`] if any value is NaN
/// or `+inf`, and [`Error::DegenerateWeights`] if every value is `-inf`.
pub fn max_log(logs: &[f32]) -> Result<f32> {
    if logs.is_empty() {
        return Err(Error::Empty);
    }
    let mut m = f32::NEG_INFINITY;
    for &l in logs {
        if l.is_nan() || l == f32::INFINITY {
            return Err(Error::NonFinite);
        }
        if l > m {
            m = l;
        }
    }
    if m == f32::NEG_INFINITY {
        return Err(Error::DegenerateWeights);
    }
    Ok(m)
}

/// `ln(e^a + e^b)` without overflow: `max + ln1p(exp(min - max))`, exact when either
/// argument is `-inf` (the other is returned).
#[inline]
pub fn log_add_exp(a: f32, b: f32) -> f32 {
    let (hi, lo) = if a > b { (a, b) } else { (b, a) };
    if lo == f32::NEG_INFINITY {
        return hi;
    }
    hi + ln1p(exp(lo - hi))
}

/// `log(sum_i exp(l_i))` without overflow: `m + log(sum_i exp(l_i - m))`, `m = max l_i`.
///
/// `-inf` terms contribute zero. Errors as [`max_log`].
pub fn log_sum_exp(logs: &[f32]) -> Result<f32> {
    let m = max_log(logs)?;
    let mut s = KahanSum::new();
    for &l in logs {
        s.add(exp(l - m));
    }
    // s >= 1 because the max term contributes exp(0) = 1.
    Ok(m + ln(s.value()))
}

/// Turns log weights into normalised weights, `w_i = exp(l_i - LSE(l))`, and returns
/// `LSE(l) = log sum_i exp(l_i)` (the log normaliser, useful for likelihood estimates).
///
/// Never produces NaN or inf: the largest weight is computed as `exp(0) = 1` before
/// normalisation, so the sum lies in `[1, N]`. `w` must have the length of `logs`.
/// Errors: [`Error::LengthMismatch`], and those of [`max_log`] (all `-inf` is
/// [`Error::DegenerateWeights`]; the caller decides the recovery, typically uniform
/// weights).
pub fn normalize_log_weights(logs: &[f32], w: &mut [f32]) -> Result<f32> {
    if w.len() != logs.len() {
        return Err(Error::LengthMismatch {
            expected: logs.len(),
            got: w.len(),
        });
    }
    let m = max_log(logs)?;
    let mut s = KahanSum::new();
    for (wi, &l) in w.iter_mut().zip(logs) {
        let e = exp(l - m);
        *wi = e;
        s.add(e);
    }
    let total = s.value();
    let inv = 1.0 / total;
    for wi in w.iter_mut() {
        *wi *= inv;
    }
    Ok(m + ln(total))
}

/// Normalises non-negative linear weights in place so they sum to 1, returning the old
/// sum. Errors: [`Error::Empty`], [`Error::NonFinite`], [`Error::NegativeWeight`], and
/// [`Error::DegenerateWeights`] when they sum to zero or overflow (weights untouched).
pub fn normalize_weights(w: &mut [f32]) -> Result<f32> {
    let total = checked_weight_sum(w)?;
    let inv = 1.0 / total;
    if !inv.is_finite() {
        // The sum is subnormal: rescale in two steps to avoid overflow of 1/total.
        let mx = w.iter().fold(0.0f32, |a, &b| if b > a { b } else { a });
        for wi in w.iter_mut() {
            *wi /= mx;
        }
        let t2 = sum(w);
        for wi in w.iter_mut() {
            *wi /= t2;
        }
        return Ok(total);
    }
    for wi in w.iter_mut() {
        *wi *= inv;
    }
    Ok(total)
}

/// Sum of non-negative weights with the checks of [`normalize_weights`].
pub fn checked_weight_sum(w: &[f32]) -> Result<f32> {
    if w.is_empty() {
        return Err(Error::Empty);
    }
    let mut s = KahanSum::new();
    for &x in w {
        if !x.is_finite() {
            return Err(Error::NonFinite);
        }
        if x < 0.0 {
            return Err(Error::NegativeWeight);
        }
        s.add(x);
    }
    let total = s.value();
    if total > 0.0 && total.is_finite() {
        Ok(total)
    } else {
        Err(Error::DegenerateWeights)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lse_matches_f64_reference() {
        let logs = [-1000.0f32, -1001.5, -999.25, f32::NEG_INFINITY, -1003.0];
        let m = -999.25f64;
        let r: f64 = m + logs.iter().map(|&l| (l as f64 - m).exp()).sum::<f64>().ln();
        let got = log_sum_exp(&logs).unwrap() as f64;
        assert!((got - r).abs() < 1e-4, "{got} vs {r}");
    }

    #[test]
    fn normalise_extreme_logs() {
        // log weights like -q p log||.|| with p = 8, q = 1: exp would underflow f32.
        let logs = [-400.0f32, -401.0, -450.0, -399.0];
        let mut w = [0.0f32; 4];
        normalize_log_weights(&logs, &mut w).unwrap();
        assert!(w.iter().all(|x| x.is_finite() && *x >= 0.0));
        assert!((sum(&w) - 1.0).abs() < 1e-6);
        assert!(w[3] > w[0] && w[0] > w[1] && w[1] > w[2]);
    }

    #[test]
    fn degenerate_inputs_are_errors() {
        let mut w = [0.0f32; 3];
        assert_eq!(
            normalize_log_weights(&[f32::NEG_INFINITY; 3], &mut w),
            Err(Error::DegenerateWeights)
        );
        assert_eq!(
            normalize_log_weights(&[0.0, f32::NAN, 0.0], &mut w),
            Err(Error::NonFinite)
        );
        assert_eq!(normalize_log_weights(&[], &mut []), Err(Error::Empty));
        assert_eq!(
            normalize_weights(&mut [0.0, 0.0]),
            Err(Error::DegenerateWeights)
        );
        assert_eq!(
            normalize_weights(&mut [1.0, -1.0]),
            Err(Error::NegativeWeight)
        );
        assert_eq!(
            normalize_weights(&mut [1.0, f32::INFINITY]),
            Err(Error::NonFinite)
        );
    }

    #[test]
    fn subnormal_weights_normalise() {
        let mut w = [1e-44f32, 2e-44, 1e-45];
        normalize_weights(&mut w).unwrap();
        assert!((sum(&w) - 1.0).abs() < 1e-5, "{w:?}");
    }
}
