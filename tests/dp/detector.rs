//! DP-TBD (Barniv 1985 / Arnold et al. 1993, Pulford and La Scala 2010, Wang and Zhang
//! 2016): exact agreement with an exhaustive search over all window-constrained tracks,
//! bad input, properties (monotone merits, recovered tracks inside the windows,
//! determinism), zero-initialised statics.

use faint::detect::dp::{
    arnold_words, first_clamped, pulford_words, second_order_words, transition_table, ArnoldDp,
    DpConfig, DpReport, DpTrack, Method, PulfordDp, SecondOrderDp, Transition,
};
use faint::detect::{run, Detector};
use faint::dp_tbd;
use faint::rng::Rng;
use faint::Error;
use proptest::prelude::*;

const M: usize = 6;
const LSB: f32 = 0.0625;

type A9 = dp_tbd!(Arnold, M, 9, 4);
type A25 = dp_tbd!(Arnold, M, 25, 4);
type S9 = dp_tbd!(SecondOrder, M, 9, 4);
type S25 = dp_tbd!(SecondOrder, M, 25, 4);
type P9 = dp_tbd!(Pulford, M, 9, 4);

fn cfg(method: Method) -> DpConfig {
    DpConfig::dim_point(method, 1)
}

/// Frames of multiples of the LSB (so quantisation is exact), `N(0, 1.5^2)`-like.
fn frames(seed: u64, n: usize, m: usize) -> Vec<Vec<f32>> {
    let mut rng = Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            (0..m * m)
                .map(|_| (1.5 * rng.normal() / LSB).round() * LSB)
                .collect()
        })
        .collect()
}

fn q(z: f32) -> i64 {
    (z / LSB).round() as i64
}

/// Exhaustive best merit (LSB) of tracks ending at each pixel, first order, radius `r`.
fn brute_first(fr: &[Vec<f32>], m: usize, r: i64) -> Vec<i64> {
    fn rec(fr: &[Vec<f32>], m: usize, r: i64, k: usize, x: i64, y: i64) -> i64 {
        let z = q(fr[k][(y as usize) * m + x as usize]);
        if k == 0 {
            return z;
        }
        let mut best = i64::MIN;
        for dy in -r..=r {
            for dx in -r..=r {
                let (px, py) = (x + dx, y + dy);
                if px < 0 || py < 0 || px >= m as i64 || py >= m as i64 {
                    continue;
                }
                best = best.max(rec(fr, m, r, k - 1, px, py));
            }
        }
        z + best
    }
    let k = fr.len() - 1;
    (0..m * m)
        .map(|i| rec(fr, m, r, k, (i % m) as i64, (i / m) as i64))
        .collect()
}

/// Exhaustive best merit (LSB) of second-order tracks ending at each pixel.
fn brute_second(fr: &[Vec<f32>], m: usize, r: i64, g: &[i32; 9]) -> Vec<i64> {
    let inside = |x: i64, y: i64| x >= 0 && y >= 0 && x < m as i64 && y < m as i64;
    // best merit of a track (t_k = (x, y), t_{k-1} = (x - dx, y - dy)) over frames 0..=k
    #[allow(clippy::too_many_arguments)]
    fn rec(
        fr: &[Vec<f32>],
        m: usize,
        r: i64,
        g: &[i32; 9],
        k: usize,
        t: (i64, i64),
        t1: (i64, i64),
        inside: &dyn Fn(i64, i64) -> bool,
    ) -> Option<i64> {
        let z = q(fr[k][(t.1 as usize) * m + t.0 as usize]);
        if k == 1 {
            return Some(z + q(fr[0][(t1.1 as usize) * m + t1.0 as usize]));
        }
        let mut best: Option<i64> = None;
        let ext = (2 * t1.0 - t.0, 2 * t1.1 - t.1);
        for ey in -1..=1i64 {
            for ex in -1..=1i64 {
                let t2 = (ext.0 + ex, ext.1 + ey);
                if !inside(t2.0, t2.1) || (t1.0 - t2.0).abs() > r || (t1.1 - t2.1).abs() > r {
                    continue;
                }
                let ge = i64::from(g[((ey + 1) * 3 + ex + 1) as usize]);
                if let Some(v) = rec(fr, m, r, g, k - 1, t1, t2, inside) {
                    best = Some(best.map_or(v + ge, |b| b.max(v + ge)));
                }
            }
        }
        best.map(|b| z + b)
    }
    let k = fr.len() - 1;
    (0..m * m)
        .map(|i| {
            let t = ((i % m) as i64, (i / m) as i64);
            let mut best = i64::MIN;
            for dy in -r..=r {
                for dx in -r..=r {
                    let t1 = (t.0 - dx, t.1 - dy);
                    if inside(t1.0, t1.1) {
                        if let Some(v) = rec(fr, m, r, g, k, t, t1, &inside) {
                            best = best.max(v);
                        }
                    }
                }
            }
            best
        })
        .collect()
}

