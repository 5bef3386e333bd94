//! CBMeMBer TBD on range x velocity power maps.

use anyhow::{anyhow, ensure, Result};
use faint_core::detect::cbmember::CbmemberConfig;
use faint_core::detect::Detector;
use faint_core::model::range_doppler::PointModel;

use super::{drive, find_default, json, load, valid, Outcome, Plain, Request};
use crate::io::input::read_real_frames;
use crate::scenario::cbmember::HostFilter as CbmemberHost;
use crate::timing::thread_cpu_seconds as cpu;

pub(super) fn default_cbmember(model: PointModel) -> String {
    json(&Plain {
        config: CbmemberConfig {
            model,
            ..CbmemberConfig::rotor_uav()
        },
    })
}

pub(super) fn run_cbmember(
    req: &Request,
    name: &'static str,
    model: PointModel,
) -> Result<Outcome> {
    let t = cpu();
    let default = match model {
        PointModel::Joint => find_default("cbmember"),
        PointModel::DopplerOnly => find_default("cbmember-doppler"),
    };
    let file: Plain<CbmemberConfig> =
        load(req, default, |f: &Plain<CbmemberConfig>| valid(&f.config))?;
    let maps = read_real_frames(req.input, 3)?;
    let g = file.config.geometry;
    let want = [g.n_range, g.n_velocity];
    ensure!(
        maps.shape[1..] == want,
        "{}: maps of shape {:?}, the config's geometry is (n_range, n_velocity) = {:?}",
        req.input.display(),
        &maps.shape[1..],
        want
    );
    let read = cpu() - t;
    let cfg = file.config;
    let mut det =
        crate::montecarlo::on_worker_stack(move || CbmemberHost::new(cfg, 0).map(Box::new))
            .map_err(|e| anyhow!("{e}"))?;
    det.configure(&cfg, req.seed).map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        name,
        det.as_mut(),
        (0..maps.frames()).map(|k| maps.frame(k)),
        req,
        &[0, 1],
    )?;
    out.read_seconds = read;
    Ok(out)
}
