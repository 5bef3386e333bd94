//! Clutter-only diagnostics of MHT-TBD at one lambda: DMHT cell size, the law of a cell's
//! count over all cells against the model's `P0` (eq. 25), and the make-up of each
//! period's largest cell (scans hit, runs of consecutive scans); the paper's law (eq.
//! 20-26) and the compound law side by side.
//! `cargo run --release --example mht_diag -- LAMBDA TRIALS`
//!
//! False tracks with targets present (item 4 of the README's MHT-TBD section):
//! `cargo run --release --example mht_diag -- fa LAMBDA TRIALS [GAMMA1 [noresid]]` runs the scene with
//! its 5 targets at the default model's `gamma_1` (or `GAMMA1`), and prints for every
//! confirmed track matching no target: its peak's raw count, plots (effective, look-back),
//! the plots that belong to targets and to other confirmed tracks, and the peak cell's
//! count without the plots it shares with the other confirmed tracks; `noresid` turns the detector's
//! residual rule (`MhtConfig::residual`) off.
//!
//! Stage attribution (`reproduce::mht::attribute`): `mht_diag stages LAMBDA TRIALS GAMMA1 [SEED]`
//! prints, for scenes `Rng::from_stream(SEED, t)` (default 5151), the stage at which each
//! lost target was stopped and what each false track is made of.
//!
//! Fig. 4 (near-optimal detector): `mht_diag fig4 N M LAMBDA TRIALS NULL` evaluates the
//! paper's law at `N` scans, window `M`, and simulates MHT-TBD with that `N`, `M` at the
//! law's `gamma_1` for grid Pfa 1e-4: Pd over `TRIALS` scenes with 5 targets
//! (`Rng::from_stream(6161, t)`), and the share of `NULL` clutter-only periods
//! (`Rng::from_stream(6262, t)`) whose largest cell reaches it / that confirm a track.
use faint_core::detect::Detector;
use faint_core::rng::Rng;
use faint_host::analysis::mht::{CellModel, ChainSource, CompoundModel};
use faint_host::instances::mht::{ANGLE_CELLS, RANGE_CELLS};
use faint_host::reproduce::mht::{detectors, model_params, thresholds, MATCH_TOL};
use faint_host::simulate::mht::{Origin, SeaClutter};

