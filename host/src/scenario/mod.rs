//! Scenario simulators, one module per paper's scene.
pub mod sea_clutter;
