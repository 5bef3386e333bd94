//! MHT-TBD (Bao et al. 2022) and the classic Hough TBD: the detector against brute-force
//! references, the analytic detection model, and the simulation-calibrated threshold. One
//! test binary for the family.
#![allow(clippy::needless_range_loop)]

mod board;
mod calibration;
mod cli;
#[path = "../common/cli.rs"]
mod common;
mod detector;
#[path = "../common/shards.rs"]
mod merge;
mod model;
mod paper_gamma;
mod shards;
mod stages;
mod thresholds;
