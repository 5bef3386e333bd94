//! What the CLI test binaries share: run `faint`, a fresh temporary folder, and the shape
//! of a rejected argument. Included by each family's test binary with
//! `#[path = "../common/cli.rs"] mod common;` (not every binary uses every item).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
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

/// Runs `faint --quiet <args>`: `(exit code, stdout, stderr)`.
pub fn faint_quiet(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_faint"))
        .arg("--quiet")
        .args(args)
        .output()
        .expect("run faint");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A fresh, empty temporary folder for one test of `family` (removed first if it exists).
pub fn temp(family: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("faint-{family}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("create a temporary folder");
    d
}

/// `p` as a `&str` (the temporary folders are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// A rejected argument: a non-zero exit, one line of stderr holding `needle`, no panic.
pub fn assert_one_line_error(code: i32, err: &str, needle: &str, args: &[&str]) {
    assert_ne!(code, 0, "{args:?}");
    assert!(err.contains(needle), "{args:?}: {err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
}
