//! Detectors, one module per paper's algorithm, behind one interface ([`Detector`]).
//!
//! | module | detector | frame |
//! |---|---|---|
//! | [`crpf`] | CRPF-TBD (Lu, Wang, Zhang 2017) | `[Complex32]`, `m` Doppler bins |
//! | [`pf_tbd`], [`bernoulli`], [`pf_lrt`] | PF-TBD, JOTT, PF-LRT (its comparators) | `[Complex32]` |
//! | [`mht`] | MHT-TBD (Bao et al. 2022), classic Hough TBD | `[Plot]`, one scan |
//! | [`phd`] | SMC-PHD TBD with the PSO step (Pei et al. 2019) | `[f32]`, one power cube |
//! | [`cbmember`] | CBMeMBer TBD, joint Doppler / micro-Doppler (rotor-UAV paper, 2023) | `[f32]` power, `[Complex32]` or `[u8]` range-Doppler map |
//! | [`dp`] | DP-TBD: first order (Barniv 1985, Arnold et al. 1993), velocity-gated (Pulford, La Scala 2010), second order (Wang, Zhang 2016) | `[f32]`, one `M x M` image |
pub mod bernoulli;
pub mod cbmember;
pub mod crpf;
pub mod dp;
mod gauss_cloud;
mod interface;
pub mod mht;
pub mod pf_lrt;
pub mod pf_tbd;
pub mod phd;

pub use interface::{
    run, Detection, Detections, Detector, FrameError, ScoreKind, TrackInfo, Validate, MAX_STATE,
};
