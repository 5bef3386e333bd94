//! Observation models shared by detectors.
pub mod power_cube;
