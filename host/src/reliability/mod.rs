//! Reliability campaigns: every detector driven with mutated configurations and hostile
//! frames ([`fuzz`]), and streamed without reset for a long run ([`soak`]).
//!
//! A fuzz *case* is one configuration (the preset's, or the preset's with one to three
//! values rewritten by [`mutate`]) and a short sequence of frames drawn by [`frames`].
//! A configuration the core rejects (`validate` or `configure`) ends the case. For one
//! that is accepted, every step is checked against the promise of the core:
//!
//! - no panic (the campaign is meant to run with overflow checks and debug assertions
//!   on: the test profile, or `--profile checked`);
//! - no NaN or infinity anywhere in the step's report or detections, and an existence
//!   score inside `[0, 1]`;
//! - a frame that fails leaves the detector unchanged: one case in four runs a second
//!   detector in lockstep that never sees the rejected frames, and the two must report
//!   the same bits after every accepted frame;
//! - no step slower than [`SLOW_STEP_S`] seconds (a hang caught in the act).
//!
//! Each failure is a [`Finding`]; findings are written as JSON to a corpus folder and
//! replayed by `tests/reliability` (a case is regenerated from its seed and index, and
//! its configuration is stored as well, so a finding names what broke).

pub mod cli;
pub mod frames;
pub mod guided;
pub mod mutate;
pub mod soak;
pub mod targets;

use std::cell::RefCell;
use std::fmt::Debug;
use std::panic::{self, AssertUnwindSafe};
use std::time::Instant;

use faint_core::detect::{Detector, ScoreKind};
use faint_core::rng::Rng;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use serde_json::Value;

pub use frames::Mode;

/// A step slower than this (seconds) is reported as a finding.
pub const SLOW_STEP_S: f64 = 2.0;

/// What went wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    /// `step`, `configure` or `reset` panicked.
    Panic,
    /// A report or detection holds NaN or infinity.
    NonFinite,
    /// An existence score outside `[0, 1]`.
    Existence,
    /// A rejected frame changed what the detector reports afterwards.
    ChangedOnError,
    /// A step took longer than [`SLOW_STEP_S`].
    Slow,
}

/// One failure, enough to replay it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// Detector name (as in `faint detect --list`).
    pub detector: String,
    /// What went wrong.
    pub kind: Kind,
    /// Master seed of the campaign.
    pub seed: u64,
    /// Case index (the case's random stream is `Rng::from_stream(seed, case)`).
    pub case: u64,
    /// Frames per case of the campaign.
    pub frames_per_case: usize,
    /// 0-based frame of the case where it happened (`None`: at configure).
    pub frame: Option<usize>,
    /// Mode of that frame.
    pub mode: Option<String>,
    /// The panic message, the offending report, or the slow step's time.
    pub message: String,
    /// JSON pointers the mutation rewrote.
    pub mutated: Vec<String>,
    /// The configuration (JSON) of the case.
    pub config: Value,
    /// The input of a coverage-guided finding (hex; [`guided`]), replayed through
    /// [`guided::by_name`] instead of regenerated from `seed` and `case`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input: Option<String>,
}

/// Counts of one campaign.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Tally {
    /// Detector name.
    pub detector: String,
    /// Cases run.
    pub cases: u64,
    /// Configurations the JSON parser rejected (a float for an integer, out of range).
    pub rejected_parse: u64,
    /// Configurations `validate` or `configure` rejected.
    pub rejected_config: u64,
    /// Frames stepped (the campaign's inputs).
    pub frames: u64,
    /// Frames the detector rejected with a typed error.
    pub rejected_frames: u64,
    /// Frames stepped in a lockstep case (twice).
    pub lockstep_frames: u64,
    /// Findings by kind: panic, non-finite, existence, changed-on-error, slow.
    pub panics: u64,
    /// See [`Kind::NonFinite`].
    pub non_finite: u64,
    /// See [`Kind::Existence`].
    pub existence: u64,
    /// See [`Kind::ChangedOnError`].
    pub changed_on_error: u64,
    /// See [`Kind::Slow`].
    pub slow: u64,
    /// Slowest step seen (s).
    pub slowest_step_s: f64,
    /// Wall time of the campaign (s).
    pub seconds: f64,
    /// The findings (the first few of each kind per campaign are kept).
    #[serde(skip)]
    pub findings: Vec<Finding>,
}

impl Tally {
    /// Total findings.
    pub fn failures(&self) -> u64 {
        self.panics + self.non_finite + self.existence + self.changed_on_error + self.slow
    }

    fn record(&mut self, f: Finding) {
        let n = match f.kind {
            Kind::Panic => &mut self.panics,
            Kind::NonFinite => &mut self.non_finite,
            Kind::Existence => &mut self.existence,
            Kind::ChangedOnError => &mut self.changed_on_error,
            Kind::Slow => &mut self.slow,
        };
        *n += 1;
        if self.findings.iter().filter(|g| g.kind == f.kind).count() < 8 {
            self.findings.push(f);
        }
    }
}

