//! MHT-TBD core: censoring against a brute-force MSHT reference, detection of a clean
//! target, the classic baseline, quantisers, and bad input.

use faint::detect::mht::{ClassicHough, ClassicHoughConfig, Geometry, MhtConfig, MhtTbd, NO_PLOT};
use faint::detect::Detector;
use faint::model::plot::Plot;
use faint::rng::Rng;
use faint::Error;
use proptest::prelude::*;

type Small = MhtTbd<96, 12, 64, 45, 8>;

fn small_cfg() -> MhtConfig {
    let mut c = MhtConfig::sea_clutter();
    c.area = [0.0, 1500.0, 0.0, 1500.0];
    c.n_scans = 12;
    c.m = 3;
    c.gate = 100.0;
    c.gamma1 = 7;
    c
}

fn random_scan(rng: &mut Rng, n: usize, side: f32) -> Vec<Plot> {
    (0..n)
        .map(|_| {
            Plot::new(
                1.0,
                rng.uniform_range(0.0, side),
                rng.uniform_range(0.0, side),
            )
        })
        .collect()
}

/// Reference censoring, literally: per window of M scans, per cell, the plot set of each
/// scan (MSHT + Algorithm 1), the AND over the window (eq. 5), then chains of gated pairs
/// (eq. 6) through the cell's plot sets.
fn brute_force_effective(
    g: &Geometry<64, 45>,
    scans: &[Vec<Plot>],
    m: usize,
    gate: f32,
) -> Vec<Vec<bool>> {
    let mut eff: Vec<Vec<bool>> = scans.iter().map(|s| vec![false; s.len()]).collect();
    let q: Vec<Vec<(i32, i32)>> = scans
        .iter()
        .map(|s| s.iter().map(|p| g.quantise(p.x, p.y)).collect())
        .collect();
    for end in (m - 1)..scans.len() {
        let s0 = end + 1 - m;
        for a in 0..45 {
            for r in 0..64 {
                let sets: Vec<Vec<usize>> = (s0..=end)
                    .map(|s| {
                        (0..scans[s].len())
                            .filter(|&k| g.rho_index_q(q[s][k].0, q[s][k].1, a) == r)
                            .collect()
                    })
                    .collect();
                if sets.iter().any(|v| v.is_empty()) {
                    continue;
                }
                // forward reachability then backward
                let mut fwd: Vec<Vec<bool>> = sets.iter().map(|v| vec![false; v.len()]).collect();
                fwd[0].iter_mut().for_each(|f| *f = true);
                for j in 1..m {
                    for (ii, &k) in sets[j].iter().enumerate() {
                        fwd[j][ii] = sets[j - 1].iter().enumerate().any(|(pi, &pk)| {
                            fwd[j - 1][pi]
                                && scans[s0 + j - 1][pk].dist2(&scans[s0 + j][k]) <= gate * gate
                        });
                    }
                }
                let mut bwd: Vec<Vec<bool>> = sets.iter().map(|v| vec![false; v.len()]).collect();
                bwd[m - 1].iter_mut().for_each(|f| *f = true);
                for j in (0..m - 1).rev() {
                    for (ii, &k) in sets[j].iter().enumerate() {
                        bwd[j][ii] = sets[j + 1].iter().enumerate().any(|(ni, &nk)| {
                            bwd[j + 1][ni]
                                && scans[s0 + j][k].dist2(&scans[s0 + j + 1][nk]) <= gate * gate
                        });
                    }
                }
                for j in 0..m {
                    for (ii, &k) in sets[j].iter().enumerate() {
                        if fwd[j][ii] && bwd[j][ii] {
                            eff[s0 + j][k] = true;
                        }
                    }
                }
            }
        }
    }
    eff
}

#[test]
fn censoring_matches_brute_force_msht() {
    // Dense enough that chains, shared cells and multi-successor pairs all occur:
    // 60 plots per scan on 1.5 km x 1.5 km puts ~0.8 plots within the 100 m gate.
    let mut rng = Rng::seed_from_u64(41);
    let mut total_eff = 0;
    for trial in 0..6 {
        let mut det = Box::new(Small::new(small_cfg()).unwrap());
        let mut scans = Vec::new();
        for s in 0..12 {
            let mut plots = random_scan(&mut rng, 60, 1500.0);
            // one straight target so true chains exist
            plots.push(Plot::new(
                5.0,
                200.0 + 60.0 * s as f32,
                300.0 + 40.0 * s as f32,
            ));
            scans.push(plots);
        }
        for sc in &scans {
            det.step(sc).unwrap();
        }
        let reference = brute_force_effective(det.msht_geometry(), &scans, 3, 100.0);
        for (s, sc) in scans.iter().enumerate() {
            for k in 0..sc.len() {
                assert_eq!(
                    det.is_effective(s, k),
                    reference[s][k],
                    "trial {trial} scan {s} plot {k}"
                );
                total_eff += usize::from(reference[s][k]);
            }
        }
    }
    assert!(
        total_eff > 100,
        "the comparison must exercise effective plots: {total_eff}"
    );
}

