//! MHT-TBD: simulation-calibrated `gamma_1` (`faint reproduce mht --gamma-from sim`).

use faint::host::montecarlo::set_quiet;
use faint::host::reproduce::mht::{
    calibrate, false_track_counts, pilot_floor, proportion_ci, CalibRule, FalseTrackCounts,
};
use faint::host::simulate::mht::SeaClutter;

fn counts(periods: u64, floor: u8, with_track: &[u64]) -> FalseTrackCounts {
    FalseTrackCounts {
        periods,
        floor,
        with_track: with_track.to_vec(),
        tracks: with_track.to_vec(),
    }
}

/// The selection rule on hand-made counts (N = 6, index = gamma_1).
#[test]
fn calibrate_rule_on_synthetic_counts() {
    // rates 1.0, 0.5, 0.2, 0.04, 0.06 (non-monotone), 0.01 at gamma 1..=6 of 100 periods
    let c = counts(100, 1, &[0, 100, 50, 20, 4, 6, 1]);
    // Pfa 0.05: 6 and 5? gamma 5 has 6 > 5: fails, so every candidate >= 6 must pass
    assert_eq!(calibrate(&c, 0.05, CalibRule::Point), (6, false));
    assert_eq!(calibrate(&c, 0.06, CalibRule::Point), (4, false));
    // nothing passes: N + 1 (never fires)
    assert_eq!(calibrate(&c, 0.001, CalibRule::Point), (7, false));
    // everything down to the floor passes: flagged
    let f = counts(100, 4, &[0, 0, 0, 0, 4, 3, 1]);
    assert_eq!(calibrate(&f, 0.05, CalibRule::Point), (4, true));
    // upper rule: 0 of 100 has a CP upper end ~0.036 > 0.01: nothing passes
    let z = counts(100, 1, &[0, 100, 50, 0, 0, 0, 0]);
    assert_eq!(calibrate(&z, 0.01, CalibRule::Upper), (7, false));
    assert_eq!(calibrate(&z, 0.05, CalibRule::Upper), (3, false));
    assert!(CalibRule::Point.passes(1, 10_000, 1e-4));
    assert!(!CalibRule::Point.passes(2, 10_000, 1e-4));
    assert!(!CalibRule::Upper.passes(0, 10_000, 1e-4));
    assert!(CalibRule::Upper.passes(0, 40_000, 1e-4));
}

/// Calibrate at Pfa 0.05 on 600 clutter-only periods (lambda 237), then check the chosen
/// `gamma_1` on 600 independent periods (other seed streams).
///
/// Tolerance: at a true rate p = 0.05 the check's count of 600 has sd
/// sqrt(600 * 0.05 * 0.95) = 5.3; the calibration's own estimate has the same noise, so
/// the chosen `gamma_1` may sit where the true rate is a little above 0.05. The test asks
/// that the check is *consistent* with the target: its Clopper-Pearson 95 % interval
/// at `gamma_1` reaches down to <= 0.05 (not significantly above; a wrong rule, a seed
/// reuse between the batches or `redetect` disagreeing with `step` would typically give
/// rates several times the target), and at `gamma_1 - 1` reaches up to >= 0.05 (the
/// calibration is not one count too conservative). Fixed seeds: deterministic.
#[test]
fn calibrated_gamma_holds_on_an_independent_batch() {
    set_quiet(true);
    let sc = SeaClutter::paper(237.0);
    let pfa = 0.05;
    let floor = pilot_floor(&sc, 11, 3);
    let c = false_track_counts(&sc, 600, 12, floor);
    let (g, at_floor) = calibrate(&c, pfa, CalibRule::Point);
    assert!(!at_floor, "calibration hit its floor {floor}");
    assert!(g <= sc.n_scans, "gamma {g}: nothing passed");
    // the rule itself: gamma passes, gamma - 1 does not
    assert!(c.with_track[g] as f64 <= pfa * 600.0);
    assert!(c.with_track[g - 1] as f64 > pfa * 600.0);
    let k = false_track_counts(&sc, 600, 13, (g - 1) as u8);
    let (p, lo, _) = proportion_ci(k.with_track[g], k.periods);
    assert!(lo <= pfa, "check rate {p} [{lo}, ..] at gamma {g}");
    let (p1, _, hi1) = proportion_ci(k.with_track[g - 1], k.periods);
    assert!(hi1 >= pfa, "check rate {p1} [.., {hi1}] at gamma {}", g - 1);
    eprintln!(
        "gamma {g}: calib {} / 600, check {} / 600 ({p1:.3} at gamma - 1)",
        c.with_track[g], k.with_track[g]
    );
}
