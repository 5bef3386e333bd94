//! Statistics of Monte Carlo runs: detection thresholds, rates and curves
//! ([`detection`]), and the OSPA and GOSPA multi-target distances ([`ospa`], [`gospa`]).

pub mod detection;
pub mod gospa;
pub mod ospa;
