//! One regression test per configuration or input that validated but then panicked
//! (with overflow checks on), hung, lost a frame, or reported NaN/inf. Each test states
//! the finding; the fix is either a validation range derived from what the arithmetic
//! holds (the test checks the typed error) or a documented recovery (the test runs the
//! detector and checks its outputs are finite).

use faint::detect::crpf::{CrpfConfig, CrpfTbd};
use faint::detect::jott::JottTbd;
use faint::detect::mht::censoring::Censor;
use faint::detect::mht::{ClassicHoughConfig, Geometry, MhtConfig, MAX_DRHO_MIN};
use faint::detect::pf_lrt::PfLrt;
use faint::detect::pf_tbd::{GaussConfig, PfTbd};
use faint::detect::phd::{Dbscan, DbscanParams, Extractor, MAX_GENERATIONS, MAX_INTENSITY};
use faint::detect::{Detector, Validate};
use faint::host::instances::mht::Mht;
use faint::host::instances::phd::HostFilter;
use faint::host::reliability::check_outputs;
use faint::host::reliability::targets::small_phd;
use faint::host::simulate::phd::Variant;
use faint::model::doppler::{check_frame, estimate_noise_variance};
use faint::model::plot::Plot;
use faint::rng::Rng;
use faint::{Complex32, Error};

/// Runs `f` on a thread with a 256 MB stack (the host filters are large values).
fn big_stack<T: Send + 'static>(f: impl FnOnce() -> T + Send + 'static) -> T {
    faint::host::montecarlo::on_worker_stack(f)
}

fn noise(rng: &mut Rng, m: usize, s: f32) -> Vec<Complex32> {
    (0..m)
        .map(|_| Complex32::new(s * rng.normal(), s * rng.normal()))
        .collect()
}

/// Steps `det` through `frames`, asserting that every accepted frame's outputs are
/// finite (and existences in `[0, 1]`).
fn clean<D, T>(det: &mut D, frames: &[Vec<T>])
where
    D: Detector<Frame = [T]>,
    D::Report: std::fmt::Debug,
{
    for (k, f) in frames.iter().enumerate() {
        if let Ok(r) = det.step(f) {
            assert_eq!(check_outputs(det, &r), None, "frame {k}");
        }
    }
}

#[test]
fn doppler_sample_interval_and_jitter_near_f32_max_are_rejected() {
    // ts = 1e30 used to reach `(b as i64 - 2)` with b = i64::MIN (overflow panic).
    let mut c = CrpfConfig::othr();
    c.model.ts = 1e30;
    assert!(matches!(c.validate(), Err(Error::InvalidConfig(_))));
    let mut c = CrpfConfig::othr();
    c.jitter_std = [1e30; 3];
    assert!(matches!(c.validate(), Err(Error::InvalidConfig(f)) if f.contains("jitter")));
    // The far-out Doppler path itself no longer overflows: a Doppler of 3e38 Hz.
    let m =
        faint::model::doppler::DopplerModel::new(32, 0.02, faint::model::doppler::Window::Hamming)
            .unwrap();
    let z = vec![Complex32::new(1.0, 0.0); 32];
    for fd in [3e38, -3e38, f32::MAX, -f32::MAX, 1e20] {
        let p = m.project(&z, fd, 1.0);
        assert!(p.hh.is_finite(), "fd {fd}");
    }
}

#[test]
fn prior_boxes_outside_the_band_and_huge_amplitudes_are_rejected() {
    // A prior Doppler box of (-3e38, 3e38) made every Doppler-frame estimate NaN; one of
    // +-1e6 Hz gave estimates far outside the band (the wrap corrected one width only).
    for fd in [(-3e38, 3e38), (-1e6, 1e6), (-25.0, 26.0)] {
        let mut c = CrpfConfig::othr();
        c.model.prior.fd = fd;
        assert!(
            matches!(c.validate(), Err(Error::InvalidConfig(f)) if f.contains("Doppler")),
            "{fd:?}"
        );
        let mut g = GaussConfig::othr(1.0);
        g.model.prior.fd = fd;
        assert!(g.validate().is_err(), "{fd:?}");
    }
    // amp_std = 1e38 gave an infinite amplitude estimate.
    let mut g = GaussConfig::othr(1.0);
    g.model.amp_std = 1e38;
    assert!(g.validate().is_err());
    let mut g = GaussConfig::othr(1.0);
    g.model.prior.amp = (0.0, 1e30);
    assert!(g.validate().is_err());
    // The preset's box edges are inside the band (closed interval).
    assert!(CrpfConfig::othr().validate().is_ok());
}

