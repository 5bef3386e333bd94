//! The crate's one error type: small, `Copy`, no allocation.

use core::fmt;

/// Everything that can go wrong in `faint-core`.
///
/// Errors carry just enough context to name the problem without allocating.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Error {
    /// A configuration value is out of its valid range; the payload names the field.
    InvalidConfig(&'static str),
    /// An input slice has the wrong length.
    LengthMismatch {
        /// The length the callee needs.
        expected: usize,
        /// The length it was given.
        got: usize,
    },
    /// An input holds NaN or +-inf.
    NonFinite,
    /// A weight is negative.
    NegativeWeight,
    /// The weights sum to zero, or their sum is not finite: nothing to resample from.
    DegenerateWeights,
    /// More items than a fixed capacity can hold.
    Capacity {
        /// The capacity.
        capacity: usize,
        /// How many items were offered.
        requested: usize,
    },
    /// An input that must not be empty is empty.
    Empty,
    /// An index buffer's type cannot address this many particles, or an index is out of
    /// range.
    IndexOutOfRange,
    /// Ancestor indices must be sorted ascending for the in-place gather.
    UnsortedAncestors,
    /// Every value is finite but a sum of them overflows `f32` (e.g. a frame's energy).
    Overflow,
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidConfig(field) => write!(f, "invalid configuration value: {field}"),
            Error::LengthMismatch { expected, got } => {
                write!(f, "wrong input length: expected {expected}, got {got}")
            }
            Error::NonFinite => f.write_str("input holds NaN or infinity"),
            Error::NegativeWeight => f.write_str("a weight is negative"),
            Error::DegenerateWeights => f.write_str("weights sum to zero or to a non-finite value"),
            Error::Capacity {
                capacity,
                requested,
            } => write!(f, "capacity {capacity} exceeded: {requested} items offered"),
            Error::Empty => f.write_str("input is empty"),
            Error::IndexOutOfRange => f.write_str("index out of range for the index type"),
            Error::UnsortedAncestors => f.write_str("ancestor indices are not sorted"),
            Error::Overflow => f.write_str("values are finite but their sum overflows f32"),
        }
    }
}

impl core::error::Error for Error {}
