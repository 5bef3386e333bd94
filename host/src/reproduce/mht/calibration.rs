//! Thresholds of `faint reproduce mht`: `gamma_1` and the classic `gamma` from the
//! analytic grid false-alarm models ([`thresholds_with`], [`GridModel`]), or `gamma_1`
//! calibrated by simulation (clutter-only false-track counts per candidate, the pilot
//! floor, [`calibrate`]) and checked on independent periods.

#[cfg(doc)]
use faint_core::detect::mht::MhtTbd;
use faint_core::detect::Detector;

use super::args::{Args, CalibRule, GammaFrom, ModelChoice, Sizes};
use super::detectors::detectors_with;
use crate::analysis::mht::{
    self as model, max_count, CellModel, ChainSource, CompoundModel, ModelParams,
};
use crate::instances::mht::{with_mht_capacity, ANGLE_CELLS, PLOTS, RANGE_CELLS, TRACKS};
use crate::simulate::mht::SeaClutter;

/// Clutter-only false-track counts per candidate `gamma_1` (index = `gamma_1`).
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FalseTrackCounts {
    /// Periods simulated.
    pub periods: u64,
    /// Smallest candidate simulated (entries below it are not measured).
    pub floor: u8,
    /// `with_track[g]`: periods with at least one confirmed track at `gamma_1 = g`.
    pub with_track: Vec<u64>,
    /// `tracks[g]`: confirmed tracks at `gamma_1 = g`, summed over the periods.
    pub tracks: Vec<u64>,
}

/// Simulate `periods` clutter-only periods of `sc` (targets removed; period `i` uses
/// `Rng::from_stream(seed, i)` through [`crate::montecarlo::run_trials`]) and count the
/// confirmed tracks, all false, for every `gamma_1` in `floor..=N`. Each period is
/// censored and integrated once; [`MhtTbd::redetect`] re-runs only the threshold,
/// condensing and track confirmation per candidate, and only for candidates up to the
/// period's largest DMHT count (no cell reaches a higher `gamma_1`: no peak, no track).
/// The host's MHT-TBD; [`false_track_counts_at`] takes the plot capacity.
pub fn false_track_counts(
    sc: &SeaClutter,
    periods: usize,
    seed: u64,
    floor: u8,
) -> FalseTrackCounts {
    false_track_counts_at((PLOTS, TRACKS), sc, periods, seed, floor)
}

/// [`false_track_counts`] with the MHT-TBD instance of `capacity = (plots per scan,
/// tracks)` (the host's or the board's, see `instances::mht`).
pub fn false_track_counts_at(
    capacity: (usize, usize),
    sc: &SeaClutter,
    periods: usize,
    seed: u64,
    floor: u8,
) -> FalseTrackCounts {
    with_mht_capacity!(capacity.0, capacity.1, |P, T| counts::<P, T>(
        sc, periods, seed, floor
    ))
}

fn counts<const P: usize, const T: usize>(
    sc: &SeaClutter,
    periods: usize,
    seed: u64,
    floor: u8,
) -> FalseTrackCounts {
    let mut null_sc = *sc;
    null_sc.n_targets = 0;
    let n = null_sc.n_scans;
    let floor = floor.max(1);
    // gamma_1 = N + 1 at the step itself: no cell reaches it, the step's own stage 3 is
    // a no-op and every candidate comes from `redetect`.
    let g_step = (n + 1).min(255) as u8;
    let per: Vec<Vec<u16>> = crate::montecarlo::run_trials(
        seed,
        periods,
        &format!("calib lambda={}", sc.lambda),
        |_, rng| {
            let mut out = vec![0u16; n + 1];
            let Ok((mut m, _)) = detectors_with::<P, T>(&null_sc, g_step, 1) else {
                return out;
            };
            let tr = null_sc.generate(rng);
            for scan in &tr.scans {
                let _ = m.step(&scan.plots);
            }
            let top = usize::from(max_count(m.accumulator())).min(n);
            for (g, o) in out
                .iter_mut()
                .enumerate()
                .take(top + 1)
                .skip(usize::from(floor))
            {
                if let Ok(d) = m.redetect(g as u8) {
                    *o = d.tracks;
                }
            }
            out
        },
    );
    let mut c = FalseTrackCounts {
        periods: periods as u64,
        floor,
        with_track: vec![0; n + 1],
        tracks: vec![0; n + 1],
    };
    for p in &per {
        for (g, &t) in p.iter().enumerate() {
            c.with_track[g] += u64::from(t > 0);
            c.tracks[g] += u64::from(t);
        }
    }
    c
}

/// Periods of the pilot batch of [`pilot_floor`].
pub const PILOT_PERIODS: usize = 200;

