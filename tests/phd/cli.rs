//! `faint reproduce phd --quick` (and its alias `psophd`) runs end to end and writes its outputs.

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