#[test]
fn clean_target_is_detected_with_its_plots() {
    let mut det = Box::new(Small::new(small_cfg()).unwrap());
    let mut rng = Rng::seed_from_u64(7);
    let mut report = None;
    for s in 0..12 {
        let mut plots = random_scan(&mut rng, 5, 1500.0);
        plots.push(Plot::new(
            9.0,
            300.0 + 70.0 * s as f32 + 3.0 * rng.normal(),
            900.0 - 30.0 * s as f32 + 3.0 * rng.normal(),
        ));
        let r = det.step(&plots).unwrap();
        assert_eq!(r.scan_in_period as usize, s);
        report = r.detection;
    }
    let d = report.expect("period complete after 12 scans");
    assert!(d.tracks >= 1, "{d:?}");
    let tr = &det.tracks()[0];
    // target plot is the last of each scan
    let own = (0..12)
        .filter(|&s| {
            tr.plots[s] != NO_PLOT && usize::from(tr.plots[s]) == det.scan_plots(s).len() - 1
        })
        .count();
    assert!(own >= 11, "track holds {own} of 12 target plots");
}

#[test]
fn classic_detects_a_line_and_reports_each_period() {
    let cfg = ClassicHoughConfig {
        area: [0.0, 1500.0, 0.0, 1500.0],
        n_scans: 10,
        gamma: 9,
    };
    let mut c = Box::new(ClassicHough::<64, 90, 8>::new(cfg).unwrap());
    for period in 0..2 {
        for s in 0..10 {
            let p = [Plot::new(1.0, 100.0 + 100.0 * s as f32, 700.0)];
            let r = c.step(&p).unwrap();
            assert_eq!(r.period_complete, s == 9, "period {period}");
        }
        assert_eq!(c.peaks().len(), 1);
        assert_eq!(c.peaks()[0].raw, 10);
    }
}

#[test]
fn quantisers_agree_away_from_cell_edges() {
    let g = Geometry::<256, 180>::for_area([0.0, 6000.0, 0.0, 6000.0]);
    let mut rng = Rng::seed_from_u64(3);
    let mut differ = 0;
    let n = 20_000;
    for _ in 0..n {
        let (x, y) = (
            rng.uniform_range(0.0, 6000.0),
            rng.uniform_range(0.0, 6000.0),
        );
        let a = rng.below(180) as usize;
        let (xq, yq) = g.quantise(x, y);
        let (i, f) = (g.rho_index_q(xq, yq, a), g.rho_index_f32(x, y, a));
        if i != f {
            differ += 1;
            assert!(i.abs_diff(f) == 1);
            // must be a boundary case: within 0.5 m of an edge
            let u = (g.rho(x, y, a) + g.rho_max()) / g.drho();
            assert!((u - u.round()).abs() * g.drho() < 0.5, "u = {u}");
        }
    }
    // 0.5 m / 33 m cells: at most a few percent of points sit that close to an edge
    assert!(differ < n / 50, "{differ}");
}

#[test]
fn bad_config_is_rejected() {
    let mut c = small_cfg();
    c.n_scans = 0;
    assert_eq!(Small::new(c).unwrap_err(), Error::InvalidConfig("n_scans"));
    let mut c = small_cfg();
    c.n_scans = 13; // > NS
    assert!(Small::new(c).is_err());
    let mut c = small_cfg();
    c.m = 2;
    assert_eq!(Small::new(c).unwrap_err(), Error::InvalidConfig("m"));
    let mut c = small_cfg();
    c.area = [0.0, f32::NAN, 0.0, 1.0];
    assert_eq!(Small::new(c).unwrap_err(), Error::InvalidConfig("area"));
    let mut c = small_cfg();
    c.gate = -1.0;
    assert!(Small::new(c).is_err());
}

#[test]
fn bad_plots_are_counted_not_fatal() {
    let mut det = Box::new(Small::new(small_cfg()).unwrap());
    let mut plots = vec![
        Plot::new(1.0, f32::NAN, 10.0),
        Plot::new(1.0, 10.0, f32::INFINITY),
        Plot::new(1.0, -5.0, 10.0),
        Plot::new(1.0, 10.0, 1e9),
        Plot::new(f32::NAN, 10.0, 10.0),
    ];
    plots.extend((0..120).map(|i| Plot::new(1.0, 10.0 * i as f32, 20.0)));
    let r = det.step(&plots).unwrap();
    assert_eq!(r.invalid, 5);
    assert_eq!(r.overflow, 120 - 96);
    assert_eq!(r.plots_kept, 96);
}

