//! `faint reproduce phd --quick` (and its alias `psophd`) runs end to end and writes its
//! outputs; bad arguments are one line naming the argument; `--quick` never overrides a
//! value given.

use std::process::Command;

#[test]
fn reproduce_psophd_quick_writes_tables_and_plots() {
    let dir = std::env::temp_dir().join(format!("faint-psophd-{}", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_faint"))
        .args(["--quiet", "reproduce", "phd", "--quick", "--out"])
        .arg(&dir)
        .output()
        .expect("run faint");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let table = std::fs::read_to_string(dir.join("table.md")).unwrap();
    for name in ["PHD-TBD", "PSO-PHD-TBD (K-means)", "PSO-PHD-TBD (DBSCAN)"] {
        assert!(table.contains(name), "{table}");
    }
    for f in [
        "frames.csv",
        "summary.csv",
        "count_9db.svg",
        "count_std_9db.svg",
        "ospa_9db.svg",
    ] {
        assert!(dir.join(f).exists(), "{f}");
    }
    let frames = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    assert_eq!(frames.lines().count(), 1 + 3 * 40);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn reproduce_psophd_rejects_bad_arguments_before_any_run() {
    for (args, needle) in [
        (vec!["--birth-pair-speed=-3"], "--birth-pair-speed"),
        (vec!["--birth-pair-speed=inf"], "--birth-pair-speed"),
        (vec!["--snr-db", "nan"], "--snr-db"),
        (vec!["--variants", "phd-tbd,kmeans"], "--variants: 'kmeans'"),
        (
            vec!["--variants", "phd-tbd,phd-tbd"],
            "--variants: 'phd-tbd' is given twice",
        ),
        (vec!["--filter-q1", "0"], "--filter-q1 must be > 0"),
        (vec!["--filter-q1", "inf"], "--filter-q1"),
        (vec!["--clutter-lambda=-1"], "--clutter-lambda must be > 0"),
        (vec!["--birth-mass", "1"], "--birth-mass must lie in (0, 1)"),
        (
            vec!["--birth-particles", "0"],
            "--birth-particles must lie in 1..=4096",
        ),
        (
            vec!["--particles-per-target", "9000"],
            "--particles-per-target must lie in 1..=8192",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_faint"))
            .args(["--quiet", "reproduce", "psophd", "--runs", "100000"])
            .args(&args)
            .output()
            .expect("run faint");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} accepted");
        assert!(stderr.contains(needle), "{args:?}: {stderr}");
    }
}

/// Runs `faint --quiet reproduce phd <args>`: `(exit code, stderr)`.
fn phd(args: &[&str]) -> (i32, String) {
    let mut all = vec!["--quiet", "reproduce", "phd"];
    all.extend_from_slice(args);
    crate::common::faint(&all)
}

#[test]
fn counts_and_snrs_are_checked_quick_or_not() {
    let dir = std::env::temp_dir().join(format!("faint-phd-bad-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    for (args, needle) in [
        (
            &["--runs", "0"][..],
            "--runs must lie in 1..=1000000, got 0",
        ),
        (
            &["--quick", "--runs", "0"][..],
            "--runs must lie in 1..=1000000, got 0",
        ),
        (&["--runs", "2000000"][..], "--runs must lie in 1..=1000000"),
        (
            &["--snr-db", "inf"][..],
            "--snr-db: 'inf' is not a finite number",
        ),
        (
            &["--quick", "--snr-db", "9,nan"][..],
            "--snr-db: 'NaN' is not a finite number",
        ),
        (
            &["--snr-db", "1e300"][..],
            "--snr-db must lie in [-60, 60] dB",
        ),
        (
            &["--snr-db", "-70"][..],
            "--snr-db must lie in [-60, 60] dB, got -70",
        ),
        (
            &["--quick", "--birth-pair-speed=-1"][..],
            "--birth-pair-speed",
        ),
        (
            &["--quick", "--filter-intensity-db", "-70"][..],
            "--filter-intensity-db must lie in [-60, 60] dB, got -70",
        ),
        (
            &["--filter-intensity-db", "inf"][..],
            "--filter-intensity-db",
        ),
        (
            &["--quick", "--cubes", "physics", "--runs", "0"][..],
            "--runs must lie in 1..=1000000, got 0",
        ),
    ] {
        let mut all = vec!["--out", out];
        all.extend_from_slice(args);
        let (code, err) = phd(&all);
        crate::common::assert_one_line_error(code, &err, needle, args);
        assert!(!dir.exists(), "{args:?} created {}", dir.display());
    }
}

#[test]
fn unwritable_out_is_named_before_any_run() {
    let (code, err) = phd(&["--runs", "100000", "--out", "/proc/faint-no-such-dir"]);
    assert_ne!(code, 0);
    assert!(err.contains("--out /proc/faint-no-such-dir"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

#[test]
fn quick_keeps_given_values() {
    let dir = std::env::temp_dir().join(format!("faint-phd-keep-{}", std::process::id()));
    let out = Command::new(env!("CARGO_BIN_EXE_faint"))
        .args(["--quiet", "reproduce", "phd", "--quick", "--runs", "1"])
        .args(["--snr-db", "7", "--out"])
        .arg(&dir)
        .output()
        .expect("run faint");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let summary = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    let rows: Vec<&str> = summary.lines().skip(1).collect();
    assert_eq!(rows.len(), 3, "{summary}");
    for r in rows {
        assert!(r.starts_with("7.0,") && r.contains(",1,"), "{summary}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// The ablation algorithm (PHD-TBD with DBSCAN) runs beside the paper's three, only the
/// selected algorithms are written, and the summary carries the count error and the
/// all-alive columns.
#[test]
fn variants_select_the_algorithms_and_the_ablation_runs() {
    let dir = std::env::temp_dir().join(format!("faint-phd-variants-{}", std::process::id()));
    let out = dir.to_str().unwrap();
    let (code, stderr) = phd(&[
        "--quick",
        "--variants",
        "phd-tbd-dbscan,phd-tbd",
        "--filter-q1",
        "2",
        "--out",
        out,
    ]);
    assert_eq!(code, 0, "{stderr}");
    let table = std::fs::read_to_string(dir.join("table.md")).unwrap();
    assert!(table.contains("PHD-TBD (DBSCAN)"), "{table}");
    assert!(!table.contains("PSO-PHD-TBD"), "{table}");
    let summary = std::fs::read_to_string(dir.join("summary.csv")).unwrap();
    let head = summary.lines().next().unwrap();
    for col in [
        "mean_abs_count_error",
        "all_alive_mean_count",
        "all_alive_mean_ospa_m",
    ] {
        assert!(head.contains(col), "{head}");
    }
    let frames = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    assert_eq!(frames.lines().count(), 1 + 2 * 40);
    let _ = std::fs::remove_dir_all(&dir);
}

/// `--cubes` takes `model` or `physics`; anything else is refused before any run, the
/// first line naming the value and `--cubes` (clap's error, like every value list).
#[test]
fn bad_cubes_are_refused() {
    let dir = std::env::temp_dir().join(format!("faint-phd-cubes-{}", std::process::id()));
    for (bad, needle) in [
        ("sinc", "invalid value 'sinc' for '--cubes"),
        ("Physics", "invalid value 'Physics' for '--cubes"),
        ("", "a value is required for '--cubes"),
    ] {
        let (code, err) = phd(&["--quick", "--cubes", bad, "--out", dir.to_str().unwrap()]);
        assert_ne!(code, 0, "{bad:?}");
        let first = err.lines().next().unwrap_or("");
        assert!(first.contains(needle), "{bad:?}: {err}");
        assert!(err.contains("[possible values: model, physics]"), "{err}");
        assert!(!dir.exists(), "{bad:?} created {}", dir.display());
    }
}

/// `--quick --cubes physics` runs end to end (one run, PHD-TBD, small filter), writes
/// the outputs of the model's cubes and says which cubes in the table and the charts.
#[test]
fn physics_cubes_run_quick() {
    let dir = std::env::temp_dir().join(format!("faint-phd-physics-{}", std::process::id()));
    let (code, err) = phd(&[
        "--quick",
        "--cubes",
        "physics",
        "--runs",
        "1",
        "--variants",
        "phd-tbd",
        "--birth-particles",
        "100",
        "--particles-per-target",
        "100",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let table = std::fs::read_to_string(dir.join("table.md")).unwrap();
    assert!(
        table.starts_with("Cubes from the physics simulator"),
        "{table}"
    );
    assert!(table.contains("| 9 | PHD-TBD | 1 |"), "{table}");
    let chart = std::fs::read_to_string(dir.join("ospa_9db.svg")).unwrap();
    assert!(chart.contains("1 runs, physics cubes (Fig. 5)"), "{chart}");
    let frames = std::fs::read_to_string(dir.join("frames.csv")).unwrap();
    assert_eq!(frames.lines().count(), 1 + 40);
    let _ = std::fs::remove_dir_all(&dir);
}
