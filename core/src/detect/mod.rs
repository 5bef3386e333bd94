//! Detectors, one module per paper's algorithm, behind one interface ([`Detector`]).
//!
//! | module | detector | frame |
//! |---|---|---|
//! | [`crpf`] | CRPF-TBD (Lu, Wang, Zhang 2017) | `[Complex32]`, `m` Doppler bins |
//! | [`pf_tbd`], [`jott`], [`pf_lrt`] | PF-TBD, JOTT, PF-LRT (its comparators) | `[Complex32]` |
//! | [`mht`] | MHT-TBD (Bao et al. 2022), classic Hough TBD | `[Plot]`, one scan |
//! | [`phd`] | SMC-PHD TBD with the PSO step (Pei et al. 2019) | `[f32]`, one power cube |
//! | [`cbmember`] | CBMeMBer TBD, joint Doppler / micro-Doppler (rotor-UAV paper, 2023) | `[f32]` power, `[Complex32]` or `[u8]` range-Doppler map |
//! | [`dp`] | DP-TBD: first order (Barniv 1985, Arnold et al. 1993), velocity-gated (Pulford, La Scala 2010), second order (Wang, Zhang 2016) | `[f32]`, one `M x M` image |
//!
//! # Building a detector
//!
//! Every detector is built one way: `new_unconfigured()`, a `const fn` (also the constant
//! [`Detector::UNCONFIGURED`]), then [`Detector::configure`] in place; `new(cfg, seed)`
//! does both and returns the detector by value (for small capacities: `CrpfTbd<6000>`
//! is 279 KB). See [`Detector`] for a `static` one.
//!
//! # Capacities
//!
//! A detector's sizes are const parameters, named for what they count; one name means
//! one thing in every family:
//!
//! | name | counts | detectors |
//! |---|---|---|
//! | `PARTICLES` | particles (per component in CBMeMBer) | CRPF-TBD, PF-TBD, JOTT, PF-LRT, SMC-PHD, CBMeMBer |
//! | `SWARM` | PSO swarm entries (parents plus children) | SMC-PHD ([`phd::Swarm`]) |
//! | `POINTS` | measurement points, one PSO objective each | SMC-PHD ([`phd::Swarm`]) |
//! | `TARGETS` | extracted target estimates | SMC-PHD |
//! | `COMPONENTS` | Bernoulli components | CBMeMBer |
//! | `BLOCK_SUMS` | block sums of the blocked likelihood | CBMeMBer |
//! | `PLOTS` | plots kept per scan | MHT-TBD |
//! | `SCANS` | scans per integration period | MHT-TBD |
//! | `RHO_CELLS`, `THETA_CELLS` | Hough grid cells in `rho` and in `theta` | MHT-TBD, classic Hough |
//! | `TRACKS` | confirmed tracks per period | MHT-TBD |
//! | `PEAKS` | peaks per period | classic Hough |
//!
//! Preset sizes have type aliases, suffixed by where they are used: `M4` the firmware's
//! (Cortex-M4F RAM), `Host` the host's (CLI and reproductions), `Small` the golden cases',
//! `Soak` the soak run's, and the particle count for the Doppler-frame detectors:
//! [`crpf::CrpfTbd1000`], [`crpf::CrpfTbd6000`] (likewise `PfTbd*`, `JottTbd*`,
//! `PfLrt*`), [`mht::MhtTbdM4`], [`mht::MhtTbdHost`], [`mht::MhtTbdSmall`],
//! [`mht::ClassicHoughHost`], [`mht::ClassicHoughSmall`], [`phd::SmcPhdTbdM4`],
//! [`phd::SmcPhdTbdHost`], [`phd::SmcPhdTbdSmall`], [`phd::SmcPhdTbdSoak`],
//! [`cbmember::CbmemberTbdM4`], [`cbmember::CbmemberTbdHost`],
//! [`cbmember::CbmemberTbdSmall`], [`cbmember::CbmemberTbdSoak`].
pub mod cbmember;
pub mod crpf;
pub mod dp;
mod gauss_cloud;
mod interface;
pub mod jott;
pub mod mht;
pub mod pf_lrt;
pub mod pf_tbd;
pub mod phd;

pub use interface::{
    run, Detection, Detections, Detector, FrameError, ScoreKind, TrackInfo, Validate, MAX_STATE,
};
