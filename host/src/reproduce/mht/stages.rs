//! Where MHT-TBD loses a target and where it admits a false track: stage 3 of the
//! detector re-run on a completed period with every peak's fate recorded (the same rules
//! as `MhtTbd`'s stage 3, checked equal to its confirmed tracks by
//! `tests/mht/stages.rs`), and each target that no confirmed track matches attributed
//! to the first stage that stopped it:
//!
//! - pre-detection: even with every pre-detection plot of the target kept, its best DMHT
//!   cell (the cell holding the target's plots in the most scans, plus the effective
//!   clutter) stays below `gamma_1` (missed plots `1 - Pd0`, plot noise, cell edges);
//! - censoring: that cell would reach `gamma_1` with all the target's plots, but with
//!   the effective plots only it does not (censoring removed plots the threshold needed);
//! - condensing/recovery: the cell reaches `gamma_1` but no peak's recovered track
//!   matches the target (the cell is in the region of a stronger peak, or the recovered
//!   line leaves the target);
//! - confirmation, merging, residual rule: the strongest peak whose track matches the
//!   target was rejected by that rule (fewer than `confirm_frac gamma_1` effective plots
//!   on one motion; more than half its plots in earlier tracks; its count without the
//!   plots shared with earlier tracks below `gamma_1`).
//!
//! A confirmed track that matches no target (a false track) is described by its
//! largest number of plots from one target and its peak cell's count without that
//! target's plots: below `gamma_1`, the target's plots lifted the cell over the
//! threshold.

use faint_core::detect::mht::{censoring::FLAG_EFFECTIVE, dmht, Peak, Track, NO_PLOT};
use faint_core::detect::Detector;
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;

use super::detectors::detectors;
use super::evaluation::{target_plots_in, track_targets};
use crate::instances::mht::{Mht, ANGLE_CELLS, PLOTS, RANGE_CELLS, SCANS, TRACKS};
use crate::simulate::mht::{Origin, SeaClutter, Trial};

/// What stage 3 did with one peak (peaks are taken strongest first).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fate {
    /// Confirmed track.
    Confirmed,
    /// Rejected by the confirmation (too few plots on one motion).
    Short,
    /// Merged: more than half of its plots are in earlier confirmed tracks.
    Merged,
    /// Rejected by the residual rule.
    Residual,
}

impl Fate {
    /// Position in `StageReport::peak_fates` (`Confirmed`, `Short`, `Merged`, `Residual`).
    pub fn index(self) -> usize {
        match self {
            Fate::Confirmed => 0,
            Fate::Short => 1,
            Fate::Merged => 2,
            Fate::Residual => 3,
        }
    }
}

