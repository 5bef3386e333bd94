//! The host's detector instances: every detector the host runs is built on the heap by
//! [`boxed`], whatever its family and size.
//!
//! A detector's state is fixed-size arrays (`CrpfTbd6000` is 279 KB, `SmcPhdTbdHost`
//! 2.5 MB), so it is built in place: its [`Detector::UNCONFIGURED`] constant is written
//! straight into a heap allocation ([`unconfigured`]), then [`Detector::configure`] sets it
//! up, exactly as `new(cfg, seed)` would build it by value.

use anyhow::{anyhow, Result};
use faint_core::detect::Detector;

/// A configured detector on the heap: [`unconfigured`], then
/// [`configure`](Detector::configure)`(cfg, seed)`. Errors: the configuration's, as the
/// core error's one line.
pub fn boxed<D: Detector>(cfg: &D::Config, seed: u64) -> Result<Box<D>> {
    let mut det = unconfigured::<D>();
    det.configure(cfg, seed).map_err(|e| anyhow!("{e}"))?;
    Ok(det)
}

/// The unconfigured detector ([`Detector::UNCONFIGURED`]) on the heap, for a caller that
/// configures it later (or reconfigures it per trial).
pub fn unconfigured<D: Detector>() -> Box<D> {
    let mut det = Box::<D>::new_uninit();
    det.write(D::UNCONFIGURED);
    // SAFETY: initialised by the `write` above.
    unsafe { det.assume_init() }
}
