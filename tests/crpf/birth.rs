//! The birth proposals of PF-TBD and JOTT (`BirthProposal`): the fixed share proposes the
//! same predicted law as the exact proposal, so the existence recursion must agree in
//! expectation; bad shares are typed errors; the output is finite and deterministic.

use faint::detect::jott::JottTbd;
use faint::detect::pf_lrt::PfLrt;
use faint::detect::pf_tbd::{BirthProposal, GaussConfig, PfTbd};
use faint::detect::Detector;
use faint::host::reproduce::crpf::run_detector;
use faint::host::simulate::crpf::{Noise, Othr, Run};
use faint::model::doppler::DopplerReport;
use faint::rng::Rng;
use faint::{Complex32, Error};

use super::detectors::var_of;

const SHARE: BirthProposal = BirthProposal::FixedShare(0.1);

fn cfg(var: f32, birth: BirthProposal) -> GaussConfig {
    GaussConfig {
        birth,
        ..GaussConfig::othr(var)
    }
}

fn existence<D: Detector<Frame = [Complex32], Report = DopplerReport>>(
    d: &mut D,
    run: &Run,
) -> Vec<f32> {
    run_detector(d, run)
        .unwrap()
        .iter()
        .map(|r| r.existence)
        .collect()
}

fn mean(v: &[f32], frames: std::ops::RangeInclusive<usize>) -> f32 {
    let n = frames.clone().count() as f32;
    frames.map(|k| v[k - 1]).sum::<f32>() / n
}

#[test]
fn exact_is_the_preset_and_bad_shares_are_typed_errors() {
    assert_eq!(GaussConfig::othr(1.0).birth, BirthProposal::Exact);
    assert_eq!(BirthProposal::default(), BirthProposal::Exact);
    assert_eq!(SHARE.birth_count::<6000>(), Ok(Some(600)));
    assert_eq!(SHARE.birth_count::<1000>(), Ok(Some(100)));
    // B is clamped to 1..=N-1.
    assert_eq!(
        BirthProposal::FixedShare(1e-6).birth_count::<10>(),
        Ok(Some(1))
    );
    assert_eq!(
        BirthProposal::FixedShare(0.999).birth_count::<10>(),
        Ok(Some(9))
    );
    assert_eq!(BirthProposal::Exact.birth_count::<1>(), Ok(None));
    // What the option adds to every Gaussian comparator's configuration.
    assert_eq!(std::mem::size_of::<BirthProposal>(), 8);
    let bad_share = Error::InvalidConfig("birth proposal share must be finite and in (0, 1)");
    for s in [0.0, 1.0, -0.1, 1.5, f32::NAN, f32::INFINITY] {
        let b = BirthProposal::FixedShare(s);
        assert_eq!(b.birth_count::<100>(), Err(bad_share), "{s}");
        let g = cfg(1.0, b);
        assert_eq!(PfTbd::<100>::new(g, 1).unwrap_err(), bad_share, "{s}");
        assert_eq!(JottTbd::<100>::new(g, 1).unwrap_err(), bad_share);
        // PF-LRT has no births but shares the config and its check.
        assert_eq!(PfLrt::<100>::new(g, 1).unwrap_err(), bad_share);
    }
    assert!(PfTbd::<1>::new(cfg(1.0, SHARE), 1).is_err());
    assert!(JottTbd::<1>::new(cfg(1.0, SHARE), 1).is_err());
    assert!(PfTbd::<1>::new(cfg(1.0, BirthProposal::Exact), 1).is_ok());

    // A rejected configure leaves the detector as it was: its run equals an untouched one.
    let sc = Othr::default();
    let run = sc.simulate(Some(8.0), Noise::Gaussian, &mut Rng::seed_from_u64(5));
    let v = var_of(&run);
    let want = existence(&mut PfTbd::<200>::new(cfg(v, SHARE), 3).unwrap(), &run);
    let mut d = PfTbd::<200>::new(cfg(v, SHARE), 3).unwrap();
    assert!(d
        .configure(&cfg(v, BirthProposal::FixedShare(2.0)), 9)
        .is_err());
    assert_eq!(existence(&mut d, &run), want);
    // Deterministic: the same seed gives the same bits, for both detectors.
    let again = existence(&mut PfTbd::<200>::new(cfg(v, SHARE), 3).unwrap(), &run);
    assert_eq!(again, want);
    let j1 = existence(&mut JottTbd::<200>::new(cfg(v, SHARE), 3).unwrap(), &run);
    let j2 = existence(&mut JottTbd::<200>::new(cfg(v, SHARE), 3).unwrap(), &run);
    assert_eq!(j1, j2);
}