#[test]
fn doppler_wrap_brings_any_finite_doppler_into_the_band() {
    let c = CrpfConfig::othr();
    let mut det = CrpfTbd::<256>::new(c, 3).unwrap();
    // The largest Doppler rate and process noise the validation accepts, so that
    // particles move several band widths: estimates must stay inside the band.
    let mut c2 = c;
    c2.model.prior.fda = (-78.0, 78.0);
    c2.jitter_std = [50.0, 78.0, 0.02];
    det.configure(&c2, 3).unwrap();
    let mut rng = Rng::seed_from_u64(4);
    for _ in 0..50 {
        let r = det.step(&noise(&mut rng, 32, 1.0)).unwrap();
        assert_eq!(check_outputs(&det, &r), None);
        if let Some(e) = r.estimate {
            assert!((-25.0..25.0).contains(&e[0]), "{e:?}");
        }
    }
}

#[test]
fn pf_lrt_log_likelihood_ratio_saturates() {
    // A tiny noise variance and strong frames drove the cumulative log-LR to +inf.
    let g = GaussConfig::othr(1e-30);
    let mut det = PfLrt::<256>::new(g, 1).unwrap();
    let mut rng = Rng::seed_from_u64(5);
    let frames: Vec<Vec<Complex32>> = (0..400).map(|_| noise(&mut rng, 32, 1e10)).collect();
    clean(&mut det, &frames);
    let mut pf = PfTbd::<256>::new(g, 1).unwrap();
    clean(&mut pf, &frames);
    let mut jott = JottTbd::<256>::new(g, 1).unwrap();
    clean(&mut jott, &frames);
}

#[test]
fn one_huge_finite_bin_is_an_overflow_not_a_non_finite_input() {
    let mut z = vec![Complex32::new(0.1, 0.0); 32];
    z[7].re = 1e30;
    assert_eq!(check_frame(&z, 32), Err(Error::Overflow));
    let a = vec![Complex32::new(1e19, 1e19); 32];
    assert_eq!(
        estimate_noise_variance([a.as_slice(), a.as_slice()], 32),
        Err(Error::Overflow)
    );
    let mut det = CrpfTbd::<256>::new(CrpfConfig::othr(), 1).unwrap();
    assert_eq!(det.step(&z).err(), Some(Error::Overflow));
}

#[test]
fn phd_birth_windows_near_f32_max_do_not_overflow() {
    // A birth std of 1e21 (or a range cell of 1e-30) overflowed `h as usize + 1` in the
    // measurement-driven birth window (82 of 1389 random valid configs).
    big_stack(|| {
        let mut rng = Rng::seed_from_u64(6);
        let mut cfgs = Vec::new();
        let mut c = small_phd(Variant::PsoDbscan);
        for comp in c.birth.components.iter_mut() {
            comp.std = [1e21; 4];
        }
        cfgs.push(c);
        let mut c = small_phd(Variant::PhdTbd);
        c.geometry.range_cell = 1e-30;
        cfgs.push(c);
        let base = small_phd(Variant::PhdTbd);
        let mut det = Box::new(HostFilter::new(base, 0).unwrap());
        let mut accepted = 0;
        for c in cfgs {
            match det.configure(&c, 1) {
                Ok(()) => accepted += 1,
                Err(e) => {
                    assert!(matches!(e, Error::InvalidConfig(_)), "{e:?}");
                    continue;
                }
            }
            let n = c.geometry.n_range * c.geometry.n_doppler * c.geometry.n_azimuth;
            let frames: Vec<Vec<f32>> = (0..3)
                .map(|_| (0..n).map(|_| rng.exponential()).collect())
                .collect();
            clean(det.as_mut(), &frames);
        }
        // The huge birth spread validates (it is a legal, if useless, prior).
        assert!(accepted >= 1);
    });
}

