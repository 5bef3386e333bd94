//! `faint calibrate`: detection thresholds at a false-alarm probability the user names,
//! for any detector, from data the user has.
//!
//! The detector runs `R` noise-only runs of `L` frames, each from a restart (run `r`
//! with the random stream `derive_seed(seed, r)`). For each frame index `k` in
//! `burn_in..L`, `s_{r,k}` is the largest score run `r` reports at frame `k` (minus
//! infinity when it reports nothing), and the threshold `t_k` is the order statistic of
//! `{s_{r,k}}` at `1 - pfa` ([`threshold_at_pfa`]): a target-free frame `k` then yields a
//! detection (a score `> t_k`) with probability at most `pfa`, and the file keeps the
//! distribution-free 95 % interval of `t_k`.
//!
//! The runs come from a noise-only recording (`--input`, cut into runs of `L` frames), or
//! are simulated from a noise model estimated on a file that may hold targets
//! (`--from-input`, [`noise`]). A `pfa` needs `R pfa >= 10` (ten expected exceedances
//! per frame index); fewer runs are refused with the amount of data that would do.

pub mod noise;

use std::path::{Path, PathBuf};

use anyhow::{bail, ensure, Context, Result};

use crate::detect::calibration::{Calibration, FrameThreshold, Source, FORMAT};
use crate::detect::{self, Request};
use crate::shard::{self, Batch, Merged, Run, Shard};
use crate::stats::detection::threshold_at_pfa;
use serde::{Deserialize, Serialize};

/// The command name in shard files.
pub const COMMAND: &str = "calibrate";

/// Expected noise exceedances per frame index a threshold needs: `runs * pfa >= 10`.
pub const MIN_EXCEEDANCES: f64 = 10.0;

/// Default frames per run of a recording (`--input`), or its length if shorter.
pub const DEFAULT_RUN_FRAMES: usize = 32;

/// Command line of `faint calibrate` (shard files keep it as JSON).
#[derive(clap::Args, Debug, Clone, Serialize, Deserialize)]
pub struct Args {
    /// Detector, as listed by `faint detect --list`.
    pub detector: String,
    /// A noise-only (or clutter-only) recording in the detector's input format, cut into
    /// runs of --run-frames frames.
    #[arg(
        long,
        required_unless_present = "from_input",
        conflicts_with = "from_input"
    )]
    pub input: Option<PathBuf>,
    /// A recording that may hold targets: its noise (or clutter) is estimated robustly
    /// (medians) and noise-only runs are simulated from that model.
    #[arg(long)]
    pub from_input: Option<PathBuf>,
    /// The detector's JSON configuration (`faint detect <detector> --print-config`)
    /// [default: the defaults]; `faint detect --calibration` must use the same.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// False-alarm probability per frame after the burn-in, in (0, 1).
    #[arg(long)]
    pub pfa: f64,
    /// Frames of each run, also the longest input the thresholds cover [default: --input:
    /// 32, or the recording's length if shorter; --from-input: the file's length].
    #[arg(long)]
    pub run_frames: Option<usize>,
    /// Frames from the start that declare nothing.
    #[arg(long, default_value_t = 0)]
    pub burn_in: usize,
    /// Simulated runs with --from-input, 1 to 1000000 [default: ceil(10 / pfa)].
    #[arg(long)]
    pub runs: Option<usize>,
    /// Seed of the detector's streams (and of the simulated noise).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The calibration file to write (JSON).
    #[arg(long)]
    pub out: PathBuf,
}

/// The fewest runs that support `pfa`.
pub fn runs_needed(pfa: f64) -> usize {
    (MIN_EXCEEDANCES / pfa).ceil() as usize
}

/// What a calibration fixes before its runs; identical in every shard (a shard file's
/// `meta`).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct Meta {
    detector: String,
    score: String,
    runs: usize,
    run_frames: usize,
    source: Source,
    config: serde_json::Value,
}

