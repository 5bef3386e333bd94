//! DP-TBD instances shared by the host and the firmware, named once (their `W` computed by
//! [`dp_tbd!`](crate::dp_tbd)).
//!
//! [`SIDE`] x [`SIDE`] images over [`HISTORY`] frames are the `dim-point` scenario's
//! (Wang, Zhang 2016, §4: 128 x 128 images, 40 frames, the whole track recovered);
//! the `Reduced` ones are the same on [`REDUCED_SIDE`] x [`REDUCED_SIDE`] images (the
//! soak runs and the reduced reliability targets).

/// Image side `M` of the `dim-point` scenario.
pub const SIDE: usize = 128;
/// Recoverable track length `L` (frames) of the `dim-point` scenario: the whole run.
pub const HISTORY: usize = 40;
/// Image side of the reduced instances.
pub const REDUCED_SIDE: usize = 32;

/// Arnold, `q_B = 9`.
pub type Arnold9 = crate::dp_tbd!(Arnold, SIDE, 9, HISTORY);
/// Arnold, `q_B = 25`.
pub type Arnold25 = crate::dp_tbd!(Arnold, SIDE, 25, HISTORY);
/// Pulford, `q_B = 9`.
pub type Pulford9 = crate::dp_tbd!(Pulford, SIDE, 9, HISTORY);
/// Pulford, `q_B = 25`.
pub type Pulford25 = crate::dp_tbd!(Pulford, SIDE, 25, HISTORY);
/// Second order, `q_B = 9`.
pub type Second9 = crate::dp_tbd!(SecondOrder, SIDE, 9, HISTORY);
/// Second order, `q_B = 25`.
pub type Second25 = crate::dp_tbd!(SecondOrder, SIDE, 25, HISTORY);
/// Arnold, `q_B = 9`, on the reduced image.
pub type Arnold9Reduced = crate::dp_tbd!(Arnold, REDUCED_SIDE, 9, HISTORY);
/// Pulford, `q_B = 9`, on the reduced image.
pub type Pulford9Reduced = crate::dp_tbd!(Pulford, REDUCED_SIDE, 9, HISTORY);
/// Second order, `q_B = 9`, on the reduced image.
pub type Second9Reduced = crate::dp_tbd!(SecondOrder, REDUCED_SIDE, 9, HISTORY);