#[test]
fn without_information_the_existence_follows_the_chain() {
    // A variance of 1e30 makes every log LR about 1e-29: the update is a no-op and the
    // existence is the prediction alone, q_k = Pb (1 - q_{k-1}) + (1 - Pd) q_{k-1} from
    // q_0 = 0.05 (Pb = Pd = 0.05: 0.095, 0.1355, ... towards 0.5).
    //
    // JOTT computes q_k from the prior weights' total, so q_k = q_{k|k-1} to rounding
    // under both proposals: the fixed share's weights Pb (1 - q) / (B q_pred) and
    // Ps q / ((N - B) q_pred) sum to 1.
    //
    // PF-TBD's existence is the particles' weighted share: its mean over seeds must follow
    // the recursion under both proposals. Tolerance: 5 standard errors of the mean over
    // S = 300 seeds (measured spread per frame, at most about 0.07 per run) plus 0.01 for
    // the O(1/N) bias of the self-normalised weights at N = 250.
    let sc = Othr::default();
    let run = sc.simulate(Some(10.0), Noise::Gaussian, &mut Rng::seed_from_u64(11));
    let k = run.frames.len();
    let mut want = vec![0.0f64; k];
    let mut q = 0.05f64;
    for w in want.iter_mut() {
        q = 0.05 * (1.0 - q) + 0.95 * q;
        *w = q;
    }
    for birth in [BirthProposal::Exact, SHARE] {
        let e = existence(&mut JottTbd::<250>::new(cfg(1e30, birth), 7).unwrap(), &run);
        for (f, (&got, &w)) in e.iter().zip(&want).enumerate() {
            assert!(
                (got as f64 - w).abs() < 1e-4,
                "JOTT {birth:?} frame {}: {got} vs {w}",
                f + 1
            );
        }
        const S: u64 = 300;
        let mut sum = vec![0.0f64; k];
        let mut sq = vec![0.0f64; k];
        for seed in 0..S {
            let e = existence(
                &mut PfTbd::<250>::new(cfg(1e30, birth), seed).unwrap(),
                &run,
            );
            for (i, &x) in e.iter().enumerate() {
                sum[i] += x as f64;
                sq[i] += (x as f64) * (x as f64);
            }
        }
        let mut worst = 0.0f64;
        for i in 0..k {
            let m = sum[i] / S as f64;
            let sd = (sq[i] / S as f64 - m * m).max(0.0).sqrt();
            let tol = 5.0 * sd / (S as f64).sqrt() + 0.01;
            worst = worst.max((m - want[i]).abs() / tol);
            assert!(
                (m - want[i]).abs() < tol,
                "PF-TBD {birth:?} frame {}: mean {m:.4} vs {:.4} (tol {tol:.4})",
                i + 1,
                want[i]
            );
        }
        println!("PF-TBD {birth:?}: worst |mean - recursion| / tolerance {worst:.2}");
    }
}