#[test]
fn swarm_and_kmeans_iterations_are_bounded() {
    // generations = 1e5 took 6 s a frame; usize::MAX hung.
    for g in [MAX_GENERATIONS + 1, 100_000, usize::MAX] {
        let mut c = small_phd(Variant::PsoKMeans);
        c.pso.as_mut().unwrap().generations = g;
        assert!(c.validate().is_err(), "generations {g}");
        let mut c = small_phd(Variant::PsoKMeans);
        c.pso.as_mut().unwrap().max_generations = g;
        assert!(c.validate().is_err(), "max_generations {g}");
        let mut c = small_phd(Variant::PsoKMeans);
        c.extractor = Extractor::KMeans { max_iter: g };
        assert!(c.validate().is_err(), "max_iter {g}");
    }
    let mut c = small_phd(Variant::PsoKMeans);
    c.pso.as_mut().unwrap().max_generations = MAX_GENERATIONS;
    assert!(c.validate().is_ok());
}

/// Brute-force DBSCAN labels, canonicalised as the list of clusters (sorted members).
fn brute_clusters(pts: &[[f32; 2]], eps: f32, min_pts: usize) -> Vec<Vec<u32>> {
    let n = pts.len();
    let near = |i: usize, j: usize| {
        let (dx, dy) = (pts[i][0] - pts[j][0], pts[i][1] - pts[j][1]);
        dx * dx + dy * dy <= eps * eps
    };
    let core: Vec<bool> = (0..n)
        .map(|i| (0..n).filter(|&j| near(i, j)).count() >= min_pts)
        .collect();
    let mut label = vec![-1i64; n];
    let mut out = Vec::new();
    for p in 0..n {
        if label[p] >= 0 || !core[p] {
            continue;
        }
        let id = out.len() as i64;
        let mut members = vec![p as u32];
        label[p] = id;
        let mut q = vec![p];
        while let Some(a) = q.pop() {
            if !core[a] {
                continue;
            }
            for (b, l) in label.iter_mut().enumerate() {
                if *l < 0 && near(a, b) {
                    *l = id;
                    members.push(b as u32);
                    q.push(b);
                }
            }
        }
        members.sort_unstable();
        out.push(members);
    }
    out.sort();
    out
}

#[test]
fn dbscan_with_a_tiny_eps_against_a_wide_spread_is_exact_not_an_error() {
    // eps = 1e-9 validated, then `step` failed ("extent over 4e9 eps") after the filter
    // had already advanced, losing the frame's report. Now the grid coarsens and the
    // clustering stays exact: checked against brute force.
    let mut rng = Rng::seed_from_u64(7);
    let mut db = Box::new(Dbscan::<512>::new());
    for trial in 0..20 {
        let spread = [1e3f32, 1e9, 1e20, 3e38][trial % 4];
        let eps = [1e-9f32, 1e-3, 1.0, 50.0][trial / 5 % 4];
        let mut pts: Vec<[f32; 2]> = Vec::new();
        for _ in 0..40 {
            let c = [rng.uniform() * spread, rng.uniform() * spread];
            for _ in 0..1 + rng.below(6) {
                pts.push([
                    c[0] + eps * 0.3 * rng.normal(),
                    c[1] + eps * 0.3 * rng.normal(),
                ]);
            }
        }
        let p = DbscanParams { eps, min_pts: 3 };
        let mut got = Vec::new();
        db.run(&pts, &p, |m| {
            let mut m = m.to_vec();
            m.sort_unstable();
            got.push(m);
        })
        .unwrap();
        got.sort();
        assert_eq!(got, brute_clusters(&pts, eps, 3), "trial {trial}");
    }
}

#[test]
fn gamma1_above_the_scan_count_plus_one_is_rejected() {
    let mut c = MhtConfig::sea_clutter();
    c.gamma1 = (c.n_scans + 2) as u8;
    assert_eq!(c.validate(), Err(Error::InvalidConfig("gamma1")));
    c.gamma1 = 255;
    assert_eq!(c.validate(), Err(Error::InvalidConfig("gamma1")));
    // n_scans + 1 is the documented "no confirmation" setting the calibration uses.
    c.gamma1 = (c.n_scans + 1) as u8;
    assert!(c.validate().is_ok());
    c.gamma1 = c.n_scans as u8;
    assert!(c.validate().is_ok());
}

