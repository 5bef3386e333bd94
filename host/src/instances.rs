//! The detector instances the host builds: every capacity the host compiles a detector
//! with, for `faint detect`, the reproductions and the statistics, in one place (the
//! dynamic-programming detectors' sizes stand with their simulator, `simulate::dp`).
//!
//! A capacity is a const parameter of a core detector type, fixed at compile time; the
//! host's instances are large (up to a few MiB), so they are built on the heap.

// ---------------------------------------------------------------------------------------
// Instance sizes, one module per family.
// ---------------------------------------------------------------------------------------

/// CRPF-TBD and the Gaussian comparators (PF-TBD, JOTT, PF-LRT) on Doppler frames: the
/// particle counts they are compiled for.
pub mod doppler {
    /// Particle counts `faint detect` builds the particle-filter detectors for.
    pub const DETECT_PARTICLES: [usize; 4] = [1000, 2000, 4000, 6000];
    /// Particle counts `faint reproduce crpf` builds its four detectors for.
    pub const REPRODUCE_PARTICLES: [usize; 7] = [100, 250, 500, 1000, 2000, 4000, 6000];
}

/// MHT-TBD and the classic Hough TBD on radar plots (Bao et al. 2022's sea-clutter
/// scene): `faint detect mht`/`classic` and `faint reproduce mht`.
pub mod mht {
    use faint_core::detect::mht::{ClassicHough, MhtTbd};

    /// Plots per scan (Poisson(398) clutter exceeds 520 with probability ~1e-9).
    pub const PLOTS: usize = 640;
    /// Scans per integration period.
    pub const SCANS: usize = 30;
    /// Hough range cells, `N_rho`.
    pub const RANGE_CELLS: usize = 256;
    /// Hough angle cells, `N_theta`.
    pub const ANGLE_CELLS: usize = 180;
    /// Confirmed tracks.
    pub const TRACKS: usize = 32;
    /// Peaks of the classic Hough TBD.
    pub const PEAKS: usize = 64;
    /// The host's MHT-TBD.
    pub type Mht = MhtTbd<PLOTS, SCANS, RANGE_CELLS, ANGLE_CELLS, TRACKS>;
    /// The host's classic Hough TBD.
    pub type Classic = ClassicHough<RANGE_CELLS, ANGLE_CELLS, PEAKS>;
}

/// The SMC-PHD / PSO-PHD detectors (Pei et al.'s six-target scene).
pub mod phd {
    /// The host's PHD filter: particles, swarm entries, points, targets.
    pub type HostFilter = faint_core::detect::phd::SmcPhdTbd<8192, 16384, 10, 16>;
}

/// CBMeMBer-TBD on range-Doppler maps (the rotor-UAV scene).
pub mod cbmember {
    use faint_core::detect::cbmember::CbmemberTbd;
    use faint_core::Complex32;

    /// Particles per Bernoulli component of the host filter.
    pub const MAX_PARTICLES: usize = 1500;
    /// The host filter: 4 components of up to [`MAX_PARTICLES`] particles, 256 x 32
    /// block sums, power maps.
    pub type HostFilter = CbmemberTbd<4, MAX_PARTICLES, 8192, [f32]>;
    /// The same on complex maps.
    pub type HostFilterComplex = CbmemberTbd<4, MAX_PARTICLES, 8192, [Complex32]>;
    /// The same on quantised `u8` maps.
    pub type HostFilterU8 = CbmemberTbd<4, MAX_PARTICLES, 8192, [u8]>;
}
