//! # faint
//!
//! Track-before-detect for dim radar targets. This crate is the command-line program
//! `faint` and a thin facade over the two libraries:
//! - [`core`] (`faint-core`): `no_std`, allocation-free detectors and primitives;
//! - [`host`] (`faint-host`): simulators, Monte Carlo runner, statistics, output.

pub use faint_core as core;
pub use faint_host as host;

/// The README's Rust examples, compiled and run as doctests.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
