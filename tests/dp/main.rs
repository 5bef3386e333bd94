//! DP-TBD (Barniv 1985, Arnold et al. 1993; Pulford, La Scala 2010; Wang, Zhang 2016): the
//! recursions against exhaustive search, bad input, and properties; the merit-distribution
//! analysis; the host layer's
//! `dim-point` scene, `faint simulate dim-point` + `faint detect dp-*` round trip and
//! `faint reproduce dp --quick`. One test binary for the family.

mod analysis;
mod cli;
mod detector;
mod host;

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
    let d = std::env::temp_dir().join(format!("faint-dp-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `p` as a `&str`.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}
