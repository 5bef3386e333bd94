//! `faint reproduce dp`: Wang, Zhang 2016, *Improved DP algorithm for low signal-to-noise
//! ratio moving target detection*: the second-order DP against Barniv / Arnold first-order
//! DP and the Pulford velocity-gated DP on the `dim-point` preset. Fig. 6 (average frames
//! to detect vs SNR), Fig. 7 (tracking error `errT` vs SNR) and Fig. 5 (the merit
//! distributions, [`fig5`]).
//!
//! Per speed, SNR point and run: one truth and its frames (stream
//! `Rng::from_stream(derive_seed(seed, speed), run)`, the same for every SNR and method),
//! run through the three detectors. A run detects at frame `n` under
//! - the **track level** (the paper's, Barniv): when the best track ending within 1 px
//!   (Chebyshev) of the true pixel has merit `>= V_T(n)`, `V_T` from the analytic
//!   noise-merit distribution at `P_FA` per noise track;
//! - the **image level**: when the global best track has merit `> V_T(n)`, `V_T(n)` the
//!   `1 - P_FA` quantile of the global best after `n` frames over noise-only runs, and
//!   ends within 1 px of the truth. Its false-alarm rate is measured on independent
//!   noise-only runs.
//!
//! Frames to detect: the first such `n` (at most the run's frames); runs not detected
//! are counted apart, not averaged in. `errT` (px): after the last frame, the RMS over
//! all frames (`L` = the run's 40 frames) of the distance between the recovered track's
//! pixel centres and the true positions, over the detected runs; the track is recovered
//! from the best end near the truth (track level) or from the global best (image level).

use std::path::{Path, PathBuf};

use anyhow::{ensure, Result};
use faint_core::detect::dp::{Method, Transition};
use serde::Serialize;

use crate::analysis::dp::track_thresholds;
use crate::cli;
use crate::io::{self, chart::Series};
use crate::montecarlo::run_trial_range;
use crate::shard::{self, Batch, Batches, Merged, Run, Shard};
use crate::simulate::dp::{DimPoint, HISTORY, METHODS};
use crate::stats::detection::{proportion, threshold_at_pfa, Proportion};
use serde::Deserialize;

pub mod eval;
pub mod fig5;

pub use eval::{
    noise_run, target_run, trace, track_error, Second25I8, Second9I8, Trace, Variant, I8_LSB,
};

/// Command-line arguments of `faint reproduce dp` (shard files keep them, without
/// `--shard`).
#[derive(clap::Args, Debug, Clone, Serialize, Deserialize)]
pub struct Args {
    /// Monte Carlo runs per SNR point and speed, 1 to 1000000 (default 100; --quick: 4).
    #[arg(long)]
    pub runs: Option<usize>,
    /// SNR grid `a:b:step`, `SNR = a / sigma` linear (eq. 29), values in [0, 100], at most
    /// 1000 points (default 1.6:2.5:0.1; --quick 2.0:2.5:0.5).
    #[arg(long, allow_hyphen_values = true)]
    pub snr: Option<String>,
    /// Target speeds in px/frame, 1 and/or 2 (default 1,2; --quick 1).
    #[arg(long, value_delimiter = ',')]
    pub speeds: Option<Vec<u8>>,
    /// Noise-only runs per speed for the image-level thresholds, and as many again for
    /// their independent false-alarm check, 100 to 1000000 (default 2000; --quick 100).
    #[arg(long)]
    pub noise_runs: Option<usize>,
    /// Frames per run, at most 40 (default 40; --quick 10).
    #[arg(long)]
    pub frames: Option<usize>,
    /// Second-order transition term: gaussian (the paper's) or hard (ablation).
    #[arg(long)]
    pub transition: Option<String>,
    /// `q_B` of every method at every speed (9 or 25; default 9 at 1 px/frame, 25 at 2).
    #[arg(long)]
    pub qb: Option<usize>,
    /// Merit cell bits of the second order: 16 (`i16`, the default) or 8 (`i8` cells
    /// with the input LSB 0.25, the STM32H743's `dp-second:128:8`); Arnold and Pulford
    /// keep `i16`.
    #[arg(long, default_value_t = 16)]
    #[serde(default = "sixteen")]
    pub second_bits: u8,
    /// Skip Fig. 5 (the merit distributions).
    #[arg(long)]
    pub no_fig5: bool,
    /// Output directory.
    #[arg(long, default_value = "out/dp")]
    pub out: PathBuf,
    /// Master seed.
    #[arg(long, default_value_t = 2016)]
    pub seed: u64,
    /// CI mode: small defaults (4 runs, SNR 2.0 and 2.5, 1 px/frame, 100 noise runs,
    /// 10 frames); never overrides a value given on the command line.
    #[arg(long)]
    pub quick: bool,
    /// One shard of the runs (`--shard I/N`, see `faint merge`).
    #[command(flatten)]
    #[serde(skip)]
    pub shard: crate::shard::ShardArg,
}

