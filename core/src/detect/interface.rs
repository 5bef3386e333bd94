//! The one interface every detector implements, and the generic frame loop built on it.
//!
//! A detector is a [`Config`](Detector::Config) validated once, a fixed-size state, a
//! borrowed [`Frame`](Detector::Frame) per step and a small `Copy`
//! [`Report`](Detector::Report). What the detector believes after a step is read back,
//! without knowing its family, as [`Detection`]s:
//!
//! ```
//! use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
//! use faint_core::detect::{run, Detector};
//! use faint_core::Complex32;
//!
//! let mut det = CrpfTbd::<256>::new(CrpfConfig::othr(), 7)?;
//! // Ten frames of 32 complex bins (a user's recorded frames go here).
//! let frames = vec![vec![Complex32::new(0.1, -0.2); 32]; 10];
//! let mut last = 0.0;
//! run(&mut det, frames.iter().map(|f| f.as_slice()), |_k, det, _report| {
//!     for d in det.detections() {
//!         // d.state() = [fd, fda, A] (CrpfTbd::STATE), d.score = existence probability
//!         last = d.score;
//!     }
//! })?;
//! assert!((0.0..=1.0).contains(&last));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use crate::{Error, Result};

/// Largest state dimension a [`Detection`] carries.
pub const MAX_STATE: usize = 6;

/// What a [`Detection::score`] measures (one kind per detector).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScoreKind {
    /// Existence probability in `[0, 1]` (CRPF-TBD, PF-TBD, JOTT).
    Existence,
    /// Cumulative log likelihood ratio `ln p(Z|H1) / p(Z|H0)` (PF-LRT).
    LogLikelihoodRatio,
    /// Binary-integration count of the Hough cell (MHT-TBD, classic Hough).
    Count,
    /// PHD mass of the extracted cluster (expected number of targets it holds).
    Mass,
    /// Dynamic-programming merit: the summed score of the best track ending at the
    /// detection, in the input's intensity units (DP-TBD).
    Merit,
}

impl ScoreKind {
    /// Short lowercase name (`existence`, `log_lr`, `count`, `mass`, `merit`).
    pub const fn name(self) -> &'static str {
        match self {
            ScoreKind::Existence => "existence",
            ScoreKind::LogLikelihoodRatio => "log_lr",
            ScoreKind::Count => "count",
            ScoreKind::Mass => "mass",
            ScoreKind::Merit => "merit",
        }
    }
}

/// Track identity of a [`Detection`], where the algorithm has one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TrackInfo {
    /// Identifier, unique among the detections of one report.
    pub id: u32,
    /// Track length: associated plots (Hough detectors).
    pub len: u32,
}

/// One detection: a state estimate (names in [`Detector::STATE`]), a score (meaning in
/// [`Detector::SCORE`]) and, where the algorithm has one, a track.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Detection {
    state: [f32; MAX_STATE],
    dim: u8,
    /// The detector's score of this detection ([`Detector::SCORE`]).
    pub score: f32,
    /// Track identity and length, `None` for detectors without tracks.
    pub track: Option<TrackInfo>,
}

impl Detection {
    /// A detection of `state` (at most [`MAX_STATE`] values; more are cut).
    pub fn new(state: &[f32], score: f32, track: Option<TrackInfo>) -> Self {
        let mut s = [0.0; MAX_STATE];
        let dim = state.len().min(MAX_STATE);
        for (o, &v) in s.iter_mut().zip(state) {
            *o = v;
        }
        Self {
            state: s,
            dim: dim as u8,
            score,
            track,
        }
    }

    /// The state estimate.
    pub fn state(&self) -> &[f32] {
        self.state.get(..usize::from(self.dim)).unwrap_or(&[])
    }
}

/// A configuration that checks itself. A config that validates can be given to its
/// detector's [`Detector::configure`]; that call adds only the checks that depend on
/// the detector's capacities.
pub trait Validate {
    /// Checks every value; `Err(Error::InvalidConfig(field))` names the first bad one.
    fn validate(&self) -> Result<()>;
}

