//! Observation models: the per-frame inputs detectors consume.
pub mod plot;