#[test]
fn areas_near_f32_max_are_rejected() {
    // Hough areas near f32::MAX gave an infinite origin.
    let mut c = MhtConfig::sea_clutter();
    c.area = [-3e38, 3e38, -1.0, 1.0];
    assert!(c.validate().is_err());
    let mut h = faint::host::detect::default_classic();
    h.area = [0.0, 2e18, 0.0, 1.0];
    assert!(<ClassicHoughConfig as Validate>::validate(&h).is_err());
    h.area = [0.0, 1e18, 0.0, 1e18];
    assert!(<ClassicHoughConfig as Validate>::validate(&h).is_ok());
    let g = Geometry::<256, 180>::for_area(h.area);
    assert!(g.rho_max().is_finite() && g.origin().0.is_finite());
}

#[test]
fn public_hough_functions_are_total() {
    // Geometry::rho, rho_index_q and trig indexed past the angle count; Censor::step
    // trusted its m and flags.
    let g = Geometry::<64, 16>::for_area([0.0, 100.0, 0.0, 100.0]);
    for a in [16, 17, usize::MAX] {
        assert!(g.rho(1.0, 2.0, a).is_finite());
        assert_eq!(g.trig(a), (1.0, 0.0));
        assert!(g.rho_index_q(i32::MAX, i32::MIN, a) < 64);
    }
    assert!(g.rho_index_q(i32::MIN, i32::MAX, 3) < 64);
    let mut c = Box::new(Censor::<8>::new());
    let a = [Plot::new(1.0, 1.0, 1.0); 4];
    let scans: [&[Plot]; 3] = [&a, &a, &a];
    let mut flags = [[0u8; 8]; 3];
    for m in [0, 1, 2, 9, usize::MAX] {
        let st = c.step(&g, &scans, &mut flags, 2, m, 10.0);
        assert_eq!(st.chains, 0, "m {m}");
    }
    let mut short = [[0u8; 8]; 1];
    let _ = c.step(&g, &scans, &mut short, 2, 3, 10.0);
    let _ = c.step(&g, &scans, &mut flags, 2, 3, f32::NAN);
    for s in 0..3 {
        let _ = c.step(&g, &scans, &mut flags, s, 3, 10.0);
    }
    assert!(flags.iter().flatten().any(|f| *f != 0));
}

#[test]
fn track_recovery_with_fewer_flag_rows_than_scans_is_total() {
    // `dmht::recover` indexed `flags[s]` for every scan: fewer flag rows than scans
    // panicked (found by the `panic-never-mht` link check). The scans without a flag row
    // are now not associated.
    use faint::detect::mht::dmht::{recover, Assoc};
    use faint::detect::mht::{Peak, Track, NO_PLOT};
    let g = Geometry::<64, 16>::for_area([0.0, 100.0, 0.0, 100.0]);
    let a = [Plot::new(1.0, 50.0, 50.0); 4];
    let scans: [&[Plot]; 3] = [&a, &a, &a];
    let flags = [[1u8; 8]; 1];
    let assoc = Assoc {
        d_max: 200.0,
        along_gate: 200.0,
        lookback: true,
    };
    let mut tr = Track::<3>::default();
    recover::<64, 16, 8, 3>(&g, Peak::default(), &scans, &flags, &assoc, &mut tr);
    assert_eq!(tr.plots[1..], [NO_PLOT, NO_PLOT]);
    assert!(tr.n_plots <= 1);
}

#[test]
fn swarm_run_with_len_past_its_capacity_is_total() {
    // `Swarm::len` is public: set past the parent capacity `S / 2`, `run` wrote children
    // past `S` (index out of bounds; found by the `panic-never-phd` link check). It now
    // runs on the first `S / 2` parents; `best_objective` past `S` is objective 0.
    use faint::detect::phd::pso::{PsoConfig, Swarm};
    let mut sw = Swarm::<8, 2>::new();
    for i in 0..4u32 {
        assert!(sw.push([i as f32, 0.0], 0.25, i, 0));
    }
    assert!(!sw.push([9.0, 9.0], 0.25, 9, 0));
    sw.len = 8;
    let mut rng = Rng::seed_from_u64(1);
    let r = sw.run(&PsoConfig::paper(), &[[1.0, 0.0], [2.0, 0.0]], &mut rng);
    assert_eq!(r.generations, PsoConfig::paper().generations);
    assert!(sw.pos.iter().all(|p| p.iter().all(|v| v.is_finite())));
    assert_eq!(sw.best_objective(99, 2), (0, f32::NEG_INFINITY));
}