/// Runs `faint calibrate` (every run, whatever the environment) and returns what it
/// wrote.
pub fn run(a: &Args) -> Result<Calibration> {
    let (meta, s) = scores(a, None)?;
    let s = s.into_iter().next().map(|b| b.results).unwrap_or_default();
    finish(a, meta, s)
}

/// `faint calibrate` with a shard (`--shard`, or a scheduler's array): runs only the
/// shard's noise runs and writes their scores to `<out stem>.shards/` for `faint merge`;
/// returns the shard file.
pub fn run_shard(a: &Args, shard: Shard) -> Result<std::path::PathBuf> {
    let t0 = std::time::Instant::now();
    let (meta, batches) = scores(a, Some(shard))?;
    let run = Run::new(COMMAND, a)?.with_meta(&meta)?;
    let seconds = t0.elapsed().as_secs_f64();
    shard::write(&shard_dir(&a.out), &run, shard, seconds, &batches)
}

/// The shard folder of a calibration written to `out`: `<out without .json>.shards`.
pub fn shard_dir(out: &Path) -> std::path::PathBuf {
    let stem = out.with_extension("");
    let mut name = stem.as_os_str().to_os_string();
    name.push(".shards");
    std::path::PathBuf::from(name)
}

/// `faint merge` of `calibrate` shards: the calibration of the whole run, written to
/// `out` if given, else to the run's `--out`.
pub fn merge(m: &Merged, out: Option<&Path>) -> Result<Calibration> {
    let mut a: Args = m.run.args()?;
    if let Some(o) = out {
        a.out = o.to_path_buf();
    }
    let meta: Meta = m.run.meta()?;
    let s = m.results::<Vec<f64>>(&["runs".to_string()])?;
    finish(&a, meta, s.into_iter().next().unwrap_or_default())
}

