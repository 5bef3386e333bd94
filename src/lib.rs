//! # faint
//!
//! Track-before-detect for dim radar targets. This crate is the command-line program
//! `faint` and a thin facade over the two libraries:
//! - the no_std core (`faint-core`), re-exported at this crate's root: allocation-free
//!   detectors and primitives (`faint::detect`, `faint::model`, `faint::rng`, ...), so
//!   no module of this crate shadows Rust's own `core`;
//! - [`host`] (`faint-host`): simulators, Monte Carlo runner, statistics, output.

pub use faint_core::*;
pub use faint_host as host;

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
