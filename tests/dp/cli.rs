//! `faint reproduce dp`: `--quick` end to end, and argument errors naming the argument.

use super::{faint, s, temp};

#[test]
fn reproduce_dp_quick_writes_every_output() {
    let dir = temp("quick");
    let (code, stdout, err) = faint(&["reproduce", "dp", "--quick", "--out", s(&dir)]);
    assert_eq!(code, 0, "{err}");
    assert!(stdout.contains("Fig. 6"), "{stdout}");
    for f in [
        "summary.md",
        "thresholds.csv",
        "fig6_fig7.csv",
        "runs.csv",
        "fig6_image_1px.svg",
        "fig7_image_1px.svg",
    ] {
        assert!(dir.join(f).exists(), "{f} missing");
    }
    // --quick: 2 SNR points x 3 methods at 1 px/frame, 4 runs each (image level).
    let csv = std::fs::read_to_string(dir.join("runs.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 2 * 3 * 4);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn quick_never_overrides_a_given_value() {
    let dir = temp("quick-runs");
    let (code, _, err) = faint(&[
        "reproduce",
        "dp",
        "--quick",
        "--runs",
        "2",
        "--snr",
        "3:3:1",
        "--no-fig5",
        "--out",
        s(&dir),
    ]);
    assert_eq!(code, 0, "{err}");
    let csv = std::fs::read_to_string(dir.join("runs.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 3 * 2);
    let md = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    assert!(md.contains("Runs per point: 2"), "{md}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_arguments_name_the_argument() {
    let dir = temp("bad-args");
    for (args, needle) in [
        (&["--runs", "0"][..], "--runs"),
        (&["--snr", "abc"][..], "--snr"),
        (&["--snr", "2:1:0.1"][..], "--snr"),
        (&["--speeds", "3"][..], "--speeds"),
        (&["--noise-runs", "10"][..], "--noise-runs"),
        (&["--frames", "41"][..], "--frames"),
        (&["--qb", "49"][..], "--qb"),
        (&["--transition", "soft"][..], "--transition"),
    ] {
        let mut all = vec!["reproduce", "dp", "--quick", "--out", s(&dir)];
        all.extend(args);
        let (code, _, err) = faint(&all);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn bad_values_and_paths_are_one_line_naming_them() {
    let dir = temp("bad-values");
    let _ = std::fs::remove_dir_all(&dir);
    for (args, needle) in [
        (
            &["--snr", "0:1:inf"][..],
            "--snr: 'inf' is not a finite number",
        ),
        (
            &["--snr", "0:100:0.01"][..],
            "--snr: '0:100:0.01' has 10001 points, at most 1000",
        ),
        (
            &["--snr", "1:200:100"][..],
            "--snr must lie in [0, 100] (a / sigma), got 101",
        ),
        (
            &["--snr=-1:1:1"][..],
            "--snr must lie in [0, 100] (a / sigma), got -1",
        ),
        (
            &["--runs", "0"][..],
            "--runs must lie in 1..=1000000, got 0",
        ),
        (
            &["--noise-runs", "0"][..],
            "--noise-runs must lie in 100..=1000000, got 0",
        ),
        (&["--frames", "0"][..], "--frames must lie in 1..=40, got 0"),
    ] {
        let mut all = vec!["reproduce", "dp", "--quick", "--out", s(&dir)];
        all.extend(args);
        let (code, _, err) = faint(&all);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
        assert!(!dir.exists(), "{args:?} created {}", dir.display());
    }
    let (code, _, err) = faint(&[
        "reproduce",
        "dp",
        "--quick",
        "--out",
        "/proc/faint-no-such-dir",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--out /proc/faint-no-such-dir"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}