fn sixteen() -> u8 {
    16
}

/// Arguments after the `--quick` defaults.
#[derive(Debug, Clone)]
struct Effective {
    runs: usize,
    snrs: Vec<f64>,
    speeds: Vec<u8>,
    noise_runs: usize,
    frames: usize,
    variant: Variant,
}

impl Args {
    fn effective(&self) -> Result<Effective> {
        let q = self.quick;
        let runs = cli::runs("--runs", self.runs.unwrap_or(if q { 4 } else { 100 }))?;
        let grid = self
            .snr
            .clone()
            .unwrap_or_else(|| if q { "2.0:2.5:0.5" } else { "1.6:2.5:0.1" }.into());
        let snrs = cli::grid("--snr", &grid)?;
        for &s in &snrs {
            cli::within("--snr", s, 0.0..=100.0, " (a / sigma)")?;
        }
        let speeds = self
            .speeds
            .clone()
            .unwrap_or_else(|| if q { vec![1] } else { vec![1, 2] });
        ensure!(!speeds.is_empty(), "--speeds needs at least one value");
        for &s in &speeds {
            ensure!(
                s == 1 || s == 2,
                "--speeds values must be 1 or 2 px/frame, got {s}"
            );
        }
        let noise_runs = self.noise_runs.unwrap_or(if q { 100 } else { 2000 });
        // At least 1 / P_FA runs resolve P_FA.
        cli::count(
            "--noise-runs",
            noise_runs,
            (1.0 / PFA).ceil() as usize..=cli::MAX_RUNS,
        )?;
        let frames = self.frames.unwrap_or(if q { 10 } else { HISTORY });
        cli::count("--frames", frames, 1..=HISTORY)?;
        let transition = match self.transition.as_deref() {
            None => None,
            Some("gaussian") => Some(Transition::Gaussian),
            Some("hard") => Some(Transition::Hard),
            Some(o) => anyhow::bail!("--transition must be gaussian or hard, got '{o}'"),
        };
        if let Some(qb) = self.qb {
            ensure!(qb == 9 || qb == 25, "--qb must be 9 or 25, got {qb}");
        }
        ensure!(
            self.second_bits == 8 || self.second_bits == 16,
            "--second-bits must be 8 or 16, got {}",
            self.second_bits
        );
        Ok(Effective {
            runs,
            snrs,
            speeds,
            noise_runs,
            frames,
            variant: Variant {
                transition,
                qb: self.qb,
                second_i8: self.second_bits == 8,
            },
        })
    }

    /// Checks every argument (one-line errors naming the argument) before any run.
    pub fn validate(&self) -> Result<()> {
        self.effective().map(|_| ())
    }
}

/// False-alarm probability of both thresholds (the paper's `P_FA = 0.01`).
pub const PFA: f64 = 0.01;

/// The paper's statements (Wang, Zhang 2016, §4, Fig. 6-7), checked against ours in
/// `summary.md`.
pub mod paper {
    /// Fig. 6: the improved DP needs the fewest frames to detect, at every SNR and both speeds.
    pub const FEWEST: &str = "improved DP needs the fewest frames to detect";
    /// Fig. 6: its advantage grows as the SNR falls.
    pub const GAP: &str = "the gap grows as the SNR falls";
    /// Fig. 6: Pulford beats Arnold at 2 px/frame.
    pub const PULFORD_FAST: &str = "Pulford needs fewer frames than Arnold at 2 px/frame";
    /// Fig. 6: Pulford needs more frames than Arnold at 1 px/frame below SNR 1.8.
    pub const PULFORD_SLOW: &str =
        "Pulford needs more frames than Arnold at 1 px/frame below SNR 1.8";
    /// Fig. 7: the improved DP has the smallest tracking error.
    pub const ERR: &str = "improved DP has the smallest errT";
}

