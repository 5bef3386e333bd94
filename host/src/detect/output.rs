//! What `faint detect` writes, and the truth file it scores against.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, ensure, Context, Result};
use serde::Serialize;

use super::{InputView, Outcome};
use crate::io::chart::{heatmap, line_chart, scatter, Cell, Series};
use crate::io::{write_csv, write_json, write_text};
use crate::stats::gospa::{gospa_with, Gospa};

/// Reads a truth file: CSV with the header `frame,<names...>` (frames numbered from
/// `first`, 0 or 1; one row per true object per frame, `names` the detector's position
/// components, e.g. `x_m,y_m`). Returns the objects of each of `frames` frames. A row
/// at frame `frames` read as 0-based (the last frame of a file numbered from 1) is an
/// error that says so.
pub fn read_truth(
    path: &Path,
    names: &[&str],
    frames: usize,
    first: usize,
) -> Result<Vec<Vec<Vec<f64>>>> {
    let p = path.display();
    let mut r = csv::ReaderBuilder::new()
        .has_headers(true)
        .from_path(path)
        .map_err(|e| anyhow!("truth {p}: cannot read: {e}"))?;
    let header: Vec<String> = r
        .headers()
        .map_err(|e| anyhow!("truth {p}: {e}"))?
        .iter()
        .map(|h| h.trim().to_string())
        .collect();
    let want: Vec<String> = std::iter::once("frame")
        .chain(names.iter().copied())
        .map(str::to_string)
        .collect();
    ensure!(
        header == want,
        "truth {p}: header is `{}`, expected `{}`",
        header.join(","),
        want.join(",")
    );
    let mut out = vec![Vec::new(); frames];
    for (i, rec) in r.records().enumerate() {
        let rec = rec.map_err(|e| anyhow!("truth {p}: row {}: {e}", i + 1))?;
        let frame: usize = rec.get(0).unwrap_or("").trim().parse().map_err(|_| {
            anyhow!(
                "truth {p}: row {}: frame is not a non-negative integer",
                i + 1
            )
        })?;
        ensure!(
            frame >= first,
            "truth {p}: row {}: frame {frame} is before the first frame {first} \
             (--truth-first-frame)",
            i + 1
        );
        let k = frame - first;
        if k >= frames {
            let hint = if first == 0 && frame == frames {
                " (the file looks numbered from 1: add --truth-first-frame 1)"
            } else {
                ""
            };
            bail!(
                "truth {p}: row {}: frame {frame} is past the input's {frames} frames{hint}",
                i + 1
            );
        }
        let frame = k;
        let mut x = Vec::with_capacity(names.len());
        for (j, name) in names.iter().enumerate() {
            let v: f64 = rec
                .get(j + 1)
                .unwrap_or("")
                .trim()
                .parse()
                .map_err(|_| anyhow!("truth {p}: row {}: {name} is not a number", i + 1))?;
            ensure!(
                v.is_finite(),
                "truth {p}: row {}: {name} is not finite",
                i + 1
            );
            x.push(v);
        }
        out[frame].push(x);
    }
    Ok(out)
}

/// Files written by [`write()`] and the run's totals.
#[derive(Debug, Clone, Serialize)]
pub struct Written {
    /// The output folder.
    pub dir: PathBuf,
    /// Detections written (score at least the minimum).
    pub detections: usize,
    /// Mean GOSPA over the frames, when a truth file was given.
    pub mean_gospa: Option<f64>,
}

#[derive(Serialize)]
struct DetectionRecord<'a> {
    frame: usize,
    detector: &'a str,
    score: f32,
    track_id: Option<u32>,
    track_len: Option<u32>,
    state: BTreeMap<&'a str, f32>,
}

#[derive(Serialize)]
struct FrameSummary {
    frame: usize,
    /// Detections the detector reported (before any selection).
    detections: usize,
    best_score: Option<f32>,
    /// Detections written (above the threshold or the minimum score).
    declared: usize,
    /// The calibrated threshold of the frame (empty without a calibration, before the
    /// burn-in; `-inf` when every detection counts).
    threshold: Option<f32>,
    /// The calibration's false-alarm probability per frame (empty without one).
    pfa: Option<f64>,
}

