//! The two detectors of `faint reproduce mht`, built for a scene and its thresholds.

use faint_core::detect::mht::{ClassicHoughConfig, MhtConfig};

use crate::instances::mht::{Classic, Mht};
use crate::simulate::mht::SeaClutter;

/// Build the two detectors for a lambda and its thresholds.
pub fn detectors(
    sc: &SeaClutter,
    gamma1: u8,
    gamma_classic: u8,
) -> anyhow::Result<(Box<Mht>, Box<Classic>)> {
    let mut cfg = MhtConfig::sea_clutter();
    cfg.area = sc.area;
    cfg.n_scans = sc.n_scans;
    cfg.gate = sc.v_max * sc.t_scan;
    cfg.along_gate = cfg.gate;
    cfg.gamma1 = gamma1;
    let mht = crate::instances::boxed::<Mht>(&cfg, 0)?;
    let ccfg = ClassicHoughConfig {
        area: sc.area,
        n_scans: sc.n_scans,
        gamma: gamma_classic,
    };
    let classic = crate::instances::boxed::<Classic>(&ccfg, 0)?;
    Ok((mht, classic))
}