/// What to run.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    /// Master seed.
    pub seed: u64,
    /// First case index (cases `first..first + cases`).
    pub first: u64,
    /// Cases.
    pub cases: u64,
    /// Frames per case.
    pub frames_per_case: usize,
}

thread_local! {
    static CAPTURE: RefCell<Option<String>> = const { RefCell::new(None) };
}

/// Installs (once) a panic hook that, on a thread inside [`catch`], stores the message
/// instead of printing it; elsewhere it calls the previous hook.
fn install_hook() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        let prev = panic::take_hook();
        panic::set_hook(Box::new(move |info| {
            let captured = CAPTURE.with(|c| {
                let mut c = c.borrow_mut();
                if c.is_some() {
                    *c = Some(info.to_string());
                    true
                } else {
                    false
                }
            });
            if !captured {
                prev(info);
            }
        }));
    });
}

/// Runs `f`, turning a panic into `Err(message)`.
fn catch<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    install_hook();
    CAPTURE.with(|c| *c.borrow_mut() = Some(String::new()));
    let r = panic::catch_unwind(AssertUnwindSafe(f));
    let msg = CAPTURE.with(|c| c.borrow_mut().take()).unwrap_or_default();
    r.map_err(|_| msg)
}

/// True when arithmetic overflow panics in this build (what a campaign should run with).
pub fn overflow_checks_on() -> bool {
    let x = std::hint::black_box(i32::MAX);
    catch(|| std::hint::black_box(x) + std::hint::black_box(1)).is_err()
}

/// The report and the detections of the last step, as text (Debug prints the shortest
/// representation that reads back to the same bits, so equal text is equal bits).
pub fn outputs<D: Detector + ?Sized>(det: &D, report: &D::Report) -> String
where
    D::Report: Debug,
{
    let mut s = format!("{report:?}");
    for d in det.detections() {
        s.push_str(&format!(" | {:?} {:?} {:?}", d.state(), d.score, d.track));
    }
    s
}

/// First problem with a step's outputs: a NaN/inf anywhere in the report or the
/// detections, or an existence outside `[0, 1]`.
pub fn check_outputs<D: Detector + ?Sized>(det: &D, report: &D::Report) -> Option<(Kind, String)>
where
    D::Report: Debug,
{
    let text = format!("{report:?}");
    if text.contains("NaN") || text.contains("inf") {
        return Some((Kind::NonFinite, text));
    }
    for d in det.detections() {
        if !(d.score.is_finite() && d.state().iter().all(|x| x.is_finite())) {
            return Some((Kind::NonFinite, format!("detection {d:?}")));
        }
        if D::SCORE == ScoreKind::Existence && !(0.0..=1.0).contains(&d.score) {
            return Some((Kind::Existence, format!("detection {d:?}")));
        }
    }
    None
}

/// How one detector is fuzzed: its preset configuration (JSON), how a frame is drawn
/// for a configuration, and where the core configuration sits in the JSON.
pub struct Target<D: Detector + ?Sized, T> {
    /// Detector name.
    pub name: &'static str,
    /// The preset configuration, serialised.
    pub base: Value,
    /// Draws one frame for a configuration.
    pub frame: fn(&mut Rng, &D::Config, Mode) -> Vec<T>,
}

impl<D: Detector + ?Sized, T> Debug for Target<D, T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Target").field("name", &self.name).finish()
    }
}

/// Runs the cases of `opts` on `a` and `b` (two detectors built with the preset; `b` is
/// the lockstep twin).
pub fn fuzz<D, T>(target: &Target<D, T>, a: &mut D, b: &mut D, opts: &Options) -> Tally
where
    D: Detector<Frame = [T]> + ?Sized,
    D::Config: Serialize + DeserializeOwned,
    D::Report: Debug,
{
    let t0 = Instant::now();
    let mut tally = Tally {
        detector: target.name.to_string(),
        ..Tally::default()
    };
    for case in opts.first..opts.first + opts.cases {
        tally.cases += 1;
        run_case(target, a, b, opts, case, &mut tally);
    }
    tally.seconds = t0.elapsed().as_secs_f64();
    tally
}

/// The configuration of case `case` (the preset for every eighth case) and the pointers
/// the mutation rewrote.
pub fn case_config(base: &Value, seed: u64, case: u64) -> (Rng, Value, Vec<String>) {
    let mut rng = Rng::from_stream(seed, case);
    let mut v = base.clone();
    let mutated = if case.is_multiple_of(8) {
        Vec::new()
    } else {
        mutate::mutate(&mut v, &mut rng)
    };
    (rng, v, mutated)
}

