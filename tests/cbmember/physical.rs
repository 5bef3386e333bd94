//! The default spread of `faint detect cbmember-doppler` on first-principles maps (the
//! physics simulator: slow-time pulses, Hamming window, FFT; not the filter's model).

use faint::detect::cbmember::{CbmemberConfig, Likelihood};
use faint::detect::Detector;
use faint::host::detect::{default_cbmember_file, normalise_frame};
use faint::host::instances::cbmember::HostFilter;
use faint::host::physics::cubes::Axis;
use faint::host::physics::maps::{MapPhysics, Rotor};
use faint::model::range_doppler::{PointModel, RdSpread};
use faint::rng::Rng;

/// Runs of 10 frames (a target at 20 dB peak-pixel SNR, random start and velocity over
/// the map, with `blades` rotor blades of eq. 11 or none): how many runs' last frame
/// reports a component within 2 cells (range, velocity) of the truth, the gate of
/// `faint evaluate`; and the reports outside that gate over frames 5-9 of every run.
fn hits(cfg: CbmemberConfig, runs: u64, blades: u32) -> (usize, usize) {
    let g = cfg.geometry;
    let mut p = MapPhysics::new(
        Axis {
            n: g.n_range,
            start: f64::from(g.range_start),
            size: f64::from(g.range_bin),
        },
        Axis {
            n: g.n_velocity,
            start: f64::from(g.velocity_start),
            size: f64::from(g.velocity_bin),
        },
    );
    if blades > 0 {
        p.rotor = Some(Rotor::rotor_uav(blades));
    }
    let (mut n, mut extra) = (0, 0);
    for seed in 1..=runs {
        let mut rng = Rng::from_stream(seed, 0);
        let (maps, truth) = p.simulate(10, Some(p.amplitude(20.0)), &mut rng);
        let mut f = Box::new(HostFilter::new(cfg, seed).unwrap());
        let mut hit = false;
        for (k, frame) in maps.chunks_exact(p.pixels()).enumerate() {
            let mut m = frame.to_vec();
            normalise_frame(&mut m).unwrap();
            f.step(&m).unwrap();
            let t = truth[k];
            let near: Vec<bool> = (0..f.detection_count())
                .filter_map(|i| f.detection(i))
                .map(|d| {
                    let dr = (f64::from(d.state()[0]) - t.range) / p.range.size;
                    let dv = p.wrap(f64::from(d.state()[1]) - t.velocity) / p.velocity.size;
                    dr.hypot(dv) <= 2.0
                })
                .collect();
            if k >= 5 {
                extra += near.iter().filter(|&&x| !x).count();
            }
            hit = near.iter().any(|&x| x);
        }
        n += usize::from(hit);
    }
    (n, extra)
}

/// The spread from the map's geometry (zeta_r 0.43 m, zeta_v 0.062 m/s for a Hamming
/// window over 512 pulses) finds the target in 10 of 10 runs (measured); the paper's
/// fixed spread (3 m, 5 m/s, blocked likelihood) in 3 of 10. Required: at least 8 and at
/// most 5 (`faint evaluate` measures Pd 1.00 for the default at 20 dB on these maps, and
/// at most 0.10 up to 30 dB for the fixed spread; the seeds are fixed).
#[test]
fn geometry_spread_detects_on_physical_maps_where_the_fixed_spread_does_not() {
    let file = default_cbmember_file(PointModel::DopplerOnly);
    let geometry = file.effective().unwrap();
    let mut fixed = geometry;
    fixed.spread = RdSpread {
        zeta_r: 3.0,
        zeta_v: 5.0,
    };
    fixed.likelihood = Likelihood::Blocked { bins: 16 };
    fixed.birth.range[1] = 1.5;
    let (a, b) = (hits(geometry, 10, 0).0, hits(fixed, 10, 0).0);
    eprintln!("runs detected of 10 at 20 dB: geometry spread {a}, fixed spread {b}");
    assert!(a >= 8, "geometry spread: {a} of 10");
    assert!(b <= 5, "fixed spread: {b} of 10");
}

/// Targets with two rotor blades (eq. 11), 10 runs per filter at 20 dB with the default
/// files: every run's last frame finds the body (measured 10 of 10 for both), and the
/// reports outside the gate over frames 5-9 stay rare (measured 4 for Doppler-only and
/// 13 for the joint filter over 50 frames; without blades, 20 runs, 6 and 12 per 100
/// frames: they are short-lived components born near the target, not the blades). Two
/// blades confirmed as targets would add up to two reports per frame; required: at
/// least 9 runs and at most 25 extra reports (0.5 per frame).
#[test]
fn blade_peaks_are_not_reported_as_extra_targets() {
    for model in [PointModel::DopplerOnly, PointModel::Joint] {
        let cfg = default_cbmember_file(model).effective().unwrap();
        let (n, extra) = hits(cfg, 10, 2);
        eprintln!("{model:?}: {n} of 10 runs found, {extra} reports outside the gate");
        assert!(n >= 9, "{model:?}: {n} of 10");
        assert!(extra <= 25, "{model:?}: {extra} extra reports");
    }
}

/// With `"spread": {"geometry": ..}` an edited `config.spread` is one line naming the
/// values for the geometry; `"spread": "config"` takes it as written; a bad range
/// resolution is refused.
#[test]
fn spread_settings_are_checked() {
    use faint::host::detect::SpreadFrom;
    let f = default_cbmember_file(PointModel::Joint);
    let mut g = f.clone();
    g.config.spread.zeta_v = 5.0;
    let e = g.effective().unwrap_err().to_string();
    assert!(
        e.contains("config.spread") && e.contains("zeta_v 0.12"),
        "{e}"
    );
    g.spread = SpreadFrom::Config;
    assert_eq!(g.effective().unwrap().spread.zeta_v, 5.0);
    let mut h = f.clone();
    if let SpreadFrom::Geometry(gs) = &mut h.spread {
        gs.range_resolution_m = 0.0;
    }
    let e = h.effective().unwrap_err().to_string();
    assert!(e.contains("range_resolution_m"), "{e}");
}