/// Which detections `faint detect` writes.
#[derive(Debug, Clone, Copy)]
pub enum Selection<'a> {
    /// Those with a score of at least this.
    MinScore(f32),
    /// Those above the calibrated threshold of their frame.
    Calibrated(&'a super::calibration::Calibration),
}

impl Selection<'_> {
    /// True if `r` is written.
    pub fn keeps(&self, r: &super::Row) -> bool {
        match self {
            Selection::MinScore(m) => r.score >= *m,
            Selection::Calibrated(c) => c.declares(r.frame, r.score),
        }
    }
}

#[derive(Serialize)]
struct GospaRow {
    frame: usize,
    truth: usize,
    estimates: usize,
    gospa: f64,
    localisation: f64,
    missed: f64,
    false_targets: f64,
}

/// Writes the outcome's data files to `dir`: the detections `select` keeps
/// (`detections.csv`, `detections.json`), every frame's reported count and best score, the
/// written count and, with a calibration, the frame's threshold and Pfa (`summary.csv`), the reports if collected (`reports.json`) and, with a
/// truth, the per-frame GOSPA (`gospa.csv`; cut-off `c`, order 2, alpha = 2) between the
/// truth and the written detections' positions. The charts are [`write_charts`].
pub fn write(
    out: &Outcome,
    dir: &Path,
    select: Selection,
    truth: Option<&[Vec<Vec<f64>>]>,
    c: f64,
) -> Result<Written> {
    crate::cli::out_dir(dir)?;
    let kept: Vec<&super::Row> = out.rows.iter().filter(|r| select.keeps(r)).collect();
    // detections.csv: fixed columns, then one per state component.
    let path = dir.join("detections.csv");
    let mut w = csv::Writer::from_path(&path)
        .with_context(|| format!("cannot create {}", path.display()))?;
    let mut header = vec!["frame", "detector", "score", "track_id", "track_len"];
    header.extend(out.state_names.iter().copied());
    w.write_record(&header)
        .with_context(|| format!("cannot write {}", path.display()))?;
    let opt = |v: Option<u32>| v.map_or(String::new(), |x| x.to_string());
    for r in &kept {
        let mut rec = vec![
            r.frame.to_string(),
            out.detector.to_string(),
            r.score.to_string(),
            opt(r.track_id),
            opt(r.track_len),
        ];
        rec.extend(r.state.iter().map(|v| v.to_string()));
        w.write_record(&rec)
            .with_context(|| format!("cannot write {}", path.display()))?;
    }
    w.flush()
        .with_context(|| format!("cannot write {}", path.display()))?;
    let records: Vec<DetectionRecord> = kept
        .iter()
        .map(|r| DetectionRecord {
            frame: r.frame,
            detector: out.detector,
            score: r.score,
            track_id: r.track_id,
            track_len: r.track_len,
            state: out
                .state_names
                .iter()
                .copied()
                .zip(r.state.iter().copied())
                .collect(),
        })
        .collect();
    write_json(dir.join("detections.json"), &records)?;
    // Per-frame summary and reports.
    let mut summary: Vec<FrameSummary> = (0..out.frames)
        .map(|frame| FrameSummary {
            frame,
            detections: 0,
            best_score: None,
            declared: 0,
            threshold: match select {
                // Thresholds are f32 scores: the narrowing is exact.
                Selection::Calibrated(c) => c.threshold(frame).value().map(|t| t as f32),
                Selection::MinScore(_) => None,
            },
            pfa: match select {
                Selection::Calibrated(c) => Some(c.pfa),
                Selection::MinScore(_) => None,
            },
        })
        .collect();
    for r in &out.rows {
        if let Some(s) = summary.get_mut(r.frame) {
            s.detections += 1;
            s.best_score = Some(s.best_score.map_or(r.score, |b| b.max(r.score)));
            if select.keeps(r) {
                s.declared += 1;
            }
        }
    }
    write_csv(dir.join("summary.csv"), &summary)?;
    if !out.reports.is_empty() {
        write_text(
            dir.join("reports.json"),
            &format!("[\n{}\n]\n", out.reports.join(",\n")),
        )?;
    }
    // GOSPA against the truth.
    let mut mean_gospa = None;
    if let Some(truth) = truth {
        ensure!(
            !out.position.is_empty(),
            "--truth: {} reports no positions to compare",
            out.detector
        );
        let mut est = vec![Vec::new(); out.frames];
        for r in &kept {
            if let Some(e) = est.get_mut(r.frame) {
                e.push(
                    out.position
                        .iter()
                        .map(|&i| f64::from(r.state.get(i).copied().unwrap_or(f32::NAN)))
                        .collect::<Vec<f64>>(),
                );
            }
        }
        let dist = |a: &Vec<f64>, b: &Vec<f64>| {
            a.iter()
                .zip(b)
                .map(|(x, y)| (x - y) * (x - y))
                .sum::<f64>()
                .sqrt()
        };
        let rows: Vec<GospaRow> = (0..out.frames)
            .map(|k| {
                let t = truth.get(k).map_or(&[][..], |v| v.as_slice());
                let e = est[k].as_slice();
                let g: Gospa = gospa_with(t, e, c, 2.0, dist);
                GospaRow {
                    frame: k,
                    truth: t.len(),
                    estimates: e.len(),
                    gospa: g.total,
                    localisation: g.localisation,
                    missed: g.missed,
                    false_targets: g.false_targets,
                }
            })
            .collect();
        if !rows.is_empty() {
            mean_gospa = Some(rows.iter().map(|r| r.gospa).sum::<f64>() / rows.len() as f64);
        }
        write_csv(dir.join("gospa.csv"), &rows)?;
    }
    Ok(Written {
        dir: dir.to_path_buf(),
        detections: kept.len(),
        mean_gospa,
    })
}

