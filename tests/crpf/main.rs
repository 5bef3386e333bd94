//! CRPF-TBD (Lu, Wang, Zhang 2017) and its comparators PF-TBD, JOTT and PF-LRT: the
//! observation model, the noise generators, the detectors, their static configuration,
//! the threshold calibration and the reproduction. One test binary for the family.

mod birth;
mod calibration;
mod cli;
#[path = "../common/cli.rs"]
mod common;
mod detectors;
#[path = "../common/shards.rs"]
mod merge;
mod model;
mod noise;
mod reproduce;
mod shards;
mod sizes;
mod statics;
mod whiten;
