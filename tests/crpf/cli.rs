//! `faint reproduce crpf` checks its arguments before any Monte Carlo work: one line
//! naming the argument and the value; `--quick` never overrides a value given.

use crate::common::faint;

fn temp(name: &str) -> std::path::PathBuf {
    std::env::temp_dir().join(format!("faint_crpf_cli_{name}_{}", std::process::id()))
}

/// Every `(args, needle)` fails with one line holding `needle`, writing nothing.
fn all_fail(cases: &[(&[&str], &str)]) {
    let dir = temp("bad");
    let out = dir.to_str().expect("utf-8 temp dir");
    for &(args, needle) in cases {
        let mut all = vec!["--quiet", "reproduce", "crpf", "--out", out];
        all.extend_from_slice(args);
        let (code, err) = faint(&all);
        crate::common::assert_one_line_error(code, &err, needle, args);
        // Nothing was written: the check comes before the output directory and the runs.
        assert!(!dir.exists(), "{args:?} created {}", dir.display());
    }
}

#[test]
fn bad_arguments_fail_before_any_work() {
    all_fail(&[
        // 1000 H0 runs resolve Pfa 0.001 once, but the calibration's halves of 500 do
        // not: this used to fail only after all H0 runs.
        (
            &["--h0-trials", "1000"],
            "--h0-trials 1000 cannot resolve --pfa 0.001",
        ),
        (&["--pfa", "0"], "--pfa must lie in (0, 1), got 0"),
        (&["--particles", "300"], "--particles 300 is not supported"),
        (
            &["--trials", "0"],
            "--trials must lie in 1..=1000000, got 0",
        ),
        (&["--h0-trials", "2000000"], "--h0-trials must lie in"),
        (&["--snr-db", "4:2:1"], "--snr-db: '4:2:1' needs a <= b"),
        (
            &["--sweeps", "--sweep-h0-trials", "5"],
            "--sweep-h0-trials must lie in 11..=1000000, got 5",
        ),
        (&["--sweep-trials", "0"], "--sweep-trials must lie in"),
        (
            &["--birth-proposal", "fixed-share:1"],
            "--birth-proposal: 'fixed-share:1': the share must lie in (0, 1)",
        ),
        (
            &["--birth-proposal", "fixed-share:x"],
            "--birth-proposal: 'fixed-share:x': 'x' is not a number",
        ),
        (
            &["--birth-proposal", "fixed"],
            "--birth-proposal: 'fixed' is neither 'exact' nor 'fixed-share:<s>'",
        ),
    ]);
}

#[test]
fn quick_does_not_hide_bad_values() {
    all_fail(&[
        (
            &["--quick", "--pfa", "2"],
            "--pfa must lie in (0, 1), got 2",
        ),
        (
            &["--quick", "--pfa", "nan"],
            "--pfa must lie in (0, 1), got NaN",
        ),
        (
            &["--quick", "--particles", "0"],
            "--particles 0 is not supported",
        ),
        (
            &["--quick", "--trials", "0"],
            "--trials must lie in 1..=1000000, got 0",
        ),
        (&["--quick", "--h0-trials", "0"], "--h0-trials must lie in"),
        (
            &["--quick", "--snr-db", "garbage"],
            "--snr-db: 'garbage' is not a grid a:b:step",
        ),
        (
            &["--quick", "--sweep-h0-trials", "3"],
            "--sweep-h0-trials must lie in 11..=1000000, got 3",
        ),
        (
            &["--quick", "--sweep-trials", "0"],
            "--sweep-trials must lie in",
        ),
    ]);
}

#[test]
fn bad_snr_grids_name_the_argument_and_value() {
    all_fail(&[
        (
            &["--snr-db", "0:1:inf"],
            "--snr-db: 'inf' is not a finite number",
        ),
        (&["--snr-db", "0:x:1"], "--snr-db: 'x' is not a number"),
        (&["--snr-db", "0:4:0"], "--snr-db: '0:4:0' needs step > 0"),
        (&["--snr-db", "0:4:-1"], "--snr-db: '0:4:-1' needs step > 0"),
        (
            &["--snr-db", "0:1e9:1"],
            "--snr-db: '0:1e9:1' has 1000000001 points, at most 1000",
        ),
        (
            &["--snr-db", "-100:0:50"],
            "--snr-db must lie in [-60, 60] dB, got -100",
        ),
    ]);
}

#[test]
fn unwritable_out_is_named() {
    let (code, err) = faint(&[
        "--quiet",
        "reproduce",
        "crpf",
        "--quick",
        "--out",
        "/proc/faint-no-such-dir",
    ]);
    assert_ne!(code, 0);
    assert!(err.contains("/proc/faint-no-such-dir"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

#[test]
fn quick_keeps_given_values() {
    let dir = temp("keep");
    let (code, err) = faint(&[
        "--quiet",
        "reproduce",
        "crpf",
        "--quick",
        "--trials",
        "2",
        "--h0-trials",
        "40",
        "--snr-db",
        "4:4:1",
        "--sweep-h0-trials",
        "11",
        "--sweep-trials",
        "1",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let md = std::fs::read_to_string(dir.join("gaussian_n100/table.md")).unwrap();
    assert!(
        md.contains("40 H0 runs, 2 H1 runs per SNR point, SNR grid 4:4:1"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