/// Draws the charts of a written outcome into `dir`: `score.svg` (best score per frame)
/// and `tracks.svg` (the detections `select` keeps, over the input).
/// Long inputs are drawn in blocks of frames (at most 400 columns) and with at most
/// 20 000 background plots, so the files stay small.
pub fn write_charts(out: &Outcome, dir: &Path, select: Selection) -> Result<()> {
    let kept: Vec<&super::Row> = out.rows.iter().filter(|r| select.keeps(r)).collect();
    let mut best = vec![None::<f32>; out.frames];
    for r in &out.rows {
        if let Some(b) = best.get_mut(r.frame) {
            *b = Some(b.map_or(r.score, |x| x.max(r.score)));
        }
    }
    // At most MAX_COLUMNS points: longer inputs show the best score of each block.
    let step = out.frames.div_ceil(MAX_COLUMNS).max(1);
    let score_pts: Vec<(f64, f64)> = best
        .chunks(step)
        .enumerate()
        .filter_map(|(i, c)| {
            let b = c.iter().flatten().copied().reduce(f32::max)?;
            Some(((i * step) as f64, f64::from(b)))
        })
        .collect();
    if !score_pts.is_empty() {
        line_chart(
            dir.join("score.svg"),
            &if step > 1 {
                format!("{}: best score of each {step} frames", out.detector)
            } else {
                format!("{}: best score per frame", out.detector)
            },
            "frame",
            out.score.name(),
            &[Series {
                name: out.detector.to_string(),
                points: score_pts,
            }],
        )?;
    }
    tracks_chart(out, &kept, &dir.join("tracks.svg"))
}

/// Columns of the Doppler map in `tracks.svg`.
const MAX_COLUMNS: usize = 400;
/// Background plots drawn in `tracks.svg`.
const MAX_POINTS: usize = 20_000;

