//! Monte Carlo evaluation of `faint reproduce mht`: one trial of both detectors scored
//! by the rules of the module doc ([`evaluate_trial`]), the scoring and clutter-only
//! trials of one lambda, and their per-lambda summary against the models.

use faint_core::detect::mht::{Track, NO_PLOT};
use faint_core::detect::Detector;

use super::args::{Args, Sizes};
use super::calibration::{model_params, proportion_ci, Gammas, GridModel};
use super::detectors::{detectors_with, MhtAt};
use crate::analysis::mht::{self as model, max_count, CellModel, ChainSource, CompoundModel};
use crate::instances::mht::{with_mht_capacity, Classic, SCANS};
use crate::simulate::mht::{Origin, SeaClutter, Trial};

/// Line-to-truth tolerance (m).
pub const MATCH_TOL: f32 = 60.0;

/// Everything measured in one trial.
#[derive(Debug, Clone, Copy, Default, serde::Serialize, serde::Deserialize)]
pub struct TrialStats {
    /// Clutter plots over the period.
    pub pre_clutter: u32,
    /// Clutter plots marked effective.
    pub eff_clutter: u32,
    /// Target plots over the period.
    pub target_plots: u32,
    /// Target plots marked effective.
    pub eff_target: u32,
    /// MHT: targets detected.
    pub mht_detected: u32,
    /// MHT: false tracks.
    pub mht_false: u32,
    /// MHT: duplicate tracks.
    pub mht_dup: u32,
    /// MHT: target plots of detected targets.
    pub mht_target_plots: u32,
    /// MHT: of those, not in the track.
    pub mht_lost: u32,
    /// MHT: plots in the matched tracks.
    pub mht_track_plots: u32,
    /// MHT: of those, not the target's.
    pub mht_wrong: u32,
    /// MHT: of the matched tracks' plots, taken by look-back.
    pub mht_lookback: u32,
    /// Classic: targets detected.
    pub classic_detected: u32,
    /// Classic: false peaks.
    pub classic_false: u32,
    /// Largest DMHT cell count of the period.
    pub mht_max_count: u8,
    /// Largest classic cell count of the period.
    pub classic_max_count: u8,
    /// MHT: plots, gated pairs and chains skipped at the detector's capacity (plots
    /// beyond `PLOTS` per scan, pairs beyond `PLOTS` per scan pair, chains beyond the
    /// per-scan budget), over the period.
    #[serde(default)]
    pub capacity_skips: u32,
    /// MHT: peaks of the period dropped beyond the track capacity.
    #[serde(default)]
    pub peaks_dropped: u32,
}

fn line_matches(theta: f32, c: f32, trial: &Trial, i: usize, t_scan: f32) -> bool {
    let (co, si) = (theta.cos(), theta.sin());
    let t = &trial.targets[i];
    (0..trial.scans.len()).all(|s| {
        let (x, y) = t.position(s as f32 * t_scan);
        (x * co + y * si - c).abs() <= MATCH_TOL
    })
}

/// Plots of `track` made by target `i`.
pub fn target_plots_in(track: &Track<SCANS>, trial: &Trial, i: usize) -> usize {
    (0..trial.scans.len())
        .filter(|&s| {
            track.plots[s] != NO_PLOT
                && trial.scans[s].origin.get(usize::from(track.plots[s]))
                    == Some(&Origin::Target(i))
        })
        .count()
}

/// The targets a confirmed track matches (scoring rule of the module doc: the line within
/// `MATCH_TOL` of all the target's noise-free positions, or more than half of the track's
/// plots the target's).
pub fn track_targets(track: &Track<SCANS>, trial: &Trial, t_scan: f32) -> Vec<usize> {
    (0..trial.targets.len())
        .filter(|&i| {
            line_matches(track.theta, track.c, trial, i, t_scan)
                || 2 * target_plots_in(track, trial, i) > usize::from(track.n_plots)
        })
        .collect()
}

