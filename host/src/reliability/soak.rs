//! Soak: one detector with its preset configuration, streamed plausible frames without a
//! reset, watching the per-frame cost, the outputs and the process's memory.
//!
//! The run is cut into [`BLOCKS`] equal blocks; the figures are the CPU time per frame of
//! the first and the last block (a drift shows as their ratio), the worst block, the
//! count of steps with a NaN/inf output or an error, and the resident memory before,
//! after, and the largest reading at a block's end (`/proc/self/statm`; the detector is
//! allocated before the first reading).
//!
//! [`Shape::Reduced`] runs the slow detectors in a smaller configuration, so that a run of
//! 1e6 frames costs minutes rather than CPU-hours (the arithmetic and the code paths are
//! those of the preset; only the sizes differ, see [`Shape`]).

use std::fmt::Debug;

use faint_core::detect::cbmember::CbmemberReport;
use faint_core::detect::dp::DpReport;
use faint_core::detect::mht::{ClassicHoughReport, MhtReport};
use faint_core::detect::phd::PhdReport;
use faint_core::detect::Detector;
use faint_core::model::doppler::DopplerReport;
use faint_core::rng::Rng;
use serde::{Deserialize, Serialize};

use super::{check_outputs, Mode, Target};
use crate::timing::thread_cpu_seconds;

/// Blocks a soak run is cut into.
pub const BLOCKS: usize = 20;

/// The configuration a soak streams frames through.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Shape {
    /// The configuration of the campaigns: the presets, with 1000 particles for the
    /// Doppler-frame filters and the PSO-PHD-TBD cube shrunk to 30 x 30 x 20 cells
    /// ([`super::targets::small_phd`]).
    #[default]
    Preset,
    /// Smaller sizes for the slow detectors, the same model otherwise:
    /// PHD-TBD and PSO-PHD-TBD on an 8 x 8 x 4 cube over the preset's extent with 50
    /// particles per target and 25 births (the swarm at most 32 particles);
    /// CBMeMBer on a 32 x 64 map over the preset's extent with `L_max = 100`,
    /// `L_min = 30` and 30 birth particles; DP-TBD on 32 x 32 images. The other
    /// detectors run their preset configuration.
    Reduced,
}

impl Shape {
    /// Short name.
    pub fn name(self) -> &'static str {
        match self {
            Shape::Preset => "preset",
            Shape::Reduced => "reduced",
        }
    }
}

