//! `faint detect` and `faint simulate`: every detector round-trips a simulated file bit
//! for bit against the reproductions' own code path, bad files and arguments are one
//! clear line with exit status 2 and nothing written, the trait's detections agree
//! with the reports, and unconfigured detectors refuse to step.

mod bad_input;
mod commands;
mod interface;
mod round_trip;
mod unconfigured;

#[path = "../common/cli.rs"]
mod common;

pub use common::{faint_quiet as faint, s};

/// A fresh temporary folder for one test.
pub fn temp(name: &str) -> std::path::PathBuf {
    common::temp("detect", name)
}

/// A NumPy-written fixture of `tests/data`.
pub fn data(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}
