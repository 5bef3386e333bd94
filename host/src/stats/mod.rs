//! Statistics of Monte Carlo runs: detection thresholds, rates and curves
//! ([`detection`]), the OSPA and GOSPA multi-target distances ([`ospa`], [`gospa`]), and
//! robust noise-level estimates of a recording ([`noise`]).

pub mod detection;
pub mod gospa;
pub mod noise;
pub mod ospa;
