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

/// `sqrt(x^2 + y^2)` without overflow or underflow of the squares: the plain form when
/// `x^2 + y^2` is a normal finite `f32` (well above the subnormals), else
/// `big sqrt(1 + (small / big)^2)`. `+inf` if either is infinite, NaN if either is NaN
/// and the other finite.
#[inline]
pub fn hypot(x: f32, y: f32) -> f32 {
    let (a, b) = (x.abs(), y.abs());
    let (big, small) = if a >= b { (a, b) } else { (b, a) };
    let s = big * big + small * small;
    if s.is_finite() && s >= 1e-30 {
        return sqrt(s);
    }
    if a == f32::INFINITY || b == f32::INFINITY {
        return f32::INFINITY;
    }
    if !(big > 0.0 && big.is_finite()) {
        // 0 or NaN.
        return big + small;
    }
    let r = small / big;
    big * sqrt(1.0 + r * r)
}

/// `1 / (k!)^2` for `k = 2..=11`: the ratios of the terms of `I0`'s power series.
const I0_RATIO: [f32; 10] = [
    1.0 / 4.0,
    1.0 / 9.0,
    1.0 / 16.0,
    1.0 / 25.0,
    1.0 / 36.0,
    1.0 / 49.0,
    1.0 / 64.0,
    1.0 / 81.0,
    1.0 / 100.0,
    1.0 / 121.0,
];

/// Abramowitz and Stegun 9.8.2: `sqrt(x) e^-x I0(x)` as a polynomial in `3.75 / x`,
/// `x >= 3.75` (absolute error below 1.9e-7), highest degree first.
const I0_ASYMPTOTIC: [f32; 9] = [
    0.003_923_77,
    -0.016_476_33,
    0.026_355_37,
    -0.020_577_06,
    0.009_162_81,
    -0.001_575_65,
    0.002_253_19,
    0.013_285_92,
    0.398_942_3,
];

/// `ln I0(x)`, the logarithm of the modified Bessel function of the first kind of order
/// 0, without overflow (`I0(x)` overflows `f32` above `x = 94`):
///
/// ```text
/// |x| < 3.75:  ln1p(sum_{k=1..11} y^k / (k!)^2),  y = x^2 / 4   (the power series, Horner)
/// |x| >= 3.75: |x| - 0.5 ln|x| + ln p(3.75 / |x|)               (Abramowitz, Stegun 9.8.2)
/// ```
///
/// Relative error below 5e-7 on `[0, 1e4]` against an `f64` series (unit test, measured
/// 1.8e-7; libm backend); finite
/// and `>= 0` for every finite `x` (`ln I0(x) <= |x|`), `+inf` at infinity, NaN for NaN.
/// Even in `x`.
pub fn ln_i0(x: f32) -> f32 {
    let a = x.abs();
    if a < 3.75 {
        ln_i0_series(a)
    } else if a == f32::INFINITY {
        a
    } else {
        a + ln_i0e_asymptotic(a)
    }
}

/// `ln(e^-|x| I0(x)) = ln I0(x) - |x|`, the scaled form of [`ln_i0`] (`<= 0`; about
/// `-0.5 ln(2 pi |x|)` for large `|x|`): finite for every finite `x`, `-inf` at
/// infinity. What a log likelihood ratio `ln I0(x) - c` with a large `x` and `c` adds to
/// `x - c` computed first (no `inf - inf`).
pub fn ln_i0e(x: f32) -> f32 {
    let a = x.abs();
    if a < 3.75 {
        ln_i0_series(a) - a
    } else {
        ln_i0e_asymptotic(a)
    }
}

/// `ln I0(a)` for `0 <= a < 3.75`: the power series.
#[inline]
fn ln_i0_series(a: f32) -> f32 {
    let h = 0.5 * a;
    let y = h * h;
    let mut acc = 1.0f32;
    for r in I0_RATIO.iter().rev() {
        acc = 1.0 + y * r * acc;
    }
    ln1p(y * acc)
}