/// The calibration's floor from a pilot batch of [`PILOT_PERIODS`] clutter-only periods
/// (seeds `Rng::from_stream(seed, i)`; not reused by the calibration): the largest
/// `gamma_1 >= min_gamma` at which at least 10 % of the pilot periods give a confirmed
/// track (`min_gamma` when none). A rate of >= 10 % in 200 periods puts the true rate far
/// above any `Pfa` worth calibrating (< 1e-2), so the calibration fails there and never
/// needs the candidates below, which are the costly ones (many peaks to recover).
pub fn pilot_floor(sc: &SeaClutter, seed: u64, min_gamma: u8) -> u8 {
    pilot_floor_at((PLOTS, TRACKS), sc, seed, min_gamma)
}

/// [`pilot_floor`] with the MHT-TBD instance of `capacity = (plots per scan, tracks)`.
pub fn pilot_floor_at(capacity: (usize, usize), sc: &SeaClutter, seed: u64, min_gamma: u8) -> u8 {
    let c = false_track_counts_at(capacity, sc, PILOT_PERIODS, seed, min_gamma);
    let min = usize::from(c.floor);
    (min..c.with_track.len())
        .rev()
        .find(|&g| 10 * c.with_track[g] >= c.periods)
        .map_or(c.floor, |g| g.min(255) as u8)
}

/// The calibrated `gamma_1`: the smallest candidate `g >= floor` such that every
/// candidate `g' >= g` passes `rule` (the rate need not be monotone in `gamma_1`: the
/// confirmation needs `confirm_frac * gamma_1` plots); `N + 1` (never fires) if even
/// `N` fails. The second value is true when the result is the floor itself (the rate
/// below it was not measured: lower `--calib-min-gamma`).
pub fn calibrate(c: &FalseTrackCounts, pfa: f64, rule: CalibRule) -> (usize, bool) {
    let n = c.with_track.len().saturating_sub(1);
    let floor = usize::from(c.floor).max(1);
    let mut g = n + 1;
    while g > floor && rule.passes(c.with_track[g - 1], c.periods, pfa) {
        g -= 1;
    }
    (g, g == floor)
}

/// A grid false-alarm model of either kind.
#[derive(Debug, Clone)]
pub enum GridModel {
    /// Eq. 20-26.
    Paper(CellModel),
    /// Compound law.
    Compound(CompoundModel),
}

impl GridModel {
    /// Build the chosen model.
    pub fn new(mp: ModelParams, choice: ModelChoice) -> Self {
        match choice {
            ModelChoice::Paper => Self::Paper(CellModel::new(mp)),
            ModelChoice::Compound => Self::Compound(CompoundModel::new(mp, ChainSource::Censoring)),
            ModelChoice::CompoundNc => Self::Compound(CompoundModel::new(mp, ChainSource::PaperNc)),
        }
    }
    /// Whole-grid Pfa at `gamma`.
    pub fn pfa_grid(&self, gamma: usize) -> f64 {
        match self {
            Self::Paper(m) => m.pfa_grid(gamma),
            Self::Compound(m) => m.pfa_grid(gamma),
        }
    }
    /// Mean cell Pfa at `gamma`.
    pub fn pfa_cell(&self, gamma: usize) -> f64 {
        match self {
            Self::Paper(m) => m.pfa_cell(gamma),
            Self::Compound(m) => m.pfa_cell(gamma),
        }
    }
    /// Smallest `gamma` with grid Pfa `<= pfa`.
    pub fn gamma_for_pfa(&self, pfa: f64) -> usize {
        match self {
            Self::Paper(m) => m.gamma_for_pfa(pfa),
            Self::Compound(m) => m.gamma_for_pfa(pfa),
        }
    }
}

/// [`thresholds_with`] the default model ([`ModelChoice::Compound`]).
pub fn thresholds(sc: &SeaClutter, pfa: f64) -> (usize, usize) {
    thresholds_with(sc, pfa, ModelChoice::default())
}

/// Thresholds for a lambda: `(gamma_1 from the MHT model `choice`, classic gamma from the
/// binomial strip model)`, both for whole-grid `Pfa <= pfa` (`N + 1` when no threshold
/// reaches it: the detector then never fires).
pub fn thresholds_with(sc: &SeaClutter, pfa: f64, choice: ModelChoice) -> (usize, usize) {
    let mp = model_params(sc);
    let g1 = GridModel::new(mp, choice).gamma_for_pfa(pfa);
    let gc = model::classic_gamma(
        f64::from(sc.area[1] - sc.area[0]),
        RANGE_CELLS,
        ANGLE_CELLS,
        sc.n_scans,
        f64::from(sc.lambda),
        pfa,
    );
    (g1, gc)
}