/// The two detection definitions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Level {
    /// Best track near the truth against the analytic per-track threshold.
    Track,
    /// Global best against the simulated image threshold, ending near the truth.
    Image,
}

impl Level {
    fn name(self) -> &'static str {
        match self {
            Level::Track => "track",
            Level::Image => "image",
        }
    }
}

/// Per-frame thresholds of one method and speed.
#[derive(Debug, Clone)]
pub struct Thresholds {
    /// Image level `V_T(n)`, index `n - 1`.
    pub image: Vec<f64>,
    /// Its 95 % interval (order statistics).
    pub image_ci: Vec<(f64, f64)>,
    /// False-alarm rate of `image` on the check runs, per `n`.
    pub check: Vec<Proportion>,
    /// Check runs with a false alarm at any `n` (what "frames to detect" would count).
    pub check_any: Proportion,
    /// Track level `V_T(n)` (`None`: not available).
    pub track: Option<Vec<f64>>,
}

/// One threshold row of `thresholds.csv`.
#[derive(Debug, Clone, Serialize)]
struct ThresholdRow {
    speed: u8,
    method: &'static str,
    n: usize,
    image_vt: f64,
    image_vt_lo: f64,
    image_vt_hi: f64,
    check_pfa: f64,
    check_lo: f64,
    check_hi: f64,
    track_vt: Option<f64>,
}

/// One point of Fig. 6 / Fig. 7 (`fig6.csv`).
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// Detection definition.
    pub level: Level,
    /// Speed (px/frame).
    pub speed: u8,
    /// Method.
    pub method: &'static str,
    /// SNR (`a / sigma`).
    pub snr: f64,
    /// Runs.
    pub runs: usize,
    /// Runs detected by the last frame.
    pub detected: usize,
    /// Runs not detected.
    pub undetected: usize,
    /// Mean frames to detect over the detected runs.
    pub frames_mean: Option<f64>,
    /// Its 95 % interval (normal approximation, `mean +- 1.96 s / sqrt(k)`).
    pub frames_lo: Option<f64>,
    /// Upper end.
    pub frames_hi: Option<f64>,
    /// Mean `errT` (px) over the detected runs.
    pub err_mean: Option<f64>,
    /// Its 95 % interval.
    pub err_lo: Option<f64>,
    /// Upper end.
    pub err_hi: Option<f64>,
}

/// One run of `runs.csv`.
#[derive(Debug, Clone, Serialize)]
struct RunRow {
    speed: u8,
    snr: f64,
    run: usize,
    method: &'static str,
    first_image: Option<usize>,
    first_track: Option<usize>,
    err_image: Option<f64>,
    err_track: Option<f64>,
}

/// Mean and 95 % normal interval of `v` (`None`s when empty).
fn mean_ci(v: &[f64]) -> (Option<f64>, Option<f64>, Option<f64>) {
    if v.is_empty() {
        return (None, None, None);
    }
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    if v.len() < 2 {
        return (Some(m), None, None);
    }
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0);
    let h = 1.96 * (var / n).sqrt();
    (Some(m), Some(m - h), Some(m + h))
}

/// The first frame `n` (1-based) at which `hit(n - 1)` holds.
fn first(frames: usize, hit: impl Fn(usize) -> bool) -> Option<usize> {
    (0..frames).find(|&i| hit(i)).map(|i| i + 1)
}

/// The first detection frame of a trace under `level`.
pub fn first_detection(t: &Trace, th: &Thresholds, level: Level) -> Option<usize> {
    match level {
        Level::Image => first(t.best.len(), |i| {
            t.best_hit[i] && f64::from(t.best[i]) > th.image[i]
        }),
        Level::Track => {
            let v = th.track.as_ref()?;
            first(t.near.len(), |i| f64::from(t.near[i]) >= v[i])
        }
    }
}