/// `ln(e^-a I0(a)) = -0.5 ln a + ln p(3.75 / a)` for `a >= 3.75` (A&S 9.8.2).
#[inline]
fn ln_i0e_asymptotic(a: f32) -> f32 {
    let u = 3.75 / a;
    let mut p = 0.0f32;
    for c in I0_ASYMPTOTIC.iter() {
        p = p * u + c;
    }
    ln(p) - 0.5 * ln(a)
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
    use std::vec;
    use std::vec::Vec;

    #[test]
    fn lse_matches_f64_reference() {
        let logs = [-1000.0f32, -1001.5, -999.25, f32::NEG_INFINITY, -1003.0];
        let m = -999.25f64;
        let r: f64 = m + logs.iter().map(|&l| (l as f64 - m).exp()).sum::<f64>().ln();
        let got = log_sum_exp(&logs).unwrap() as f64;
        assert!((got - r).abs() < 1e-4, "{got} vs {r}");
    }

    /// `ln I0(x)` in `f64` from the power series `sum_k (x/2)^(2k) / (k!)^2`, summed in
    /// the log domain (no overflow up to `x = 1e4` and beyond).
    fn ln_i0_reference(x: f64) -> f64 {
        if x == 0.0 {
            return 0.0;
        }
        let lh = (0.5 * x).ln();
        // ln of term k, and the running log-sum; stop once the terms fall 50 nats below.
        let (mut lt, mut acc) = (0.0f64, 0.0f64);
        let mut k = 1.0f64;
        loop {
            lt += 2.0 * lh - 2.0 * k.ln();
            let (hi, lo) = if acc > lt { (acc, lt) } else { (lt, acc) };
            acc = hi + (lo - hi).exp().ln_1p();
            if lt < acc - 50.0 && k > 0.5 * x {
                return acc;
            }
            k += 1.0;
        }
    }

    /// `ln_i0` against the `f64` series on `[0, 1e4]` (a geometric grid from 1e-6, the
    /// switch at 3.75 from both sides, and integers): relative error below 5e-7; finite
    /// and even beyond.
    #[test]
    fn ln_i0_matches_the_f64_series() {
        let mut xs: Vec<f32> = vec![0.0, 3.749_999_8, 3.75, 3.750_000_2, 1e4];
        let mut x = 1e-6f64;
        while x <= 1e4 {
            xs.push(x as f32);
            x *= 1.01;
        }
        xs.extend((1..=2000).map(|i| i as f32 * 0.01));
        xs.extend((1..=100).map(|i| i as f32 * 100.0));
        let mut worst = (0.0f64, 0.0f32);
        for &x in &xs {
            let got = ln_i0(x);
            let want = ln_i0_reference(x as f64);
            assert!(got.is_finite() && got >= 0.0, "ln_i0({x}) = {got}");
            assert_eq!(got.to_bits(), ln_i0(-x).to_bits(), "even at {x}");
            if want == 0.0 {
                assert_eq!(got, 0.0);
                continue;
            }
            let rel = ((got as f64 - want) / want).abs();
            if rel > worst.0 {
                worst = (rel, x);
            }
        }
        std::eprintln!("ln_i0: worst relative error {:e} at {}", worst.0, worst.1);
        assert!(
            worst.0 < 5e-7,
            "worst relative error {} at {}",
            worst.0,
            worst.1
        );
        for x in [f32::MAX, 1e30, 1e-30, 1e-40, f32::MIN_POSITIVE, -f32::MAX] {
            let v = ln_i0(x);
            assert!(
                v.is_finite() && v >= 0.0 && v <= x.abs(),
                "ln_i0({x}) = {v}"
            );
        }
        assert!(ln_i0(f32::NAN).is_nan());
        assert_eq!(ln_i0(f32::INFINITY), f32::INFINITY);
        // The scaled form: ln I0(x) - x, finite up to f32::MAX.
        for &x in &xs {
            let want = ln_i0_reference(x as f64) - x as f64;
            let got = ln_i0e(x) as f64;
            assert!(
                (got - want).abs() <= 2e-6 * (1.0 + x as f64),
                "ln_i0e({x}) = {got}"
            );
        }
        for x in [f32::MAX, 1e30, 0.0, -1e30] {
            let v = ln_i0e(x);
            assert!(v.is_finite() && v <= 0.0, "ln_i0e({x}) = {v}");
        }
    }

    #[test]
    fn hypot_neither_overflows_nor_underflows() {
        let cases: [(f32, f32, f64); 7] = [
            (3.0, 4.0, 5.0),
            (3e30, 4e30, 5e30),
            (3e-30, 4e-30, 5e-30),
            (-3e-40, 4e-40, 5e-40),
            (f32::MAX, f32::MAX, f32::MAX as f64 * 2f64.sqrt()),
            (0.0, -2.0, 2.0),
            (1e20, 1e-20, 1e20),
        ];
        for (x, y, want) in cases {
            let got = hypot(x, y) as f64;
            if want > f32::MAX as f64 {
                assert_eq!(got, f64::INFINITY);
            } else {
                assert!(
                    ((got - want) / want).abs() < 1e-6,
                    "hypot({x}, {y}) = {got}"
                );
            }
        }
        assert_eq!(hypot(0.0, 0.0), 0.0);
        assert_eq!(hypot(f32::INFINITY, f32::NAN), f32::INFINITY);
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
