//! `faint detect` and `faint simulate`: every detector round-trips a simulated file bit
//! for bit against the reproductions' own code path, bad files and arguments are one
//! clear line with exit status 2 and nothing written, and the trait's detections agree
//! with the reports.

mod bad_input;
mod commands;
mod interface;
mod round_trip;

use std::path::{Path, PathBuf};
use std::process::Command;

/// Runs the `faint` binary: `(exit code, stdout, stderr)`.
pub fn faint(args: &[&str]) -> (i32, String, String) {
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

/// A fresh temporary folder for one test.
pub fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("faint-detect-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A NumPy-written fixture of `tests/data`.
pub fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// `p` as a `&str`.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}
