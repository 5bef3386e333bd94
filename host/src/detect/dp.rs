//! DP-TBD on intensity images.

use anyhow::{ensure, Result};
use faint_core::detect::dp::{first_clamped, DpConfig, DpReport, MeritCell, Method};
use serde::{Deserialize, Serialize};

use super::{drive_with, find_default, json, load, valid, Outcome, Request, XY_POSITION};
use crate::io::input::read_real_frames;
use crate::scenario::dp::with_dp;
use crate::timing::thread_cpu_seconds as cpu;

/// A DP-TBD detector's configuration file: `q_B` (9 or 25, compiled in) and the core
/// configuration; `M = 128` and `L = 40` are compiled in.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DpFile {
    /// Predecessor window `q_B`: 9 (3 x 3, up to 1 px/frame) or 25 (5 x 5, up to 2).
    pub q_b: usize,
    /// The core configuration.
    pub config: DpConfig,
}

pub(super) fn default_dp(method: Method) -> String {
    json(&DpFile {
        q_b: 9,
        config: DpConfig::dim_point(method, 1),
    })
}

/// A DP report as one line of `reports.json`.
#[derive(Serialize)]
struct DpReportJson {
    frame: u32,
    best_x: u16,
    best_y: u16,
    best_merit: f32,
    clamped: u32,
}

fn dp_report_json(r: &DpReport) -> String {
    serde_json::to_string(&DpReportJson {
        frame: r.frame,
        best_x: r.best.x,
        best_y: r.best.y,
        best_merit: r.best.merit,
        clamped: r.clamped,
    })
    .unwrap_or_default()
}

pub(super) fn run_dp(req: &Request, name: &'static str, method: Method) -> Result<Outcome> {
    let t = cpu();
    let default = find_default(name);
    let file: DpFile = load(req, default, |f: &DpFile| {
        ensure!(
            f.q_b == 9 || f.q_b == 25,
            "q_b = {}: must be 9 or 25 (compiled in)",
            f.q_b
        );
        ensure!(
            f.config.method == method,
            "config.method is {:?}; {name} runs {:?}",
            f.config.method,
            method
        );
        valid(&f.config)
    })?;
    let images = read_real_frames(req.input, 3)?;
    let m = crate::scenario::dp::SIDE;
    ensure!(
        images.shape[1..] == [m, m],
        "{}: images of shape {:?}, the DP detectors are built for (K, {m}, {m})",
        req.input.display(),
        images.shape
    );
    let cfg = file.config;
    refuse_clamped(req, &cfg, &images.data, m, m)?;
    let read = cpu() - t;
    let mut out = with_dp!(method, file.q_b, &cfg, |det| {
        let mut det = det;
        drive_with(
            name,
            det.as_mut(),
            (0..images.frames()).map(|k| images.frame(k)),
            req,
            XY_POSITION,
            dp_report_json,
        )?
    });
    out.read_seconds = read;
    Ok(out)
}

/// Refuses input the quantiser would clamp (the core clamps and counts such pixels; here
/// they are an error naming the first one, before the detector runs): frame `k`, pixel
/// `(x, y)` of a row-major `h x w` frame.
fn refuse_clamped(req: &Request, cfg: &DpConfig, data: &[f32], h: usize, w: usize) -> Result<()> {
    let n = (h * w).max(1);
    for (k, frame) in data.chunks(n).enumerate() {
        if let Some(i) = first_clamped::<i16>(cfg, frame) {
            let lim = i16::ZMAX as f32 * cfg.lsb;
            anyhow::bail!(
                "{}: frame {k}, pixel (x, y) = ({}, {}) is {}, outside the DP quantiser's range +-{lim} ({} LSB of lsb = {}); normalise the images or raise lsb",
                req.input.display(),
                i % w,
                i / w,
                frame[i],
                i16::ZMAX,
                cfg.lsb
            );
        }
    }
    Ok(())
}
