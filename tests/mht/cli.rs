//! `faint reproduce mht --quick` runs end to end and writes every output (a regression
//! test: a log-scale chart once made it loop forever after the CSV files); bad arguments
//! are one line naming the argument; `--quick` never overrides a value given.

use std::process::Command;
use std::time::{Duration, Instant};

#[test]
fn reproduce_mht_quick_finishes_and_writes_summary() {
    let dir = std::env::temp_dir().join(format!("faint-mht-quick-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let mut child = Command::new(env!("CARGO_BIN_EXE_faint"))
        .args(["--quiet", "reproduce", "mht", "--quick", "--out"])
        .arg(&dir)
        .stdout(std::process::Stdio::null())
        .spawn()
        .expect("run faint");
    // About 7 s in release on the 2-core machine; 300 s leaves room for a loaded one.
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(300) {
            let _ = child.kill();
            panic!("reproduce mht --quick did not finish in 300 s");
        }
        std::thread::sleep(Duration::from_millis(100));
    };
    assert!(status.success());
    assert!(dir.join("summary.md").exists());
    assert!(dir.join("summary.csv").exists());
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `faint --quiet reproduce mht <args>`: `(exit code, stderr)`.
fn mht(args: &[&str]) -> (i32, String) {
    let mut all = vec!["--quiet", "reproduce", "mht"];
    all.extend_from_slice(args);
    crate::common::faint(&all)
}

#[test]
fn bad_arguments_are_one_line_naming_the_argument_quick_or_not() {
    let dir = std::env::temp_dir().join(format!("faint-mht-bad-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    for (args, needle) in [
        (
            &["--trials", "0"][..],
            "--trials must lie in 1..=1000000, got 0",
        ),
        (
            &["--quick", "--trials", "0"][..],
            "--trials must lie in 1..=1000000, got 0",
        ),
        (
            &["--quick", "--null-trials", "0"][..],
            "--null-trials must lie in",
        ),
        (
            &["--quick", "--calib-periods", "0"][..],
            "--calib-periods must lie in",
        ),
        (
            &["--quick", "--calib-check", "2000000"][..],
            "--calib-check must lie in 0..=1000000",
        ),
        (
            &["--quick", "--pfa", "2"][..],
            "--pfa must lie in (0, 1), got 2",
        ),
        (
            &["--quick", "--pfa", "1"][..],
            "--pfa must lie in (0, 1), got 1",
        ),
        (
            &["--lambda", "inf"][..],
            "--lambda: 'inf' is not a finite number",
        ),
        (
            &["--lambda", "nan"][..],
            "--lambda: 'NaN' is not a finite number",
        ),
        (
            &["--gamma1", "0"][..],
            "--gamma1 must lie in 1..=255, got 0",
        ),
        (
            &["--calib-min-gamma", "0"][..],
            "--calib-min-gamma must lie in 1..=255, got 0",
        ),
    ] {
        let mut all = vec!["--out", out];
        all.extend_from_slice(args);
        let (code, err) = mht(&all);
        crate::common::assert_one_line_error(code, &err, needle, args);
        assert!(!dir.exists(), "{args:?} created {}", dir.display());
    }
}

#[test]
fn unwritable_out_is_named() {
    let (code, err) = mht(&["--quick", "--out", "/proc/faint-no-such-dir"]);
    assert_ne!(code, 0);
    assert!(err.contains("--out /proc/faint-no-such-dir"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

#[test]
fn quick_keeps_given_values() {
    let dir = std::env::temp_dir().join(format!("faint-mht-keep-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let out = Command::new(env!("CARGO_BIN_EXE_faint"))
        .args(["--quiet", "reproduce", "mht", "--quick", "--lambda", "80"])
        .args(["--trials", "3", "--null-trials", "2", "--out"])
        .arg(&dir)
        .output()
        .expect("run faint");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let md = std::fs::read_to_string(dir.join("summary.md")).unwrap();
    assert!(
        md.contains("Trials per lambda: 3 with 5 targets, 2 clutter-only"),
        "{md}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
