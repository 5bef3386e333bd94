//! The detector instances the host builds: every capacity the host compiles a detector
//! with, for `faint detect`, the reproductions and the statistics, in one place (the
//! dynamic-programming detectors' sizes stand with their simulator, `simulate::dp`).
//!
//! A capacity is a const parameter of a core detector type, fixed at compile time; the
//! host's instances are large (`CrpfTbd6000` is 279 KB, the host's PHD filter a few MiB),
//! so every detector the host runs is built on the heap by [`boxed`], whatever its family
//! and size: its [`Detector::UNCONFIGURED`] constant is written straight into a heap
//! allocation ([`unconfigured`]), then [`Detector::configure`] sets it up, exactly as
//! `new(cfg, seed)` would build it by value.

use anyhow::{anyhow, Result};
use faint_core::detect::Detector;

/// A configured detector on the heap: [`unconfigured`], then
/// [`configure`](Detector::configure)`(cfg, seed)`. Errors: the configuration's, as the
/// core error's one line.
pub fn boxed<D: Detector>(cfg: &D::Config, seed: u64) -> Result<Box<D>> {
    let mut det = unconfigured::<D>();
    det.configure(cfg, seed).map_err(|e| anyhow!("{e}"))?;
    Ok(det)
}

/// The unconfigured detector ([`Detector::UNCONFIGURED`]) on the heap, for a caller that
/// configures it later (or reconfigures it per trial).
pub fn unconfigured<D: Detector>() -> Box<D> {
    let mut det = Box::<D>::new_uninit();
    det.write(D::UNCONFIGURED);
    // SAFETY: initialised by the `write` above.
    unsafe { det.assume_init() }
}

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

    /// Plots per scan of the STM32H743's MHT-TBD (the largest `mht:P` of the firmware's
    /// board-fit matrix that fits the part; `faint reproduce mht --plots 512`).
    pub const BOARD_PLOTS: usize = 512;
    /// A smaller track store (`--tracks 16`): the firmware image's before it moved to
    /// the host's 32, measured to cost Pd (docs/mht.md, "On the STM32H743").
    pub const SMALL_TRACKS: usize = 16;
    /// The STM32H743's MHT-TBD: the firmware's `MhtTbd<512, 30, 256, 180, 32>`, on the
    /// host's grid (`--plots 512`).
    pub type Board = MhtTbd<BOARD_PLOTS, SCANS, RANGE_CELLS, ANGLE_CELLS, TRACKS>;
    /// The plot capacities `faint reproduce mht --plots` accepts: the host's and the
    /// board's.
    pub const REPRODUCE_PLOTS: [usize; 2] = [PLOTS, BOARD_PLOTS];
    /// The track capacities `faint reproduce mht --tracks` accepts.
    pub const REPRODUCE_TRACKS: [usize; 2] = [TRACKS, SMALL_TRACKS];

    // The board instance is the firmware's type and the host's the core's host type.
    const _: fn(faint_core::detect::mht::MhtTbdM4) -> Board = |d| d;
    const _: fn(faint_core::detect::mht::MhtTbdHost) -> Mht = |d| d;

    /// Runs `$body` with `$p` and `$t` consts, the plot and track capacities of the
    /// instance with `$plots` plots per scan and `$tracks` tracks ([`BOARD_PLOTS`],
    /// [`SMALL_TRACKS`]: the board's plots, the smaller track store; any other value: the host's [`PLOTS`], [`TRACKS`]).
    /// The one place a capacity picks an instance.
    macro_rules! with_mht_capacity {
        ($plots:expr, $tracks:expr, |$p:ident, $t:ident| $body:expr) => {{
            use $crate::instances::mht as im_;
            match ($plots == im_::BOARD_PLOTS, $tracks == im_::SMALL_TRACKS) {
                (true, true) => {
                    const $p: usize = im_::BOARD_PLOTS;
                    const $t: usize = im_::SMALL_TRACKS;
                    $body
                }
                (true, false) => {
                    const $p: usize = im_::BOARD_PLOTS;
                    const $t: usize = im_::TRACKS;
                    $body
                }
                (false, true) => {
                    const $p: usize = im_::PLOTS;
                    const $t: usize = im_::SMALL_TRACKS;
                    $body
                }
                (false, false) => {
                    const $p: usize = im_::PLOTS;
                    const $t: usize = im_::TRACKS;
                    $body
                }
            }
        }};
    }
    pub(crate) use with_mht_capacity;
}

/// The SMC-PHD / PSO-PHD detectors (Pei et al.'s six-target scene).
pub mod phd {
    /// The host's PHD filter: particles, swarm entries, points, targets.
    pub type HostFilter = faint_core::detect::phd::SmcPhdTbdHost;
}

/// CBMeMBer-TBD on range-Doppler maps (the rotor-UAV scene).
pub mod cbmember {
    use faint_core::detect::cbmember::CbmemberTbdHost;
    use faint_core::Complex32;

    /// Particles per Bernoulli component of the host filter (its `PARTICLES`).
    pub const MAX_PARTICLES: usize = 1500;
    /// The host filter: 4 components of up to [`MAX_PARTICLES`] particles, 256 x 32
    /// block sums, power maps.
    pub type HostFilter = CbmemberTbdHost;
    /// The same on complex maps.
    pub type HostFilterComplex = CbmemberTbdHost<[Complex32]>;
    /// The same on quantised `u8` maps.
    pub type HostFilterU8 = CbmemberTbdHost<[u8]>;
}
