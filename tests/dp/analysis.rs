//! The merit-distribution analysis (Wang, Zhang 2016, §3): its lattice laws against an
//! independent population simulation of the same independence model, its exact cases
//! (n <= 2) against the detectors, and the analysis figure's ordering.

use faint_core::detect::dp::{transition_table, DpConfig, Method};
use faint_core::dp_tbd;
use faint_core::rng::Rng;
use faint_host::analysis::dp::{analyse, montecarlo, track_thresholds, Setup};

const PFA: f64 = 0.01;

fn setup(method: Method, qb: usize) -> Setup {
    Setup {
        method,
        qb,
        step: (1, 0),
        refine: 1,
    }
}

/// `round(z / lsb)` for `z ~ N(mu, sigma^2)`.
fn draw(rng: &mut Rng, mu: f64, cfg: &DpConfig) -> i64 {
    let z = mu + f64::from(cfg.sigma) * f64::from(rng.normal());
    (z / f64::from(cfg.lsb)).round() as i64
}

/// Population simulation of the independence model: each max takes independent members
/// of the previous frame's population (so the candidates are i.i.d., as the analysis
/// assumes); a second, independent implementation of the recursions of the module doc.
/// Returns the noise pixel merits and the target pixel merits after `n` frames (LSB).
fn population(
    cfg: &DpConfig,
    method: Method,
    n: usize,
    size: usize,
    amp: f64,
    rng: &mut Rng,
) -> (Vec<i64>, Vec<i64>) {
    let pick = |pool: &[i64], rng: &mut Rng| pool[rng.below(pool.len() as u32) as usize];
    if method == Method::Arnold {
        let mut x: Vec<i64> = (0..size).map(|_| draw(rng, 0.0, cfg)).collect();
        let mut t: Vec<i64> = (0..size).map(|_| draw(rng, amp, cfg)).collect();
        for _ in 1..n {
            let nt: Vec<i64> = (0..size)
                .map(|i| {
                    let others = (0..8).map(|_| pick(&x, rng)).max().unwrap_or(i64::MIN);
                    draw(rng, amp, cfg) + t[i].max(others)
                })
                .collect();
            x = (0..size)
                .map(|_| draw(rng, 0.0, cfg) + (0..9).map(|_| pick(&x, rng)).max().unwrap())
                .collect();
            t = nt;
        }
        return (x, t);
    }
    // second order, q_B = 9, target step d* = (1, 0): state d = (dx, dy), index (dy+1)3+(dx+1)
    let g = transition_table(cfg);
    let star = 5usize;
    let cands = |d: usize| -> Vec<(usize, usize)> {
        let (dx, dy) = (d as i32 % 3 - 1, d as i32 / 3 - 1);
        (0..9usize)
            .filter_map(|e| {
                let (ex, ey) = (e as i32 % 3 - 1, e as i32 / 3 - 1);
                let (px, py) = (dx - ex, dy - ey);
                (px.abs() <= 1 && py.abs() <= 1).then(|| (e, ((py + 1) * 3 + px + 1) as usize))
            })
            .collect()
    };
    let mut y: Vec<Vec<i64>> = (0..9)
        .map(|_| (0..size).map(|_| draw(rng, 0.0, cfg)).collect())
        .collect();
    let mut a: Vec<i64> = (0..size).map(|_| draw(rng, amp, cfg)).collect();
    for _ in 2..n {
        let ca = cands(star);
        let na: Vec<i64> = (0..size)
            .map(|i| {
                let mut best = a[i] + i64::from(g[4]);
                for &(e, p) in ca.iter().filter(|(e, _)| *e != 4) {
                    best = best.max(pick(&y[p], rng) + i64::from(g[e]));
                }
                draw(rng, amp, cfg) + best
            })
            .collect();
        let ny: Vec<Vec<i64>> = (0..9)
            .map(|d| {
                let c = cands(d);
                (0..size)
                    .map(|_| {
                        let best = c
                            .iter()
                            .map(|&(e, p)| pick(&y[p], rng) + i64::from(g[e]))
                            .max()
                            .unwrap();
                        draw(rng, 0.0, cfg) + best
                    })
                    .collect()
            })
            .collect();
        y = ny;
        a = na;
    }
    let noise = (0..size)
        .map(|_| draw(rng, 0.0, cfg) + (0..9).map(|d| pick(&y[d], rng)).max().unwrap())
        .collect();
    let target = (0..size)
        .map(|i| {
            let others = (0..9)
                .filter(|&d| d != star)
                .map(|d| pick(&y[d], rng))
                .max()
                .unwrap();
            draw(rng, amp, cfg) + a[i].max(others)
        })
        .collect();
    (noise, target)
}