/// The per-frame largest scores `s[r][k]` of the noise runs `shard` holds (every run for
/// `None`), as one batch `runs`, with what the calibration fixed before them.
fn scores(a: &Args, shard: Option<Shard>) -> Result<(Meta, Vec<Batch<Vec<f64>>>)> {
    let entry = detect::find(&a.detector)?;
    crate::cli::probability("--pfa", a.pfa)?;
    if let Some(l) = a.run_frames {
        crate::cli::count("--run-frames", l, 1..=crate::cli::MAX_RUNS)?;
    }
    if let Some(r) = a.runs {
        crate::cli::count("--runs", r, 1..=crate::cli::MAX_RUNS)?;
    }
    let text = match &a.config {
        Some(p) => std::fs::read_to_string(p)
            .with_context(|| format!("--config {}: cannot read", p.display()))?,
        None => (entry.default_config)(),
    };
    let config: serde_json::Value = serde_json::from_str(&text).with_context(|| {
        format!(
            "--config {}: not JSON",
            a.config.as_deref().unwrap_or(Path::new("")).display()
        )
    })?;
    let need = runs_needed(a.pfa);
    let scratch =
        std::env::temp_dir().join(format!("faint-calibrate-{}-{}", std::process::id(), a.seed));
    let (input, runs, l, source) = match (&a.input, &a.from_input) {
        (Some(path), None) => {
            detect::check_input(path)?;
            let lay = noise::layout(entry.input, path)?;
            let l = a.run_frames.unwrap_or(DEFAULT_RUN_FRAMES.min(lay.frames));
            let runs = lay.frames / l.max(1);
            if runs < need {
                bail!(
                    "--pfa {}: needs at least {need} noise runs of {l} frames ({} frames); {} has {} frames ({runs} runs): give more noise, lower --run-frames or raise --pfa",
                    a.pfa,
                    need * l,
                    path.display(),
                    lay.frames
                );
            }
            let src = Source::Recording {
                file: path.display().to_string(),
                frames: lay.frames,
            };
            (path.clone(), runs, l, src)
        }
        (None, Some(path)) => {
            detect::check_input(path)?;
            let (model, lay) = noise::estimate(entry.input, path, &config)
                .with_context(|| format!("--from-input {}", path.display()))?;
            let l = a.run_frames.unwrap_or(lay.frames);
            let runs = a.runs.unwrap_or(need);
            ensure!(
                runs >= need,
                "--runs {runs} cannot support --pfa {}: needs at least {need}",
                a.pfa
            );
            ensure!(
                runs.saturating_mul(l) <= 10_000_000,
                "{runs} runs of {l} frames: more than 10 000 000 frames to simulate"
            );
            std::fs::create_dir_all(&scratch)
                .with_context(|| format!("cannot create {}", scratch.display()))?;
            let ext = if matches!(entry.input, detect::InputKind::Plots) {
                "csv"
            } else {
                "npy"
            };
            let sim = scratch.join(format!("noise.{ext}"));
            noise::simulate(&model, &lay.frame_shape, runs * l, a.seed, path, &sim)?;
            let src = Source::Model {
                file: path.display().to_string(),
                frames: lay.frames,
                model,
            };
            (sim, runs, l, src)
        }
        _ => bail!("give one of --input NOISE or --from-input FILE"),
    };
    ensure!(
        a.burn_in < l,
        "--burn-in {} must be below --run-frames {l}",
        a.burn_in
    );
    let mut score = String::new();
    let batch = Batch::run("runs", runs, shard, |range| -> Result<Vec<Vec<f64>>> {
        let req = Request {
            input: &input,
            config: a.config.as_deref().zip(Some(text.as_str())),
            seed: a.seed,
            reports: false,
            restart_every: Some(l),
            runs: shard.map(|_| range.clone()),
        };
        let outcome = (entry.run)(&req);
        let _ = std::fs::remove_dir_all(&scratch);
        let outcome = outcome?;
        score = outcome.score.name().to_string();
        // s[r - first][k]: the largest score of run r at frame k.
        let mut s = vec![vec![f64::NEG_INFINITY; l]; range.len()];
        for row in &outcome.rows {
            let (r, k) = (row.frame / l, row.frame % l);
            if !range.contains(&r) {
                continue;
            }
            ensure!(
                !row.score.is_nan(),
                "{}: a NaN score at frame {} of the noise",
                entry.name,
                row.frame
            );
            s[r - range.start][k] = s[r - range.start][k].max(f64::from(row.score));
        }
        Ok(s)
    })?;
    let meta = Meta {
        detector: entry.name.to_string(),
        score,
        runs,
        run_frames: l,
        source,
        config,
    };
    Ok((meta, vec![batch]))
}

/// The thresholds from the scores `s[r][k]` of every noise run, written to `a.out`.
fn finish(a: &Args, meta: Meta, s: Vec<Vec<f64>>) -> Result<Calibration> {
    let l = meta.run_frames;
    // The statistics are f32 scores widened to f64: the cast back is exact.
    let finite = |x: f64| x.is_finite().then_some(x as f32);
    let mut thresholds = Vec::with_capacity(l - a.burn_in);
    for k in a.burn_in..l {
        let col: Vec<f64> = s.iter().map(|run| run[k]).collect();
        let t = threshold_at_pfa(&col, a.pfa)?;
        thresholds.push(FrameThreshold {
            frame: k,
            value: finite(t.value),
            ci_low: finite(t.ci_low),
            ci_high: finite(t.ci_high),
            reported: col.iter().filter(|x| x.is_finite()).count(),
            exceedances: Some(col.iter().filter(|&&x| x > t.value).count()),
        });
    }
    let cal = Calibration {
        format: FORMAT,
        faint_version: env!("CARGO_PKG_VERSION").to_string(),
        detector: meta.detector,
        score: meta.score,
        pfa: a.pfa,
        burn_in: a.burn_in,
        run_frames: l,
        runs: meta.runs,
        source: meta.source,
        seed: a.seed,
        config: meta.config,
        thresholds,
    };
    if let Some(parent) = a.out.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(parent)
            .with_context(|| format!("--out {}: cannot create its folder", a.out.display()))?;
    }
    crate::io::write_json(&a.out, &cal)?;
    Ok(cal)
}