/// Image-level thresholds of every method from the calibration runs, checked on the
/// independent check runs (`[run][method][frame]` best merits).
fn image_thresholds(
    cal: &[Vec<Vec<f32>>],
    check: &[Vec<Vec<f32>>],
    frames: usize,
) -> Result<Vec<Thresholds>> {
    let mut out = Vec::new();
    for mi in 0..METHODS.len() {
        let mut image = Vec::with_capacity(frames);
        let mut image_ci = Vec::with_capacity(frames);
        let mut checks = Vec::with_capacity(frames);
        for n in 0..frames {
            let h0: Vec<f64> = cal.iter().map(|r| f64::from(r[mi][n])).collect();
            let t = threshold_at_pfa(&h0, PFA)?;
            image.push(t.value);
            image_ci.push((t.ci_low, t.ci_high));
            let k = check
                .iter()
                .filter(|r| f64::from(r[mi][n]) > t.value)
                .count();
            checks.push(proportion(k, check.len()));
        }
        let any = check
            .iter()
            .filter(|r| (0..frames).any(|n| f64::from(r[mi][n]) > image[n]))
            .count();
        out.push(Thresholds {
            image,
            image_ci,
            check: checks,
            check_any: proportion(any, check.len()),
            track: None,
        });
    }
    Ok(out)
}

/// Everything measured at one speed.
struct SpeedResult {
    speed: u8,
    thresholds: Vec<Thresholds>,
    /// `[snr][run][method]`.
    traces: Vec<Vec<Vec<Trace>>>,
}

/// The batch keys of one speed: its calibration and check noise-only runs, then its
/// target runs at each SNR.
fn speed_keys(e: &Effective, speed: u8) -> Vec<String> {
    let mut k = vec![format!("{speed} px noise"), format!("{speed} px check")];
    k.extend((0..e.snrs.len()).map(|j| format!("{speed} px snr {j}")));
    k
}

/// Every batch of the run, speed after speed.
fn keys(e: &Effective) -> Vec<String> {
    e.speeds.iter().flat_map(|&s| speed_keys(e, s)).collect()
}

/// The runs of every batch that `shard` holds (all of them for `None`): noise-only runs
/// on the streams of `DimPoint::calibration_seed` and `check_seed`, target runs on
/// those of `DimPoint::target_seed` (the same frames at every SNR).
fn collect(
    sc: &DimPoint,
    e: &Effective,
    seed: u64,
    shard: Option<Shard>,
) -> Result<Vec<Batch<ciborium::Value>>> {
    let v = e.variant;
    let mut out = Vec::new();
    for &speed in &e.speeds {
        let mut keys = speed_keys(e, speed).into_iter();
        for (master, label) in [
            (DimPoint::calibration_seed(seed, speed), "noise"),
            (DimPoint::check_seed(seed, speed), "check"),
        ] {
            let b = Batch::run(
                keys.next().unwrap_or_default(),
                e.noise_runs,
                shard,
                |range| {
                    run_trial_range(
                        master,
                        range,
                        &format!("dp {label} {speed} px"),
                        |_, rng| noise_run(sc, speed, &v, rng),
                    )
                    .into_iter()
                    .collect::<Result<Vec<_>>>()
                },
            )?;
            out.push(b.into_values()?);
        }
        for &snr in &e.snrs {
            let label = format!("dp {speed} px SNR {snr:.2}");
            let b = Batch::run(keys.next().unwrap_or_default(), e.runs, shard, |range| {
                run_trial_range(
                    DimPoint::target_seed(seed, speed),
                    range,
                    &label,
                    |_, rng| target_run(sc, speed, snr, &v, rng),
                )
                .into_iter()
                .collect::<Result<Vec<_>>>()
            })?;
            out.push(b.into_values()?);
        }
    }
    Ok(out)
}

/// Everything measured at one speed, from its batches: the image-level thresholds from
/// the noise-only runs, the analytic track-level ones, the target runs' traces.
fn speed_result(sc: &DimPoint, e: &Effective, speed: u8, b: &Batches) -> Result<SpeedResult> {
    let v = e.variant;
    let keys = speed_keys(e, speed);
    let cal: Vec<Vec<Vec<f32>>> = b.get(&keys[0])?;
    let check: Vec<Vec<Vec<f32>>> = b.get(&keys[1])?;
    let mut thresholds = image_thresholds(&cal, &check, sc.frames)?;
    let qb = v.qb(speed)?;
    for (t, &m) in thresholds.iter_mut().zip(&METHODS) {
        let vt = track_thresholds(&v.config(m, speed), qb, sc.frames, PFA)?;
        t.track = Some(vt.into_iter().map(f64::from).collect());
    }
    let traces = keys[2..]
        .iter()
        .map(|k| b.get::<Vec<Trace>>(k))
        .collect::<Result<_>>()?;
    Ok(SpeedResult {
        speed,
        thresholds,
        traces,
    })
}