/// The estimated tracks over the input: Doppler estimates over the frames' bin powers,
/// Hough tracks over every plot, PHD estimates in x/y.
fn tracks_chart(out: &Outcome, kept: &[&super::Row], path: &Path) -> Result<()> {
    let title = format!("{}: detections over the input", out.detector);
    match &out.view {
        InputView::Doppler { frames, bin_hz } => {
            let bins = bin_hz.len();
            if bins == 0 || out.frames == 0 {
                return Ok(());
            }
            let df = if bins > 1 {
                f64::from((bin_hz[1] - bin_hz[0]).abs())
            } else {
                1.0
            };
            // At most MAX_COLUMNS columns: longer inputs show the largest power of each
            // block of `step` frames (a 10 000-frame file stays a small SVG).
            let step = out.frames.div_ceil(MAX_COLUMNS).max(1);
            let mut cells = Vec::with_capacity(out.frames.div_ceil(step) * bins);
            for k0 in (0..out.frames).step_by(step) {
                for (b, &f) in bin_hz.iter().enumerate() {
                    let p = (k0..(k0 + step).min(out.frames))
                        .filter_map(|k| frames.get(k * bins + b))
                        .fold(0.0f32, |m, z| m.max(z.norm_sqr()));
                    let f = f64::from(f);
                    cells.push(Cell {
                        x0: k0 as f64,
                        x1: (k0 + step) as f64,
                        y0: f - 0.5 * df,
                        y1: f + 0.5 * df,
                        value: 10.0 * f64::from(p.max(1e-30)).log10(),
                    });
                }
            }
            let pts = kept
                .iter()
                .filter_map(|r| Some((r.frame as f64 + 0.5, f64::from(*r.state.first()?))))
                .collect();
            heatmap(
                path,
                &title,
                "frame",
                &if step > 1 {
                    format!("Doppler (Hz); grey: largest bin power of {step} frames (dB)")
                } else {
                    "Doppler (Hz); grey: bin power (dB)".to_string()
                },
                &cells,
                &[Series {
                    name: format!("{} estimate", out.detector),
                    points: pts,
                }],
            )
        }
        InputView::Plots(scans) => {
            // At most MAX_POINTS background plots (every k-th one beyond that).
            let total: usize = scans.iter().map(Vec::len).sum();
            let every = total.div_ceil(MAX_POINTS).max(1);
            let bg: Vec<(f64, f64)> = scans
                .iter()
                .flatten()
                .step_by(every)
                .map(|p| (f64::from(p.x), f64::from(p.y)))
                .collect();
            if bg.is_empty() {
                return Ok(());
            }
            let series = if out.position.len() == 2 {
                vec![Series {
                    name: format!("{} track ends", out.detector),
                    points: kept
                        .iter()
                        .filter_map(|r| {
                            Some((f64::from(*r.state.first()?), f64::from(*r.state.get(1)?)))
                        })
                        .collect(),
                }]
            } else {
                Vec::new()
            };
            let label = if every > 1 {
                format!("y (m); grey: every {every}th plot")
            } else {
                "y (m); grey: every plot".to_string()
            };
            scatter(path, &title, "x (m)", &label, &bg, &series)
        }
        InputView::None => {
            if out.position.len() != 2 || kept.is_empty() {
                return Ok(());
            }
            let (i, j) = (out.position[0], out.position[1]);
            let pts: Vec<(f64, f64)> = kept
                .iter()
                .filter_map(|r| Some((f64::from(*r.state.get(i)?), f64::from(*r.state.get(j)?))))
                .collect();
            scatter(
                path,
                &title,
                out.state_names.get(i).copied().unwrap_or("x"),
                out.state_names.get(j).copied().unwrap_or("y"),
                &[],
                &[Series {
                    name: format!("{} estimates", out.detector),
                    points: pts,
                }],
            )
        }
    }
}

/// Fails unless `path` names a file that exists.
pub fn check_input(path: &Path) -> Result<()> {
    if !path.is_file() {
        bail!("--input {}: no such file", path.display());
    }
    Ok(())
}
