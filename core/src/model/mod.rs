//! Observation and motion models shared by detectors.
pub mod doppler;
