//! Closed-form detection models.
pub mod dp;
pub mod mht;
