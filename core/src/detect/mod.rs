//! Detectors, one module per family.
pub mod hough;
