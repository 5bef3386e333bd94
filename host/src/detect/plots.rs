//! The plot detectors: MHT-TBD and the classic Hough TBD.

use anyhow::{anyhow, ensure, Result};
use faint_core::detect::mht::{ClassicHoughConfig, MhtConfig};

use faint_core::detect::Detector;

use super::{
    drive, find_default, json, load, valid, InputView, Outcome, Plain, Request, XY_POSITION,
};
use crate::io::input::read_plots;
use crate::reproduce::mht::{Classic, Mht};
use crate::scenario::mht::SeaClutter;
use crate::timing::thread_cpu_seconds as cpu;

/// MHT-TBD's default configuration file: the sea-clutter preset.
pub(super) fn default_mht() -> String {
    json(&Plain {
        config: MhtConfig::sea_clutter(),
    })
}

/// The classic Hough TBD's default configuration file ([`default_classic`]).
pub(super) fn default_hough() -> String {
    json(&Plain {
        config: default_classic(),
    })
}

/// The classic Hough TBD's default: the sea-clutter area and period, and the threshold
/// the binomial strip model gives for a whole-grid false-alarm rate of 1e-4 at a clutter
/// density of 80 plots per scan (28 counts; the reproduction's value at that density).
pub fn default_classic() -> ClassicHoughConfig {
    let sc = SeaClutter::paper(80.0);
    let gamma = crate::analysis::mht::classic_gamma(
        f64::from(sc.area[1] - sc.area[0]),
        crate::reproduce::mht::NR,
        crate::reproduce::mht::NT,
        sc.n_scans,
        f64::from(sc.lambda),
        1e-4,
    );
    ClassicHoughConfig {
        area: sc.area,
        n_scans: sc.n_scans,
        gamma: gamma.min(255) as u8,
    }
}

pub(super) fn run_mht(req: &Request) -> Result<Outcome> {
    let t = cpu();
    let file: Plain<MhtConfig> = load(req, find_default("mht"), |f: &Plain<MhtConfig>| {
        valid(&f.config)?;
        ensure!(
            f.config.n_scans <= crate::reproduce::mht::NS,
            "invalid configuration value: n_scans (at most {} here)",
            crate::reproduce::mht::NS
        );
        Ok(())
    })?;
    let scans = read_plots(req.input)?;
    let read = cpu() - t;
    let mut det = Box::new(Mht::unconfigured());
    det.configure(&file.config, req.seed)
        .map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        "mht",
        det.as_mut(),
        scans.iter().map(|s| s.as_slice()),
        req,
        XY_POSITION,
    )?;
    out.view = InputView::Plots(scans);
    out.read_seconds = read;
    Ok(out)
}

pub(super) fn run_classic(req: &Request) -> Result<Outcome> {
    let t = cpu();
    let file: Plain<ClassicHoughConfig> = load(
        req,
        find_default("hough-classic"),
        |f: &Plain<ClassicHoughConfig>| valid(&f.config),
    )?;
    let scans = read_plots(req.input)?;
    let read = cpu() - t;
    let mut det = Box::new(Classic::new(file.config).map_err(|e| anyhow!("{e}"))?);
    det.configure(&file.config, req.seed)
        .map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        "hough-classic",
        det.as_mut(),
        scans.iter().map(|s| s.as_slice()),
        req,
        &[],
    )?;
    out.view = InputView::Plots(scans);
    out.read_seconds = read;
    Ok(out)
}
