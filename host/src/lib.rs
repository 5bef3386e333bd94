//! # faint-host
//!
//! The std side of faint. Data flows one way:
//! `simulate -> frames -> detector (faint-core) -> report -> statistics`.
//!
//! - [`montecarlo`]: parallel trials with per-trial seeds, identical for any thread count.
//! - [`shard`]: a run's trials split into shards (`--shard i/n`, SLURM and Kubernetes
//!   arrays) and merged bit for bit (`faint merge`).
//! - [`stats`]: thresholds at a false-alarm rate, detection rates with confidence
//!   intervals, Pd-versus-SNR crossings, ROC, OSPA, GOSPA.
//! - [`io`]: CSV, JSON, Markdown tables and SVG charts; recorded frames and plot lists
//!   read from and written to `.npy`/`.npz`/CSV.
//! - [`reproduce`]: one module per paper, behind `faint reproduce <name>`.
//! - [`detect`]: every detector on a user's files, behind `faint detect <name>`.
//! - [`instances`]: every capacity the host builds a detector with, and the one helper
//!   that builds every detector the host runs on the heap.
//! - [`calibrate`]: thresholds at a false-alarm probability, behind `faint calibrate <name>`.
//! - [`timing`]: this thread's CPU time, for measurements on a shared machine.
//! - [`cli`]: checks and parsers of command-line values shared by every command.
//! - [`reliability`]: fuzz and soak campaigns over every detector (`faint fuzz`, `faint soak`).
//! - [`simulate`]: the simulated scenes, one module per paper (presets are data), and
//!   their frames and truth as files, behind `faint simulate <scenario>`.
//! - [`physics`]: simulators written from the physics, and `faint evaluate` on them.

#![warn(missing_docs)]

pub mod analysis;
pub mod calibrate;
pub mod cli;
pub mod detect;
pub mod instances;
pub mod io;
pub mod montecarlo;
pub mod physics;
pub mod reliability;
pub mod reproduce;
pub mod shard;
pub mod simulate;
pub mod stats;
pub mod timing;