/// The interface of every detector in faint.
///
/// One [`step`](Detector::step) per frame; a frame that fails does so with a typed error
/// before any state changes. After a successful step,
/// [`detections`](Detector::detections) iterates what the detector reports for it.
///
/// Every detector is built the same way: its `const fn new_unconfigured()` (the constant
/// [`UNCONFIGURED`](Detector::UNCONFIGURED)), then [`configure`](Detector::configure) in
/// place. A large detector can therefore live in a `static` (its unconfigured state is
/// all-zero bits, in `.bss` on a target, for every detector but MHT-TBD) without a copy
/// through the stack and without `unsafe` for its construction:
///
/// ```
/// use faint_core::detect::crpf::{CrpfConfig, CrpfTbd1000};
/// use faint_core::detect::Detector;
/// use faint_core::Complex32;
/// use std::sync::Mutex;
///
/// static DET: Mutex<CrpfTbd1000> = Mutex::new(CrpfTbd1000::new_unconfigured());
///
/// let mut det = DET.lock()?; // an error only if another holder panicked
/// assert!(det.step(&[Complex32::new(0.0, 0.0); 32]).is_err()); // not configured yet
/// det.configure(&CrpfConfig::othr(), 7)?;
/// let report = det.step(&[Complex32::new(0.1, -0.2); 32])?;
/// assert_eq!(report.frame, 1);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
///
/// On a target without `std` the same constant initialises a `static mut`, a
/// `critical_section::Mutex<RefCell<_>>` or a `static_cell::StaticCell`; on a host,
/// `Box::new(D::UNCONFIGURED)` then `configure` builds one on the heap.
pub trait Detector {
    /// One frame of input, borrowed: `[Complex32]` (Doppler frames), `[Plot]` (plot
    /// lists), `[f32]` (power cubes, images).
    type Frame: ?Sized;
    /// Runtime configuration.
    type Config: Validate + Copy;
    /// What one step returns (small, `Copy`).
    type Report: Copy;
    /// Names (with units) of the components of [`Detection::state`].
    const STATE: &'static [&'static str];
    /// What [`Detection::score`] measures.
    const SCORE: ScoreKind;

    /// The unconfigured detector, a compile-time constant (also `new_unconfigured()` on
    /// every detector). Until [`configure`](Detector::configure) succeeds, every other call
    /// returns a typed error or nothing. Generic code builds any detector in place from it
    /// (a `static`, or a `Box` on a host).
    const UNCONFIGURED: Self;

    /// Validates `cfg` against the detector's capacities and restarts in place from
    /// `seed`, as a new detector would start; on error `self` is unchanged. Works on an
    /// [`UNCONFIGURED`](Detector::UNCONFIGURED) detector, e.g. one in a `static`.
    fn configure(&mut self, cfg: &Self::Config, seed: u64) -> Result<()>;
    /// The configuration in use.
    fn config(&self) -> &Self::Config;
    /// Restarts from frame 0 with the same configuration and a new random stream.
    fn reset(&mut self, seed: u64);
    /// Processes one frame.
    fn step(&mut self, frame: &Self::Frame) -> Result<Self::Report>;
    /// Number of detections of the last step.
    fn detection_count(&self) -> usize;
    /// Detection `i` of the last step (`None` past [`detection_count`](Self::detection_count)).
    fn detection(&self, i: usize) -> Option<Detection>;

    /// The detections of the last step.
    fn detections(&self) -> Detections<'_, Self> {
        Detections { det: self, next: 0 }
    }
}

/// The `const UNCONFIGURED: Self` item of a detector whose unconfigured state is all-zero
/// bits (every field: numbers, `bool`, `Option` of numbers, enums with a 0 tag, arrays
/// and structs of those), so that a `static` of it lands in `.bss`. The one place a
/// detector is built by zeroing.
macro_rules! unconfigured_is_zero {
    () => {
        // SAFETY: an associated `const` is evaluated by the compiler for every type that
        // uses it, and the evaluator rejects a value that is invalid for its type (an
        // enum tag without a variant, a reference, a `NonZero`): a detector with a field
        // for which all-zero bits are not a valid value fails to compile.
        #[allow(unsafe_code)]
        const UNCONFIGURED: Self = unsafe { ::core::mem::MaybeUninit::zeroed().assume_init() };
    };
}
pub(crate) use unconfigured_is_zero;

/// Iterator over a detector's [`Detection`]s (see [`Detector::detections`]).
#[derive(Debug)]
pub struct Detections<'a, D: ?Sized> {
    det: &'a D,
    next: usize,
}

impl<D: Detector + ?Sized> Iterator for Detections<'_, D> {
    type Item = Detection;

    fn next(&mut self) -> Option<Detection> {
        let d = self.det.detection(self.next)?;
        self.next += 1;
        Some(d)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.det.detection_count().saturating_sub(self.next);
        (n, Some(n))
    }
}

/// A frame that [`run`] could not process: its 0-based index and the error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameError {
    /// 0-based index of the frame.
    pub frame: usize,
    /// What the detector said.
    pub error: Error,
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "frame {}: {}", self.frame, self.error)
    }
}

impl core::error::Error for FrameError {}

/// The frame loop: steps `det` through `frames` and calls `sink(k, det, &report)` after
/// each step `k` (0-based), where `det.detections()` holds that frame's detections.
/// Stops at the first frame that fails (the detector is left as before that frame).
/// Returns the number of frames processed.
pub fn run<'f, D, I, S>(
    det: &mut D,
    frames: I,
    mut sink: S,
) -> core::result::Result<usize, FrameError>
where
    D: Detector + ?Sized,
    D::Frame: 'f,
    I: IntoIterator<Item = &'f D::Frame>,
    S: FnMut(usize, &D, &D::Report),
{
    let mut n = 0usize;
    for frame in frames {
        match det.step(frame) {
            Ok(report) => sink(n, det, &report),
            Err(error) => return Err(FrameError { frame: n, error }),
        }
        n += 1;
    }
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn detection_keeps_its_state() {
        let d = Detection::new(&[1.0, 2.0, 3.0], 0.5, None);
        assert_eq!(d.state(), &[1.0, 2.0, 3.0]);
        let long = Detection::new(&[1.0; 9], 0.0, Some(TrackInfo { id: 1, len: 4 }));
        assert_eq!(long.state().len(), MAX_STATE);
        assert_eq!(Detection::default().state(), &[] as &[f32]);
    }
}