fn false_tracks(a: &[String]) {
    let lambda: f32 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(164.0);
    let trials: u64 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(200);
    let sc = SeaClutter::paper(lambda);
    let g1 = a
        .get(4)
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| thresholds(&sc, 1e-4).0 as u8);
    let no_resid = a.get(5).map(String::as_str) == Some("noresid");
    let n = sc.n_scans;
    let (mut nfa, mut n_resid_below, mut n_det) = (0usize, 0usize, 0usize);
    println!(
        "lambda {lambda} trials {trials} gamma_1 {g1} residual rule {}",
        !no_resid
    );
    println!("trial raw n_plots n_eff lookback target_plots(own max) in_other_tracks resid_count");
    for t in 0..trials {
        let mut rng = Rng::from_stream(4242, t);
        let tr = sc.generate(&mut rng);
        let Ok((mut m, _)) = detectors(&sc, g1, n as u8) else {
            return;
        };
        let mut cfg = *m.config();
        cfg.residual = !no_resid;
        if m.configure(&cfg, 0).is_err() {
            return;
        }
        for s in &tr.scans {
            let _ = m.step(&s.plots);
        }
        n_det += tr
            .targets
            .iter()
            .filter(|tg| {
                m.tracks().iter().any(|trk| {
                    let (co, si) = (trk.theta.cos(), trk.theta.sin());
                    (0..n).all(|s| {
                        let (x, y) = tg.position(s as f32 * sc.t_scan);
                        (x * co + y * si - trk.c).abs() <= MATCH_TOL
                    })
                })
            })
            .count();
        let tracks = m.tracks();
        let g = *m.dmht_geometry();
        for (ti, trk) in tracks.iter().enumerate() {
            let (co, si) = (trk.theta.cos(), trk.theta.sin());
            let mut per_target = vec![0usize; tr.targets.len()];
            for s in 0..n {
                let k = trk.plots[s];
                if k != u16::MAX {
                    if let Origin::Target(i) = tr.scans[s].origin[usize::from(k)] {
                        per_target[i] += 1;
                    }
                }
            }
            let matched = (0..tr.targets.len()).any(|i| {
                (0..n).all(|s| {
                    let (x, y) = tr.targets[i].position(s as f32 * sc.t_scan);
                    (x * co + y * si - trk.c).abs() <= MATCH_TOL
                }) || 2 * per_target[i] > usize::from(trk.n_plots)
            });
            if matched {
                continue;
            }
            nfa += 1;
            let in_other = (0..n)
                .filter(|&s| {
                    trk.plots[s] != u16::MAX
                        && tracks
                            .iter()
                            .enumerate()
                            .any(|(oi, o)| oi != ti && o.plots[s] == trk.plots[s])
                })
                .count();
            // peak cell count without the plots of the other confirmed tracks
            let (r, aa) = (usize::from(trk.peak.r), usize::from(trk.peak.a));
            let resid = (0..n)
                .filter(|&s| {
                    tr.scans[s].plots.iter().enumerate().any(|(k, p)| {
                        m.is_effective(s, k)
                            && g.rho_index_f32(p.x, p.y, aa) == r
                            && !(usize::from(trk.plots[s]) == k
                                && tracks
                                    .iter()
                                    .enumerate()
                                    .any(|(oi, o)| oi != ti && usize::from(o.plots[s]) == k))
                    })
                })
                .count();
            if resid < usize::from(g1) {
                n_resid_below += 1;
            }
            println!(
                "{t:>5} {:>3} {:>7} {:>5} {:>8} {:>3} ({:>2}) {:>15} {:>11}",
                trk.peak.raw,
                trk.n_plots,
                trk.n_effective,
                trk.lookback.count_ones(),
                per_target.iter().sum::<usize>(),
                per_target.iter().max().copied().unwrap_or(0),
                in_other,
                resid
            );
        }
    }
    println!(
        "false tracks {nfa} in {trials} trials; without the plots shared with other tracks, {n_resid_below} of them fall below gamma_1; targets detected (line within MATCH_TOL) {n_det} of {}",
        trials as usize * sc.n_targets
    );
}

