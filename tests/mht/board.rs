//! `faint reproduce mht --plots 512 [--tracks 16]`: the STM32H743's MHT-TBD (512 plots
//! per scan, 32 tracks) and a smaller track store next to the host's (640, 32). Above 512
//! plots per scan the board's instance skips plots and counts them; the host's keeps them.

use faint::host::instances::mht::{BOARD_PLOTS, PLOTS, SMALL_TRACKS, TRACKS};
use faint::host::reproduce::mht::{detectors, detectors_with, evaluate_trial};
use faint::host::simulate::mht::SeaClutter;
use faint::rng::Rng;

/// At 560 clutter plots per scan every scan of this trial holds more than 512 plots
/// and fewer than 640: the board's instance skips some, the host's none.
#[test]
fn the_board_instance_skips_plots_beyond_512() {
    assert_eq!(
        (BOARD_PLOTS, SMALL_TRACKS, PLOTS, TRACKS),
        (512, 16, 640, 32)
    );
    let sc = SeaClutter::paper(560.0);
    let tr = sc.generate(&mut Rng::from_stream(7, 0));
    let most = tr.scans.iter().map(|s| s.plots.len()).max().unwrap();
    let least = tr.scans.iter().map(|s| s.plots.len()).min().unwrap();
    assert!(
        least > BOARD_PLOTS && most < PLOTS,
        "{least}..={most} plots per scan"
    );
    let (mut host, mut classic) = detectors(&sc, 30, 30).unwrap();
    let h = evaluate_trial(&sc, &tr, &mut *host, &mut classic);
    let (mut board, mut classic) = detectors_with::<BOARD_PLOTS, TRACKS>(&sc, 30, 30).unwrap();
    let b = evaluate_trial(&sc, &tr, &mut *board, &mut classic);
    assert_eq!(h.capacity_skips, 0);
    let beyond: usize = tr.scans.iter().map(|s| s.plots.len() - BOARD_PLOTS).sum();
    assert!(
        b.capacity_skips as usize >= beyond,
        "{} < {beyond}",
        b.capacity_skips
    );
    // the host's detector marks effective plots the board's never saw
    assert!(h.eff_clutter + h.eff_target >= b.eff_clutter + b.eff_target);
}

/// The flags run end to end and the summary names the capacity; another value is a
/// one-line error.
#[test]
fn capacity_flags_run_and_name_the_capacity() {
    let dir = crate::common::temp("mht", "plots-flag");
    let out = dir.to_str().unwrap();
    let base = [
        "--quiet",
        "reproduce",
        "mht",
        "--quick",
        "--lambda",
        "560",
        "--trials",
        "2",
        "--null-trials",
        "1",
        "--out",
        out,
    ];
    for (plots, tracks, skipped) in [
        ("512", "16", true),
        ("640", "32", false),
        ("512", "32", true),
    ] {
        let mut a = base.to_vec();
        a.extend(["--plots", plots, "--tracks", tracks]);
        let (code, err) = crate::common::faint(&a);
        assert_eq!(code, 0, "--plots {plots}: {err}");
        let md = std::fs::read_to_string(dir.join("summary.md")).unwrap();
        let line = md
            .lines()
            .find(|l| l.starts_with("MHT-TBD capacity:"))
            .unwrap();
        assert!(
            line.contains(&format!("{plots} plots per scan, {tracks} tracks")),
            "{line}"
        );
        let skips = line
            .split("per lambda: ")
            .nth(1)
            .and_then(|s| s.split(';').next())
            .and_then(|s| s.trim().parse::<u64>().ok())
            .unwrap();
        assert_eq!(skips > 0, skipped, "--plots {plots}: {line}");
    }
    for (flag, v, needle) in [
        (
            "--plots",
            "600",
            "--plots must be one of [640, 512] (the compiled-in capacities), got 600",
        ),
        (
            "--tracks",
            "8",
            "--tracks must be one of [32, 16] (the compiled-in capacities), got 8",
        ),
    ] {
        let mut a = base.to_vec();
        a.extend([flag, v]);
        let (code, err) = crate::common::faint(&a);
        crate::common::assert_one_line_error(code, &err, needle, &[flag, v]);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