fn merits<D: DpTrack>(d: &D) -> Vec<i64> {
    let m = D::SIDE;
    (0..m * m)
        .map(|i| {
            let v = d.merit(i % m, i / m).unwrap();
            let l = (v / LSB).round();
            assert_eq!(l * LSB, v, "merit not a multiple of the LSB");
            l as i64
        })
        .collect()
}

fn run_all<D: DpTrack>(d: &mut D, fr: &[Vec<f32>]) -> Vec<DpReport> {
    let mut reps = Vec::new();
    run(d, fr.iter().map(|f| f.as_slice()), |_, _, r| reps.push(*r)).unwrap();
    reps
}

#[test]
fn first_order_equals_exhaustive_search() {
    for seed in 0..6 {
        for n in 1..=4 {
            let fr = frames(seed, n, M);
            let mut a = A9::new(cfg(Method::Arnold)).unwrap();
            let reps = run_all(&mut a, &fr);
            let want = brute_first(&fr, M, 1);
            assert_eq!(merits(&a), want, "3x3 seed {seed} n {n}");
            let best = *want.iter().max().unwrap();
            assert_eq!(q(reps[n - 1].best.merit), best);
            let mut b = A25::new(cfg(Method::Arnold)).unwrap();
            run_all(&mut b, &fr);
            assert_eq!(merits(&b), brute_first(&fr, M, 2), "5x5 seed {seed} n {n}");
        }
    }
}

/// At `M = 16` the first order runs its 8-pixel blocks (at `M = 6` only the tail).
#[test]
fn first_order_equals_exhaustive_search_on_wider_frames() {
    const W: usize = 16;
    for seed in 0..3 {
        let fr = frames(50 + seed, 4, W);
        let mut a = <dp_tbd!(Arnold, W, 9, 4)>::new(cfg(Method::Arnold)).unwrap();
        run_all(&mut a, &fr);
        assert_eq!(merits(&a), brute_first(&fr, W, 1), "3x3 seed {seed}");
        let mut b = <dp_tbd!(Arnold, W, 25, 4)>::new(cfg(Method::Arnold)).unwrap();
        run_all(&mut b, &fr);
        assert_eq!(merits(&b), brute_first(&fr, W, 2), "5x5 seed {seed}");
        for i in 0..W * W {
            let (x, y) = (i % W, i / W);
            let mut t = [[0u16; 2]; 4];
            assert_eq!(a.track(x, y, &mut t), 4);
            let sum: i64 = (0..4)
                .map(|j| q(fr[3 - j][t[j][1] as usize * W + t[j][0] as usize]))
                .sum();
            assert_eq!(sum, q(a.merit(x, y).unwrap()), "track at {x},{y}");
        }
    }
}

#[test]
fn second_order_equals_exhaustive_search() {
    // sigma_I = 0.5 (the preset) and the hard window give separable tables (the fast
    // row-maxima path), sigma_I = 0.7 does not (the general 2-D path).
    for (transition, sigma_i) in [
        (Transition::Gaussian, 0.5),
        (Transition::Hard, 0.5),
        (Transition::Gaussian, 0.7),
    ] {
        let mut c = cfg(Method::SecondOrder);
        c.transition = transition;
        c.sigma_i = sigma_i;
        let g = transition_table(&c);
        for seed in 0..4 {
            for n in 1..=4 {
                let fr = frames(100 + seed, n, M);
                let mut s = S9::new(c).unwrap();
                run_all(&mut s, &fr);
                let want = if n == 1 {
                    fr[0].iter().map(|&z| q(z)).collect()
                } else {
                    brute_second(&fr, M, 1, &g)
                };
                assert_eq!(merits(&s), want, "{transition:?} q_B 9 seed {seed} n {n}");
                let mut s = S25::new(c).unwrap();
                run_all(&mut s, &fr);
                let want = if n == 1 {
                    fr[0].iter().map(|&z| q(z)).collect()
                } else {
                    brute_second(&fr, M, 2, &g)
                };
                assert_eq!(merits(&s), want, "{transition:?} q_B 25 seed {seed} n {n}");
            }
        }
    }
}