/// Run both detectors on one trial and score them (MHT-TBD at any capacity).
pub fn evaluate_trial<const P: usize, const T: usize>(
    sc: &SeaClutter,
    trial: &Trial,
    mht: &mut MhtAt<P, T>,
    classic: &mut Classic,
) -> TrialStats {
    let mut st = TrialStats::default();
    let nt = trial.targets.len();
    for scan in &trial.scans {
        if let Ok(r) = mht.step(&scan.plots) {
            let c = &r.censor;
            st.capacity_skips += r.overflow + c.pair_overflow + c.chain_overflow;
            if let Some(d) = r.detection {
                st.peaks_dropped += u32::from(d.condense.dropped);
            }
        }
        let _ = classic.step(&scan.plots);
    }
    // censoring statistics (plots are stored in input order: all are in-area)
    for (s, scan) in trial.scans.iter().enumerate() {
        for (k, o) in scan.origin.iter().enumerate() {
            let eff = mht.is_effective(s, k);
            match o {
                Origin::Clutter => {
                    st.pre_clutter += 1;
                    st.eff_clutter += u32::from(eff);
                }
                Origin::Target(_) => {
                    st.target_plots += 1;
                    st.eff_target += u32::from(eff);
                }
            }
        }
    }
    st.mht_max_count = max_count(mht.accumulator());
    st.classic_max_count = max_count(classic.accumulator());
    // MHT tracks
    let tracks = mht.tracks();
    let mut matched = vec![false; nt];
    for tr in tracks {
        let hits = track_targets(tr, trial, sc.t_scan);
        if hits.is_empty() {
            st.mht_false += 1;
        } else if hits.iter().all(|&i| matched[i]) {
            st.mht_dup += 1;
        }
        for i in hits {
            matched[i] = true;
        }
    }
    for (i, m) in matched.iter().enumerate() {
        if !*m {
            continue;
        }
        st.mht_detected += 1;
        let own = |s: usize, k: u16| {
            k != NO_PLOT && trial.scans[s].origin[usize::from(k)] == Origin::Target(i)
        };
        let best = tracks.iter().max_by_key(|tr| {
            (0..trial.scans.len())
                .filter(|&s| own(s, tr.plots[s]))
                .count()
        });
        let n_own: u32 = trial
            .scans
            .iter()
            .map(|sd| {
                sd.origin
                    .iter()
                    .filter(|&&o| o == Origin::Target(i))
                    .count() as u32
            })
            .sum();
        st.mht_target_plots += n_own;
        if let Some(tr) = best {
            let got = (0..trial.scans.len())
                .filter(|&s| own(s, tr.plots[s]))
                .count() as u32;
            st.mht_lost += n_own - got.min(n_own);
            st.mht_track_plots += u32::from(tr.n_plots);
            st.mht_wrong += u32::from(tr.n_plots) - got;
            st.mht_lookback += tr.lookback.count_ones();
        } else {
            st.mht_lost += n_own;
        }
    }
    // classic peaks
    let g = classic.geometry();
    let (x0, y0) = g.origin();
    let mut cmatched = vec![false; nt];
    for pk in classic.peaks() {
        let a = usize::from(pk.a);
        let (co, si) = g.trig(a);
        let c = x0 * co + y0 * si + g.rho_center(usize::from(pk.r));
        let hits: Vec<usize> = (0..nt)
            .filter(|&i| line_matches(g.theta(a), c, trial, i, sc.t_scan))
            .collect();
        if hits.is_empty() {
            st.classic_false += 1;
        }
        for i in hits {
            cmatched[i] = true;
        }
    }
    st.classic_detected = cmatched.iter().filter(|&&m| m).count() as u32;
    st
}

/// The trials `range` of lambda number `li` at the thresholds `th`: scoring trials
/// (targets on, stream `derive_seed(seed, li)`) or, with `null`, clutter-only trials
/// (stream `derive_seed(seed, li) ^ 0x6e75_6c6c`). Trial `i` is the same whichever
/// range (shard) runs it.
pub(super) fn trials(
    args: &Args,
    li: usize,
    sc: &SeaClutter,
    th: &Gammas,
    null: bool,
    range: std::ops::Range<usize>,
) -> anyhow::Result<Vec<TrialStats>> {
    let lambda = sc.lambda;
    let mut sc = *sc;
    let (g1, gc) = (th.gamma1, th.gamma_classic);
    let g1u = g1.clamp(1, 255) as u8;
    let gcu = gc.clamp(1, 255) as u8;
    // Surface a configuration error once, before the trials (which cannot report it).
    with_mht_capacity!(args.plots, args.tracks, |P, T| detectors_with::<P, T>(
        &sc, g1u, gcu
    )
    .map(|_| ())
    .map_err(|e| anyhow::anyhow!("lambda {lambda}: {e}")))?;
    let mut seed = faint_core::rng::derive_seed(args.seed, li as u64);
    let label = if null {
        sc.n_targets = 0;
        seed ^= 0x6e75_6c6c;
        format!("null lambda={lambda}")
    } else {
        format!("mht lambda={lambda}")
    };
    Ok(with_mht_capacity!(args.plots, args.tracks, |P, T| {
        crate::montecarlo::run_trial_range(seed, range, &label, |_, rng| {
            let Ok((mut m, mut c)) = detectors_with::<P, T>(&sc, g1u, gcu) else {
                return TrialStats::default();
            };
            let tr = sc.generate(rng);
            evaluate_trial(&sc, &tr, &mut *m, &mut c)
        })
    }))
}

