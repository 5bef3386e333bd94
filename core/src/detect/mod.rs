//! Detectors.
pub mod phd;
