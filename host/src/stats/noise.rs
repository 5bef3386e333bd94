//! Robust noise-level estimates of a recording that may hold targets: medians, which a
//! few target cells do not move (a target filling a share `e` of the cells moves the
//! median by about the `e / 2` quantile, against a mean moved by `e` times its power).
//!
//! Used by `faint detect` to normalise an input to the noise level the configuration's
//! SNRs refer to, and by `faint calibrate --from-input` to model the noise.

/// `1.4826 MAD` estimates a Gaussian's standard deviation (`1 / Phi^-1(3/4)`).
pub const MAD_TO_STD: f64 = 1.482_602_218_505_602;

/// The median of `v` (the mean of the two middle values for an even count; `v` is
/// reordered, in `O(n)`); `None` when empty.
pub fn median(v: &mut [f64]) -> Option<f64> {
    let n = v.len();
    if n == 0 {
        return None;
    }
    let (lo, mid, _) = v.select_nth_unstable_by(n / 2, f64::total_cmp);
    let hi = *mid;
    Some(if n % 2 == 1 {
        hi
    } else {
        0.5 * (lo.iter().copied().fold(f64::NEG_INFINITY, f64::max) + hi)
    })
}

/// Mean of exponentially distributed powers (`|z|^2` of circular complex Gaussian
/// cells), `median / ln 2`; `None` when empty or when the median is not positive and
/// finite (no noise to measure).
pub fn exponential_mean(powers: impl IntoIterator<Item = f64>) -> Option<f64> {
    let mut v: Vec<f64> = powers.into_iter().collect();
    let med = median(&mut v)?;
    let mean = med / std::f64::consts::LN_2;
    (mean > 0.0 && mean.is_finite()).then_some(mean)
}

/// Location and standard deviation of Gaussian samples, `(median, 1.4826 MAD)`; `None`
/// when empty or when the MAD is not positive and finite.
pub fn gaussian_location_scale(samples: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = samples.into_iter().collect();
    let loc = median(&mut v)?;
    let mut dev: Vec<f64> = v.iter().map(|x| (x - loc).abs()).collect();
    let std = MAD_TO_STD * median(&mut dev)?;
    (std > 0.0 && std.is_finite() && loc.is_finite()).then_some((loc, std))
}

#[cfg(test)]
mod tests {
    use super::*;
    use faint_core::rng::Rng;

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(&mut [3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&mut [4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&mut []), None);
    }

    #[test]
    fn exponential_mean_ignores_a_few_strong_cells() {
        // 100 000 unit-mean exponential powers: the median / ln 2 estimate has a relative
        // sd of about 1 / (ln 2 sqrt(n)) = 0.5 %; 2 % of the cells at power 1e6 (targets)
        // move the median by the 1 % quantile shift, about 1.5 % - so 4 % holds both.
        let mut rng = Rng::seed_from_u64(3);
        let mut p: Vec<f64> = (0..100_000).map(|_| f64::from(rng.exponential())).collect();
        for x in p.iter_mut().step_by(50) {
            *x = 1e6;
        }
        let m = exponential_mean(p.iter().copied()).unwrap();
        assert!((m - 1.0).abs() < 0.04, "{m}");
        let mean = p.iter().sum::<f64>() / p.len() as f64;
        assert!(mean > 1e4, "the plain mean is moved by the targets: {mean}");
        assert_eq!(exponential_mean([0.0, 0.0, 1.0]), None);
        assert_eq!(exponential_mean([]), None);
    }

    #[test]
    fn gaussian_location_scale_of_offset_noise() {
        // N(3000, 2^2), 100 000 samples: median and 1.4826 MAD within 1 % (their sds are
        // about 0.4 % and 0.5 % of sigma).
        let mut rng = Rng::seed_from_u64(4);
        let v: Vec<f64> = (0..100_000)
            .map(|_| 3000.0 + 2.0 * f64::from(rng.normal()))
            .collect();
        let (loc, std) = gaussian_location_scale(v).unwrap();
        assert!((loc - 3000.0).abs() < 0.02, "{loc}");
        assert!((std / 2.0 - 1.0).abs() < 0.01, "{std}");
        assert_eq!(gaussian_location_scale([5.0, 5.0, 5.0]), None);
    }
}
