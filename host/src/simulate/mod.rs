//! Simulation: every scene the host simulates, one module per detector family, and
//! `faint simulate`, which writes a scene's frames and truth as files (`files.rs`).
//!
//! A scene is a preset named like its paper's scene on the CLI: [`crpf`] holds `othr`,
//! [`mht`] `sea-clutter`, [`phd`] `six-targets`, [`cbmember`] `rotor-uav`, [`dp`]
//! `dim-point`. A preset is data: a struct holding the paper's values and the documented
//! choices for what the paper leaves open. The allocation-free pieces the firmware and the
//! golden cases share are in `faint_core::simulate`.

use anyhow::{bail, Result};

pub mod cbmember;
pub mod crpf;
pub mod dp;
mod files;
pub mod mht;
pub mod phd;

pub use files::{check, simulate, truth_path, Simulated, Spec};

/// `(name, one-line description, preset as JSON)` of every built-in scenario.
type Entry = (&'static str, &'static str, fn() -> serde_json::Value);

const CATALOGUE: &[Entry] = &[(
    "dim-point",
    "DP-TBD (Wang, Zhang 2016): one sub-pixel point target in 128 x 128 Gaussian-noise images, 1 or 2 px/frame, SNR 1.6-2.5, 40 frames",
    dp::DimPoint::describe,
), (
    "rotor-uav",
    "CBMeMBer joint Doppler / micro-Doppler TBD (rotor-UAV paper, 2023): one rotor UAV, 256 x 512 range-Doppler maps, B = 2, 40 frames",
    cbmember::RotorUav::describe,
), (
    "othr",
    "sky-wave OTHR, one range cell, Doppler-manoeuvring target, K = m = 32 (Lu et al. 2017)",
    crpf::describe,
), (
    "sea-clutter",
    "MHT-TBD (Bao et al. 2022): 6 km x 6 km sea surface, 5 CV targets, Poisson clutter (shown at lambda = 398)",
    || serde_json::to_value(mht::SeaClutter::paper(398.0)).unwrap_or_default(),
), (
    "six-targets",
    "Pei et al. 2019 PSO-PHD-TBD: six CV targets, range x Doppler x azimuth power cube, 40 frames",
    phd::SixTargets::describe,
)];

/// Names and descriptions of the built-in scenarios.
pub fn catalogue() -> impl Iterator<Item = (&'static str, &'static str)> {
    CATALOGUE.iter().map(|(n, d, _)| (*n, *d))
}

/// The preset called `name`, as JSON; an unknown name is an error that lists the
/// known ones.
pub fn describe(name: &str) -> Result<serde_json::Value> {
    match CATALOGUE.iter().find(|(n, _, _)| *n == name) {
        Some((_, _, f)) => Ok(f()),
        None => {
            let known: Vec<&str> = CATALOGUE.iter().map(|e| e.0).collect();
            bail!(
                "unknown scenario '{name}'; known scenarios: {}",
                if known.is_empty() {
                    "(none)".to_string()
                } else {
                    known.join(", ")
                }
            )
        }
    }
}
