//! Distribution tests of the samplers against exact moments and a Kolmogorov-Smirnov
//! bound.
//!
//! KS bound: for n i.i.d. draws, P(sqrt(n) D_n > x) -> 2 sum_k (-1)^(k-1) exp(-2 k^2 x^2)
//! (Kolmogorov). At x = 1.95 the tail is 2 exp(-7.605) - ... = 0.0010, so a correct
//! sampler fails a fixed-seed test with probability about 1e-3; a Ziggurat with a wrong
//! table or a biased tail moves D_n by far more at n = 200 000 (1.95 / sqrt(n) = 0.0044).
//! Moment tolerances are 5 standard errors of the sample moment, computed from the
//! exact higher moments of the target distribution.

use faint::rng::Rng;
use statrs::distribution::{ContinuousCDF, Exp, Normal};

const N: usize = 200_000;
const KS_CRIT: f64 = 1.95;

fn ks(mut xs: Vec<f64>, cdf: impl Fn(f64) -> f64) -> f64 {
    xs.sort_by(f64::total_cmp);
    let n = xs.len() as f64;
    let mut d: f64 = 0.0;
    for (i, &x) in xs.iter().enumerate() {
        let f = cdf(x);
        d = d
            .max((f - i as f64 / n).abs())
            .max(((i + 1) as f64 / n - f).abs());
    }
    d * n.sqrt()
}

fn moments(xs: &[f64]) -> (f64, f64, f64, f64) {
    let n = xs.len() as f64;
    let m1 = xs.iter().sum::<f64>() / n;
    let c = |k: i32| xs.iter().map(|x| (x - m1).powi(k)).sum::<f64>() / n;
    (m1, c(2), c(3), c(4))
}

#[test]
fn normal_moments_and_ks() {
    let mut rng = Rng::seed_from_u64(12345);
    let xs: Vec<f64> = (0..N).map(|_| rng.normal() as f64).collect();
    assert!(xs.iter().all(|x| x.is_finite()));
    let (m, v, s3, k4) = moments(&xs);
    let n = N as f64;
    // se(mean) = 1/sqrt(n); se(var) = sqrt(2/n); se(third moment) = sqrt(15/n);
    // se(fourth) = sqrt((105 - 9)/n) = sqrt(96/n).
    assert!(m.abs() < 5.0 / n.sqrt(), "mean {m}");
    assert!((v - 1.0).abs() < 5.0 * (2.0 / n).sqrt(), "var {v}");
    assert!(s3.abs() < 5.0 * (15.0 / n).sqrt(), "m3 {s3}");
    assert!((k4 - 3.0).abs() < 5.0 * (96.0 / n).sqrt(), "m4 {k4}");
    let nd = Normal::new(0.0, 1.0).unwrap();
    let d = ks(xs.clone(), |x| nd.cdf(x));
    assert!(d < KS_CRIT, "KS statistic {d}");
    // The tail beyond r = 3.44 is reached: P(|x| > 3.44) = 5.8e-4, about 116 draws.
    let tail = xs.iter().filter(|x| x.abs() > 3.442_62).count();
    assert!((70..170).contains(&tail), "tail count {tail}");
}

#[test]
fn exponential_moments_and_ks() {
    let mut rng = Rng::seed_from_u64(777);
    let xs: Vec<f64> = (0..N).map(|_| rng.exponential() as f64).collect();
    let (m, v, _, _) = moments(&xs);
    let n = N as f64;
    // Exp(1): var 1, var of sample variance ~ (mu4 - 1)/n = 8/n.
    assert!((m - 1.0).abs() < 5.0 / n.sqrt(), "mean {m}");
    assert!((v - 1.0).abs() < 5.0 * (8.0 / n).sqrt(), "var {v}");
    let e = Exp::new(1.0).unwrap();
    assert!(ks(xs, |x| e.cdf(x)) < KS_CRIT);
}

#[test]
fn uniform_and_bernoulli() {
    let mut rng = Rng::seed_from_u64(9);
    let xs: Vec<f64> = (0..N).map(|_| rng.uniform() as f64).collect();
    let (m, v, _, _) = moments(&xs);
    let n = N as f64;
    // U(0,1): var 1/12; var of sample variance = (1/80 - 1/144)/n.
    assert!((m - 0.5).abs() < 5.0 * (1.0 / 12.0 / n).sqrt());
    assert!((v - 1.0 / 12.0).abs() < 5.0 * ((1.0 / 80.0 - 1.0 / 144.0) / n).sqrt());
    assert!(ks(xs, |x| x.clamp(0.0, 1.0)) < KS_CRIT);
    let k = (0..N).filter(|_| rng.bernoulli(0.3)).count() as f64;
    assert!((k / n - 0.3).abs() < 5.0 * (0.21 / n).sqrt());
    // gaussian(mu, sigma) is an affine map of normal().
    let g: Vec<f64> = (0..N).map(|_| rng.gaussian(2.0, 3.0) as f64).collect();
    let (gm, gv, _, _) = moments(&g);
    assert!((gm - 2.0).abs() < 5.0 * 3.0 / n.sqrt());
    assert!((gv - 9.0).abs() < 5.0 * 9.0 * (2.0 / n).sqrt());
}

#[test]
fn streams_are_uncorrelated() {
    // Neighbouring trial streams must not be correlated: the correlation of 50 000 pairs
    // has sd 1/sqrt(50 000) = 0.0045; 5 sd = 0.022.
    let n = 50_000;
    let mut a = Rng::from_stream(1, 0);
    let mut b = Rng::from_stream(1, 1);
    let r: f64 = (0..n)
        .map(|_| (a.normal() as f64) * (b.normal() as f64))
        .sum::<f64>()
        / n as f64;
    assert!(r.abs() < 0.022, "correlation {r}");
}
