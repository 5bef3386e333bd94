//! The two detectors of `faint reproduce mht`, built for a scene and its thresholds: the
//! host's MHT-TBD ([`detectors`]) or, for `--plots 512` and/or `--tracks 16`, the
//! STM32H743's or a smaller track store ([`detectors_with`] at those capacities).

use faint_core::detect::mht::{ClassicHoughConfig, MhtConfig, MhtTbd};

use crate::instances::mht::{Classic, Mht, ANGLE_CELLS, PLOTS, RANGE_CELLS, SCANS, TRACKS};
use crate::simulate::mht::SeaClutter;

/// The MHT-TBD of `P` plots per scan and `T` tracks on the host's grid.
pub type MhtAt<const P: usize, const T: usize> = MhtTbd<P, SCANS, RANGE_CELLS, ANGLE_CELLS, T>;

/// Build the two detectors for a lambda and its thresholds (the host's capacities).
pub fn detectors(
    sc: &SeaClutter,
    gamma1: u8,
    gamma_classic: u8,
) -> anyhow::Result<(Box<Mht>, Box<Classic>)> {
    detectors_with::<PLOTS, TRACKS>(sc, gamma1, gamma_classic)
}

/// [`detectors`] with MHT-TBD's plot and track capacities `P` and `T` (the classic
/// Hough TBD is the host's).
pub fn detectors_with<const P: usize, const T: usize>(
    sc: &SeaClutter,
    gamma1: u8,
    gamma_classic: u8,
) -> anyhow::Result<(Box<MhtAt<P, T>>, Box<Classic>)> {
    let mut cfg = MhtConfig::sea_clutter();
    cfg.area = sc.area;
    cfg.n_scans = sc.n_scans;
    cfg.gate = sc.v_max * sc.t_scan;
    cfg.along_gate = cfg.gate;
    cfg.gamma1 = gamma1;
    let mht = crate::instances::boxed::<MhtAt<P, T>>(&cfg, 0)?;
    let ccfg = ClassicHoughConfig {
        area: sc.area,
        n_scans: sc.n_scans,
        gamma: gamma_classic,
    };
    let classic = crate::instances::boxed::<Classic>(&ccfg, 0)?;
    Ok((mht, classic))
}
