//! What the CLI test binaries share: run `faint`, and the shape of a rejected argument.

use std::process::Command;

/// Runs `faint <args>`: `(exit code, stderr)`.
pub fn faint(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_faint"))
        .args(args)
        .output()
        .expect("run faint");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A rejected argument: a non-zero exit, one line of stderr holding `needle`, no panic.
pub fn assert_one_line_error(code: i32, err: &str, needle: &str, args: &[&str]) {
    assert_ne!(code, 0, "{args:?}");
    assert!(err.contains(needle), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
}
