//! Statistics of Monte Carlo runs: detection thresholds, rates and curves
//! ([`detection`]), and the OSPA multi-target distance ([`ospa`]).

pub mod detection;
pub mod ospa;
