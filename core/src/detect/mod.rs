//! Detectors, one module per paper's algorithm.
pub mod bernoulli;
pub mod crpf;
mod gauss_cloud;
pub mod hough;
pub mod pf_lrt;
pub mod pf_tbd;
pub mod phd;
