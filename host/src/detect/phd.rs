//! The PHD family on range x Doppler x azimuth power cubes.

use anyhow::{anyhow, ensure, Result};
use faint_core::detect::phd::PhdConfig;

use faint_core::detect::Detector;

use super::{drive, find_default, json, load, valid, Outcome, Plain, Request};
use crate::io::input::read_real_frames;
pub(super) use crate::scenario::phd::Variant;
use crate::scenario::phd::{HostFilter, SixTargets};
use crate::timing::thread_cpu_seconds as cpu;

/// The state indices of the PHD state's position `(x, y)`.
const PHD_POSITION: &[usize] = &[0, 2];

pub(super) fn default_phd(v: Variant) -> String {
    json(&Plain {
        config: SixTargets::new(9.0).config(v),
    })
}

pub(super) fn run_phd(req: &Request, name: &'static str) -> Result<Outcome> {
    let t = cpu();
    let default = find_default(name);
    let file: Plain<PhdConfig> = load(req, default, |f: &Plain<PhdConfig>| valid(&f.config))?;
    let cubes = read_real_frames(req.input, 4)?;
    let g = file.config.geometry;
    let want = [g.n_range, g.n_doppler, g.n_azimuth];
    ensure!(
        cubes.shape[1..] == want,
        "{}: cubes of shape {:?}, the config's geometry is (n_range, n_doppler, n_azimuth) = {:?}",
        req.input.display(),
        &cubes.shape[1..],
        want
    );
    let read = cpu() - t;
    let cfg = file.config;
    // Large filter: built on a worker stack, then boxed.
    let mut det = crate::montecarlo::on_worker_stack(move || HostFilter::new(cfg, 0).map(Box::new))
        .map_err(|e| anyhow!("{e}"))?;
    det.configure(&cfg, req.seed).map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        name,
        det.as_mut(),
        (0..cubes.frames()).map(|k| cubes.frame(k)),
        req,
        PHD_POSITION,
    )?;
    out.read_seconds = read;
    Ok(out)
}