#[test]
fn degenerate_geometry_all_plots_at_one_point() {
    let mut det = Box::new(Small::new(small_cfg()).unwrap());
    let mut last = None;
    for _ in 0..12 {
        let plots = vec![Plot::new(1.0, 700.0, 700.0); 4];
        last = det.step(&plots).unwrap().detection;
    }
    let d = last.unwrap();
    assert_eq!(d.effective_plots, 48);
    assert!(d.drho.is_finite() && d.drho > 0.0);
    assert!(d.tracks >= 1);
    for tr in det.tracks() {
        assert!(tr.c.is_finite() && tr.theta.is_finite());
    }
}

#[test]
fn empty_scans_give_empty_reports() {
    let mut det = Box::new(Small::new(small_cfg()).unwrap());
    for s in 0..24 {
        let r = det.step(&[]).unwrap();
        if s % 12 == 11 {
            let d = r.detection.unwrap();
            assert_eq!((d.effective_plots, d.tracks), (0, 0));
        } else {
            assert!(r.detection.is_none());
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn never_panics_and_tracks_are_valid(
        seed in any::<u64>(),
        n in 0usize..140,
        junk in prop::collection::vec((any::<f32>(), any::<f32>()), 0..6),
    ) {
        let mut det = Box::new(Small::new(small_cfg()).unwrap());
        let mut rng = Rng::seed_from_u64(seed);
        for s in 0..12 {
            let mut plots = random_scan(&mut rng, n, 1500.0);
            plots.extend(junk.iter().map(|&(x, y)| Plot::new(1.0, x, y)));
            let r = det.step(&plots).unwrap();
            prop_assert_eq!(u32::from(r.plots_kept) + r.invalid + r.overflow, r.plots_in);
            if s == 11 {
                prop_assert!(r.detection.is_some());
            }
        }
        for tr in det.tracks() {
            for s in 0..12 {
                let k = tr.plots[s];
                prop_assert!(k == NO_PLOT || usize::from(k) < det.scan_plots(s).len());
            }
            prop_assert!(tr.n_plots >= small_cfg().min_track_plots);
        }
    }
}

/// `redetect(g)` on a completed period equals a detector configured with `gamma_1 = g`
/// fed the same scans (the calibration in `reproduce mht --gamma-from sim` relies on it),
/// for every `g` and over periods with targets, clutter chains and confirmed tracks.
#[test]
fn redetect_equals_a_detector_configured_with_that_gamma() {
    let mut rng = Rng::seed_from_u64(31);
    let mut base = Box::new(Small::new(small_cfg()).unwrap());
    assert_eq!(
        base.redetect(5).unwrap_err(),
        Error::InvalidConfig("no completed period")
    );
    let mut with_tracks = 0;
    for period in 0..6 {
        let scans: Vec<Vec<Plot>> = (0..12)
            .map(|s| {
                let mut plots = random_scan(&mut rng, 40 + 10 * period, 1500.0);
                for t in 0..3 {
                    if rng.uniform() < 0.9 {
                        plots.push(Plot::new(
                            9.0,
                            200.0 + 400.0 * t as f32 + 60.0 * s as f32 + 5.0 * rng.normal(),
                            1300.0 - 250.0 * t as f32 - 40.0 * s as f32 + 5.0 * rng.normal(),
                        ));
                    }
                }
                plots
            })
            .collect();
        for (s, p) in scans.iter().enumerate() {
            base.step(p).unwrap();
            if s < 11 {
                assert!(base.redetect(5).is_err(), "mid-period redetect must fail");
            }
        }
        assert_eq!(
            base.redetect(0).unwrap_err(),
            Error::InvalidConfig("gamma1")
        );
        for g in (1..=13u8).rev() {
            let mut cfg = small_cfg();
            cfg.gamma1 = g;
            let mut fresh = Box::new(Small::new(cfg).unwrap());
            let mut want = None;
            for p in &scans {
                want = fresh.step(p).unwrap().detection;
            }
            let got = base.redetect(g).unwrap();
            assert_eq!(Some(got), want, "period {period} gamma {g}");
            assert_eq!(base.tracks().len(), fresh.tracks().len());
            for (a, b) in base.tracks().iter().zip(fresh.tracks()) {
                assert_eq!(a.plots, b.plots);
                assert_eq!(a.peak, b.peak);
                assert_eq!(a.theta.to_bits(), b.theta.to_bits());
                assert_eq!(a.c.to_bits(), b.c.to_bits());
                assert_eq!(
                    (a.n_plots, a.n_effective, a.lookback),
                    (b.n_plots, b.n_effective, b.lookback)
                );
            }
            with_tracks += usize::from(!base.tracks().is_empty());
        }
        // the configured gamma_1 is unchanged
        assert_eq!(base.config().gamma1, 7);
    }
    // the comparison covered confirmed tracks, not only empty periods
    assert!(with_tracks >= 20, "{with_tracks}");
}