/// The merit of the recovered track, recomputed from the frames, equals the reported
/// merit, and every step lies in the windows.
#[test]
fn recovered_tracks_achieve_their_merit() {
    let c = cfg(Method::SecondOrder);
    let g = transition_table(&c);
    for seed in 0..5 {
        let fr = frames(200 + seed, 4, M);
        let mut a = A9::new(cfg(Method::Arnold)).unwrap();
        let mut s = S9::new(c).unwrap();
        run_all(&mut a, &fr);
        run_all(&mut s, &fr);
        for i in 0..M * M {
            let (x, y) = (i % M, i / M);
            let mut t = [[0u16; 2]; 4];
            assert_eq!(a.track(x, y, &mut t), 4);
            let sum: i64 = (0..4)
                .map(|j| q(fr[3 - j][t[j][1] as usize * M + t[j][0] as usize]))
                .sum();
            assert_eq!(sum, q(a.merit(x, y).unwrap()));
            for w in t.windows(2) {
                assert!(w[0][0].abs_diff(w[1][0]) <= 1 && w[0][1].abs_diff(w[1][1]) <= 1);
            }
            assert_eq!(s.track(x, y, &mut t), 4);
            let mut sum: i64 = (0..4)
                .map(|j| q(fr[3 - j][t[j][1] as usize * M + t[j][0] as usize]))
                .sum();
            for j in 0..2 {
                // t[j] = t_k, t[j+1] = t_{k-1}, t[j+2] = t_{k-2}
                let p = |k: usize| (i64::from(t[k][0]), i64::from(t[k][1]));
                let (a0, a1, a2) = (p(j), p(j + 1), p(j + 2));
                let (ex, ey) = (a2.0 - (2 * a1.0 - a0.0), a2.1 - (2 * a1.1 - a0.1));
                assert!(ex.abs() <= 1 && ey.abs() <= 1, "outside R_I");
                assert!(
                    (a1.0 - a2.0).abs() <= 1 && (a1.1 - a2.1).abs() <= 1,
                    "outside R_B"
                );
                sum += i64::from(g[((ey + 1) * 3 + ex + 1) as usize]);
            }
            assert_eq!(sum, q(s.merit(x, y).unwrap()), "second order at {x},{y}");
        }
    }
}

fn bad_input_checks<D: DpTrack>(d: &mut D, m: usize) {
    let fr = frames(7, 3, m);
    d.step(&fr[0]).unwrap();
    let before = (0..m * m)
        .map(|i| d.merit(i % m, i / m))
        .collect::<Vec<_>>();
    let frames_before = d.frames();
    // wrong length
    assert_eq!(
        d.step(&fr[1][..m * m - 1]),
        Err(Error::LengthMismatch {
            expected: m * m,
            got: m * m - 1
        })
    );
    // NaN / inf anywhere: typed error, state unchanged
    for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
        for at in [0, m * m / 2, m * m - 1] {
            let mut z = fr[1].clone();
            z[at] = bad;
            assert_eq!(d.step(&z), Err(Error::NonFinite));
        }
    }
    assert_eq!(d.frames(), frames_before);
    let after = (0..m * m)
        .map(|i| d.merit(i % m, i / m))
        .collect::<Vec<_>>();
    assert_eq!(before, after);
    // huge finite values: clamped, finite merits, counted
    let huge: Vec<f32> = (0..m * m)
        .map(|i| if i % 2 == 0 { f32::MAX } else { -1e30 })
        .collect();
    for _ in 0..5 {
        let r = d.step(&huge).unwrap();
        assert_eq!(r.clamped as usize, m * m);
        assert!(r.best.merit.is_finite());
    }
    // 5 clamped frames at +16384 LSB (1024 intensity) after the first frame
    let b = d.best().unwrap().merit;
    assert!(b > 5.0 * 1000.0 && b <= 5.0 * 1024.0 + 20.0, "{b}");
    for i in 0..m * m {
        assert!(d.merit(i % m, i / m).unwrap().is_finite());
    }
    // all-equal images: every merit finite, the best equals n * value (+ transitions)
    d.reset(0);
    let flat = vec![1.25f32; m * m];
    let mut r = d.step(&flat).unwrap();
    for _ in 0..9 {
        r = d.step(&flat).unwrap();
    }
    assert_eq!(r.frame, 10);
    assert!(
        r.best.merit <= 12.5 && r.best.merit > 12.5 - 8.0 * 1.0,
        "{}",
        r.best.merit
    );
    let mut t = [[0u16; 2]; 16];
    assert!(d.track(r.best.x.into(), r.best.y.into(), &mut t) >= 1);
    assert_eq!(d.merit(m, 0), None);
    assert_eq!(d.track(0, m, &mut t), 0);
}