fn points(r: &SpeedResult, snrs: &[f64], level: Level, runs_out: &mut Vec<RunRow>) -> Vec<Point> {
    let mut out = Vec::new();
    for (mi, m) in METHODS.iter().enumerate() {
        let th = &r.thresholds[mi];
        if level == Level::Track && th.track.is_none() {
            continue;
        }
        for (si, &snr) in snrs.iter().enumerate() {
            let mut frames = Vec::new();
            let mut errs = Vec::new();
            let runs = r.traces[si].len();
            for (ri, tr) in r.traces[si].iter().enumerate() {
                let t = &tr[mi];
                let f = first_detection(t, th, level);
                let err = match level {
                    Level::Image => t.err_best,
                    Level::Track => t.err_near,
                };
                if let Some(f) = f {
                    frames.push(f as f64);
                    if let Some(e) = err {
                        errs.push(e);
                    }
                }
                if level == Level::Image {
                    runs_out.push(RunRow {
                        speed: r.speed,
                        snr,
                        run: ri,
                        method: m.name(),
                        first_image: f,
                        first_track: first_detection(t, th, Level::Track),
                        err_image: t.err_best,
                        err_track: t.err_near,
                    });
                }
            }
            let (fm, flo, fhi) = mean_ci(&frames);
            let (em, elo, ehi) = mean_ci(&errs);
            out.push(Point {
                level,
                speed: r.speed,
                method: m.name(),
                snr,
                runs,
                detected: frames.len(),
                undetected: runs - frames.len(),
                frames_mean: fm,
                frames_lo: flo,
                frames_hi: fhi,
                err_mean: em,
                err_lo: elo,
                err_hi: ehi,
            });
        }
    }
    out
}

fn label(m: &str) -> &'static str {
    match m {
        "arnold" => "Arnold DP",
        "pulford" => "Pulford DP",
        _ => "improved (second-order) DP",
    }
}

fn plot_level(d: &std::path::Path, pts: &[Point], level: Level, speed: u8) -> Result<()> {
    let sel: Vec<&Point> = pts
        .iter()
        .filter(|p| p.level == level && p.speed == speed)
        .collect();
    if sel.is_empty() {
        return Ok(());
    }
    let series = |f: fn(&Point) -> Option<f64>| -> Vec<Series> {
        METHODS
            .iter()
            .map(|m| Series {
                name: label(m.name()).into(),
                points: sel
                    .iter()
                    .filter(|p| p.method == m.name())
                    .filter_map(|p| f(p).map(|y| (p.snr, y)))
                    .collect(),
            })
            .collect()
    };
    let l = level.name();
    let s6 = series(|p| p.frames_mean);
    if s6.iter().any(|s| !s.points.is_empty()) {
        io::chart::line_chart(
            d.join(format!("fig6_{l}_{speed}px.svg")),
            &format!("Fig. 6: frames to detect, {l} level, {speed} px/frame"),
            "SNR (a / sigma)",
            "average frames to detect",
            &s6,
        )?;
    }
    let s7 = series(|p| p.err_mean);
    if s7.iter().any(|s| !s.points.is_empty()) {
        io::chart::line_chart(
            d.join(format!("fig7_{l}_{speed}px.svg")),
            &format!("Fig. 7: errT at the last frame, {l} level, {speed} px/frame"),
            "SNR (a / sigma)",
            "errT (px)",
            &s7,
        )?;
    }
    Ok(())
}

fn f2(x: Option<f64>) -> String {
    io::fmt_opt(x, 2)
}

fn interval(lo: Option<f64>, hi: Option<f64>) -> String {
    match (lo, hi) {
        (Some(a), Some(b)) => format!("[{a:.2}, {b:.2}]"),
        _ => "-".into(),
    }
}