/// The lattice laws equal the population simulation of the same model. At 200 000
/// samples the standard error of a rate p is sqrt(p (1 - p) / 2e5): 0.00022 at 0.01,
/// 0.0011 at 0.5; resampling from a finite population inflates it slightly, so the
/// tolerance is 5 of them (a wrong recursion, e.g. candidates not sharing their pixel's
/// z, moves the second-order rates by 0.002-0.02 at n = 6).
#[test]
fn the_laws_match_a_population_simulation_of_the_independence_model() {
    let n = 6;
    let size = 200_000;
    for method in [Method::Arnold, Method::SecondOrder] {
        let cfg = DpConfig::dim_point(method, 1);
        let amp = 2.0 * f64::from(cfg.sigma);
        let c = analyse(&cfg, &setup(method, 9), n, PFA, Some(amp)).unwrap();
        let mut rng = Rng::from_stream(77, method as u64);
        let (noise, target) = population(&cfg, method, n, size, amp, &mut rng);
        let v = (c.threshold[n - 1] / f64::from(cfg.lsb)).round() as i64;
        let share = |s: &[i64]| s.iter().filter(|&&x| x >= v).count() as f64 / s.len() as f64;
        let (pf, pd) = (share(&noise), share(&target));
        let tol = |p: f64| 5.0 * (p * (1.0 - p) / size as f64).sqrt();
        assert!(
            (pf - c.pfa[n - 1]).abs() < tol(c.pfa[n - 1]),
            "{method:?}: population P_FA {pf} vs law {}",
            c.pfa[n - 1]
        );
        assert!(
            (pd - c.pd[n - 1]).abs() < tol(c.pd[n - 1]),
            "{method:?}: population P_D {pd} vs law {}",
            c.pd[n - 1]
        );
    }
}

/// For n <= 2 the candidates of every max are distinct pixels of one frame, so the
/// independence model is exact and the detectors must agree with it. 8 images of
/// 256 x 256 give 5e5 pixel tracks per frame; neighbouring tracks share candidates at
/// n = 2 (correlation ~0.16), so the tolerance is 4 binomial standard errors doubled.
#[test]
fn the_detectors_match_the_exact_cases() {
    type A = dp_tbd!(Arnold, 256, 9, 2);
    type S = dp_tbd!(SecondOrder, 256, 9, 3);
    for method in [Method::Arnold, Method::SecondOrder] {
        let cfg = DpConfig::dim_point(method, 1);
        let c = analyse(&cfg, &setup(method, 9), 2, PFA, None).unwrap();
        let vt: Vec<f32> = c.threshold.iter().map(|&v| v as f32).collect();
        let mc = match method {
            Method::Arnold => {
                montecarlo::noise_check(|| Box::new(A::new_unconfigured()), &cfg, 1, &vt, PFA, 8, 5)
            }
            _ => {
                montecarlo::noise_check(|| Box::new(S::new_unconfigured()), &cfg, 1, &vt, PFA, 8, 5)
            }
        }
        .unwrap();
        for (k, (point, &p)) in mc.iter().zip(&c.pfa).enumerate() {
            let se = (p * (1.0 - p) / point.exceed.samples as f64).sqrt();
            assert!(
                (point.exceed.rate - p).abs() < 8.0 * se,
                "{method:?} n = {}: detector {} vs law {p}",
                k + 1,
                point.exceed.rate
            );
        }
    }
}

/// The analysis figure's claims, from the laws (deterministic): at SNR 2 the second-order
/// DP has the higher P_D from n = 3 on at both window sizes, and going from q_B = 9 to 25
/// costs it less P_D than it costs the first-order DP.
#[test]
fn second_order_wins_and_is_less_sensitive_to_the_window() {
    let pd = |method: Method, qb: usize| {
        let cfg = DpConfig::dim_point(method, 1);
        analyse(&cfg, &setup(method, qb), 12, PFA, Some(3.0))
            .unwrap()
            .pd
    };
    let (a9, a25, s9, s25) = (
        pd(Method::Arnold, 9),
        pd(Method::Arnold, 25),
        pd(Method::SecondOrder, 9),
        pd(Method::SecondOrder, 25),
    );
    for k in 2..12 {
        assert!(s9[k] > a9[k] && s25[k] > a25[k], "n = {}", k + 1);
        assert!(s9[k] - s25[k] < a9[k] - a25[k], "n = {}", k + 1);
    }
}

/// Thresholds are multiples of the merit LSB (the detectors' merits are), grow with n,
/// and Pulford gets Arnold's.
#[test]
fn track_thresholds_are_on_the_merit_lattice() {
    for method in [Method::Arnold, Method::Pulford, Method::SecondOrder] {
        let cfg = DpConfig::dim_point(method, 1);
        let vt = track_thresholds(&cfg, 9, 10, PFA).unwrap();
        assert_eq!(vt.len(), 10);
        for w in vt.windows(2) {
            assert!(w[1] > w[0]);
        }
        for v in &vt {
            assert_eq!((v / cfg.lsb).fract(), 0.0);
        }
    }
    let a = track_thresholds(&DpConfig::dim_point(Method::Arnold, 1), 9, 5, PFA).unwrap();
    let p = track_thresholds(&DpConfig::dim_point(Method::Pulford, 1), 9, 5, PFA).unwrap();
    assert_eq!(a, p);
    let cfg = DpConfig::dim_point(Method::Arnold, 1);
    assert!(track_thresholds(&cfg, 16, 5, PFA).is_err());
    assert!(track_thresholds(&cfg, 9, 0, PFA).is_err());
    assert!(track_thresholds(&cfg, 9, 5, 1.5).is_err());
}
