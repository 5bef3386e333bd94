//! # faint-core
//!
//! `#![no_std]`, allocation-free building blocks and detectors for track-before-detect
//! (TBD) on DSP-class microcontrollers (Cortex-M4F/M7, `thumbv7em-none-eabihf`).
//!
//! Every detector follows one shape: a `Config` of runtime tunables validated once
//! (`Config::validate` returns [`Error`] on a bad value), a `State<const N: usize>` made of
//! fixed-size arrays, a borrowed input per frame, and one `step` call per frame that
//! returns a small `Copy` report. Nothing allocates, nothing panics on bad input: wrong
//! sizes, NaN/inf samples and degenerate weights come back as [`Error`] or as a documented
//! recovery.
//!
//! Map of the crate:
//! - [`rng`]: seeded Xoshiro128++ streams and samplers (uniform, normal, exponential,
//!   Bernoulli), bit-identical on x86_64 and thumbv7em.
//! - [`math`]: the `f32` backend (`libm` or `micromath`) and log-domain helpers.
//! - [`particles`]: resampling (systematic, stratified, residual, multinomial) into a
//!   caller's index buffer, in-place gather, effective sample size.
//! - [`existence`]: the two-state Markov chain of target existence shared by the
//!   existence-carrying filters.
//! - [`scene`]: allocation-free scene synthesis (clutter plots, detections, power-cube
//!   returns) shared by the host simulators, the golden cases and the firmware.
//! - [`Complex32`]: complex samples, from `num-complex`.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]
#![cfg_attr(
    not(test),
    deny(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

#[cfg(test)]
extern crate std;

pub mod detect;
pub mod error;
pub mod existence;
pub mod math;
pub mod model;
pub mod particles;
pub mod rng;
pub mod scene;
pub mod statistic;

pub use error::Error;
pub use num_complex::Complex32;

/// Result alias used throughout the crate.
pub type Result<T> = core::result::Result<T, Error>;