#[test]
fn bad_input_is_a_typed_error_and_leaves_the_state() {
    bad_input_checks(&mut A9::new(cfg(Method::Arnold)).unwrap(), M);
    bad_input_checks(&mut A25::new(cfg(Method::Arnold)).unwrap(), M);
    bad_input_checks(&mut S9::new(cfg(Method::SecondOrder)).unwrap(), M);
    bad_input_checks(&mut S25::new(cfg(Method::SecondOrder)).unwrap(), M);
    bad_input_checks(&mut P9::new(cfg(Method::Pulford)).unwrap(), M);
}

#[test]
fn bad_configs_are_typed_errors() {
    let a = cfg(Method::Arnold);
    // wrong method for the type
    assert_eq!(
        A9::new(cfg(Method::SecondOrder)).err(),
        Some(Error::InvalidConfig("method"))
    );
    assert_eq!(S9::new(a).err(), Some(Error::InvalidConfig("method")));
    // L = 0
    assert_eq!(
        ArnoldDp::<M, 9, 0, 0>::new(a).err(),
        Some(Error::InvalidConfig("L"))
    );
    assert_eq!(
        SecondOrderDp::<M, 9, 0, 0>::new(cfg(Method::SecondOrder)).err(),
        Some(Error::InvalidConfig("L"))
    );
    // window larger than the image
    assert_eq!(
        <dp_tbd!(Arnold, 4, 25, 2)>::new(a).err(),
        Some(Error::InvalidConfig("window larger than the image"))
    );
    assert_eq!(
        <dp_tbd!(SecondOrder, 2, 9, 2)>::new(cfg(Method::SecondOrder)).err(),
        Some(Error::InvalidConfig("window larger than the image"))
    );
    // not a square window
    assert_eq!(
        <dp_tbd!(Arnold, M, 10, 2)>::new(a).err(),
        Some(Error::InvalidConfig("q_b"))
    );
    // bad values, named
    for (f, name) in [
        (DpConfig { lsb: 0.0, ..a }, "lsb"),
        (DpConfig { lsb: f32::NAN, ..a }, "lsb"),
        (DpConfig { sigma: -1.0, ..a }, "sigma"),
        (DpConfig { a_design: 0.0, ..a }, "a_design"),
        (DpConfig { sigma_i: 0.0, ..a }, "sigma_i"),
        (
            DpConfig {
                p0: f32::INFINITY,
                ..a
            },
            "p0",
        ),
        (DpConfig { q: -0.1, ..a }, "q"),
        (DpConfig { r: 0.0, ..a }, "r"),
        (DpConfig { gate: 0, ..a }, "gate"),
        (DpConfig { top_k: 0, ..a }, "top_k"),
        (DpConfig { top_k: 9, ..a }, "top_k"),
    ] {
        assert_eq!(A9::new(f).err(), Some(Error::InvalidConfig(name)), "{name}");
    }
    // a failed configure leaves a working detector as it was
    let mut d = A9::new(a).unwrap();
    let fr = frames(3, 2, M);
    d.step(&fr[0]).unwrap();
    let before = d.merit(2, 2);
    assert!(d.configure(&DpConfig { lsb: -1.0, ..a }, 0).is_err());
    assert_eq!(d.merit(2, 2), before);
    assert_eq!(d.config(), &a);
}

#[test]
fn unconfigured_detectors_refuse_to_step() {
    let z = vec![0.0f32; M * M];
    assert_eq!(
        A9::new_unconfigured().step(&z),
        Err(Error::InvalidConfig("unconfigured"))
    );
    assert_eq!(
        S9::new_unconfigured().step(&z),
        Err(Error::InvalidConfig("unconfigured"))
    );
    assert_eq!(
        P9::new_unconfigured().step(&z),
        Err(Error::InvalidConfig("unconfigured"))
    );
}