/// Targets found without the residual rule but not with it: the residual count of the
/// track that found them (plots of the tracks confirmed before it removed) and what those
/// earlier tracks were.
fn lost_targets(a: &[String]) {
    let lambda: f32 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(164.0);
    let trials: u64 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(200);
    let sc = SeaClutter::paper(lambda);
    let g1 = a
        .get(4)
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| thresholds(&sc, 1e-4).0 as u8);
    let n = sc.n_scans;
    let found = |m: &faint_host::instances::mht::Mht,
                 tg: &faint_host::simulate::mht::TargetTruth| {
        m.tracks().iter().position(|trk| {
            let (co, si) = (trk.theta.cos(), trk.theta.sin());
            (0..n).all(|s| {
                let (x, y) = tg.position(s as f32 * sc.t_scan);
                (x * co + y * si - trk.c).abs() <= MATCH_TOL
            })
        })
    };
    println!("lambda {lambda} gamma_1 {g1}: trial target raw n_plots resid earlier_tracks_claiming(target plots of them)");
    let mut lost = 0;
    for t in 0..trials {
        let mut rng = Rng::from_stream(4242, t);
        let tr = sc.generate(&mut rng);
        let (Ok((mut off, _)), Ok((mut on, _))) =
            (detectors(&sc, g1, n as u8), detectors(&sc, g1, n as u8))
        else {
            return;
        };
        let mut cfg = *off.config();
        cfg.residual = false;
        if off.configure(&cfg, 0).is_err() {
            return;
        }
        let (mut d_off, mut d_on) = (None, None);
        for s in &tr.scans {
            if let Ok(r) = off.step(&s.plots) {
                d_off = r.detection.or(d_off);
            }
            if let Ok(r) = on.step(&s.plots) {
                d_on = r.detection.or(d_on);
            }
        }
        if (0..tr.targets.len())
            .any(|i| found(&off, &tr.targets[i]).is_some() && found(&on, &tr.targets[i]).is_none())
        {
            println!("  off {:?}\n  on  {:?}", d_off, d_on);
        }
        for (i, tg) in tr.targets.iter().enumerate() {
            let (Some(ti), None) = (found(&off, tg), found(&on, tg)) else {
                continue;
            };
            lost += 1;
            let tracks = off.tracks();
            let trk = &tracks[ti];
            let g = *off.dmht_geometry();
            let (r, aa) = (usize::from(trk.peak.r), usize::from(trk.peak.a));
            let resid = (0..n)
                .filter(|&s| {
                    tr.scans[s].plots.iter().enumerate().any(|(k, p)| {
                        off.is_effective(s, k)
                            && g.rho_index_f32(p.x, p.y, aa) == r
                            && !(usize::from(trk.plots[s]) == k
                                && tracks[..ti].iter().any(|o| usize::from(o.plots[s]) == k))
                    })
                })
                .count();
            let claim: Vec<String> = tracks[..ti]
                .iter()
                .enumerate()
                .filter_map(|(oi, o)| {
                    let shared = (0..n)
                        .filter(|&s| o.plots[s] != u16::MAX && o.plots[s] == trk.plots[s])
                        .count();
                    let own_i = (0..n)
                        .filter(|&s| {
                            o.plots[s] != u16::MAX
                                && tr.scans[s].origin[usize::from(o.plots[s])] == Origin::Target(i)
                        })
                        .count();
                    (shared > 0)
                        .then(|| format!("#{oi}: {shared} shared, {own_i}/{} of target", o.n_plots))
                })
                .collect();
            println!(
                "{t:>5} {i} {:>3} {:>3} {resid:>3} {}",
                trk.peak.raw,
                trk.n_plots,
                claim.join("; ")
            );
        }
    }
    println!("lost {lost}");
}

fn fig4(a: &[String]) {
    use faint_host::reproduce::mht::{evaluate_trial, proportion_ci};
    let arg = |i: usize, d: f64| a.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let (n, mw, lambda) = (arg(2, 20.0) as usize, arg(3, 7.0) as usize, arg(4, 300.0));
    let (trials, null) = (arg(5, 200.0) as u64, arg(6, 200.0) as u64);
    let mut mp = model_params(&SeaClutter::paper(lambda as f32));
    mp.n = n;
    mp.m = mw;
    let cm = CellModel::new(mp);
    let g = cm.gamma_for_pfa(1e-4);
    println!(
        "paper law N {n} M {mw} lambda {lambda}: p_ch {:.4} p_dh {:.4} gamma_1 {g} grid Pfa {:.3e} model Pd {:.4}",
        cm.p_ch,
        cm.p_dh,
        cm.pfa_grid(g),
        cm.pd(g)
    );
    let mut sc = SeaClutter::paper(lambda as f32);
    sc.n_scans = n;
    let build = || {
        let (mut m, c) = detectors(&sc, g.min(255) as u8, n as u8).ok()?;
        let mut cfg = *m.config();
        cfg.m = mw;
        m.configure(&cfg, 0).ok()?;
        Some((m, c))
    };
    let Some((mut m, mut c)) = build() else {
        eprintln!("bad configuration");
        return;
    };
    let (mut det, mut fa) = (0u64, 0u64);
    for t in 0..trials {
        let tr = sc.generate(&mut Rng::from_stream(6161, t));
        let st = evaluate_trial(&sc, &tr, &mut m, &mut c);
        det += u64::from(st.mht_detected);
        fa += u64::from(st.mht_false);
    }
    let nt = trials * sc.n_targets as u64;
    let (p, lo, hi) = proportion_ci(det, nt);
    println!("simulated Pd {p:.4} [{lo:.4}, {hi:.4}] ({det} of {nt}), false tracks {fa} in {trials} scenes");
    sc.n_targets = 0;
    let (mut cell, mut conf) = (0u64, 0u64);
    for t in 0..null {
        let tr = sc.generate(&mut Rng::from_stream(6262, t));
        let st = evaluate_trial(&sc, &tr, &mut m, &mut c);
        cell += u64::from(usize::from(st.mht_max_count) >= g);
        conf += u64::from(st.mht_false > 0);
    }
    let (p, lo, hi) = proportion_ci(cell, null);
    let (q, qlo, qhi) = proportion_ci(conf, null);
    println!(
        "clutter-only periods: largest cell >= gamma_1 {p:.4} [{lo:.4}, {hi:.4}] ({cell} of {null}); with a confirmed track {q:.4} [{qlo:.4}, {qhi:.4}] ({conf})"
    );
}