#[test]
fn censoring_with_a_gate_wider_than_the_area_is_bounded() {
    // A gate of 1e10 m with m = 6 made every pair of plots a candidate and the chain
    // search visit up to P^5 partial chains (2.9 s for one scan; fuzz corpus
    // `mht-slow-935-0.json`); the budget of completed chains did not bound the partial
    // ones. The search now stops after NODE_BUDGET_PER_PLOT * P partial chains.
    use faint::detect::mht::censoring::NODE_BUDGET_PER_PLOT;
    let g = Geometry::<256, 180>::for_area([0.0, 6000.0, 0.0, 6000.0]);
    let mut rng = Rng::seed_from_u64(8);
    // 64 plots per scan in a capacity of 256: 256 gated pairs per scan, about four
    // continuations per partial chain. The sixth scan is empty, so no chain completes
    // (the chain budget never binds) while the window holds 256 + 1024 + 4096 + 16384
    // partial chains, more than the node budget of 64 * 256.
    const P: usize = 256;
    let scans: Vec<Vec<Plot>> = (0..6)
        .map(|k| {
            let n = if k == 5 { 0 } else { 64 };
            (0..n)
                .map(|_| Plot::new(1.0, 6000.0 * rng.uniform(), 6000.0 * rng.uniform()))
                .collect()
        })
        .collect();
    let refs: Vec<&[Plot]> = scans.iter().map(|s| s.as_slice()).collect();
    let mut flags = vec![[0u8; P]; 6];
    let mut c = Box::new(Censor::<P>::new());
    let mut last = Default::default();
    for s in 0..6 {
        last = c.step(&g, &refs, &mut flags, s, 6, 1e10);
    }
    assert_eq!(last.chains, 0);
    assert!(last.chain_overflow > 0, "the node budget never engaged");
    assert!(NODE_BUDGET_PER_PLOT * (P as u32) < 256 + 1024 + 4096 + 16384);
}

#[test]
fn mht_rho_floor_near_f32_max_is_rejected_and_the_grid_is_finite() {
    // Coverage-guided finding: `drho_min = 3e38` validated, and a period whose plots sit
    // at one point took the floor as the rho half-range: the cell `2 rho_max / R` was inf.
    let mut c = MhtConfig::sea_clutter();
    c.drho_min = 3e38;
    assert_eq!(c.validate(), Err(Error::InvalidConfig("drho_min")));
    c.drho_min = f32::INFINITY;
    assert!(c.validate().is_err());
    // The largest accepted floor, on a period of plots at one point (degenerate geometry).
    c.drho_min = MAX_DRHO_MIN;
    c.n_scans = 4;
    c.gamma1 = 3;
    big_stack(move || {
        let mut det = Box::new(Mht::new(c).unwrap());
        let scan = [Plot::new(10.0, 10.0, 1.0); 3];
        let mut periods = 0;
        for _ in 0..8 {
            let r = det.step(&scan[..]).unwrap();
            assert_eq!(check_outputs(det.as_ref(), &r), None);
            if let Some(p) = r.detection {
                assert!(p.drho.is_finite() && p.drho > 0.0, "{p:?}");
                periods += 1;
            }
        }
        assert_eq!(periods, 2);
    });
    // The public grid caps any half-range so its cell stays finite.
    for r in [3e38, f32::MAX, f32::INFINITY] {
        let g = Geometry::<64, 16>::new(0.0, 0.0, r);
        assert!(g.drho().is_finite() && g.rho_max().is_finite(), "{r}");
    }
}

