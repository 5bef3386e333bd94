//! Observation and motion models: the per-frame inputs detectors consume.
pub mod doppler;
pub mod plot;
pub mod power_cube;
pub mod range_doppler;
