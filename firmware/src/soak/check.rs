//! The output check, the host soak's (`check_outputs`): "NaN" or "inf" anywhere in the
//! report's Debug text, a non-finite detection, or an existence score outside [0, 1].

use core::fmt::{self, Debug, Write};

use faint_core::detect::{Detector, ScoreKind};

/// A `fmt::Write` that only notes whether "NaN" or "inf" was written.
struct NonFinite(bool);

impl Write for NonFinite {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        if s.contains("NaN") || s.contains("inf") {
            self.0 = true;
        }
        Ok(())
    }
}

/// True when `report` or `det`'s detections carry a NaN/inf, or an existence score is
/// outside `[0, 1]`.
pub fn bad_output<D: Detector + ?Sized>(det: &D, report: &D::Report) -> bool
where
    D::Report: Debug,
{
    let mut probe = NonFinite(false);
    let _ = write!(probe, "{report:?}");
    if probe.0 {
        return true;
    }
    det.detections().any(|d| {
        !(d.score.is_finite() && d.state().iter().all(|x| x.is_finite()))
            || (D::SCORE == ScoreKind::Existence && !(0.0..=1.0).contains(&d.score))
    })
}