/// Stage 3 of `m`'s completed period at `gamma1`: every peak's recovered track and fate.
/// The confirmed ones equal `m.tracks()` when `gamma1` is `m`'s `gamma_1`.
pub fn stage3_fates(m: &Mht, gamma1: u8) -> Vec<(Track<SCANS>, Fate)> {
    let cfg = *m.config();
    let ns = cfg.n_scans.min(SCANS);
    let mut acc = Box::new(m.accumulator().clone());
    let mut peaks = [Peak::default(); TRACKS];
    let n_peaks = usize::from(acc.condense(gamma1, &mut peaks).peaks).min(TRACKS);
    let scans: Vec<&[Plot]> = (0..ns).map(|s| m.scan_plots(s)).collect();
    let flags: Vec<[u8; PLOTS]> = (0..ns)
        .map(|s| {
            let mut f = [0u8; PLOTS];
            for (k, fk) in f.iter_mut().enumerate().take(scans[s].len()) {
                if m.is_effective(s, k) {
                    *fk = FLAG_EFFECTIVE;
                }
            }
            f
        })
        .collect();
    let assoc = dmht::Assoc {
        d_max: cfg.d_max,
        along_gate: cfg.along_gate,
        lookback: cfg.lookback,
    };
    let geom = m.dmht_geometry();
    let mut confirmed: Vec<Track<SCANS>> = Vec::new();
    let mut out = Vec::with_capacity(n_peaks);
    for pk in &peaks[..n_peaks] {
        let mut tr = Track::<SCANS>::default();
        dmht::recover::<RANGE_CELLS, ANGLE_CELLS, PLOTS, SCANS>(
            geom, *pk, &scans, &flags, &assoc, &mut tr,
        );
        let shared = |s: usize| {
            tr.plots[s] != NO_PLOT && confirmed.iter().any(|o| o.plots[s] == tr.plots[s])
        };
        let fate = if tr.n_plots < cfg.min_track_plots
            || f32::from(tr.n_effective) < cfg.confirm_frac * f32::from(gamma1)
        {
            Fate::Short
        } else if 2 * (0..ns).filter(|&s| shared(s)).count() > usize::from(tr.n_plots) {
            Fate::Merged
        } else if cfg.residual && !confirmed.is_empty() && {
            let (r, a) = (usize::from(pk.r), usize::from(pk.a));
            let in_cell = |s: usize, k: usize| {
                let (xq, yq) = geom.quantise(scans[s][k].x, scans[s][k].y);
                geom.rho_index_q(xq, yq, a) == r
            };
            let resid = (0..ns)
                .filter(|&s| {
                    (0..scans[s].len()).any(|k| {
                        m.is_effective(s, k)
                            && !(usize::from(tr.plots[s]) == k && shared(s))
                            && in_cell(s, k)
                    })
                })
                .count();
            resid < usize::from(gamma1)
        } {
            Fate::Residual
        } else {
            Fate::Confirmed
        };
        if fate == Fate::Confirmed {
            confirmed.push(tr);
        }
        out.push((tr, fate));
    }
    out
}

/// Stage at which a target was lost (or `Detected`), in pipeline order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Loss {
    /// A confirmed track matches the target.
    Detected,
    /// Its best cell stays below `gamma_1` even with all its pre-detection plots.
    PreDetection,
    /// Its best cell reaches `gamma_1` only with the plots censoring removed.
    Censoring,
    /// The cell reaches `gamma_1`, no peak's recovered track matches the target.
    Condensing,
    /// The matching peak's track failed the confirmation.
    Confirmation,
    /// The matching peak's track was merged into earlier tracks.
    Merging,
    /// The matching peak's track failed the residual rule.
    Residual,
}

impl Loss {
    /// All stages, in pipeline order.
    pub const ALL: [Loss; 7] = [
        Loss::Detected,
        Loss::PreDetection,
        Loss::Censoring,
        Loss::Condensing,
        Loss::Confirmation,
        Loss::Merging,
        Loss::Residual,
    ];
    fn index(self) -> usize {
        Self::ALL.iter().position(|&l| l == self).unwrap_or(0)
    }
}

/// One false track (matches no target).
#[derive(Debug, Clone, Copy)]
pub struct FalseTrack {
    /// Peak cell's raw count.
    pub raw: u8,
    /// Associated plots.
    pub n_plots: u16,
    /// Largest number of its plots made by one target.
    pub target_plots: usize,
    /// That target is matched by a confirmed track.
    pub target_detected: bool,
    /// Scans in which the peak cell holds an effective plot not made by that target.
    pub count_without_target: usize,
    /// Plots shared with the tracks confirmed before it.
    pub shared_earlier: usize,
}

/// Stage attribution over a batch of trials.
#[derive(Debug, Clone, Default)]
pub struct StageReport {
    /// Trials.
    pub trials: u64,
    /// Targets (trials x targets per trial).
    pub targets: u64,
    /// Targets per [`Loss`] (index in [`Loss::ALL`] order).
    pub loss: [u64; 7],
    /// Targets with fewer than `gamma_1` pre-detection plots in the period (part of
    /// `PreDetection`).
    pub few_plots: u64,
    /// Peaks per [`Fate`] (`Confirmed`, `Short`, `Merged`, `Residual`).
    pub peak_fates: [u64; 4],
    /// The false tracks.
    pub false_tracks: Vec<FalseTrack>,
}

