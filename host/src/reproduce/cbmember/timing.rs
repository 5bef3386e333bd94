//! Table 3 of `faint reproduce cbmember`: CPU time per frame of the filters' `step`.

use std::time::Instant;

use anyhow::Result;
use faint_core::detect::Detector;
use faint_core::model::range_doppler::PointModel;
use faint_core::rng::Rng;
use serde::Serialize;

use super::paper;
use crate::instances::cbmember::HostFilter;
use crate::simulate::cbmember::{MapSource, RotorUav};

/// Table 3 timing row.
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct TimingRow {
    /// Algorithm.
    pub algorithm: String,
    /// `L_max`.
    pub particles: usize,
    /// Frames timed.
    pub frames: usize,
    /// Mean particles updated per frame (births included).
    pub particles_per_frame: f64,
    /// Mean CPU time per frame of the filter's `step` (ms, one thread; wall time where
    /// the thread's CPU time is not available).
    pub ms_per_frame: f64,
    /// The paper's (s).
    pub paper_s: Option<f64>,
    /// Paper / ours.
    pub speed_up: Option<f64>,
}

/// CPU time of this thread in ns (Linux `/proc/thread-self/schedstat`), or None.
fn thread_cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

pub(super) fn timing(frames: usize, seed: u64) -> Result<Vec<TimingRow>> {
    let mut sc = RotorUav::new(-10.0);
    sc.frames = frames;
    let truth = sc.truth();
    let mut out = Vec::new();
    for (algo, model, particles) in [
        ("Doppler-only", PointModel::DopplerOnly, 1500usize),
        ("joint", PointModel::Joint, 700),
        ("joint", PointModel::Joint, 1000),
        ("joint", PointModel::Joint, 1500),
    ] {
        let mut rng = Rng::from_stream(seed, 77);
        let mut src = MapSource::new(&sc);
        let mut f = crate::instances::boxed::<HostFilter>(&sc.config(model, particles), seed)?;
        let mut map = Vec::new();
        let mut secs = 0.0;
        let mut parts = 0usize;
        for (k, t) in truth.iter().enumerate() {
            src.power(&sc, t, k, &mut rng, &mut map);
            let (t0, c0) = (Instant::now(), thread_cpu_ns());
            let r = f.step(&map[..]).map_err(|e| anyhow::anyhow!("{e}"))?;
            // Thread CPU time where Linux gives it (a shared machine's waits for a core
            // are not counted), else wall time.
            secs += match (c0, thread_cpu_ns()) {
                (Some(a), Some(b)) => (b - a) as f64 * 1e-9,
                _ => t0.elapsed().as_secs_f64(),
            };
            parts += r.particles;
        }
        let ms = 1e3 * secs / frames as f64;
        let paper = paper::TABLE3
            .iter()
            .find(|p| p.0 == algo && p.1 == particles)
            .map(|p| p.2);
        out.push(TimingRow {
            algorithm: algo.to_string(),
            particles,
            frames,
            particles_per_frame: parts as f64 / frames as f64,
            ms_per_frame: ms,
            paper_s: paper,
            speed_up: paper.map(|p| 1e3 * p / ms),
        });
    }
    Ok(out)
}