/// `configure` on a zeroed (const) value equals `new`, and `reset` restarts exactly.
#[test]
fn zeroed_statics_and_reset_equal_a_new_detector() {
    static mut S: S9 = S9::new_unconfigured();
    let c = cfg(Method::SecondOrder);
    let fr = frames(11, 6, M);
    let mut fresh = S9::new(c).unwrap();
    let want = run_all(&mut fresh, &fr);
    #[allow(static_mut_refs)]
    // SAFETY: the only reference to `S`, in this one test.
    let s = unsafe { &mut S };
    s.configure(&c, 99).unwrap();
    assert_eq!(run_all(s, &fr), want);
    s.reset(5);
    assert_eq!(run_all(s, &fr), want);
    assert_eq!(merits(s), merits(&fresh));
}

fn detections_are_consistent<D: DpTrack>(d: &mut D, top_k: u8) {
    let mut c = *d.config();
    c.top_k = top_k;
    c.separation = 1;
    d.configure(&c, 0).unwrap();
    let fr = frames(21, 5, M);
    run_all(d, &fr);
    let n = d.detection_count();
    assert!(n >= 1 && n <= usize::from(top_k));
    let dets: Vec<_> = d.detections().collect();
    assert_eq!(dets.len(), n);
    let best = d.best().unwrap();
    assert_eq!(dets[0].score, best.merit);
    for (i, det) in dets.iter().enumerate() {
        let s = det.state();
        assert_eq!(s.len(), 4);
        let (x, y) = ((s[0] - 0.5) as usize, (s[1] - 0.5) as usize);
        assert_eq!(d.merit(x, y), Some(det.score));
        assert!(s[2].abs() <= 2.0 && s[3].abs() <= 2.0);
        assert_eq!(det.track.unwrap().id, i as u32);
        if i > 0 {
            assert!(det.score <= dets[i - 1].score);
            for o in &dets[..i] {
                let (ox, oy) = ((o.state()[0] - 0.5) as usize, (o.state()[1] - 0.5) as usize);
                assert!(
                    ox.abs_diff(x) > 1 || oy.abs_diff(y) > 1,
                    "ends not distinct"
                );
            }
        }
    }
    // the global best is the max over all pixels
    let max = (0..M * M)
        .map(|i| d.merit(i % M, i / M).unwrap())
        .fold(f32::MIN, f32::max);
    assert_eq!(best.merit, max);
    assert_eq!(
        d.best_within(usize::from(best.x), usize::from(best.y), 1)
            .unwrap()
            .merit,
        max
    );
}

#[test]
fn detections_are_the_distinct_best_ends() {
    for k in [1, 3, 8] {
        detections_are_consistent(&mut A9::new(cfg(Method::Arnold)).unwrap(), k);
        detections_are_consistent(&mut S9::new(cfg(Method::SecondOrder)).unwrap(), k);
        detections_are_consistent(&mut P9::new(cfg(Method::Pulford)).unwrap(), k);
    }
}

/// Pulford: every recovered step lies in `R_B`; the KF velocity of a straight track of
/// a bright target converges to the target's velocity.
#[test]
fn pulford_follows_a_bright_target() {
    type P = dp_tbd!(Pulford, 24, 9, 12);
    let mut d = P::new(cfg(Method::Pulford)).unwrap();
    let mut rng = Rng::seed_from_u64(4);
    for k in 0..12 {
        let mut z: Vec<f32> = (0..24 * 24).map(|_| 1.5 * rng.normal()).collect();
        let (x, y) = (3.2 + 0.9 * k as f32, 5.5 + 0.4 * k as f32);
        z[(y as usize) * 24 + x as usize] += 15.0;
        d.step(&z).unwrap();
    }
    let b = d.best().unwrap();
    assert_eq!((b.x, b.y), (13, 9));
    let mut t = [[0u16; 2]; 12];
    assert_eq!(d.track(13, 9, &mut t), 12);
    for (j, p) in t.iter().enumerate() {
        let k = 11 - j;
        let (x, y) = (3.2 + 0.9 * k as f32, 5.5 + 0.4 * k as f32);
        assert_eq!((p[0], p[1]), (x as u16, y as u16), "frame {k}");
    }
    let (f, age) = d.filter(13, 9).unwrap();
    assert_eq!(age, 11);
    // measurements are pixel indices (quantisation error up to 0.5 px, R = 1/12):
    // the filter's velocity is within 0.3 px/frame of the truth
    assert!(
        (f[2] - 0.9).abs() < 0.3 && (f[3] - 0.4).abs() < 0.3,
        "{f:?}"
    );
    let det = d.detection(0).unwrap();
    assert!((det.state()[2] - 0.9).abs() < 0.15, "{:?}", det.state());
}

