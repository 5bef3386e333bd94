//! The tabulated observation model `h_k(x)` against the exact windowed DFT in `f64`.

use faint::host::simulate::crpf::{window, windowed_dft};
use faint::model::doppler::*;
use faint::rng::Rng;
use faint::Complex32;

/// Exact `h_b = A sum_n w_n exp(j 2 pi fd n ts) exp(-j 2 pi b n / m)` over all bins, f64.
fn exact(fd: f64, amp: f64, m: usize, ts: f64) -> Vec<(f64, f64)> {
    let w = window(m);
    (0..m)
        .map(|b| {
            let (mut re, mut im) = (0.0, 0.0);
            for (n, wn) in w.iter().enumerate() {
                let ph =
                    2.0 * std::f64::consts::PI * (fd * ts * n as f64 - (b * n) as f64 / m as f64);
                re += amp * wn * ph.cos();
                im += amp * wn * ph.sin();
            }
            (re, im)
        })
        .collect()
}

#[test]
fn response_error_below_stated_bound_over_the_band() {
    let model = DopplerModel::new(32, 0.02, Window::Hamming).unwrap();
    let mut worst = 0.0f64;
    // 20 000 Doppler values over the band [-25, 25) Hz (1/12.8 of a bin apart, plus
    // an irrational offset so the grid does not line up with the table).
    for i in 0..20_000 {
        let fd = -25.0 + 50.0 * (i as f64 + 0.3137) / 20_000.0;
        let ex = exact(fd, 1.0, 32, 0.02);
        let mut r = [Complex32::new(0.0, 0.0); SPAN];
        let first = model.response(fd as f32, 1.0, &mut r);
        let mut approx = vec![(0.0f64, 0.0f64); 32];
        for (j, v) in r.iter().enumerate() {
            approx[(first + j) % 32] = (v.re as f64, v.im as f64);
        }
        let num: f64 = ex
            .iter()
            .zip(&approx)
            .map(|(a, b)| (a.0 - b.0).powi(2) + (a.1 - b.1).powi(2))
            .sum();
        let den: f64 = ex.iter().map(|a| a.0 * a.0 + a.1 * a.1).sum();
        worst = worst.max((num / den).sqrt());
    }
    println!("worst relative response error {worst:.3e}");
    assert!(worst < RESPONSE_ERROR_BOUND, "worst {worst}");
    // The bound is not loose by orders of magnitude: side lobes are really left out.
    assert!(worst > RESPONSE_ERROR_BOUND / 20.0);
}

#[test]
fn projection_matches_direct_residual() {
    // ||z - h||^2 by the projection against the same quantity computed directly from
    // the exact h over all 32 bins (f64). The difference is the approximation error of h
    // times ||z||, bounded by 2 ||z|| ||h|| bound + bound^2 ||h||^2.
    let model = DopplerModel::new(32, 0.02, Window::Hamming).unwrap();
    let mut rng = Rng::seed_from_u64(11);
    for _ in 0..2000 {
        let z: Vec<Complex32> = (0..32)
            .map(|_| Complex32::new(3.0 * rng.normal(), 3.0 * rng.normal()))
            .collect();
        let fd = rng.uniform_range(-25.0, 25.0);
        let amp = rng.uniform_range(0.05, 1.5);
        let zz: f32 = z.iter().map(|c| c.norm_sqr()).sum();
        let p = model.project(&z, fd, amp);
        let ex = exact(fd as f64, amp as f64, 32, 0.02);
        let direct: f64 = z
            .iter()
            .zip(&ex)
            .map(|(a, b)| (a.re as f64 - b.0).powi(2) + (a.im as f64 - b.1).powi(2))
            .sum();
        let hh: f64 = ex.iter().map(|b| b.0 * b.0 + b.1 * b.1).sum();
        let bound = 2.0 * (zz as f64).sqrt() * hh.sqrt() * RESPONSE_ERROR_BOUND
            + hh * RESPONSE_ERROR_BOUND * RESPONSE_ERROR_BOUND
            + 1e-5 * direct;
        let got = p.residual_norm2(zz) as f64;
        assert!(
            (got - direct).abs() <= bound,
            "got {got} direct {direct} bound {bound}"
        );
    }
}