/// The Markdown table of one level and speed: one row per SNR, per method the mean
/// frames to detect, its interval and the undetected count (Fig. 6), and `errT` (Fig. 7).
fn table(pts: &[Point], level: Level, speed: u8) -> Option<String> {
    let sel: Vec<&Point> = pts
        .iter()
        .filter(|p| p.level == level && p.speed == speed)
        .collect();
    if sel.is_empty() {
        return None;
    }
    let mut snrs: Vec<f64> = sel.iter().map(|p| p.snr).collect();
    snrs.sort_by(f64::total_cmp);
    snrs.dedup();
    let mut rows = Vec::new();
    for s in snrs {
        let mut row = vec![format!("{s:.2}")];
        for m in METHODS {
            match sel.iter().find(|p| p.snr == s && p.method == m.name()) {
                Some(p) => {
                    row.push(format!(
                        "{} {} ({})",
                        f2(p.frames_mean),
                        interval(p.frames_lo, p.frames_hi),
                        p.undetected
                    ));
                    row.push(f2(p.err_mean));
                }
                None => {
                    row.push("-".into());
                    row.push("-".into());
                }
            }
        }
        rows.push(row);
    }
    Some(io::markdown_table(
        &[
            "SNR",
            "Arnold frames [95 %] (undetected)",
            "Arnold errT",
            "Pulford frames [95 %] (undetected)",
            "Pulford errT",
            "second-order frames [95 %] (undetected)",
            "second-order errT",
        ],
        &rows,
    ))
}

fn find(pts: &[Point], level: Level, speed: u8, m: Method, snr: f64) -> Option<&Point> {
    pts.iter()
        .find(|p| p.level == level && p.speed == speed && p.method == m.name() && p.snr == snr)
}

/// The paper's statements against ours for one level: `(statement, ours, verdict)`.
fn statements(pts: &[Point], level: Level, speeds: &[u8], snrs: &[f64]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    let fm = |p: Option<&Point>| p.and_then(|p| p.frames_mean);
    let em = |p: Option<&Point>| p.and_then(|p| p.err_mean);
    let verdict = |k: usize, n: usize| {
        if n == 0 {
            "not measured".to_string()
        } else if k == n {
            "reproduced".to_string()
        } else if k == 0 {
            "not reproduced".to_string()
        } else {
            format!("partly ({k} of {n})")
        }
    };
    // Fewest frames: second order below both first orders at every (speed, SNR).
    let (mut k, mut n) = (0, 0);
    let mut gaps: Vec<String> = Vec::new();
    for &s in speeds {
        let mut g = Vec::new();
        for &snr in snrs {
            let a = fm(find(pts, level, s, Method::Arnold, snr));
            let p = fm(find(pts, level, s, Method::Pulford, snr));
            let q = fm(find(pts, level, s, Method::SecondOrder, snr));
            if let (Some(a), Some(p), Some(q)) = (a, p, q) {
                n += 1;
                if q < a && q < p {
                    k += 1;
                }
                g.push((snr, a.min(p) - q));
            }
        }
        if let (Some(lo), Some(hi)) = (g.first(), g.last()) {
            gaps.push(format!(
                "{s} px/frame: {:.2} frames at SNR {:.2}, {:.2} at {:.2}",
                lo.1, lo.0, hi.1, hi.0
            ));
        }
    }
    out.push(vec![
        paper::FEWEST.into(),
        format!("second order below both at {k} of {n} (speed, SNR) points"),
        verdict(k, n),
    ]);
    let grows = gaps.len();
    let mut kg = 0;
    for &s in speeds {
        let g: Vec<f64> = snrs
            .iter()
            .filter_map(|&snr| {
                let a = fm(find(pts, level, s, Method::Arnold, snr))?;
                let p = fm(find(pts, level, s, Method::Pulford, snr))?;
                let q = fm(find(pts, level, s, Method::SecondOrder, snr))?;
                Some(a.min(p) - q)
            })
            .collect();
        if g.len() >= 2 && g.first() > g.last() {
            kg += 1;
        }
    }
    out.push(vec![
        paper::GAP.into(),
        format!("best first order minus second order: {}", gaps.join("; ")),
        verdict(kg, grows),
    ]);
    if speeds.contains(&2) {
        let (mut k, mut n) = (0, 0);
        for &snr in snrs {
            if let (Some(a), Some(p)) = (
                fm(find(pts, level, 2, Method::Arnold, snr)),
                fm(find(pts, level, 2, Method::Pulford, snr)),
            ) {
                n += 1;
                if p < a {
                    k += 1;
                }
            }
        }
        out.push(vec![
            paper::PULFORD_FAST.into(),
            format!("Pulford below Arnold at {k} of {n} SNR points"),
            verdict(k, n),
        ]);
    }
    if speeds.contains(&1) {
        let (mut k, mut n) = (0, 0);
        for &snr in snrs.iter().filter(|&&s| s < 1.8 - 1e-9) {
            if let (Some(a), Some(p)) = (
                fm(find(pts, level, 1, Method::Arnold, snr)),
                fm(find(pts, level, 1, Method::Pulford, snr)),
            ) {
                n += 1;
                if p > a {
                    k += 1;
                }
            }
        }
        out.push(vec![
            paper::PULFORD_SLOW.into(),
            format!("Pulford above Arnold at {k} of {n} SNR points below 1.8"),
            verdict(k, n),
        ]);
    }
    let (mut k, mut n) = (0, 0);
    for &s in speeds {
        for &snr in snrs {
            let a = em(find(pts, level, s, Method::Arnold, snr));
            let p = em(find(pts, level, s, Method::Pulford, snr));
            let q = em(find(pts, level, s, Method::SecondOrder, snr));
            if let (Some(a), Some(p), Some(q)) = (a, p, q) {
                n += 1;
                if q < a && q < p {
                    k += 1;
                }
            }
        }
    }
    out.push(vec![
        paper::ERR.into(),
        format!("second order smallest at {k} of {n} (speed, SNR) points"),
        verdict(k, n),
    ]);
    out
}

