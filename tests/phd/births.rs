//! `faint detect`'s default PHD configuration finds targets anywhere in the cube (not only
//! at the six-targets preset's birth points) and gives the same detections whatever the
//! input's power scale.

use faint::detect::phd::PhdConfig;
use faint::detect::Detector;
use faint::host::detect::{default_phd_file, normalise_frame};
use faint::host::instances::phd::HostFilter;
use faint::host::simulate::phd::{SixTargets, TargetSpec, TruthTarget, Variant};
use faint::rng::Rng;

/// The preset's three birth means (x, y) in m.
const PRESET_BIRTHS: [[f64; 2]; 3] = [[250.0, 1500.0], [1000.0, 1000.0], [1750.0, 500.0]];

/// One target with a random start (range 400-2600 m, azimuth 10-80 deg, speed 5-40 m/s,
/// any heading) at least 300 m from every preset birth mean, inside the cube for all
/// `frames` frames.
fn random_target(rng: &mut Rng, frames: usize) -> TargetSpec {
    loop {
        let r = 400.0 + 2200.0 * rng.uniform() as f64;
        let b = (10.0 + 70.0 * rng.uniform() as f64).to_radians();
        let s = 5.0 + 35.0 * rng.uniform() as f64;
        let h = std::f64::consts::TAU * rng.uniform() as f64;
        let init = [r * b.cos(), s * h.cos(), r * b.sin(), s * h.sin()];
        let far = PRESET_BIRTHS
            .iter()
            .all(|p| (p[0] - init[0]).hypot(p[1] - init[2]) > 300.0);
        let inside = (0..frames).all(|k| {
            let (x, y) = (init[0] + k as f64 * init[1], init[2] + k as f64 * init[3]);
            let (rr, bb) = (x.hypot(y), y.atan2(x).to_degrees());
            (100.0..2800.0).contains(&rr) && (3.0..87.0).contains(&bb)
        });
        if far && inside {
            return TargetSpec {
                appear: 1,
                disappear: frames,
                init,
            };
        }
    }
}

/// Frames of one run, the run's truth, and for each frame the estimates' `(x, y)`.
type Run = Vec<(Vec<TruthTarget>, Vec<[f32; 2]>)>;

/// Runs `cfg` on the scenario `sc` (cubes scaled by `scale`, then normalised when
/// `normalise`), seeds `seed`.
fn run(sc: &SixTargets, cfg: PhdConfig, seed: u64, scale: f32, normalise: bool) -> Run {
    let mut rng = Rng::seed_from_u64(seed);
    let truth = sc.truth(&mut rng);
    let mut f = Box::new(HostFilter::new(cfg, seed).unwrap());
    let mut cube = Vec::new();
    let mut out = Vec::new();
    for frame in &truth {
        sc.cube(frame, &mut rng, &mut cube);
        if scale != 1.0 {
            cube.iter_mut().for_each(|v| *v *= scale);
        }
        if normalise {
            normalise_frame(&mut cube).unwrap();
        }
        f.step(&cube).unwrap();
        let est = f
            .estimates()
            .iter()
            .map(|e| [e.state[0], e.state[2]])
            .collect();
        out.push((frame.clone(), est));
    }
    out
}

/// The target is found: an estimate within 50 m (the preset's OSPA cut-off) of it in at
/// least half of the frames after a 6-frame burn-in.
fn found(run: &Run) -> bool {
    let late = &run[6..];
    let hits = late
        .iter()
        .filter(|(t, est)| {
            t.iter().all(|t| {
                est.iter()
                    .any(|e| (e[0] as f64 - t.state[0]).hypot(e[1] as f64 - t.state[2]) <= 50.0)
            })
        })
        .count();
    2 * hits >= late.len()
}

fn scenario(rng: &mut Rng, frames: usize) -> SixTargets {
    let mut sc = SixTargets::new(9.0);
    sc.frames = frames;
    sc.targets = vec![random_target(rng, frames)];
    sc
}

/// Runs out of `runs` (targets from a fixed stream) in which the target is found.
fn share(variant: Variant, default: bool, runs: u64, frames: usize) -> u64 {
    let mut pos = Rng::seed_from_u64(20_260_001);
    let mut n = 0;
    for r in 0..runs {
        let sc = scenario(&mut pos, frames);
        let cfg = if default {
            default_phd_file(variant).effective().unwrap()
        } else {
            sc.config(variant)
        };
        let res = faint::host::montecarlo::on_worker_stack(move || run(&sc, cfg, r, 1.0, default));
        n += u64::from(found(&res));
    }
    n
}

/// Measured: the default configuration found the target in 8 of 8 runs, the preset's
/// fixed births (300 m or more away) in 0 of 8. Required: at least 6 of 8 and at most 2
/// of 8: the bound leaves room for two misses of a filter that, at 9 dB, finds a target
/// it has births for in nearly every run, and still fails the fixed-birth behaviour
/// (targets reachable only within ~60 m of a birth point).
#[test]
fn default_config_finds_targets_away_from_the_preset_birth_points() {
    let default = share(Variant::PhdTbd, true, 8, 15);
    let preset = share(Variant::PhdTbd, false, 8, 15);
    eprintln!("found: default births {default}/8, preset births {preset}/8");
    assert!(default >= 6, "default births found {default} of 8");
    assert!(preset <= 2, "preset births found {preset} of 8");
}