fn run_case<D, T>(
    target: &Target<D, T>,
    a: &mut D,
    b: &mut D,
    opts: &Options,
    case: u64,
    tally: &mut Tally,
) where
    D: Detector<Frame = [T]> + ?Sized,
    D::Config: Serialize + DeserializeOwned,
    D::Report: Debug,
{
    let (mut rng, v, mutated) = case_config(&target.base, opts.seed, case);
    let finding = |kind, frame: Option<usize>, mode: Option<Mode>, message: String| Finding {
        detector: target.name.to_string(),
        kind,
        seed: opts.seed,
        case,
        frames_per_case: opts.frames_per_case,
        frame,
        mode: mode.map(|m| m.name().to_string()),
        message,
        mutated: mutated.clone(),
        config: v.clone(),
        input: None,
    };
    let Ok(cfg) = serde_json::from_value::<D::Config>(v.clone()) else {
        tally.rejected_parse += 1;
        return;
    };
    let det_seed = rng.next_u64();
    let lockstep = case % 4 == 1;
    match catch(|| {
        let ra = a.configure(&cfg, det_seed);
        let rb = if lockstep {
            b.configure(&cfg, det_seed)
        } else {
            Ok(())
        };
        (ra, rb)
    }) {
        Err(msg) => {
            tally.record(finding(Kind::Panic, None, None, msg));
            return;
        }
        Ok((Err(_), _)) | Ok((_, Err(_))) => {
            tally.rejected_config += 1;
            return;
        }
        Ok((Ok(()), Ok(()))) => {}
    }
    let mut had_error = false;
    for k in 0..opts.frames_per_case {
        let mode = Mode::draw(&mut rng);
        let frame = (target.frame)(&mut rng, &cfg, mode);
        tally.frames += 1;
        let t = Instant::now();
        let res = catch(|| {
            a.step(&frame)
                .map(|r| (check_outputs(a, &r), lockstep.then(|| outputs(a, &r))))
        });
        let dt = t.elapsed().as_secs_f64();
        tally.slowest_step_s = tally.slowest_step_s.max(dt);
        if dt > SLOW_STEP_S {
            tally.record(finding(
                Kind::Slow,
                Some(k),
                Some(mode),
                format!("{dt:.2} s"),
            ));
        }
        match res {
            Err(msg) => {
                tally.record(finding(Kind::Panic, Some(k), Some(mode), msg));
                return;
            }
            Ok(Err(_)) => {
                tally.rejected_frames += 1;
                had_error = true;
            }
            Ok(Ok((problem, out_a))) => {
                if let Some((kind, msg)) = problem {
                    tally.record(finding(kind, Some(k), Some(mode), msg));
                    return;
                }
                if let Some(out_a) = out_a {
                    tally.lockstep_frames += 1;
                    let problem = match catch(|| twin_check(b, &frame, &out_a, had_error)) {
                        Ok(p) => p,
                        Err(msg) => Some((Kind::Panic, format!("the twin panicked: {msg}"))),
                    };
                    if let Some((kind, msg)) = problem {
                        tally.record(finding(kind, Some(k), Some(mode), msg));
                        return;
                    }
                }
            }
        }
    }
}

/// Steps the twin `b` (stepped only on the frames the detector accepted) on `frame`,
/// which the detector accepted with outputs `out_a` ([`outputs`]), and compares: the
/// same bits, or a [`Kind::ChangedOnError`] (after a rejection, `had_error`: a rejected
/// frame or configuration changed the state; without one: the detector is not
/// deterministic).
pub fn twin_check<D>(
    b: &mut D,
    frame: &D::Frame,
    out_a: &str,
    had_error: bool,
) -> Option<(Kind, String)>
where
    D: Detector + ?Sized,
    D::Report: Debug,
{
    let msg = match b.step(frame) {
        Ok(r) => {
            let out_b = outputs(b, &r);
            if out_b == out_a {
                return None;
            }
            if had_error {
                format!("after a rejection: {out_a} | twin: {out_b}")
            } else {
                format!("twin disagrees with no rejection: {out_a} | twin: {out_b}")
            }
        }
        Err(e) => format!("the twin rejected a frame the detector accepted: {e:?}"),
    };
    Some((Kind::ChangedOnError, msg))
}

/// Re-runs the case of `f` (same seed, index and frame count, or the same input bytes
/// for a coverage-guided finding) on its detector.
pub fn replay(f: &Finding) -> anyhow::Result<Tally> {
    if let Some(hex) = &f.input {
        let data = guided::from_hex(hex)?;
        let mut t = Tally {
            detector: f.detector.clone(),
            cases: 1,
            ..Tally::default()
        };
        if let Some(g) = guided::finding(&f.detector, &data)? {
            t.record(g);
        }
        return Ok(t);
    }
    let opts = Options {
        seed: f.seed,
        first: f.case,
        cases: 1,
        frames_per_case: f.frames_per_case,
    };
    match targets::run(&f.detector, targets::Job::Fuzz(opts))? {
        targets::Outcome::Fuzz(t) => Ok(t),
        targets::Outcome::Soak(_) => anyhow::bail!("internal: a soak outcome from a fuzz job"),
    }
}