/// Cells of the DMHT grid: scans with a plot selected by `pick` in cell `(r, a)`.
fn cell_scans(
    m: &Mht,
    ns: usize,
    r: usize,
    a: usize,
    pick: impl Fn(usize, usize) -> bool,
) -> usize {
    let g = m.dmht_geometry();
    (0..ns)
        .filter(|&s| {
            m.scan_plots(s).iter().enumerate().any(|(k, p)| {
                pick(s, k) && {
                    let (xq, yq) = g.quantise(p.x, p.y);
                    g.rho_index_q(xq, yq, a) == r
                }
            })
        })
        .count()
}

/// The DMHT cell holding target `i`'s pre-detection plots in the most scans (ties: the
/// larger accumulator count).
fn best_cell(m: &Mht, trial: &Trial, ns: usize, i: usize) -> (usize, usize) {
    let g = m.dmht_geometry();
    let mut best = (0usize, 0u8, 0usize, 0usize);
    let mut seen = vec![0u32; RANGE_CELLS];
    for a in 0..ANGLE_CELLS {
        seen.fill(0);
        for s in 0..ns {
            for (k, p) in m.scan_plots(s).iter().enumerate() {
                if trial.scans[s].origin.get(k) == Some(&Origin::Target(i)) {
                    let (xq, yq) = g.quantise(p.x, p.y);
                    let r = g.rho_index_q(xq, yq, a);
                    if let Some(w) = seen.get_mut(r) {
                        *w |= 1 << s;
                    }
                }
            }
        }
        for (r, w) in seen.iter().enumerate() {
            let key = (w.count_ones() as usize, m.accumulator().count(r, a));
            if key > (best.0, best.1) {
                best = (key.0, key.1, r, a);
            }
        }
    }
    (best.2, best.3)
}

impl StageReport {
    /// Add one completed period of `m` (configured with `gamma1`) on `trial`.
    pub fn add(&mut self, m: &Mht, trial: &Trial, t_scan: f32, gamma1: u8) {
        let ns = m.config().n_scans.min(SCANS);
        let fates = stage3_fates(m, gamma1);
        self.trials += 1;
        for (_, f) in &fates {
            self.peak_fates[f.index()] += 1;
        }
        let confirmed: Vec<&Track<SCANS>> = fates
            .iter()
            .filter(|(_, f)| *f == Fate::Confirmed)
            .map(|(t, _)| t)
            .collect();
        let detected: Vec<bool> = (0..trial.targets.len())
            .map(|i| {
                confirmed
                    .iter()
                    .any(|t| track_targets(t, trial, t_scan).contains(&i))
            })
            .collect();
        for (i, &det) in detected.iter().enumerate() {
            self.targets += 1;
            let own = |s: usize, k: usize| trial.scans[s].origin.get(k) == Some(&Origin::Target(i));
            let n_own: usize = (0..ns)
                .map(|s| {
                    (0..trial.scans[s].origin.len())
                        .filter(|&k| own(s, k))
                        .count()
                })
                .sum();
            let loss = if det {
                Loss::Detected
            } else if let Some((_, f)) = fates
                .iter()
                .find(|(t, _)| track_targets(t, trial, t_scan).contains(&i))
            {
                match f {
                    Fate::Short => Loss::Confirmation,
                    Fate::Merged => Loss::Merging,
                    Fate::Residual | Fate::Confirmed => Loss::Residual,
                }
            } else {
                let (r, a) = best_cell(m, trial, ns, i);
                let actual = usize::from(m.accumulator().count(r, a));
                let all_kept = cell_scans(m, ns, r, a, |s, k| m.is_effective(s, k) || own(s, k));
                if actual >= usize::from(gamma1) {
                    Loss::Condensing
                } else if all_kept >= usize::from(gamma1) {
                    Loss::Censoring
                } else {
                    if n_own < usize::from(gamma1) {
                        self.few_plots += 1;
                    }
                    Loss::PreDetection
                }
            };
            self.loss[loss.index()] += 1;
        }
        for (ci, t) in confirmed.iter().enumerate() {
            if !track_targets(t, trial, t_scan).is_empty() {
                continue;
            }
            let (best_i, best_n) = (0..trial.targets.len())
                .map(|i| (i, target_plots_in(t, trial, i)))
                .max_by_key(|&(i, n)| (n, usize::MAX - i))
                .unwrap_or((0, 0));
            let (r, a) = (usize::from(t.peak.r), usize::from(t.peak.a));
            let count_without_target = cell_scans(m, ns, r, a, |s, k| {
                m.is_effective(s, k)
                    && (best_n == 0
                        || trial.scans[s].origin.get(k) != Some(&Origin::Target(best_i)))
            });
            let shared_earlier = (0..ns)
                .filter(|&s| {
                    t.plots[s] != NO_PLOT
                        && confirmed[..ci].iter().any(|o| o.plots[s] == t.plots[s])
                })
                .count();
            self.false_tracks.push(FalseTrack {
                raw: t.peak.raw,
                n_plots: t.n_plots,
                target_plots: best_n,
                target_detected: best_n > 0 && detected.get(best_i).copied().unwrap_or(false),
                count_without_target,
                shared_earlier,
            });
        }
    }