/// The same cubes multiplied by 10 and by 1e6 give the same detections after the noise
/// normalisation: same count every frame, positions within 1 m (the scaled cubes differ
/// from the originals by f32 rounding, one unit in the last place per cell, which the
/// filter's sums carry into its estimates at far below a metre).
#[test]
fn detections_do_not_depend_on_the_input_scale() {
    let mut pos = Rng::seed_from_u64(20_260_002);
    let sc = scenario(&mut pos, 12);
    let cfg = default_phd_file(Variant::PhdTbd).effective().unwrap();
    let base = {
        let sc = sc.clone();
        faint::host::montecarlo::on_worker_stack(move || run(&sc, cfg, 5, 1.0, true))
    };
    assert!(found(&base), "the reference run must detect the target");
    for scale in [10.0f32, 1.0e6] {
        let sc = sc.clone();
        let other = faint::host::montecarlo::on_worker_stack(move || run(&sc, cfg, 5, scale, true));
        for (k, ((_, a), (_, b))) in base.iter().zip(&other).enumerate() {
            assert_eq!(a.len(), b.len(), "scale {scale}, frame {k}");
            for (p, q) in a.iter().zip(b) {
                let d = (p[0] - q[0]).hypot(p[1] - q[1]);
                assert!(d <= 1.0, "scale {scale}, frame {k}: {p:?} vs {q:?}");
            }
        }
    }
}

/// The scale-free file refuses contradictions with one line naming the value, and a
/// frame without a noise level.
#[test]
fn scale_settings_refuse_contradictions() {
    use faint::host::detect::NoiseLevel as Noise;
    let f = default_phd_file(Variant::PhdTbd);
    assert!(f.effective().is_ok());
    let mut g = f.clone();
    g.config.noise_var = 1.0;
    let e = g.effective().unwrap_err().to_string();
    assert!(
        e.contains("config.noise_var") && e.contains("snr_db"),
        "{e}"
    );
    let mut g = f.clone();
    g.config.birth.intensity = [1.0, 2.0];
    let e = g.effective().unwrap_err().to_string();
    assert!(e.contains("config.birth.intensity"), "{e}");
    let mut g = f.clone();
    g.noise = Noise::AsIs;
    let e = g.effective().unwrap_err().to_string();
    assert!(e.contains("snr_db is only used"), "{e}");
    g.snr_db = None;
    assert!(
        g.effective().is_ok(),
        "as-is without snr_db takes the config as it is"
    );
    let mut g = f.clone();
    g.snr_db = None;
    assert!(g
        .effective()
        .unwrap_err()
        .to_string()
        .contains("needs snr_db"));
    for bad in [
        [f32::NAN, 1.0],
        [5.0, 4.0],
        [1.0, f32::INFINITY],
        [1.0, 300.0],
    ] {
        let mut g = f.clone();
        g.snr_db.as_mut().unwrap().birth = bad;
        let e = g.effective().unwrap_err().to_string();
        assert!(e.contains("snr_db.birth"), "{bad:?}: {e}");
    }
    let mut zero = vec![0.0f32; 101];
    zero[3] = 5.0;
    assert_eq!(normalise_frame(&mut zero), Err(0.0));
    assert_eq!(zero[3], 5.0, "a refused frame is unchanged");
    // Exponential powers of mean 4: the estimate is within 5 % (the median of n
    // exponentials of mean mu has standard deviation mu / sqrt(n), 1 % of the median
    // mu ln 2 at n = 20 001, so 5 % is 5 standard deviations).
    let mut rng = Rng::seed_from_u64(9);
    let mut v: Vec<f32> = (0..20_001).map(|_| 4.0 * rng.exponential()).collect();
    let n = normalise_frame(&mut v).unwrap();
    assert!((n / 4.0 - 1.0).abs() < 0.05, "{n}");
}

/// The region birth mode is validated: 1..=64 peaks, a finite non-negative tangential
/// spread; it needs no birth component.
#[test]
fn region_birth_mode_is_validated() {
    use faint::detect::phd::{BirthMode, MAX_REGION_CELLS};
    use faint::detect::Validate;
    let mut c = default_phd_file(Variant::PhdTbd).effective().unwrap();
    assert_eq!(c.birth.n_components, 0);
    assert!(c.validate().is_ok());
    for (cells, t) in [
        (0, 40.0),
        (MAX_REGION_CELLS + 1, 40.0),
        (8, -1.0),
        (8, f32::NAN),
    ] {
        c.birth.mode = BirthMode::Region {
            cells,
            tangential_std: t,
        };
        assert!(c.validate().is_err(), "{cells} {t}");
    }
    c.birth.mode = BirthMode::Gaussian;
    assert!(
        c.validate().is_err(),
        "the Gaussian mixture needs a component"
    );
}
