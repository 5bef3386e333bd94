//! # faint-host
//!
//! The std side of faint: scenario simulators, the Monte Carlo runner, detection
//! statistics, and CSV/JSON/plot output.

pub mod analysis;
pub mod reproduce;
pub mod scenario;