/// Per-lambda summary row.
#[derive(Debug, serde::Serialize)]
pub(super) struct Summary {
    pub(super) lambda: f32,
    pub(super) trials: usize,
    pub(super) null_trials: usize,
    pub(super) gamma1: usize,
    pub(super) gamma_classic: usize,
    pub(super) clutter_per_scan_before: f64,
    pub(super) clutter_per_scan_after: f64,
    pub(super) clutter_after_model: f64,
    pub(super) clutter_after_compound: f64,
    pub(super) target_plots_kept: f64,
    pub(super) mht_pd: f64,
    pub(super) mht_pd_lo: f64,
    pub(super) mht_pd_hi: f64,
    pub(super) mht_false_tracks: u64,
    pub(super) mht_trials_with_fa: u64,
    pub(super) mht_dup: u64,
    pub(super) plot_loss: f64,
    pub(super) wrong_plot: f64,
    pub(super) lookback_share: f64,
    pub(super) classic_pd: f64,
    pub(super) classic_false_peaks: u64,
    pub(super) classic_trials_with_fa: u64,
    pub(super) null_pfa_sim: f64,
    pub(super) null_pfa_lo: f64,
    pub(super) null_pfa_hi: f64,
    pub(super) null_pfa_model: f64,
    pub(super) null_confirmed_fa_trials: u64,
    pub(super) classic_null_pfa_sim: f64,
    pub(super) gamma1_model: usize,
    pub(super) calib_periods: u64,
    pub(super) calib_periods_with_track: u64,
    pub(super) calib_rate: f64,
    pub(super) calib_rate_hi: f64,
    pub(super) calib_at_floor: bool,
    pub(super) check_periods: u64,
    pub(super) check_periods_with_track: u64,
    pub(super) check_tracks: u64,
    pub(super) check_rate: f64,
    pub(super) check_rate_lo: f64,
    pub(super) check_rate_hi: f64,
    /// MHT: plots, pairs and chains skipped at capacity, scoring and clutter-only trials.
    pub(super) capacity_skips: u64,
    /// MHT: peaks dropped beyond the track capacity, scoring and clutter-only trials.
    pub(super) peaks_dropped: u64,
}

/// Clutter-only Pfa row.
#[derive(Debug, serde::Serialize)]
pub(super) struct NullRow {
    pub(super) lambda: f32,
    pub(super) gamma: usize,
    pub(super) sim_pfa: f64,
    pub(super) model_pfa: f64,
    pub(super) classic_sim_pfa: f64,
}

