//! PSO-PHD-TBD (Pei, Huang, Dong, He, Chen, Chen, "PHD-based particle swarm optimization
//! particle filter radar track-before-detect algorithm", J. Radar Sci. Tech. 17(3), 2019):
//! an SMC-PHD track-before-detect filter on range x Doppler x azimuth power cubes, with
//! an NSGA-II multi-objective particle swarm step between prediction and update, and
//! DBSCAN state extraction; the plain PHD-TBD and K-means extraction are the baselines.
//!
//! - [`smc_phd`]: the filter ([`SmcPhdTbd`], [`PhdConfig`], [`PhdReport`]).
//! - [`pso`]: swarm, weighted crowding, selection, mutation.
//! - [`ndsort`]: non-dominated sorts: ENS-BS, and divide-and-conquer for three or more
//!   objectives.
//! - [`dbscan`]: grid-indexed DBSCAN.
//! - [`kmeans`]: deterministic K-means.
//! - the observation model lives in [`crate::model::power_cube`].

pub mod dbscan;
pub mod kmeans;
pub mod ndsort;
pub mod pso;
pub mod smc_phd;

pub use dbscan::{Dbscan, DbscanParams};
pub use kmeans::KMeans;
pub use pso::{PsoConfig, Swarm, MAX_GENERATIONS};
pub use smc_phd::{
    BirthComponent, BirthMode, BirthModel, Estimate, Extractor, PhdConfig, PhdReport, PhdStage,
    SmcPhdTbd, SmcPhdTbdHost, SmcPhdTbdM4, SmcPhdTbdM4Half, SmcPhdTbdSmall, SmcPhdTbdSoak,
    MAX_BIRTH_COMPONENTS, MAX_INTENSITY, MAX_MUTATION, MAX_REGION_CELLS,
};
