//! CBMeMBer TBD with joint Doppler / micro-Doppler (rotor-UAV paper, 2023): the filter and
//! its measurement model, and the reproduction's command line. One test binary for the
//! family.

mod births;
mod board;
mod cli;
#[path = "../common/cli.rs"]
mod common;
mod filter;
#[path = "../common/shards.rs"]
mod merge;
mod physical;
mod shards;