fn stages(a: &[String]) {
    let lambda: f32 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(398.0);
    let trials: u64 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(200);
    let g1: u8 = a.get(4).and_then(|s| s.parse().ok()).unwrap_or(21);
    let seed: u64 = a.get(5).and_then(|s| s.parse().ok()).unwrap_or(5151);
    match faint_host::reproduce::mht::attribute(lambda, g1, trials, seed) {
        Ok(rep) => {
            println!(
                "{}",
                faint_host::reproduce::mht::StageReport::MARKDOWN_HEADER
            );
            println!("{}", rep.markdown_row(lambda, g1));
            println!(
                "peak fates (confirmed, short, merged, residual): {:?}",
                rep.peak_fates
            );
            println!("false tracks: raw n_plots target_plots target_detected count_without_target shared_earlier");
            for f in &rep.false_tracks {
                println!(
                    "  {:>3} {:>3} {:>3} {:>5} {:>3} {:>3}",
                    f.raw,
                    f.n_plots,
                    f.target_plots,
                    f.target_detected,
                    f.count_without_target,
                    f.shared_earlier
                );
            }
        }
        Err(e) => eprintln!("{e}"),
    }
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    if a.get(1).map(String::as_str) == Some("lost") {
        lost_targets(&a);
        return;
    }
    if a.get(1).map(String::as_str) == Some("fig4") {
        fig4(&a);
        return;
    }
    if a.get(1).map(String::as_str) == Some("stages") {
        stages(&a);
        return;
    }
    if a.get(1).map(String::as_str) == Some("fa") {
        false_tracks(&a);
        return;
    }
    let lambda: f32 = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(164.0);
    let trials: u64 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(100);
    let mut sc = SeaClutter::paper(lambda);
    sc.n_targets = 0;
    let n = sc.n_scans;
    let cm = CellModel::new(model_params(&sc));
    let cn = CompoundModel::new(model_params(&sc), ChainSource::PaperNc);
    let cp = CompoundModel::new(model_params(&sc), ChainSource::Censoring);
    let mut hist = vec![0u64; n + 1];
    let (mut drho_sum, mut eff_sum) = (0.0f64, 0u64);
    let mut max_hist = vec![0u64; n + 1];
    let (mut runs3_sum, mut iso_sum, mut hits_sum, mut longest_sum) = (0u64, 0u64, 0u64, 0u64);
    for t in 0..trials {
        let mut rng = Rng::from_stream(777, t);
        let tr = sc.generate(&mut rng);
        let Ok((mut m, _)) = detectors(&sc, n as u8, n as u8) else {
            return;
        };
        for s in &tr.scans {
            let _ = m.step(&s.plots);
        }
        let g = m.dmht_geometry();
        drho_sum += f64::from(g.drho());
        let acc = m.accumulator();
        let mut best = (0u8, 0usize, 0usize);
        for aa in 0..ANGLE_CELLS {
            for r in 0..RANGE_CELLS {
                let c = acc.count(r, aa);
                hist[usize::from(c)] += 1;
                if c > best.0 {
                    best = (c, r, aa);
                }
            }
        }
        max_hist[usize::from(best.0)] += 1;
        // scans with an effective plot in the largest cell
        let mut hit = vec![false; n];
        for (si, s) in tr.scans.iter().enumerate() {
            for (k, p) in s.plots.iter().enumerate() {
                if m.is_effective(si, k) {
                    eff_sum += 1;
                    if g.rho_index_f32(p.x, p.y, best.2) == best.1 {
                        hit[si] = true;
                    }
                }
            }
        }
        let (mut run, mut runs3, mut iso, mut longest) = (0usize, 0u64, 0u64, 0usize);
        for h in hit.iter().chain(std::iter::once(&false)) {
            if *h {
                run += 1;
            } else {
                if run >= 3 {
                    runs3 += 1;
                } else {
                    iso += run as u64;
                }
                longest = longest.max(run);
                run = 0;
            }
        }
        runs3_sum += runs3;
        iso_sum += iso;
        longest_sum += longest as u64;
        hits_sum += hit.iter().filter(|h| **h).count() as u64;
    }
    let tf = trials as f64;
    let cells = (RANGE_CELLS * ANGLE_CELLS) as f64 * tf;
    println!(
        "lambda {lambda} trials {trials}: mean DMHT drho {:.2} m, effective plots/scan {:.2}, model p_ch {:.4}, N_c {}, m0-model p0_cross {:.4}",
        drho_sum / tf,
        eff_sum as f64 / tf / n as f64,
        cm.p_ch,
        cm.n_c,
        cm.p0_cross
    );
    println!(
        "compound: chains {:.1} -> {:.2} effective plots/scan (with N_c: {} -> {:.2}), drho {:.2} cells",
        cp.chains,
        cp.clutter_per_scan(),
        cn.chains,
        cn.clutter_per_scan(),
        cp.drho
    );
    let mut sc5 = sc;
    sc5.n_targets = 5;
    println!(
        "gamma_1 for grid Pfa 1e-4: paper N_t=5 {}, N_t=0 {}; compound N_t=0 {}, N_t=5 {}; compound with N_c, N_t=0 {}",
        CellModel::new(model_params(&sc5)).gamma_for_pfa(1e-4),
        cm.gamma_for_pfa(1e-4),
        cp.gamma_for_pfa(1e-4),
        CompoundModel::new(model_params(&sc5), ChainSource::Censoring).gamma_for_pfa(1e-4),
        cn.gamma_for_pfa(1e-4)
    );
    println!("gamma  sim_cell_tail  paper_cell_tail  compound_cell_tail  cmp_Nc_cell_tail  sim_grid(max>=g)  paper_grid  compound_grid  cmp_Nc_grid");
    let mut tail = 0u64;
    let mut mtail = 0u64;
    let mut rows = Vec::new();
    for gm in (1..=n).rev() {
        tail += hist[gm];
        mtail += max_hist[gm];
        rows.push(format!(
            "{gm:>5}  {:>13.3e}  {:>15.3e}  {:>18.3e}  {:>16.3e}  {:>16.4}  {:>10.3e}  {:>13.3e}  {:>11.3e}",
            tail as f64 / cells,
            cm.pfa_cell(gm),
            cp.pfa_cell(gm),
            cn.pfa_cell(gm),
            mtail as f64 / tf,
            cm.pfa_grid(gm),
            cp.pfa_grid(gm),
            cn.pfa_grid(gm)
        ));
    }
    for r in rows.iter().rev() {
        println!("{r}");
    }
    println!(
        "largest cell per period: mean count(scans hit) {:.2}, runs >= 3 scans {:.2}, scans outside such runs {:.2}, longest run {:.2}",
        hits_sum as f64 / tf,
        runs3_sum as f64 / tf,
        iso_sum as f64 / tf,
        longest_sum as f64 / tf
    );
}
