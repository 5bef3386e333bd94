//! The core primitives: samplers against exact laws, and property tests of resampling,
//! log-domain normalisation and the existence chain. One test binary.

mod props;
mod samplers;
