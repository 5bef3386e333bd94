//! # faint-core
//!
//! `#![no_std]`, allocation-free building blocks and detectors for track-before-detect
//! (TBD) on DSP-class microcontrollers (Cortex-M4F/M7, `thumbv7em-none-eabihf`).
//!
//! Every detector implements one interface, [`detect::Detector`]: a `Config` of runtime
//! tunables validated once ([`detect::Validate`]; [`Error`] on a bad value), a state of
//! fixed-size arrays (const generics), a borrowed frame per step, one `step` per frame
//! returning a small `Copy` report, and its detections read back in one form whatever the
//! family. Nothing allocates, nothing panics on bad input: wrong sizes, NaN/inf samples
//! and degenerate weights come back as [`Error`] (before any state changes) or as a
//! documented recovery.
//!
//! ```
//! use faint_core::detect::mht::{MhtConfig, MhtTbd};
//! use faint_core::detect::{run, Detector};
//! use faint_core::model::plot::Plot;
//! use faint_core::rng::Rng;
//! use faint_core::simulate;
//!
//! // 30 scans of 60 clutter plots and one target moving 20 m per scan (6 km x 6 km).
//! let mut rng = Rng::seed_from_u64(1);
//! let scans: Vec<Vec<Plot>> = (0..30)
//!     .map(|s| {
//!         let mut plots = vec![Plot::new(0.0, 0.0, 0.0); 60];
//!         simulate::clutter_plots(&mut rng, [0.0, 6000.0, 0.0, 6000.0], &mut plots, |_| 1.0);
//!         plots.push(Plot::new(5.0, 1000.0 + 20.0 * s as f32, 2000.0 + 10.0 * s as f32));
//!         plots
//!     })
//!     .collect();
//! // Capacities: 128 plots per scan, 30 scans, a 256 x 180 Hough grid, 16 tracks.
//! let mut det = Box::new(MhtTbd::<128, 30, 256, 180, 16>::new(MhtConfig::sea_clutter())?);
//! let mut found = Vec::new();
//! run(det.as_mut(), scans.iter().map(|s| s.as_slice()), |_, det, _| {
//!     found.extend(det.detections().map(|d| (d.state()[0], d.state()[1])));
//! })?;
//! // The target's track ends near (1580, 2290) m.
//! assert!(found.iter().any(|&(x, y)| (x - 1580.0).abs() < 30.0 && (y - 2290.0).abs() < 30.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Map of the crate:
//! - [`detect`]: the [`detect::Detector`] interface, the generic frame loop
//!   [`detect::run`], and one module per family (`crpf`, `pf_tbd`, `jott`, `pf_lrt`,
//!   `mht`, `phd`).
//! - [`model`]: observation models per input (Doppler frames, plot lists, power cubes).
//! - [`rng`]: seeded Xoshiro128++ streams and samplers (uniform, normal, exponential,
//!   Bernoulli), bit-identical on x86_64 and thumbv7em.
//! - [`math`]: the `f32` backend (`libm` or `micromath`) and log-domain helpers.
//! - [`particles`]: resampling (systematic, stratified, residual, multinomial) into a
//!   caller's index buffer, in-place gathers, effective sample size.
//! - [`existence`]: the two-state Markov chain of target existence and its fast samplers,
//!   shared by the existence-carrying filters.
//! - [`statistic`]: test statistics over K frames (`zeta_K`, `D_K`).
//! - [`sort`]: a panic-free in-place unstable sort (introsort) for the detectors the
//!   panic-never link checks cover.
//! - [`simulate`]: allocation-free simulation of scenes (clutter plots, detections,
//!   power-cube returns) shared by the host simulators, the golden cases and the firmware.
//! - [`Complex32`]: complex samples, from `num-complex`.
#![no_std]
// `unsafe` only in the Cortex-M4 `asm!` blocks of `detect::dp` (each with its SAFETY note).
#![deny(unsafe_code)]
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
pub mod simulate;
pub mod sort;
pub mod statistic;

pub use error::Error;
pub use num_complex::Complex32;

/// Result alias used throughout the crate.
pub type Result<T> = core::result::Result<T, Error>;