#[test]
fn phd_intensities_past_the_cap_are_rejected_and_estimates_stay_finite() {
    // Coverage-guided finding: a birth intensity window `[11.9, 3e38]` validated, and the
    // first frame's K-means estimate summed two intensities near 3e38: inf.
    big_stack(|| {
        let mut c = small_phd(Variant::PhdTbd);
        c.birth.intensity = [11.9, 3e38];
        assert!(c.validate().is_err());
        let mut m = small_phd(Variant::PhdTbd);
        m.min_intensity = 2e28;
        assert!(m.validate().is_err());
        // At the cap, with the intensity noise pushing past it every frame.
        c.birth.intensity = [MAX_INTENSITY; 2];
        c.q_intensity = 1e38;
        let mut det = Box::new(HostFilter::new(c, 0).unwrap());
        let mut rng = Rng::seed_from_u64(7);
        let n = c.geometry.n_range * c.geometry.n_doppler * c.geometry.n_azimuth;
        let frames: Vec<Vec<f32>> = (0..6)
            .map(|_| (0..n).map(|_| 1e30 * rng.exponential()).collect())
            .collect();
        clean(det.as_mut(), &frames);
    });
}

#[test]
fn non_dominated_sort_with_nan_values_terminates() {
    // Coverage-guided finding (PSO-PHD-TBD with DBSCAN, SIGSEGV after 128 369 inputs, no
    // libFuzzer report): a swarm position that overflowed gave a NaN fitness, the pivot of
    // the divide-and-conquer sort then separated nothing, and `helper_a` recursed on the
    // same list until the stack overflowed. Any value now gives ranks.
    use faint::detect::phd::ndsort::{rank_sorted, Workspace};
    big_stack(|| {
        let mut rng = Rng::seed_from_u64(79);
        for case in 0..200 {
            let n = 1 + rng.below(400) as usize;
            let m = 3 + rng.below(6) as usize;
            let nan_share = [1.0f32, 0.5, 0.05][case % 3];
            let f: Vec<[f32; 8]> = (0..n)
                .map(|_| {
                    core::array::from_fn(|_| {
                        if rng.uniform() < nan_share {
                            f32::NAN
                        } else {
                            (rng.uniform() * 6.0).floor()
                        }
                    })
                })
                .collect();
            let (mut rank, mut work, mut scratch, mut ord1, mut fen) = (
                vec![0u32; n],
                vec![0u32; n],
                vec![0u32; n],
                vec![0u32; n],
                vec![0u32; n],
            );
            let ws = Workspace {
                work: &mut work,
                scratch: &mut scratch,
                order1: &mut ord1,
                fenwick: &mut fen,
            };
            let fronts = rank_sorted(n, m, |p, j| f[p][j], &mut rank, ws);
            assert!(
                fronts <= n && rank.iter().all(|&r| (r as usize) < n),
                "case {case}"
            );
        }
    });
}

#[test]
fn swarm_steps_that_overflow_positions_keep_outputs_finite() {
    // The swarm configurations that reach non-finite positions (the route to the NaN
    // fitness above): a mutation half-width whose draw `U[-m, m]` overflows is rejected;
    // huge but accepted inertia and acceleration factors run with finite outputs (a
    // particle pushed out of the cube dies in the update).
    big_stack(|| {
        let mut c = small_phd(Variant::PsoDbscan);
        c.pso.as_mut().unwrap().mutation = 3e38;
        assert!(c.validate().is_err());
        let mut rng = Rng::seed_from_u64(8);
        let base = small_phd(Variant::PsoDbscan);
        let n = base.geometry.n_range * base.geometry.n_doppler * base.geometry.n_azimuth;
        let frames: Vec<Vec<f32>> = (0..6)
            .map(|_| (0..n).map(|_| 2.0 * rng.exponential()).collect())
            .collect();
        for (inertia, c1, mutation) in [(3e38, 1.0, 2.0), (1.0, 3e38, 2.0), (2.0, 2.0, 8e37)] {
            let mut c = small_phd(Variant::PsoDbscan);
            let p = c.pso.as_mut().unwrap();
            (p.inertia, p.c1, p.c2, p.mutation) = (inertia, c1, c1, mutation);
            p.max_generations = 1000;
            p.threshold = 2.0;
            let mut det = Box::new(HostFilter::new(c, 0).unwrap());
            clean(det.as_mut(), &frames);
        }
    });
}
