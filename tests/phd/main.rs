//! PSO-PHD-TBD (Pei et al. 2019) and PHD-TBD: the swarm, sort and clustering building
//! blocks against brute force, the filter on the `six-targets` preset, and the
//! reproduction's command line. One test binary for the family.

mod algorithms;
mod births;
mod cli;
#[path = "../common/cli.rs"]
mod common;
mod dbscan_exact;
mod dbscan_reference;
mod filter;
mod m4;
mod m4_budget;
#[path = "../common/shards.rs"]
mod merge;
mod shards;
mod spread;
