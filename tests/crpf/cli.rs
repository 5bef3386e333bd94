//! `faint reproduce crpf` checks its arguments before any Monte Carlo work.

use std::process::Command;

fn faint(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_faint"))
        .args(args)
        .output()
        .expect("run faint");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn bad_arguments_fail_before_any_work() {
    let dir = std::env::temp_dir().join(format!("faint_crpf_cli_{}", std::process::id()));
    let out = dir.to_str().expect("utf-8 temp dir");
    for (args, needle) in [
        // 1000 H0 runs resolve Pfa 0.001 once, but the calibration's halves of 500 do
        // not: this used to fail only after all H0 runs.
        (
            &["--h0-trials", "1000"][..],
            "--h0-trials 1000 cannot resolve --pfa 0.001",
        ),
        (&["--pfa", "0"][..], "--pfa must lie in (0, 1)"),
        (
            &["--particles", "300"][..],
            "--particles 300 is not supported",
        ),
        (&["--trials", "0"][..], "--trials must be at least 1"),
        (&["--snr-db", "4:2:1"][..], "needs step > 0 and b >= a"),
        (
            &["--sweeps", "--sweep-h0-trials", "5"][..],
            "--sweep-h0-trials must be more than 10",
        ),
    ] {
        let mut all = vec!["reproduce", "crpf", "--out", out];
        all.extend_from_slice(args);
        let (code, err) = faint(&all);
        assert_ne!(code, 0, "{args:?}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{err}");
        // Nothing was written: the check comes before the output directory and the runs.
        assert!(!dir.exists(), "{args:?} created {}", dir.display());
    }
}
