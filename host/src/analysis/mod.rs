//! Closed-form detection models.
pub mod hough_model;
