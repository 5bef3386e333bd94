//! One reproduction per paper.
pub mod mht;