fn small_frames() -> impl Strategy<Value = Vec<Vec<f32>>> {
    prop::collection::vec(
        prop::collection::vec((-64i32..=64).prop_map(|v| v as f32 * LSB * 4.0), M * M),
        1..=5,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Raising any pixel of any frame never lowers any merit (all three recursions).
    #[test]
    fn merits_are_monotone_in_the_input(
        fr in small_frames(),
        k in 0usize..5,
        at in 0..M * M,
        bump in 1i32..40,
    ) {
        let k = k % fr.len();
        let mut up = fr.clone();
        up[k][at] += bump as f32 * LSB;
        let mut a0 = A9::new(cfg(Method::Arnold)).unwrap();
        let mut a1 = A9::new(cfg(Method::Arnold)).unwrap();
        run_all(&mut a0, &fr);
        run_all(&mut a1, &up);
        let mut s0 = S9::new(cfg(Method::SecondOrder)).unwrap();
        let mut s1 = S9::new(cfg(Method::SecondOrder)).unwrap();
        run_all(&mut s0, &fr);
        run_all(&mut s1, &up);
        for (lo, hi) in merits(&a0).iter().zip(merits(&a1).iter()) {
            prop_assert!(hi >= lo);
        }
        for (lo, hi) in merits(&s0).iter().zip(merits(&s1).iter()) {
            prop_assert!(hi >= lo);
        }
    }

    /// Recovered tracks step inside `R_B` (second order: inside `R_I` too), start at the
    /// queried pixel and have `min(L, frames)` positions; Pulford tracks step inside `R_B`.
    #[test]
    fn recovered_tracks_stay_inside_the_windows(fr in small_frames(), at in 0..M * M) {
        let (x, y) = (at % M, at / M);
        let mut a = A25::new(cfg(Method::Arnold)).unwrap();
        let mut s = S9::new(cfg(Method::SecondOrder)).unwrap();
        let mut p = P9::new(cfg(Method::Pulford)).unwrap();
        run_all(&mut a, &fr);
        run_all(&mut s, &fr);
        run_all(&mut p, &fr);
        let mut t = [[0u16; 2]; 8];
        let n = a.track(x, y, &mut t);
        prop_assert_eq!(n, fr.len().min(4));
        prop_assert_eq!(t[0], [x as u16, y as u16]);
        for w in t[..n].windows(2) {
            prop_assert!(w[0][0].abs_diff(w[1][0]) <= 2 && w[0][1].abs_diff(w[1][1]) <= 2);
        }
        let n = s.track(x, y, &mut t);
        prop_assert_eq!(n, fr.len().min(4));
        for w in t[..n].windows(3) {
            let e = |c: usize| i32::from(w[2][c]) - (2 * i32::from(w[1][c]) - i32::from(w[0][c]));
            prop_assert!(e(0).abs() <= 1 && e(1).abs() <= 1);
        }
        for w in t[..n].windows(2) {
            prop_assert!(w[0][0].abs_diff(w[1][0]) <= 1 && w[0][1].abs_diff(w[1][1]) <= 1);
        }
        let n = p.track(x, y, &mut t);
        prop_assert!(n >= 1 && n <= fr.len().min(4));
        for w in t[..n].windows(2) {
            prop_assert!(w[0][0].abs_diff(w[1][0]) <= 1 && w[0][1].abs_diff(w[1][1]) <= 1);
        }
    }

    /// The same frames give the same bits, from a new detector and after `reset`.
    #[test]
    fn runs_are_deterministic(fr in small_frames()) {
        let mut p = P9::new(cfg(Method::Pulford)).unwrap();
        let r1 = run_all(&mut p, &fr);
        let m1 = merits(&p);
        p.reset(1);
        prop_assert_eq!(run_all(&mut p, &fr), r1);
        prop_assert_eq!(merits(&p), m1);
        let mut s = S25::new(cfg(Method::SecondOrder)).unwrap();
        let r1 = run_all(&mut s, &fr);
        let mut s2 = S25::new(cfg(Method::SecondOrder)).unwrap();
        prop_assert_eq!(run_all(&mut s2, &fr), r1);
    }
}

/// Static RAM of each type equals its documented formula (`dp::*_bytes`), on 32-bit
/// targets (the firmware prints the same sizes) and on this host.
#[test]
fn static_ram_equals_the_formulas() {
    use faint::detect::dp::{arnold_bytes, pulford_bytes, second_order_bytes};
    use std::mem::size_of;
    macro_rules! check {
        ($t:ident, $words:ident, $bytes:ident, $m:literal, $qb:literal, $l:literal, $c:ty) => {
            assert_eq!(
                size_of::<$t<$m, $qb, $l, { $words($m, $qb, $l) }, $c>>(),
                $bytes($m, $qb, $l, size_of::<$c>()),
                "{} M {} q_B {} L {} {}",
                stringify!($t),
                $m,
                $qb,
                $l,
                stringify!($c)
            );
        };
    }
    check!(ArnoldDp, arnold_words, arnold_bytes, 128, 9, 8, i16);
    check!(ArnoldDp, arnold_words, arnold_bytes, 128, 9, 8, i8);
    check!(ArnoldDp, arnold_words, arnold_bytes, 128, 25, 8, i16);
    check!(ArnoldDp, arnold_words, arnold_bytes, 12, 49, 3, i8);
    check!(PulfordDp, pulford_words, pulford_bytes, 128, 9, 8, i16);
    check!(PulfordDp, pulford_words, pulford_bytes, 16, 25, 5, i8);
    check!(
        SecondOrderDp,
        second_order_words,
        second_order_bytes,
        128,
        9,
        8,
        i16
    );
    check!(
        SecondOrderDp,
        second_order_words,
        second_order_bytes,
        128,
        9,
        8,
        i8
    );
    check!(
        SecondOrderDp,
        second_order_words,
        second_order_bytes,
        20,
        25,
        4,
        i16
    );
    check!(
        SecondOrderDp,
        second_order_words,
        second_order_bytes,
        12,
        9,
        2,
        i8
    );
    // The goal: the 128 x 128 second order with L = 8 in at most 512 KiB (with i8 merits).
    assert!(second_order_bytes(128, 9, 8, 1) <= 512 * 1024);
    assert!(second_order_bytes(128, 9, 6, 2) <= 512 * 1024);
    assert!(second_order_bytes(128, 9, 7, 2) > 512 * 1024);
}

/// `first_clamped` is the detectors' own clamping rule: on frames with pixels at, just
/// inside and just outside `+-ZMAX` LSB (1024 at `lsb = 1/16`), it flags exactly the
/// frames whose report counts clamped pixels, and the first such pixel. Regression: a
/// background of 3000 was clamped to 1024 silently, every merit equal, best end (0, 0).
#[test]
fn first_clamped_finds_the_pixels_the_quantiser_clamps() {
    let c = cfg(Method::Arnold);
    let lim = 16384.0 * c.lsb;
    let mut d = A9::new_unconfigured();
    d.configure(&c, 0).unwrap();
    let base = frames(41, 1, M).remove(0);
    let just_out = f32::from_bits(lim.to_bits() + 1);
    for (at, v, clamps) in [
        (3, lim, false),
        (3, -lim, false),
        (7, just_out, true),
        (M * M - 1, -just_out, true),
        (0, 3000.0, true),
        (5, 1e30, true),
    ] {
        let mut z = base.clone();
        z[at] = v;
        let r = d.step(&z).unwrap();
        assert_eq!(r.clamped > 0, clamps, "{v} at {at}");
        assert_eq!(first_clamped::<i16>(&c, &z), clamps.then_some(at), "{v}");
    }
    // The issue's case: every pixel 3000 (+ noise) is clamped; all are flagged.
    let bright: Vec<f32> = base.iter().map(|z| 3000.0 + z).collect();
    assert_eq!(first_clamped::<i16>(&c, &bright), Some(0));
    assert_eq!(d.step(&bright).unwrap().clamped as usize, M * M);
    assert_eq!(first_clamped::<i16>(&c, &base), None);
}