/// The model parameters of a scenario.
pub fn model_params(sc: &SeaClutter) -> ModelParams {
    ModelParams {
        a_cells: sc.cells(),
        n: sc.n_scans,
        m: 3,
        pd0: f64::from(sc.pd0),
        n_targets: sc.n_targets,
        gate_cells: f64::from(sc.v_max * sc.t_scan / sc.resolution),
        n_rho: RANGE_CELLS,
        n_theta: ANGLE_CELLS,
        lambda: f64::from(sc.lambda),
    }
}

/// Clopper-Pearson 95 % interval of `k / n`: `(p, lo, hi)`.
pub fn proportion_ci(k: u64, n: u64) -> (f64, f64, f64) {
    let p = crate::stats::detection::proportion(k as usize, n as usize);
    (p.p, p.lo, p.hi)
}

/// Calibration / check row (`calib.csv`).
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct CalibRow {
    lambda: f32,
    batch: String,
    gamma: usize,
    periods: u64,
    periods_with_track: u64,
    tracks: u64,
    rate: f64,
    rate_lo: f64,
    rate_hi: f64,
}

fn calib_rows(lambda: f32, batch: &'static str, c: &FalseTrackCounts, rows: &mut Vec<CalibRow>) {
    for g in usize::from(c.floor)..c.with_track.len() {
        let (p, lo, hi) = proportion_ci(c.with_track[g], c.periods);
        rows.push(CalibRow {
            lambda,
            batch: batch.to_string(),
            gamma: g,
            periods: c.periods,
            periods_with_track: c.with_track[g],
            tracks: c.tracks[g],
            rate: p,
            rate_lo: lo,
            rate_hi: hi,
        });
    }
}

/// Seed tags of the pilot, calibration and check batches (independent of the scoring trials'
/// `derive_seed(seed, li)` and of the null trials' `seed ^ 0x6e75_6c6c`).
const CALIB_TAG: u64 = 0x6361_6c69_6200_0001;
const CHECK_TAG: u64 = 0x6368_6563_6b00_0002;
const PILOT_TAG: u64 = 0x7069_6c6f_7400_0003;

/// The thresholds of one lambda and, with `--gamma-from sim`, the counts behind `gamma_1`.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Gammas {
    /// `gamma_1` used by the trials.
    pub(super) gamma1: usize,
    /// `gamma_1` of the `--model` law.
    pub(super) gamma1_model: usize,
    /// Threshold of the classic detector.
    pub(super) gamma_classic: usize,
    /// Calibration counts and whether `gamma_1` is at their floor (`--gamma-from sim`).
    pub(super) calib: Option<(FalseTrackCounts, bool)>,
    /// Counts of the independent check periods (`--gamma-from sim`, `--calib-check > 0`).
    pub(super) check: Option<FalseTrackCounts>,
}

/// The thresholds of lambda number `li` (scenario `sc`): `--gamma1`, or `gamma_1`
/// calibrated by simulation (its rows appended to `calib_csv`), or the model's.
pub(super) fn gammas(
    args: &Args,
    sizes: &Sizes,
    li: usize,
    sc: &SeaClutter,
    calib_csv: &mut Vec<CalibRow>,
) -> Gammas {
    let Sizes {
        calib_periods,
        calib_check,
        ..
    } = *sizes;
    let lambda = sc.lambda;
    let (g1_model, gc) = thresholds_with(sc, args.pfa, args.model);
    let mut calib = None;
    let mut check = None;
    let g1 = if let Some(g) = args.gamma1 {
        usize::from(g)
    } else if args.gamma_from == GammaFrom::Sim {
        let floor = pilot_floor_at(
            (args.plots, args.tracks),
            sc,
            faint_core::rng::derive_seed(args.seed ^ PILOT_TAG, li as u64),
            args.calib_min_gamma,
        );
        let c = false_track_counts_at(
            (args.plots, args.tracks),
            sc,
            calib_periods,
            faint_core::rng::derive_seed(args.seed ^ CALIB_TAG, li as u64),
            floor,
        );
        let (g, at_floor) = calibrate(&c, args.pfa, args.calib_rule);
        calib_rows(lambda, "calib", &c, calib_csv);
        if calib_check > 0 {
            // the check needs the chosen gamma_1 only; two below it for context
            let k = false_track_counts_at(
                (args.plots, args.tracks),
                sc,
                calib_check,
                faint_core::rng::derive_seed(args.seed ^ CHECK_TAG, li as u64),
                (g.saturating_sub(2).clamp(1, 255) as u8).max(args.calib_min_gamma),
            );
            calib_rows(lambda, "check", &k, calib_csv);
            check = Some(k);
        }
        calib = Some((c, at_floor));
        g
    } else {
        g1_model
    };
    Gammas {
        gamma1: g1,
        gamma1_model: g1_model,
        gamma_classic: gc,
        calib,
        check,
    }
}
