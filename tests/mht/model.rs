//! MHT-TBD analytic model: exact run-value law vs brute force and simulation, hit
//! probabilities, and the model threshold applied in simulation.

use faint::detect::Detector;
use faint::host::analysis::mht::{
    self as model, coverage_pmf, lattice_measure, run_value, run_value_pmf, run_value_pmf_brute,
    CellModel, ChainSource, CompoundModel, ModelParams,
};
use faint::host::reproduce::mht::{detectors, evaluate_trial, model_params};
use faint::host::simulate::mht::SeaClutter;
use faint::rng::Rng;

#[test]
fn run_value_examples() {
    let s = |v: &str| v.chars().map(|c| c == '1').collect::<Vec<_>>();
    assert_eq!(run_value(&s("0110111011110"), 3), 7);
    assert_eq!(run_value(&s("111"), 3), 3);
    assert_eq!(run_value(&s("11011"), 3), 0);
    // m_s = X + (M-1) I: 5 overlapping 3-runs in "1111111", one cluster
    assert_eq!(run_value(&s("1111111"), 3), 5 + 2);
}

#[test]
fn dp_matches_brute_force_enumeration() {
    for n in [1usize, 3, 5, 8, 12] {
        for m in [1usize, 2, 3, 4, 7] {
            for p in [0.05, 0.3, 0.5, 0.85] {
                let dp = run_value_pmf(n, m, p);
                let bf = run_value_pmf_brute(n, m, p);
                for (v, (a, b)) in dp.iter().zip(&bf).enumerate() {
                    assert!((a - b).abs() < 1e-12, "n={n} m={m} p={p} v={v}: {a} vs {b}");
                }
                assert!((dp.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            }
        }
    }
}

#[test]
fn dp_matches_simulated_sequences() {
    // 200 000 sequences: each cell's frequency has sd <= sqrt(0.25/2e5) = 1.1e-3;
    // 5 sd = 5.6e-3 bounds every one of the 31 cells with margin.
    let (n, m, p) = (30usize, 3usize, 0.3f64);
    let pmf = run_value_pmf(n, m, p);
    let mut counts = vec![0u32; n + 1];
    let mut rng = Rng::seed_from_u64(11);
    let trials = 200_000;
    let mut seq = vec![false; n];
    for _ in 0..trials {
        for s in seq.iter_mut() {
            *s = rng.bernoulli(p as f32);
        }
        counts[run_value(&seq, m)] += 1;
    }
    for v in 0..=n {
        let f = f64::from(counts[v]) / f64::from(trials);
        let sd = (pmf[v] * (1.0 - pmf[v]) / f64::from(trials)).sqrt();
        assert!(
            (f - pmf[v]).abs() <= 5.0 * sd + 1e-4,
            "v={v}: sim {f} vs {}",
            pmf[v]
        );
    }
}

#[test]
fn hit_probabilities_are_probabilities_and_monotone() {
    let mut last = (0.0, 0.0);
    for lambda in [10.0, 80.0, 164.0, 237.0, 316.0, 398.0, 1000.0] {
        let mp = ModelParams::paper(lambda);
        let (pc, pd) = (model::p_ch(&mp), model::p_dh(&mp));
        assert!((0.0..=1.0).contains(&pc) && (0.0..=1.0).contains(&pd));
        assert!(pd >= mp.pd0, "clutter can only add hits to a target cell");
        assert!(pc > last.0 && pd > last.1, "both grow with lambda");
        last = (pc, pd);
    }
    // no clutter: the target hits with Pd0, clutter never
    let mp = ModelParams::paper(0.0);
    assert_eq!(model::p_ch(&mp), 0.0);
    assert!((model::p_dh(&mp) - 0.85).abs() < 1e-12);
}

#[test]
fn grid_pfa_and_pd_are_monotone_in_gamma() {
    let cm = CellModel::new(ModelParams::paper(300.0));
    for g in 1..30 {
        assert!(cm.pfa_grid(g + 1) <= cm.pfa_grid(g));
        assert!(cm.pd(g + 1) <= cm.pd(g));
    }
    let g = cm.gamma_for_pfa(1e-4);
    assert!(cm.pfa_grid(g) <= 1e-4 && cm.pfa_grid(g - 1) > 1e-4);
}

#[test]
fn classic_chord_lengths() {
    let h = 3000.0;
    assert!((model::chord(0.0, 0.0, h) - 6000.0).abs() < 1e-9);
    assert!(
        (model::chord(0.0, std::f64::consts::FRAC_PI_4, h) - 6000.0 * 2f64.sqrt()).abs() < 1e-6
    );
    assert_eq!(model::chord(5000.0, 0.3, h), 0.0);
}

#[test]
fn lattice_measure_counts_points_in_the_strip() {
    // every point is in the strip over a measure w of offsets: sum_k k mu_k = j w
    for (j, d, w) in [
        (1usize, 0.7, 1.1),
        (3, 0.0, 1.1),
        (3, 0.3, 1.1),
        (5, 2.0, 1.1),
        (30, 0.05, 1.0),
    ] {
        let mut out = vec![0.0; j + 1];
        lattice_measure(j, d, w, &mut out);
        let tot: f64 = out.iter().enumerate().map(|(k, m)| k as f64 * m).sum();
        assert!((tot - j as f64 * w).abs() < 1e-9, "j={j} d={d}: {tot}");
    }
    // collinear (d = 0): all j points together over w
    let mut out = vec![0.0; 4];
    lattice_measure(3, 0.0, 1.0, &mut out);
    assert_eq!(out, vec![0.0, 0.0, 0.0, 1.0]);
    // spacing 0.4 in a strip of width 1
    let mut out = vec![0.0; 4];
    lattice_measure(3, 0.4, 1.0, &mut out);
    // u0 + {0, .4, .8} in [0, 1): 3 points for u0 in [0, .2); 2 for [-.4, 0) and [.2, .6);
    // 1 for [-.8, -.4) and [.6, 1)
    assert!(
        (out[3] - 0.2).abs() < 1e-12
            && (out[2] - 0.8).abs() < 1e-12
            && (out[1] - 0.8).abs() < 1e-12
    );
}

#[test]
fn coverage_dp_matches_closed_form_and_simulation() {
    // only single-scan intervals: each scan covered independently with 1 - exp(-nu)
    let n = 12;
    let nu1 = 0.3;
    let nu: Vec<Vec<f64>> = (0..n)
        .map(|_| (0..=n).map(|k| if k == 1 { nu1 } else { 0.0 }).collect())
        .collect();
    let dp = coverage_pmf(n, &nu);
    let bin = model::binomial_pmf(n, 1.0 - f64::exp(-nu1));
    for (a, b) in dp.iter().zip(&bin) {
        assert!((a - b).abs() < 1e-12);
    }
    // mixed lengths, starts uniform over 0..=n-k: against 200 000 simulated Boolean models
    // (5 sd of a frequency <= 5 * sqrt(0.25 / 2e5) = 5.6e-3)
    let lam = [0.0, 0.8, 0.3, 0.2, 0.1, 0.05];
    let nu: Vec<Vec<f64>> = (0..n)
        .map(|t| {
            (0..=n)
                .map(|k| {
                    if k == 0 || k >= lam.len() || t + k > n {
                        0.0
                    } else {
                        lam[k] / (n - k + 1) as f64
                    }
                })
                .collect()
        })
        .collect();
    let dp = coverage_pmf(n, &nu);
    assert!((dp.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    let mut rng = Rng::seed_from_u64(77);
    let trials = 200_000u32;
    let mut counts = vec![0u32; n + 1];
    let poisson = |rng: &mut Rng, mu: f64| {
        let (mut k, mut p, l) = (0u32, 1.0f64, (-mu).exp());
        loop {
            p *= f64::from(rng.uniform_open0());
            if p <= l {
                return k;
            }
            k += 1;
        }
    };
    for _ in 0..trials {
        let mut cov = vec![false; n];
        for (k, &l) in lam.iter().enumerate().skip(1) {
            for _ in 0..poisson(&mut rng, l) {
                let t0 = rng.below((n - k + 1) as u32) as usize;
                cov[t0..t0 + k].iter_mut().for_each(|c| *c = true);
            }
        }
        counts[cov.iter().filter(|c| **c).count()] += 1;
    }
    for v in 0..=n {
        let f = f64::from(counts[v]) / f64::from(trials);
        assert!((f - dp[v]).abs() < 5.6e-3, "v={v}: sim {f} vs dp {}", dp[v]);
    }
}

/// The model's threshold in simulation: clutter-only periods through the full detector,
/// largest DMHT count per period, against the compound law with `N_t = 0` (what such a
/// period holds). Level: grid Pfa 0.1 so that 400 periods resolve it (binomial sd 0.015).
/// Measured with 10 000 periods per lambda (README "Compound law: validation"): the
/// compound law's grid Pfa is never below the simulated one, and its threshold for a given
/// Pfa is the simulated one or one count above (conservative: branched chains are
/// counted twice, and the model's `drho` is the MSHT's 33 m while the DMHT's is smaller at
/// low lambda), two at lambda 398 at this level (its effective clutter density is 24 %
/// high there: 66.7 vs 53.9 plots per scan; one count at the 1e-4 level). The test
/// asserts exactly that, `g_sim <= g_model <= g_sim + slack`; the paper variant (eq. 20-26)
/// is optimistic by 2-4 counts at lambda 164-316 (`g_model < g_sim`).
#[test]
fn model_threshold_holds_in_simulation() {
    for (lambda, slack) in [
        (80.0f32, 1usize),
        (164.0, 1),
        (237.0, 1),
        (316.0, 1),
        (398.0, 2),
    ] {
        let mut sc = SeaClutter::paper(lambda);
        sc.n_targets = 0;
        let cm = CompoundModel::new(model_params(&sc), ChainSource::Censoring);
        let level = 0.1;
        let g_model = cm.gamma_for_pfa(level);
        let (mut m, mut c) = detectors(&sc, g_model as u8, 30).unwrap();
        let mut rng = Rng::seed_from_u64(2024 + lambda as u64);
        let trials = 400;
        let maxes: Vec<u8> = (0..trials)
            .map(|_| {
                let tr = sc.generate(&mut rng);
                evaluate_trial(&sc, &tr, &mut m, &mut c).mht_max_count
            })
            .collect();
        let sim_pfa = |g: usize| {
            maxes.iter().filter(|&&x| usize::from(x) >= g).count() as f64 / trials as f64
        };
        let g_sim = (1..=31).find(|&g| sim_pfa(g) <= level).unwrap();
        eprintln!(
            "lambda {lambda}: model gamma {g_model} (model Pfa {:.3}, sim Pfa {:.3}); sim gamma {g_sim}",
            cm.pfa_grid(g_model),
            sim_pfa(g_model)
        );
        assert!(
            g_sim <= g_model && g_model <= g_sim + slack,
            "lambda {lambda}: model {g_model}, sim {g_sim}"
        );
    }
}

/// Where the paper model's gap lives and that the compound law closes it (README "Why the
/// model and simulation differ"), lambda 164, 300 clutter-only periods, models with
/// `N_t = 0`:
/// (1) eq. 28 applied to the *simulated* per-cell tail reproduces the simulated grid Pfa
/// (measured with 1000 periods: 0.086 vs 0.081 at gamma 10), so cell correlation is not
/// the cause; the factor-2 band leaves room for the binomial error of ~30-100 periods
/// above the level and for mild clustering of high cells.
/// (2) the paper's cell law `P0` (eq. 25) is far too light in its tail: measured 1.2e-5
/// (sim) vs 2.1e-9 (paper) at gamma 9, ~5000x; asserted > 100x.
/// (3) the compound law's mean cell tail is within [0.7, 3] x the simulated one (measured
/// with 10 000 periods: 1.58x at gamma 9, 1.76x at 10; here 1.8x, 2.0x); with 300 periods the simulated
/// tail at gamma 10 rests on ~35 cells from ~30 periods (chains make high cells come in
/// groups), so its error is ~+-30 %, hence the band.
#[test]
fn compound_law_closes_the_cell_gap() {
    let mut sc = SeaClutter::paper(164.0);
    sc.n_targets = 0;
    let cm = CellModel::new(model_params(&sc));
    let cp = CompoundModel::new(model_params(&sc), ChainSource::Censoring);
    let n = sc.n_scans;
    let (mut m, _) = detectors(&sc, n as u8, n as u8).unwrap();
    let mut rng = Rng::seed_from_u64(4164);
    let periods = 300usize;
    let mut cell_hist = vec![0u64; n + 1];
    let mut max_hist = vec![0u64; n + 1];
    for _ in 0..periods {
        let tr = sc.generate(&mut rng);
        for s in &tr.scans {
            m.step(&s.plots).unwrap();
        }
        let acc = m.accumulator();
        let mut mx = 0u8;
        for a in 0..180 {
            for r in 0..256 {
                let c = acc.count(r, a);
                cell_hist[usize::from(c)] += 1;
                mx = mx.max(c);
            }
        }
        max_hist[usize::from(mx)] += 1;
    }
    let cells = 256.0 * 180.0;
    let tail = |h: &[u64], g: usize| h[g..].iter().sum::<u64>() as f64;
    for g in [9usize, 10] {
        let cell_sim = tail(&cell_hist, g) / (cells * periods as f64);
        let grid_sim = tail(&max_hist, g) / periods as f64;
        let grid_eq28 = -(cells * (-cell_sim).ln_1p()).exp_m1();
        eprintln!(
            "gamma {g}: cell sim {cell_sim:.3e} paper {:.3e} compound {:.3e}; grid sim {grid_sim:.3} eq28(sim cell) {grid_eq28:.3}",
            cm.pfa_cell(g),
            cp.pfa_cell(g)
        );
        assert!(
            grid_eq28 <= 2.0 * grid_sim && grid_sim <= 2.0 * grid_eq28,
            "gamma {g}: eq. 28 on the simulated cell tail {grid_eq28:.3} vs grid {grid_sim:.3}"
        );
        assert!(
            cell_sim > 100.0 * cm.pfa_cell(g),
            "gamma {g}: paper cell tail {:.3e} no longer far below simulation {cell_sim:.3e}",
            cm.pfa_cell(g)
        );
        let r = cp.pfa_cell(g) / cell_sim;
        assert!(
            (0.7..=3.0).contains(&r),
            "gamma {g}: compound cell tail {:.3e} vs simulation {cell_sim:.3e}",
            cp.pfa_cell(g)
        );
    }
}

/// The residual rule (`MhtConfig::residual`: a later peak must reach `gamma_1` without the
/// plots its track shares with the tracks confirmed before it) against target-induced
/// false tracks, lambda 164 at the paper law's `gamma_1 = 11` (where they are frequent),
/// 300 trials with the scene's 5 targets, same seeds with the rule on and off. Measured
/// with 2000 trials (`mht_diag fa 164 2000 11 [noresid]`): 71 false tracks without the
/// rule (66 of them below `gamma_1` without their plots shared with other tracks), 11 with
/// it; targets whose line is found 9668 vs 9652 of 10 000. Expected here ~11 vs ~2: the
/// test asserts at least a 3x cut and at most 1 % of the targets lost (the paired
/// difference is ~0.2 %, a handful of targets in 1500).
#[test]
fn residual_rule_removes_target_induced_false_tracks() {
    let sc = SeaClutter::paper(164.0);
    let trials = 300u64;
    let mut out = [(0u32, 0u32); 2];
    for (i, residual) in [false, true].into_iter().enumerate() {
        let (mut m, mut c) = detectors(&sc, 11, 31).unwrap();
        let mut cfg = *m.config();
        cfg.residual = residual;
        m.configure(&cfg, 0).unwrap();
        for t in 0..trials {
            let mut rng = Rng::from_stream(9164, t);
            let tr = sc.generate(&mut rng);
            let st = evaluate_trial(&sc, &tr, &mut m, &mut c);
            out[i].0 += st.mht_false;
            out[i].1 += st.mht_detected;
        }
    }
    eprintln!(
        "without the rule: {:?}, with: {:?} (false tracks, targets detected)",
        out[0], out[1]
    );
    assert!(out[0].0 >= 3 * out[1].0.max(1), "{out:?}");
    let n = (trials * 5) as f64;
    assert!(
        f64::from(out[1].1) >= f64::from(out[0].1) - 0.01 * n,
        "{out:?}"
    );
}