#[test]
fn scenario_dft_agrees_with_model_on_noise_free_target() {
    // The simulator's windowed DFT of a pure tone equals the model's response.
    let model = DopplerModel::new(32, 0.02, Window::Hamming).unwrap();
    let w = window(32);
    for fd in [-24.9f64, -3.3, 0.0, 0.78, 12.5, 24.99] {
        let s: Vec<(f64, f64)> = (0..32)
            .map(|n| {
                let ph = 2.0 * std::f64::consts::PI * fd * 0.02 * n as f64;
                (0.7 * ph.cos(), 0.7 * ph.sin())
            })
            .collect();
        let z = windowed_dft(&s, &w);
        let zz: f32 = z.iter().map(|c| c.norm_sqr()).sum();
        let p = model.project(&z, fd as f32, 0.7);
        // Perfect fit: residual is the left-out energy only (relative bound^2).
        assert!(
            p.residual_norm2(zz)
                <= zz * (RESPONSE_ERROR_BOUND * RESPONSE_ERROR_BOUND) as f32 + 1e-4
        );
    }
}

#[test]
fn bad_configs_and_frames_are_errors() {
    use faint::Error;
    assert!(DopplerModel::new(4, 0.02, Window::Hamming).is_err());
    assert!(DopplerModel::new(MAX_BINS + 1, 0.02, Window::Hamming).is_err());
    assert!(DopplerModel::new(32, 0.0, Window::Hamming).is_err());
    assert!(DopplerModel::new(32, f32::NAN, Window::Hamming).is_err());
    let z = vec![Complex32::new(0.0, 0.0); 31];
    assert_eq!(
        check_frame(&z, 32),
        Err(Error::LengthMismatch {
            expected: 32,
            got: 31
        })
    );
    let mut z = vec![Complex32::new(1.0, 0.0); 32];
    z[3].im = f32::INFINITY;
    assert_eq!(check_frame(&z, 32), Err(Error::NonFinite));
    let zero = vec![Complex32::new(0.0, 0.0); 32];
    assert!(estimate_noise_variance([zero.as_slice()], 32).is_err());
    assert_eq!(
        estimate_noise_variance(std::iter::empty::<&[Complex32]>(), 32),
        Err(Error::Empty)
    );
}

#[test]
fn cached_projection_matches_direct() {
    // `project_cached` (CRPF-TBD's continuing particles) against `project`: the same
    // sums regrouped (`A + frac D`, `||h||^2` as a quadratic in `frac`) and the table
    // position from one scaled Doppler, so they differ by rounding and by the fraction's
    // resolution (2^-11 of a table step, about 1e-5 of |h|): the tolerance 1e-4 of the
    // scale sqrt(||z||^2 ||h||^2) (resp. of ||h||^2) is ten times that (measured worst:
    // 2.6e-6, 1.9e-6, 3.8e-6 for m = 32, 16, 64; m = 64 mixes cached first bins < 32
    // and direct ones). Several frames
    // through one cache (each entry must be refilled after `new_frame`), Dopplers over
    // the band and its edges (bins that wrap), amplitudes 0.05-1.5.
    let mut rng = Rng::seed_from_u64(42);
    for (m, ts) in [(32usize, 0.02f32), (16, 0.04), (64, 0.01)] {
        let model = DopplerModel::new(m, ts, Window::Hamming).unwrap();
        let half = 0.5 / ts;
        let mut cache = ProjectionCache::default();
        let mut worst = 0.0f32;
        for _ in 0..20 {
            cache.new_frame();
            let z: Vec<Complex32> = (0..m)
                .map(|_| Complex32::new(3.0 * rng.normal(), 3.0 * rng.normal()))
                .collect();
            let zz: f32 = z.iter().map(|c| c.norm_sqr()).sum();
            for i in 0..2000 {
                let fd = match i % 4 {
                    0 => half * (1.0 - 1e-6 * rng.uniform()),
                    1 => -half * (1.0 - 1e-3 * rng.uniform()),
                    _ => rng.uniform_range(-half, half),
                };
                let amp = rng.uniform_range(0.05, 1.5);
                let d = model.project(&z, fd, amp);
                let c = model.project_cached::<true>(&mut cache, &z, fd, amp);
                let r = model.project_cached::<false>(&mut cache, &z, fd, amp);
                let scale = (zz * d.hh).sqrt();
                let e = ((c.zh - d.zh).norm() / scale).max((c.hh - d.hh).abs() / d.hh);
                assert!(e < 1e-4, "m {m} fd {fd} amp {amp}: {c:?} vs {d:?}");
                assert_eq!((r.zh.re, r.zh.im, r.hh), (c.zh.re, 0.0, c.hh));
                worst = worst.max(e);
            }
        }
        println!("m = {m}: worst relative difference {worst:e}");
        // Not finite: the direct path.
        let z = vec![Complex32::new(1.0, 0.0); m];
        let n = model.project_cached::<true>(&mut cache, &z, f32::NAN, 1.0);
        assert_eq!(n, model.project(&z, f32::NAN, 1.0));
    }
}
