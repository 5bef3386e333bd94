//! Soak: one detector with its preset configuration, streamed plausible frames without a
//! reset, watching the per-frame cost, the outputs and the process's memory.
//!
//! The run is cut into [`BLOCKS`] equal blocks; the figures are the CPU time per frame of
//! the first and the last block (a drift shows as their ratio), the worst block, the
//! count of steps with a NaN/inf output or an error, and the resident memory before and
//! after (`/proc/self/statm`; the detector is allocated before the first reading).

use std::fmt::Debug;

use faint_core::detect::Detector;
use faint_core::rng::Rng;
use serde::{Deserialize, Serialize};

use super::{check_outputs, Mode, Target};
use crate::timing::thread_cpu_seconds;

/// Blocks a soak run is cut into.
pub const BLOCKS: usize = 20;

/// What a soak run measured.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Soak {
    /// Detector name.
    pub detector: String,
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
}

/// Resident set size of this process (KiB; 0 where `/proc` is unavailable).
pub fn rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/statm")
        .ok()
        .and_then(|s| s.split_whitespace().nth(1)?.parse::<u64>().ok())
        .map_or(0, |pages| pages * 4)
}

/// Streams `frames` plausible frames (seed `seed`) through `det`, configured with the
/// target's preset.
pub fn soak<D, T>(target: &Target<D, T>, det: &mut D, frames: u64, seed: u64) -> Soak
where
    D: Detector<Frame = [T]> + ?Sized,
    D::Config: serde::de::DeserializeOwned,
    D::Report: Debug,
{
    let mut out = Soak {
        detector: target.name.to_string(),
        frames,
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
            }
            Err(_) => out.errors += 1,
        }
        if n_block == block {
            blocks.push(1e6 * t_block / n_block as f64);
            t_block = 0.0;
            n_block = 0;
        }
    }
    if n_block > 0 {
        blocks.push(1e6 * t_block / n_block as f64);
    }
    out.rss_after_kib = rss_kib();
    out.first_us = blocks.first().copied().unwrap_or(0.0);
    out.last_us = blocks.last().copied().unwrap_or(0.0);
    out.worst_us = blocks.iter().copied().fold(0.0, f64::max);
    out
}