    /// Targets lost at `l`.
    pub fn lost_at(&self, l: Loss) -> u64 {
        self.loss[l.index()]
    }

    /// Markdown table of the attribution (one row).
    pub fn markdown_row(&self, lambda: f32, gamma1: u8) -> String {
        let f = &self.false_tracks;
        let mixed = f.iter().filter(|t| t.target_plots > 0).count();
        let lifted = f
            .iter()
            .filter(|t| t.target_plots > 0 && t.count_without_target < usize::from(gamma1))
            .count();
        let tdet = f.iter().filter(|t| t.target_detected).count();
        let l = |x: Loss| self.lost_at(x);
        format!(
            "| {lambda} | {gamma1} | {} | {} | {} | {} ({} with < gamma_1 plots) | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
            self.trials,
            self.targets,
            l(Loss::Detected),
            l(Loss::PreDetection),
            self.few_plots,
            l(Loss::Censoring),
            l(Loss::Condensing),
            l(Loss::Confirmation),
            l(Loss::Merging),
            l(Loss::Residual),
            f.len(),
            f.len() - mixed,
            mixed,
            lifted,
            tdet
        )
    }

    /// Header of [`StageReport::markdown_row`].
    pub const MARKDOWN_HEADER: &'static str = "| lambda | gamma_1 | trials | targets | detected | lost: pre-detection | censoring | condensing/recovery | confirmation | merging | residual rule | false tracks | of them: clutter only | with target plots | target plots lift the cell over gamma_1 | that target detected by another track |\n|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|";
}

/// Stage attribution at `lambda`, `gamma1` over `trials` scenes with the preset's targets,
/// scene `t` drawn from `Rng::from_stream(seed, t)`.
pub fn attribute(lambda: f32, gamma1: u8, trials: u64, seed: u64) -> anyhow::Result<StageReport> {
    let sc = SeaClutter::paper(lambda);
    let (mut m, _) = detectors(&sc, gamma1, sc.n_scans as u8)?;
    let mut rep = StageReport::default();
    for t in 0..trials {
        let tr = sc.generate(&mut Rng::from_stream(seed, t));
        for s in &tr.scans {
            m.step(&s.plots).map_err(|e| anyhow::anyhow!("{e}"))?;
        }
        rep.add(&m, &tr, sc.t_scan, gamma1);
    }
    Ok(rep)
}
