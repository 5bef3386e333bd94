//! The OTHR noise generators: complex Gaussian and complex generalized Gaussian (c = 0.1).

use faint::host::simulate::crpf::*;
use faint::rng::Rng;

#[test]
fn complex_gaussian_variance_and_kurtosis() {
    // 400 000 draws: E|w|^2 = 1 with sd 1/sqrt(n) = 0.0016; E|w|^4/(E|w|^2)^2 = 2 with
    // sd about sqrt(20/n) = 0.007; tolerances are > 5 sd.
    let mut rng = Rng::seed_from_u64(3);
    let n = 400_000;
    let (mut m2, mut m4) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let (a, b) = complex_gaussian(1.0, &mut rng);
        let r2 = a * a + b * b;
        m2 += r2;
        m4 += r2 * r2;
    }
    m2 /= n as f64;
    m4 /= n as f64;
    assert!((m2 - 1.0).abs() < 0.01, "{m2}");
    assert!((m4 / (m2 * m2) - 2.0).abs() < 0.04, "{}", m4 / (m2 * m2));
}

#[test]
fn cgg_kurtosis_formula() {
    // Gamma(30) Gamma(10) / Gamma(20)^2 = 29! 9! / 19!^2.
    let exact: f64 =
        (20..=29).map(|k| k as f64).product::<f64>() / (10..=19).map(|k| k as f64).product::<f64>();
    assert!((cgg_kurtosis(0.1) / exact - 1.0).abs() < 1e-9);
    assert!(
        (cgg_kurtosis(0.1) - 217.0).abs() < 1.0,
        "{}",
        cgg_kurtosis(0.1)
    );
    // c = 1 is the complex Gaussian: kurtosis 2.
    assert!((cgg_kurtosis(1.0) - 2.0).abs() < 1e-9);
}

#[test]
fn cgg_variance_and_shape() {
    // Variance: E|w|^2 = s2. With kurtosis 217 the sample mean of |w|^2 has relative sd
    // sqrt(216/n) = 0.0104 at n = 2e6; tolerance 0.06 is about 6 sd.
    // Kurtosis: the sample fourth moment of this law has relative sd
    // sqrt(E|w|^8/(E|w|^4)^2 / n) = sqrt(2.8e6 / n), i.e. useless at any feasible n,
    // so the kurtosis is checked through the law itself: (alpha |w|^2)^c must be
    // Gamma(1/c, 1) (mean 10, variance 10), which fixes every moment of |w|, and the
    // phase must be uniform (E e^{j phase} = 0). Sd of the gamma mean: sqrt(10/n) =
    // 0.0022; of its variance: about sqrt((mu4 - s^4)/n) = sqrt(320/n) = 0.013.
    let c = 0.1;
    let s2 = 2.5;
    let ln_alpha = cgg_ln_alpha(c, s2);
    let mut rng = Rng::seed_from_u64(17);
    let n = 2_000_000;
    let (mut m2, mut g1, mut g2, mut cr, mut ci) = (0.0f64, 0.0, 0.0, 0.0, 0.0);
    for _ in 0..n {
        let (a, b) = complex_generalized_gaussian(c, s2, &mut rng);
        let r2 = a * a + b * b;
        m2 += r2;
        let g = ((ln_alpha + r2.ln()) * c).exp();
        g1 += g;
        g2 += g * g;
        let r = r2.sqrt();
        cr += a / r;
        ci += b / r;
    }
    let nf = n as f64;
    m2 /= nf;
    let mean = g1 / nf;
    let var = g2 / nf - mean * mean;
    assert!((m2 / s2 - 1.0).abs() < 0.06, "E|w|^2 = {m2}");
    assert!((mean - 10.0).abs() < 0.015, "gamma mean {mean}");
    assert!((var - 10.0).abs() < 0.1, "gamma var {var}");
    assert!((cr / nf).abs() < 0.005 && (ci / nf).abs() < 0.005);
}

#[test]
fn snr_definition_eq18() {
    // A bin-centred noise-free target: max_b |h_b|^2 / sigma0^2 equals the SNR.
    let sc = Othr::default();
    for snr in [-3.0f64, 0.0, 5.0, 12.0] {
        let a = sc.amplitude(snr);
        let w = window(32);
        let fd = 5.0 / (32.0 * 0.02); // bin 5
        let s: Vec<(f64, f64)> = (0..32)
            .map(|n| {
                let ph = 2.0 * std::f64::consts::PI * fd * 0.02 * n as f64;
                (a * ph.cos(), a * ph.sin())
            })
            .collect();
        let z = windowed_dft(&s, &w);
        let peak = z.iter().map(|c| c.norm_sqr() as f64).fold(0.0, f64::max);
        let got = 10.0 * (peak / sc.bin_noise_var()).log10();
        assert!((got - snr).abs() < 1e-4, "{got} vs {snr}");
    }
    // sigma0^2 is the per-bin variance of windowed white noise: check by simulation.
    let mut rng = Rng::seed_from_u64(5);
    let mut acc = 0.0f64;
    let runs = 400;
    for _ in 0..runs {
        let r = sc.simulate(None, Noise::Gaussian, &mut rng);
        acc += r
            .frames
            .iter()
            .flatten()
            .map(|c| c.norm_sqr() as f64)
            .sum::<f64>();
    }
    let per_bin = acc / (runs * 32 * 32) as f64;
    // 409 600 bins (correlated in pairs at most): relative sd below 0.005.
    assert!(
        (per_bin / sc.bin_noise_var() - 1.0).abs() < 0.02,
        "{per_bin}"
    );
}