/// Two work counters of a step, read from its report: what a cost drift is checked
/// against (their block means are kept with the CPU times).
pub trait WorkCounters {
    /// What the two counters are.
    const NAMES: [&'static str; 2];
    /// The counters of this report.
    fn work(&self) -> [f64; 2];
}

impl WorkCounters for DopplerReport {
    const NAMES: [&'static str; 2] = ["estimate's abs(fda) (Hz/s)", "estimate's amplitude"];
    fn work(&self) -> [f64; 2] {
        self.estimate
            .map_or([0.0; 2], |x| [f64::from(x[1].abs()), f64::from(x[2])])
    }
}

impl WorkCounters for MhtReport {
    const NAMES: [&'static str; 2] = ["plots kept", "chains"];
    fn work(&self) -> [f64; 2] {
        [f64::from(self.plots_kept), f64::from(self.censor.chains)]
    }
}

impl WorkCounters for ClassicHoughReport {
    const NAMES: [&'static str; 2] = ["plots used", "peaks"];
    fn work(&self) -> [f64; 2] {
        [f64::from(self.plots_used), f64::from(self.condense.peaks)]
    }
}

impl WorkCounters for PhdReport {
    const NAMES: [&'static str; 2] = ["particles", "N_hat"];
    fn work(&self) -> [f64; 2] {
        [self.particles as f64, self.n_hat as f64]
    }
}

impl WorkCounters for CbmemberReport {
    const NAMES: [&'static str; 2] = ["live components", "particles updated"];
    fn work(&self) -> [f64; 2] {
        [self.components as f64, self.particles as f64]
    }
}

impl WorkCounters for DpReport {
    const NAMES: [&'static str; 2] = ["best merit", "clamped pixels"];
    fn work(&self) -> [f64; 2] {
        [f64::from(self.best.merit), f64::from(self.clamped)]
    }
}

/// What a soak run measured.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Soak {
    /// Detector name.
    pub detector: String,
    /// The configuration's size.
    pub shape: Shape,
    /// Frames streamed.
    pub frames: u64,
    /// Steps that returned an error.
    pub errors: u64,
    /// Steps with a NaN/inf output or an existence outside `[0, 1]`.
    pub bad_outputs: u64,
    /// CPU microseconds per frame, first block.
    pub first_us: f64,
    /// CPU microseconds per frame, last block.
    pub last_us: f64,
    /// CPU microseconds per frame, slowest block.
    pub worst_us: f64,
    /// Resident memory before the first frame (KiB).
    pub rss_before_kib: u64,
    /// Resident memory after the last frame (KiB).
    pub rss_after_kib: u64,
    /// Largest resident memory read at the end of a block (KiB).
    pub rss_max_kib: u64,
    /// CPU microseconds per frame of every block, in order.
    pub blocks_us: Vec<f64>,
    /// What the work counters are ([`WorkCounters::NAMES`]).
    pub work_names: Vec<String>,
    /// Block means of the two work counters, in order.
    pub blocks_work: Vec<[f64; 2]>,
}

/// Resident set size of this process (KiB; 0 where `/proc` is unavailable).
pub fn rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |pages| pages * 4)
}

/// Streams `frames` plausible frames (seed `seed`) through `det`, configured with the
/// target's configuration (`shape` is recorded, the target already holds its sizes).
pub fn soak<D, T>(target: &Target<D, T>, det: &mut D, frames: u64, seed: u64, shape: Shape) -> Soak
where
    D: Detector<Frame = [T]> + ?Sized,
    D::Config: serde::de::DeserializeOwned,
    D::Report: Debug + WorkCounters,
{
    let mut out = Soak {
        detector: target.name.to_string(),
        shape,
        frames,
        work_names: D::Report::NAMES.iter().map(|n| n.to_string()).collect(),
        ..Soak::default()
    };
    let Ok(cfg) = serde_json::from_value::<D::Config>(target.base.clone()) else {
        out.errors = frames;
        return out;
    };
    if det.configure(&cfg, seed).is_err() {
        out.errors = frames;
        return out;
    }
    let mut rng = Rng::seed_from_u64(seed);
    let block = (frames / BLOCKS as u64).max(1);
    out.rss_before_kib = rss_kib();
    let mut t_block = 0.0f64;
    let mut n_block = 0u64;
    let mut blocks = Vec::with_capacity(BLOCKS + 1);
    let mut work = [0.0f64; 2];
    for _ in 0..frames {
        let frame = (target.frame)(&mut rng, &cfg, Mode::Plausible);
        let t = thread_cpu_seconds();
        let r = det.step(&frame);
        t_block += thread_cpu_seconds() - t;
        n_block += 1;
        match r {
            Ok(rep) => {
                if check_outputs(det, &rep).is_some() {
                    out.bad_outputs += 1;
                }
                let w = rep.work();
                work[0] += w[0];
                work[1] += w[1];
            }
            Err(_) => out.errors += 1,
        }
        if n_block == block {
            blocks.push(1e6 * t_block / n_block as f64);
            out.blocks_work
                .push([work[0] / n_block as f64, work[1] / n_block as f64]);
            work = [0.0; 2];
            out.rss_max_kib = out.rss_max_kib.max(rss_kib());
            if !crate::montecarlo::quiet() {
                let w = out.blocks_work.last().copied().unwrap_or_default();
                eprintln!(
                    "soak {}: block {}/{BLOCKS}, {:.1} us/frame, errors {}, NaN/inf {}, {} {:.3}, {} {:.3}",
                    target.name,
                    blocks.len(),
                    blocks.last().copied().unwrap_or(0.0),
                    out.errors,
                    out.bad_outputs,
                    D::Report::NAMES[0],
                    w[0],
                    D::Report::NAMES[1],
                    w[1]
                );
            }
            t_block = 0.0;
            n_block = 0;
        }
    }
    if n_block > 0 {
        blocks.push(1e6 * t_block / n_block as f64);
        out.blocks_work
            .push([work[0] / n_block as f64, work[1] / n_block as f64]);
    }
    out.rss_after_kib = rss_kib();
    out.rss_max_kib = out.rss_max_kib.max(out.rss_after_kib);
    out.first_us = blocks.first().copied().unwrap_or(0.0);
    out.last_us = blocks.last().copied().unwrap_or(0.0);
    out.worst_us = blocks.iter().copied().fold(0.0, f64::max);
    out.blocks_us = blocks;
    out
}