/// The summary of one lambda from its scoring trials `res` and clutter-only trials
/// `nres`; appends the clutter-only grid Pfa per `gamma` to `null_rows`.
pub(super) fn summarise(
    args: &Args,
    sizes: &Sizes,
    sc: &SeaClutter,
    th: &Gammas,
    res: &[TrialStats],
    nres: &[TrialStats],
    null_rows: &mut Vec<NullRow>,
) -> Summary {
    let Sizes {
        trials,
        null_trials,
        ..
    } = *sizes;
    let Gammas {
        gamma1: g1,
        gamma1_model: g1_model,
        gamma_classic: gc,
        ref calib,
        ref check,
    } = *th;
    let lambda = sc.lambda;
    let sc = *sc;
    let mut null_sc = sc;
    null_sc.n_targets = 0;
    let sum = |f: &dyn Fn(&TrialStats) -> u32| res.iter().map(|t| u64::from(f(t))).sum::<u64>();
    let n_scans = (sc.n_scans * trials) as f64;
    let det = sum(&|t| t.mht_detected);
    let (pd, lo, hi) = proportion_ci(det, (trials * sc.n_targets) as u64);
    let cdet = sum(&|t| t.classic_detected);
    let cm = CellModel::new(model_params(&sc));
    // the clutter-only periods are compared with the chosen model for N_t = 0
    let null_model = GridModel::new(model_params(&null_sc), args.model);
    let m0 = cm
        .p0_raw
        .iter()
        .enumerate()
        .skip(1)
        .map(|(k, p)| k as f64 * p)
        .sum::<f64>();
    // expected effective clutter plots per scan: N_rho N_theta E[m] / N per cell-track
    // would count a plot once per cell it shares; the model's number of clutter
    // tracks times their mean length, per scan:
    let after_model = cm.n_c * (m0 / model::tail(&cm.p0_raw, 1).max(1e-300)) / sc.n_scans as f64;
    let nhit = nres
        .iter()
        .filter(|t| usize::from(t.mht_max_count) >= g1)
        .count() as u64;
    let (np, nlo, nhi) = proportion_ci(nhit, null_trials as u64);
    let chit = nres
        .iter()
        .filter(|t| usize::from(t.classic_max_count) >= gc)
        .count() as f64;
    for g in 1..=sc.n_scans {
        let k = nres
            .iter()
            .filter(|t| usize::from(t.mht_max_count) >= g)
            .count() as u64;
        let kc = nres
            .iter()
            .filter(|t| usize::from(t.classic_max_count) >= g)
            .count() as u64;
        null_rows.push(NullRow {
            lambda,
            gamma: g,
            sim_pfa: k as f64 / null_trials.max(1) as f64,
            model_pfa: null_model.pfa_grid(g),
            classic_sim_pfa: kc as f64 / null_trials.max(1) as f64,
        });
    }
    Summary {
        lambda,
        trials,
        null_trials,
        gamma1: g1,
        gamma_classic: gc,
        clutter_per_scan_before: sum(&|t| t.pre_clutter) as f64 / n_scans,
        clutter_per_scan_after: sum(&|t| t.eff_clutter) as f64 / n_scans,
        clutter_after_model: after_model,
        clutter_after_compound: CompoundModel::new(model_params(&null_sc), ChainSource::Censoring)
            .clutter_per_scan(),
        target_plots_kept: sum(&|t| t.eff_target) as f64 / sum(&|t| t.target_plots).max(1) as f64,
        mht_pd: pd,
        mht_pd_lo: lo,
        mht_pd_hi: hi,
        mht_false_tracks: sum(&|t| t.mht_false),
        mht_trials_with_fa: res.iter().filter(|t| t.mht_false > 0).count() as u64,
        mht_dup: sum(&|t| t.mht_dup),
        plot_loss: sum(&|t| t.mht_lost) as f64 / sum(&|t| t.mht_target_plots).max(1) as f64,
        wrong_plot: sum(&|t| t.mht_wrong) as f64 / sum(&|t| t.mht_track_plots).max(1) as f64,
        lookback_share: sum(&|t| t.mht_lookback) as f64 / sum(&|t| t.mht_track_plots).max(1) as f64,
        classic_pd: cdet as f64 / (trials * sc.n_targets).max(1) as f64,
        classic_false_peaks: sum(&|t| t.classic_false),
        classic_trials_with_fa: res.iter().filter(|t| t.classic_false > 0).count() as u64,
        null_pfa_sim: np,
        null_pfa_lo: nlo,
        null_pfa_hi: nhi,
        null_pfa_model: null_model.pfa_grid(g1),
        null_confirmed_fa_trials: nres.iter().filter(|t| t.mht_false > 0).count() as u64,
        classic_null_pfa_sim: chit / null_trials.max(1) as f64,
        gamma1_model: g1_model,
        calib_periods: calib.as_ref().map_or(0, |c| c.0.periods),
        calib_periods_with_track: calib
            .as_ref()
            .and_then(|c| c.0.with_track.get(g1).copied())
            .unwrap_or(0),
        calib_rate: calib.as_ref().map_or(f64::NAN, |c| {
            proportion_ci(c.0.with_track.get(g1).copied().unwrap_or(0), c.0.periods).0
        }),
        calib_rate_hi: calib.as_ref().map_or(f64::NAN, |c| {
            proportion_ci(c.0.with_track.get(g1).copied().unwrap_or(0), c.0.periods).2
        }),
        calib_at_floor: calib.as_ref().is_some_and(|c| c.1),
        check_periods: check.as_ref().map_or(0, |c| c.periods),
        check_periods_with_track: check
            .as_ref()
            .and_then(|c| c.with_track.get(g1).copied())
            .unwrap_or(0),
        check_tracks: check
            .as_ref()
            .and_then(|c| c.tracks.get(g1).copied())
            .unwrap_or(0),
        check_rate: check.as_ref().map_or(f64::NAN, |c| {
            proportion_ci(c.with_track.get(g1).copied().unwrap_or(0), c.periods).0
        }),
        check_rate_lo: check.as_ref().map_or(f64::NAN, |c| {
            proportion_ci(c.with_track.get(g1).copied().unwrap_or(0), c.periods).1
        }),
        check_rate_hi: check.as_ref().map_or(f64::NAN, |c| {
            proportion_ci(c.with_track.get(g1).copied().unwrap_or(0), c.periods).2
        }),
        capacity_skips: res
            .iter()
            .chain(nres)
            .map(|t| u64::from(t.capacity_skips))
            .sum(),
        peaks_dropped: res
            .iter()
            .chain(nres)
            .map(|t| u64::from(t.peaks_dropped))
            .sum(),
    }
}