#[test]
fn fixed_share_tracks_at_15_db_like_the_exact_proposal() {
    // The 15 dB runs of the detectors test (seeds 1, 2 Gaussian, 3 CGG), 8 detector seeds
    // each, N = 1000: the mean over the 8 seeds of the existence over frames 14-26 must
    // be high under both proposals (> 0.9) and agree within 0.05 (the same law; the
    // proposals differ only in Monte Carlo error), and low before the target (frames 1-6)
    // and after it (29-32; a single seed's can reach 0.35 under the exact proposal).
    let sc = Othr::default();
    for (seed, noise) in [
        (1u64, Noise::Gaussian),
        (2, Noise::Gaussian),
        (3, Noise::Cgg),
    ] {
        let run = sc.simulate(Some(15.0), noise, &mut Rng::seed_from_u64(seed));
        let v = var_of(&run);
        let mut during = [[0.0f32; 2]; 2];
        let mut before = [[0.0f32; 2]; 2];
        let mut after = [[0.0f32; 2]; 2];
        for (p, birth) in [BirthProposal::Exact, SHARE].into_iter().enumerate() {
            for s in 0..8u64 {
                let dets: [(usize, Vec<f32>); 2] = [
                    (
                        0,
                        existence(
                            &mut PfTbd::<1000>::new(cfg(v, birth), 100 + s).unwrap(),
                            &run,
                        ),
                    ),
                    (
                        1,
                        existence(
                            &mut JottTbd::<1000>::new(cfg(v, birth), 100 + s).unwrap(),
                            &run,
                        ),
                    ),
                ];
                for (d, e) in dets {
                    assert!(e.iter().all(|x| x.is_finite() && (0.0..=1.0).contains(x)));
                    before[d][p] += mean(&e, 1..=6) / 8.0;
                    after[d][p] += mean(&e, 29..=32) / 8.0;
                    during[d][p] += mean(&e, 14..=26) / 8.0;
                }
            }
        }
        for (d, name) in ["PF-TBD", "JOTT"].iter().enumerate() {
            let [exact, share] = during[d];
            println!("{name} {noise:?} seed {seed}: frames 14-26 exact {exact:.3} fixed share {share:.3}");
            assert!(exact > 0.9 && share > 0.9, "{name} {noise:?}");
            assert!((exact - share).abs() < 0.05, "{name} {noise:?}");
            for p in 0..2 {
                let (b, a) = (before[d][p], after[d][p]);
                println!("  proposal {p}: frames 1-6 {b:.3}, 29-32 {a:.3}");
                assert!(b < 0.3 && a < 0.3, "{name} {noise:?} proposal {p}");
            }
        }
    }
}

#[test]
fn fixed_share_h0_existence_stays_low_and_bad_frames_are_handled() {
    // H0, 20 runs per noise, N = 500: the mean existence over the 32 frames under the
    // fixed share is no higher than the exact proposal's on the same runs plus 0.05, and
    // below 0.5 (a target at 15 dB gives 0.9+). The exact proposal's own level is
    // 0.28 (PF-TBD) and 0.40 (JOTT) under Gaussian noise: the independent-bin likelihood
    // is overconfident on the windowed bins (docs/measurements/crpf.md, Fidelity).
    let sc = Othr::default();
    for noise in [Noise::Gaussian, Noise::Cgg] {
        let mut m = [[0.0f32; 2]; 2];
        for seed in 0..20u64 {
            let run = sc.simulate(None, noise, &mut Rng::seed_from_u64(2000 + seed));
            let v = var_of(&run);
            for (p, birth) in [BirthProposal::Exact, SHARE].into_iter().enumerate() {
                let pf = existence(&mut PfTbd::<500>::new(cfg(v, birth), seed).unwrap(), &run);
                let jo = existence(&mut JottTbd::<500>::new(cfg(v, birth), seed).unwrap(), &run);
                m[0][p] += mean(&pf, 1..=32) / 20.0;
                m[1][p] += mean(&jo, 1..=32) / 20.0;
            }
        }
        for (d, name) in ["PF-TBD", "JOTT"].iter().enumerate() {
            let [exact, share] = m[d];
            println!("H0 {name} {noise:?}: mean existence exact {exact:.3} fixed share {share:.3}");
            assert!(share < 0.5 && share < exact + 0.05, "{name} {noise:?}");
        }
    }
    // Zero frames, then 1e12-scaled ones: finite output in [0, 1].
    let run = sc.simulate(Some(10.0), Noise::Gaussian, &mut Rng::seed_from_u64(9));
    let v = var_of(&run);
    let zero = vec![Complex32::new(0.0, 0.0); 32];
    let big: Vec<Complex32> = run.frames[8].iter().map(|c| c * 1e12).collect();
    let mut pf = PfTbd::<100>::new(cfg(v, SHARE), 1).unwrap();
    let mut jo = JottTbd::<100>::new(cfg(v, SHARE), 1).unwrap();
    for z in [&zero, &zero, &big, &big, &zero]
        .into_iter()
        .chain(run.frames.iter())
    {
        for r in [pf.step(z).unwrap(), jo.step(z).unwrap()] {
            assert!(r.existence.is_finite() && (0.0..=1.0).contains(&r.existence));
            assert!(r.estimate.is_none_or(|e| e.iter().all(|x| x.is_finite())));
        }
    }
}