/// The command name in shard files.
pub const COMMAND: &str = "reproduce dp";

/// The scene of the run.
fn scene(e: &Effective) -> DimPoint {
    DimPoint {
        frames: e.frames,
        ..DimPoint::default()
    }
}

/// Runs the reproduction: the whole run, or with `--shard` (or a scheduler's array) one
/// shard's noise-only and target runs, written to `<out>/shards/` for `faint merge`
/// (Fig. 5 is computed by the merge).
pub fn run(args: &Args) -> Result<()> {
    let e = args.effective()?;
    let shard = args.shard.resolve()?;
    cli::out_dir(&args.out)?;
    let t0 = std::time::Instant::now();
    let batches = collect(&scene(&e), &e, args.seed, shard)?;
    match shard {
        None => analyse(args, &e, &Batches::whole(batches)),
        Some(s) => shard::finish(
            &args.out.join("shards"),
            &Run::new(COMMAND, args)?,
            s,
            t0,
            &batches,
        )
        .map(|_| ()),
    }
}

/// `faint merge` of `reproduce dp` shards: the outputs of the unsharded run, written
/// where it writes them (under `out` if given, else the run's `--out`).
pub fn merge(m: &Merged, out: Option<&Path>) -> Result<()> {
    let mut args: Args = m.run.args()?;
    if let Some(o) = out {
        args.out = o.to_path_buf();
    }
    let e = args.effective()?;
    analyse(&args, &e, &m.batches(&keys(&e))?)
}

/// The outputs of the run from its batches (Fig. 5 computed here: its runs are not
/// sharded).
fn analyse(args: &Args, e: &Effective, batches: &Batches) -> Result<()> {
    batches.expect(&keys(e))?;
    let sc = scene(e);
    let e = e.clone();
    let d = &args.out;
    cli::out_dir(d)?;
    let mut results = Vec::new();
    for &speed in &e.speeds {
        results.push(speed_result(&sc, &e, speed, batches)?);
    }
    let mut th_rows = Vec::new();
    for r in &results {
        for (mi, m) in METHODS.iter().enumerate() {
            let t = &r.thresholds[mi];
            for n in 0..sc.frames {
                th_rows.push(ThresholdRow {
                    speed: r.speed,
                    method: m.name(),
                    n: n + 1,
                    image_vt: t.image[n],
                    image_vt_lo: t.image_ci[n].0,
                    image_vt_hi: t.image_ci[n].1,
                    check_pfa: t.check[n].p,
                    check_lo: t.check[n].lo,
                    check_hi: t.check[n].hi,
                    track_vt: t.track.as_ref().map(|v| v[n]),
                });
            }
        }
    }
    io::write_csv(d.join("thresholds.csv"), &th_rows)?;
    let mut pts = Vec::new();
    let mut runs = Vec::new();
    for r in &results {
        pts.extend(points(r, &e.snrs, Level::Image, &mut runs));
        pts.extend(points(r, &e.snrs, Level::Track, &mut Vec::new()));
    }
    io::write_csv(d.join("fig6_fig7.csv"), &pts)?;
    io::write_csv(d.join("runs.csv"), &runs)?;
    for level in [Level::Track, Level::Image] {
        for &s in &e.speeds {
            plot_level(d, &pts, level, s)?;
        }
    }
    let fig5 = if args.no_fig5 {
        "Fig. 5: skipped (--no-fig5).\n".to_string()
    } else {
        // 20 frames: the noise check's cones (radius 2 (n - 1)) must fit its images
        let opts = fig5::Fig5Options {
            snr: 2.0,
            noise_tracks: if args.quick { 20_000 } else { 400_000 },
            target_tracks: if args.quick { 100 } else { 2_000 },
            frames: if args.quick { 10 } else { 20 },
            pfa: PFA,
            seed: args.seed,
        };
        fig5::run(&opts, d)?
    };
    let md = summary(args, &e, &sc, &results, &pts, &fig5);
    io::write_text(d.join("summary.md"), &md)?;
    println!("{md}");
    println!("wrote {}", d.display());
    Ok(())
}

