//! Closed-form detection models.
pub mod mht;
