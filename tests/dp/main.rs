//! DP-TBD (Barniv 1985, Arnold et al. 1993; Pulford, La Scala 2010; Wang, Zhang 2016): the
//! recursions against exhaustive search, bad input, and properties; the merit-distribution
//! analysis; the host layer's
//! `dim-point` scene, `faint simulate dim-point` + `faint detect dp-*` round trip and
//! `faint reproduce dp --quick`. One test binary for the family.

mod analysis;
mod board;
mod cli;
mod detector;
mod host;
#[path = "../common/shards.rs"]
mod merge;
mod shards;

#[path = "../common/cli.rs"]
mod common;

pub use common::{faint_quiet as faint, s};

/// A fresh temporary folder for one test.
pub fn temp(name: &str) -> std::path::PathBuf {
    common::temp("dp", name)
}