fn summary(
    args: &Args,
    e: &Effective,
    sc: &DimPoint,
    results: &[SpeedResult],
    pts: &[Point],
    fig5: &str,
) -> String {
    let mut md = String::new();
    md.push_str("# DP-TBD: Wang, Zhang 2016 (Fig. 5-7)\n\n");
    let cmd = std::env::args().collect::<Vec<_>>().join(" ");
    md.push_str(&format!(
        "Command: `{cmd}`. Runs per point: {}, noise-only runs per speed: {} (calibration) + {} (check), frames: {}, seed {}, transition: {}, q_B: {}, second-order merits: {}.\n\n",
        e.runs,
        e.noise_runs,
        e.noise_runs,
        sc.frames,
        args.seed,
        e.variant
            .transition
            .map_or("preset (gaussian)", |t| match t {
                Transition::Gaussian => "gaussian",
                Transition::Hard => "hard",
            }),
        e.variant
            .qb
            .map_or("preset (9 at 1 px/frame, 25 at 2)".to_string(), |q| q.to_string()),
        if e.variant.second_i8 {
            "i8, LSB 0.25"
        } else {
            "i16"
        },
    ));
    md.push_str("## Image-level thresholds (P_FA = 0.01)\n\n");
    let mut rows = Vec::new();
    for r in results {
        for (mi, m) in METHODS.iter().enumerate() {
            let t = &r.thresholds[mi];
            let last = sc.frames - 1;
            let k: usize = t.check.iter().map(|p| p.k).sum();
            let n: usize = t.check.iter().map(|p| p.n).sum();
            rows.push(vec![
                format!("{}", r.speed),
                label(m.name()).into(),
                format!("{:.2}", t.image[last]),
                format!(
                    "{:.4} [{:.4}, {:.4}]",
                    t.check[last].p, t.check[last].lo, t.check[last].hi
                ),
                format!("{:.4}", k as f64 / n.max(1) as f64),
                format!(
                    "{:.3} [{:.3}, {:.3}]",
                    t.check_any.p, t.check_any.lo, t.check_any.hi
                ),
            ]);
        }
    }
    md.push_str(&io::markdown_table(
        &[
            "px/frame",
            "method",
            "V_T(last frame)",
            "check P_FA at the last frame [95 %]",
            "check P_FA, mean over n",
            "check runs with a false alarm at any n [95 %]",
        ],
        &rows,
    ));
    md.push('\n');
    for level in [Level::Track, Level::Image] {
        md.push_str(&format!(
            "## Fig. 6 and Fig. 7, {} level\n\nPer cell: mean frames to detect over the detected runs, its 95 % interval, (runs not detected by frame {}); errT in px over the detected runs.\n\n",
            level.name(),
            sc.frames
        ));
        let mut any = false;
        for &s in &e.speeds {
            if let Some(t) = table(pts, level, s) {
                any = true;
                md.push_str(&format!("### {s} px/frame\n\n{t}\n"));
            }
        }
        if !any {
            md.push_str("Not measured.\n\n");
            continue;
        }
        md.push_str("### The paper's statements\n\n");
        md.push_str(&io::markdown_table(
            &["paper", "ours", "verdict"],
            &statements(pts, level, &e.speeds, &e.snrs),
        ));
        md.push('\n');
    }
    md.push_str("## Fig. 5\n\n");
    md.push_str(fig5);
    md
}
