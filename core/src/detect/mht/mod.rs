//! MHT-TBD: modified Hough transform track-before-detect for dense clutter
//! (Bao, Lu, Tian, Tian, Acta Electronica Sinica 50(7), 2022), and the classic
//! Carlson Hough TBD baseline.
//!
//! Three stages (Fig. 1): pre-detection (outside this module: the input plots), plot
//! censoring ([`censoring`]: MSHT + M-scan collinearity + velocity gate -> effective
//! plots `S_ep`), detection and track recovery ([`dmht`]: data-matched Hough transform of
//! `S_ep`, binary integration, 3x3 Gaussian smoothing, threshold `gamma_1`, condensing,
//! line-to-plot association).
//!
//! Streaming: [`MhtTbd::step`] takes one scan. Integration periods are **blocked**: scans
//! `0..N`, `N..2N`, ... form periods; the step that completes a period runs the DMHT and
//! returns a [`PeriodSummary`] in its report; the tracks are then readable with
//! [`MhtTbd::tracks`] (and as [`Detection`]s, [`Detector::detections`]) until the next `step` starts a new period. Censoring windows do not
//! cross period boundaries (the plots of a period are judged on that period's scans only,
//! as the paper's model of a cell's `N`-scan hit sequence assumes).
//!
//! Bad input, all counted in the report, never a panic:
//! - plots with NaN/inf fields or outside the surveillance area are skipped (`invalid`);
//! - plots beyond the capacity `PLOTS` of a scan are skipped (`overflow`);
//! - gated pairs beyond `PLOTS` per scan pair and chains beyond `4 PLOTS` per scan are
//!   skipped ([`CensorStats`]); peaks beyond `TRACKS` are dropped weakest first
//!   ([`CondenseStats`]);
//! - degenerate geometry (all effective plots at one point): the DMHT rho range is
//!   floored at `drho_min` so the transform is defined (every curve passes through the
//!   middle rho cell); a period without effective plots reports zero tracks;
//! - zero scans per period, `M` outside `3..=8`, `N > SCANS` or `N > 64`, a non-finite or
//!   empty area: [`Error::InvalidConfig`] at construction.
//!
//! Memory (all fixed at compile time): the period's plots `SCANS x PLOTS` (12 B each) plus
//! one flag byte each, the censoring pair ring `8 x PLOTS x 4 B` and x-sort keys
//! `PLOTS x 8 B`, the accumulator `RHO_CELLS x THETA_CELLS x 4 B` and `TRACKS` tracks of
//! `SCANS` indices.

pub mod censoring;
pub mod classic;
pub mod dmht;
pub mod geometry;

pub use censoring::{CensorStats, MAX_M};
pub use classic::{
    ClassicHough, ClassicHoughConfig, ClassicHoughHost, ClassicHoughReport, ClassicHoughSmall,
};
pub use dmht::{Accumulator, CondenseStats, Peak, Track, NO_PLOT};
pub use geometry::Geometry;

use crate::detect::{Detection, Detector, ScoreKind, TrackInfo, Validate};

use crate::model::plot::Plot;
use crate::{math, Error, Result};
use censoring::{Censor, FLAG_EFFECTIVE};

/// Kept plots of scan `s` of a period store (`counts[s] <= P`; empty past the store).
fn kept<'a, const PLOTS: usize, const SCANS: usize>(
    plots: &'a [[Plot; PLOTS]; SCANS],
    counts: &[u16; SCANS],
    s: usize,
) -> &'a [Plot] {
    match (plots.get(s), counts.get(s)) {
        (Some(p), Some(&n)) => p.get(..usize::from(n)).unwrap_or(&[]),
        _ => &[],
    }
}

/// The first `ns` scans of a period store: `(plots, flags, kept count)` each.
fn period<'a, const PLOTS: usize, const SCANS: usize>(
    plots: &'a [[Plot; PLOTS]; SCANS],
    flags: &'a [[u8; PLOTS]; SCANS],
    counts: &'a [u16; SCANS],
    ns: usize,
) -> impl Iterator<Item = (&'a [Plot; PLOTS], &'a [u8; PLOTS], usize)> + 'a {
    plots
        .iter()
        .zip(flags)
        .zip(counts)
        .take(ns)
        .map(|((p, f), &n)| (p, f, usize::from(n)))
}

/// The effective plots among the first `n` of a scan, with their indices.
fn effective<'a, const PLOTS: usize>(
    plots: &'a [Plot; PLOTS],
    flags: &'a [u8; PLOTS],
    n: usize,
) -> impl Iterator<Item = (&'a Plot, usize)> + 'a {
    plots
        .iter()
        .zip(flags)
        .take(n)
        .enumerate()
        .filter(|(_, (_, &f))| f & FLAG_EFFECTIVE != 0)
        .map(|(k, (p, _))| (p, k))
}

/// True when the plot is finite and inside `[x_min, x_max] x [y_min, y_max]`.
#[inline]
pub fn in_area(p: &Plot, area: [f32; 4]) -> bool {
    p.x.is_finite()
        && p.y.is_finite()
        && p.x >= area[0]
        && p.x <= area[1]
        && p.y >= area[2]
        && p.y <= area[3]
}

/// Largest coordinate magnitude of an area (m): the grid's half diagonal
/// `sqrt(hx^2 + hy^2)` of eq. 7 then stays finite (`2 (1e18)^2 < f32::MAX`).
pub const MAX_COORDINATE: f32 = 1e18;

/// Largest [`MhtConfig::drho_min`] (m): above the diagonal of any valid area
/// (`2 sqrt(2) MAX_COORDINATE`), far below where `2 rho_max` overflows `f32`.
pub const MAX_DRHO_MIN: f32 = 4.0 * MAX_COORDINATE;

pub(crate) fn validate_area(area: [f32; 4]) -> Result<()> {
    let inside = |v: &f32| v.abs() <= MAX_COORDINATE; // false for NaN
    if !area.iter().all(inside) || area[1] <= area[0] || area[3] <= area[2] {
        return Err(Error::InvalidConfig("area"));
    }
    Ok(())
}

/// Runtime configuration of MHT-TBD.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct MhtConfig {
    /// Surveillance area `[x_min, x_max, y_min, y_max]` (m), `|coordinates| <= 1e18`.
    pub area: [f32; 4],
    /// Sliding-window length `M` (3..=8).
    pub m: usize,
    /// Scans per integration period `N` (`M..=min(NS, 64)`).
    pub n_scans: usize,
    /// Velocity gate `V_max T_scan` (m), eq. 6.
    pub gate: f32,
    /// PeriodSummary threshold `gamma_1` on the binary-integration count of a cell (the
    /// smoothing only locates the peak, see [`Accumulator::condense`]); `1..=n_scans`,
    /// or `n_scans + 1` for no confirmation (periods are still integrated).
    pub gamma1: u8,
    /// Apply the 3x3 Gaussian smoothing to locate the peaks.
    pub smooth: bool,
    /// Plot-to-line distance `D_max` (m), eq. 9.
    pub d_max: f32,
    /// Along-line gate around the track's predicted position (m).
    pub along_gate: f32,
    /// Look back into the pre-detection plots when no effective plot qualifies.
    pub lookback: bool,
    /// Tracks with fewer associated plots are not confirmed.
    pub min_track_plots: u16,
    /// A track is confirmed only if its effective plots that follow one constant-velocity
    /// motion along the line (the along-gated association) number at least
    /// `confirm_frac * gamma_1`: the paper's "correct the detections with the association
    /// results"; it rejects peaks built from pieces of unrelated chains and tracks.
    pub confirm_frac: f32,
    /// Smallest DMHT rho half-range (m) (degenerate geometry), in `(0, 4e18]`: the upper
    /// end is above the diagonal of the largest valid area (`2.9e18` m), so every
    /// geometry an area allows is reachable, and keeps the rho cell `2 rho_max / R` finite.
    pub drho_min: f32,
    /// Sequential extraction: a peak after the first confirmed track is confirmed only if
    /// its cell's binary-integration count, without the plots its track shares with the
    /// tracks confirmed so far (peaks are taken strongest first), still reaches `gamma_1`:
    /// the threshold test applied to what the confirmed tracks do not explain. Rejects
    /// lines through a run of a detected target's plots plus clutter (extension; measured
    /// in the README). Plots of other tracks that merely cross the cell still count.
    pub residual: bool,
}

impl MhtConfig {
    /// The paper's sea-clutter setting (§5.1): 6 km x 6 km, `N = 30`, `M = 3`,
    /// `V_max T_scan = 20 m/s x 5 s = 100 m`, `gamma_1 = 22` (the paper's value at
    /// `lambda ~ 398`; the host computes it from the model for a wanted `Pfa`).
    pub const fn sea_clutter() -> Self {
        Self {
            area: [0.0, 6000.0, 0.0, 6000.0],
            m: 3,
            n_scans: 30,
            gate: 100.0,
            gamma1: 22,
            smooth: true,
            d_max: 30.0,
            along_gate: 100.0,
            lookback: true,
            min_track_plots: 3,
            confirm_frac: 0.75,
            drho_min: 50.0,
            residual: true,
        }
    }
}

impl Validate for MhtConfig {
    /// Checks the values (the capacity `SCANS` of a detector is checked by its
    /// [`Detector::configure`]).
    fn validate(&self) -> Result<()> {
        validate_area(self.area)?;
        if !(3..=MAX_M).contains(&self.m) {
            return Err(Error::InvalidConfig("m"));
        }
        if self.n_scans == 0 || self.n_scans < self.m || self.n_scans > 64 {
            return Err(Error::InvalidConfig("n_scans"));
        }
        if !(self.gate.is_finite() && self.gate > 0.0) {
            return Err(Error::InvalidConfig("gate"));
        }
        // A track has at most `n_scans` plots: `n_scans + 1` turns confirmation off
        // (periods are still integrated, for `redetect`), anything larger is an error.
        if self.gamma1 == 0 || usize::from(self.gamma1) > self.n_scans + 1 {
            return Err(Error::InvalidConfig("gamma1"));
        }
        if !(self.d_max.is_finite() && self.d_max > 0.0) {
            return Err(Error::InvalidConfig("d_max"));
        }
        if !(self.along_gate.is_finite() && self.along_gate > 0.0) {
            return Err(Error::InvalidConfig("along_gate"));
        }
        if !(self.confirm_frac.is_finite() && (0.0..=1.0).contains(&self.confirm_frac)) {
            return Err(Error::InvalidConfig("confirm_frac"));
        }
        if !(self.drho_min > 0.0 && self.drho_min <= MAX_DRHO_MIN) {
            return Err(Error::InvalidConfig("drho_min"));
        }
        Ok(())
    }
}

/// Summary of one completed integration period.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct PeriodSummary {
    /// Plots kept over the period (pre-detection plots, after invalid/overflow).
    pub pre_plots: u32,
    /// Effective plots `|S_ep|`.
    pub effective_plots: u32,
    /// DMHT origin `(x0, y0)`: centroid of `S_ep` (eq. 7).
    pub origin: (f32, f32),
    /// DMHT rho cell size (m).
    pub drho: f32,
    /// Condensing counters.
    pub condense: CondenseStats,
    /// Confirmed tracks (see [`MhtTbd::tracks`]).
    pub tracks: u16,
    /// Peaks whose track had fewer than `min_track_plots` plots or fewer than
    /// `confirm_frac * gamma_1` effective plots.
    pub short: u16,
    /// Peaks whose track had more than half its plots already in stronger tracks (a
    /// second peak of one target, or a line across several targets' tracks).
    pub merged: u16,
    /// Peaks whose cell count without the confirmed tracks' plots is below `gamma_1`
    /// ([`MhtConfig::residual`]).
    pub residual: u16,
}

/// One step's report.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct MhtReport {
    /// Index of this scan within its period.
    pub scan_in_period: u16,
    /// Plots offered.
    pub plots_in: u32,
    /// Plots kept.
    pub plots_kept: u16,
    /// Plots skipped: non-finite or outside the area.
    pub invalid: u32,
    /// Plots skipped: beyond the capacity `PLOTS`.
    pub overflow: u32,
    /// Censoring counters of this scan's window.
    pub censor: CensorStats,
    /// Set when this scan completed a period.
    pub detection: Option<PeriodSummary>,
}

/// The firmware's detector: 512 plots per scan, 30 scans, a 256 x 180 grid, 32 tracks
/// (the host's track store: 16 dropped target peaks and cost Pd, docs/mht.md).
pub type MhtTbdM4 = MhtTbd<512, 30, 256, 180, 32>;
/// The host's detector (`faint reproduce mht`, the soak run): 640 plots per scan, 30
/// scans, a 256 x 180 grid, 32 tracks.
pub type MhtTbdHost = MhtTbd<640, 30, 256, 180, 32>;
/// The golden case's detector: 48 plots per scan, 10 scans, a 32 x 30 grid, 4 tracks.
pub type MhtTbdSmall = MhtTbd<48, 10, 32, 30, 4>;

/// Streaming MHT-TBD detector: `PLOTS` plots per scan, `SCANS` scans per period at most,
/// a `RHO_CELLS x THETA_CELLS` Hough grid, `TRACKS` tracks per period.
#[derive(Debug, Clone)]
pub struct MhtTbd<
    const PLOTS: usize,
    const SCANS: usize,
    const RHO_CELLS: usize,
    const THETA_CELLS: usize,
    const TRACKS: usize,
> {
    cfg: MhtConfig,
    msht: Geometry<RHO_CELLS, THETA_CELLS>,
    dmht: Geometry<RHO_CELLS, THETA_CELLS>,
    plots: [[Plot; PLOTS]; SCANS],
    counts: [u16; SCANS],
    flags: [[u8; PLOTS]; SCANS],
    censor: Censor<PLOTS>,
    acc: Accumulator<RHO_CELLS, THETA_CELLS>,
    peaks: [Peak; TRACKS],
    tracks: [Track<SCANS>; TRACKS],
    ntracks: usize,
    scan: usize,
    /// Stage-3 input summary of the period the last `step` completed (for
    /// [`MhtTbd::redetect`]); `None` otherwise.
    period: Option<PeriodSummary>,
}

impl<
        const PLOTS: usize,
        const SCANS: usize,
        const RHO_CELLS: usize,
        const THETA_CELLS: usize,
        const TRACKS: usize,
    > MhtTbd<PLOTS, SCANS, RHO_CELLS, THETA_CELLS, TRACKS>
{
    /// A detector for a configuration (validated here). The struct is large
    /// (`~ NS P 13 + R A 4` bytes): box it on the host, make it `static` on a target.
    pub fn new(cfg: MhtConfig) -> Result<Self> {
        let mut d = Self::new_unconfigured();
        d.configure(&cfg, 0)?;
        Ok(d)
    }

    /// The unconfigured detector for `static` or `Box` storage (a compile-time
    /// constant, [`Detector::UNCONFIGURED`]; not all-zero bits: its scan index is
    /// `usize::MAX`). [`MhtTbd::configure`] must succeed before `step`; until then `step`
    /// returns `Error::InvalidConfig("unconfigured")`.
    pub const fn new_unconfigured() -> Self {
        const EMPTY: Plot = Plot::new(0.0, 0.0, 0.0);
        Self {
            cfg: MhtConfig::sea_clutter(),
            msht: Geometry::placeholder(),
            dmht: Geometry::placeholder(),
            plots: [[EMPTY; PLOTS]; SCANS],
            counts: [0; SCANS],
            flags: [[0; PLOTS]; SCANS],
            censor: Censor::new(),
            acc: Accumulator::new(),
            peaks: [Peak {
                r: 0,
                a: 0,
                value16: 0,
                raw: 0,
                cells: 0,
            }; TRACKS],
            tracks: [Track::empty(); TRACKS],
            ntracks: 0,
            scan: usize::MAX,
            period: None,
        }
    }

    /// Change `gamma_1` (takes effect at the next period end).
    pub fn set_gamma1(&mut self, gamma1: u8) -> Result<()> {
        if gamma1 == 0 {
            return Err(Error::InvalidConfig("gamma1"));
        }
        self.cfg.gamma1 = gamma1;
        Ok(())
    }

    /// Single-frame (MSHT) geometry: origin at the area centre.
    pub fn msht_geometry(&self) -> &Geometry<RHO_CELLS, THETA_CELLS> {
        &self.msht
    }

    /// DMHT geometry of the last completed period.
    pub fn dmht_geometry(&self) -> &Geometry<RHO_CELLS, THETA_CELLS> {
        &self.dmht
    }

    /// DMHT accumulator of the last completed period.
    pub fn accumulator(&self) -> &Accumulator<RHO_CELLS, THETA_CELLS> {
        &self.acc
    }

    /// Kept plots of scan `s` of the current (or just completed) period.
    pub fn scan_plots(&self, s: usize) -> &[Plot] {
        kept(&self.plots, &self.counts, s)
    }

    /// True when plot `k` of scan `s` is in `S_ep`.
    pub fn is_effective(&self, s: usize, k: usize) -> bool {
        self.flags
            .get(s)
            .and_then(|f| f.get(k))
            .is_some_and(|f| f & FLAG_EFFECTIVE != 0)
    }

    /// Number of effective plots in scan `s`.
    pub fn effective_count(&self, s: usize) -> usize {
        let n = self.counts.get(s).map_or(0, |&n| usize::from(n));
        self.flags.get(s).map_or(0, |f| {
            f.iter()
                .take(n)
                .filter(|&&b| b & FLAG_EFFECTIVE != 0)
                .count()
        })
    }

    /// Confirmed tracks of the last completed period, strongest peak first.
    pub fn tracks(&self) -> &[Track<SCANS>] {
        self.tracks.get(..self.ntracks).unwrap_or(&[])
    }

    /// One scan of plots (the [`Detector::step`]). See the module doc for the handling of
    /// bad plots.
    fn step_scan(&mut self, scan_plots: &[Plot]) -> Result<MhtReport> {
        let s = self.scan;
        if s >= SCANS {
            return Err(Error::InvalidConfig("unconfigured"));
        }
        self.period = None;
        if s == 0 {
            self.counts = [0; SCANS];
            self.ntracks = 0;
        }
        let mut rep = MhtReport {
            scan_in_period: s as u16,
            plots_in: scan_plots.len() as u32,
            ..Default::default()
        };
        // copy valid plots into the period store
        let mut n = 0usize;
        for p in scan_plots {
            if !in_area(p, self.cfg.area) || !p.amplitude.is_finite() {
                rep.invalid += 1;
            } else if n < PLOTS {
                self.plots[s][n] = *p;
                n += 1;
            } else {
                rep.overflow += 1;
            }
        }
        self.counts[s] = n as u16;
        if let Some(f) = self.flags[s].get_mut(..n) {
            f.fill(0);
        }
        rep.plots_kept = n as u16;
        // stage 2: censoring of the window ending at s
        {
            let plots = &self.plots;
            let counts = &self.counts;
            let scans: [&[Plot]; SCANS] = core::array::from_fn(|i| kept(plots, counts, i));
            rep.censor = self.censor.step(
                &self.msht,
                &scans[..=s],
                &mut self.flags,
                s,
                self.cfg.m,
                self.cfg.gate,
            );
        }
        self.scan += 1;
        if self.scan == self.cfg.n_scans {
            self.scan = 0;
            rep.detection = Some(self.detect());
        }
        Ok(rep)
    }

    /// Re-run the `gamma_1`-dependent part of stage 3 (threshold, condensing, track
    /// recovery, confirmation, residual rule) on the period the last [`Detector::step`]
    /// completed, with `gamma1` in place of the configured `gamma_1`. Censoring and the
    /// binary integration do not depend on `gamma_1`, so the result (and
    /// [`MhtTbd::tracks`], which it replaces) is exactly what `step` would have given with
    /// `gamma_1 = gamma1`. The configured `gamma_1` is unchanged. Used to calibrate
    /// `gamma_1` by simulation without censoring a period once per candidate.
    ///
    /// Errors: `InvalidConfig("gamma1")` for 0, `InvalidConfig("no completed period")`
    /// when the last `step` did not complete a period.
    pub fn redetect(&mut self, gamma1: u8) -> Result<PeriodSummary> {
        if gamma1 == 0 {
            return Err(Error::InvalidConfig("gamma1"));
        }
        let det = self
            .period
            .ok_or(Error::InvalidConfig("no completed period"))?;
        Ok(self.extract(gamma1, det))
    }

    /// Stage 3 over the completed period.
    fn detect(&mut self) -> PeriodSummary {
        let det = self.integrate();
        self.period = Some(det);
        self.extract(self.cfg.gamma1, det)
    }

    /// Stage 3, the part independent of `gamma_1`: DMHT geometry, binary integration and
    /// smoothing of `S_ep`.
    fn integrate(&mut self) -> PeriodSummary {
        // n_scans <= NS (configure checks it)
        let ns = self.cfg.n_scans.min(SCANS);
        let mut det = PeriodSummary::default();
        // centroid and extent of S_ep (f64-free: two-pass in f32 about the area centre)
        let (ax, ay) = self.msht.origin();
        let (mut sx, mut sy, mut ne) = (0.0f32, 0.0f32, 0u32);
        for (plots, flags, n) in period(&self.plots, &self.flags, &self.counts, ns) {
            det.pre_plots += n as u32;
            for (p, _) in effective(plots, flags, n) {
                sx += p.x - ax;
                sy += p.y - ay;
                ne += 1;
            }
        }
        det.effective_plots = ne;
        self.acc.reset();
        if ne == 0 {
            self.dmht = Geometry::new(ax, ay, self.msht.rho_max());
            det.origin = self.dmht.origin();
            det.drho = self.dmht.drho();
            return det;
        }
        let x0 = ax + sx / ne as f32;
        let y0 = ay + sy / ne as f32;
        let mut r2 = 0.0f32;
        for (plots, flags, n) in period(&self.plots, &self.flags, &self.counts, ns) {
            for (p, _) in effective(plots, flags, n) {
                let d2 = (p.x - x0) * (p.x - x0) + (p.y - y0) * (p.y - y0);
                if d2 > r2 {
                    r2 = d2;
                }
            }
        }
        // 1 % margin so the farthest plot is not on the clamp edge
        let rho_max = (math::sqrt(r2) * 1.01).max(self.cfg.drho_min);
        self.dmht = Geometry::new(x0, y0, rho_max);
        det.origin = (x0, y0);
        det.drho = self.dmht.drho();
        // binary integration of S_ep (eq. 7)
        for (s, (plots, flags, n)) in period(&self.plots, &self.flags, &self.counts, ns).enumerate()
        {
            let tag = (s + 1) as u8;
            for (p, _) in effective(plots, flags, n) {
                self.acc.add_point(&self.dmht, tag, p.x, p.y);
            }
        }
        self.acc.finish(self.cfg.smooth);
        det
    }

    /// Stage 3, the part that depends on `gamma_1`: threshold, condensing, track recovery
    /// and confirmation (an empty accumulator gives no peaks).
    fn extract(&mut self, gamma1: u8, mut det: PeriodSummary) -> PeriodSummary {
        // n_scans <= NS (configure checks it)
        let ns = self.cfg.n_scans.min(SCANS);
        det.condense = self.acc.condense(gamma1, &mut self.peaks);
        // track recovery
        let assoc = dmht::Assoc {
            d_max: self.cfg.d_max,
            along_gate: self.cfg.along_gate,
            lookback: self.cfg.lookback,
        };
        let plots = &self.plots;
        let counts = &self.counts;
        let scans: [&[Plot]; SCANS] = core::array::from_fn(|i| kept(plots, counts, i));
        let mut nt = 0usize;
        for i in 0..usize::from(det.condense.peaks).min(TRACKS) {
            let pk = self.peaks[i];
            let mut tr = Track::<SCANS>::default();
            dmht::recover::<RHO_CELLS, THETA_CELLS, PLOTS, SCANS>(
                &self.dmht,
                pk,
                &scans[..ns],
                &self.flags,
                &assoc,
                &mut tr,
            );
            let need = self.cfg.confirm_frac * f32::from(gamma1);
            if tr.n_plots < self.cfg.min_track_plots || f32::from(tr.n_effective) < need {
                det.short += 1;
                continue;
            }
            let tracks = self.tracks.get(..nt).unwrap_or(&[]);
            let claimed = (tr.plots.iter().enumerate().take(ns))
                .filter(|&(s, &k)| {
                    k != NO_PLOT && tracks.iter().any(|o| o.plots.get(s) == Some(&k))
                })
                .count();
            let dup = 2 * claimed > usize::from(tr.n_plots);
            if dup {
                det.merged += 1;
                continue;
            }
            if self.cfg.residual && nt > 0 {
                let (r, a) = (usize::from(pk.r), usize::from(pk.a));
                let mut resid = 0u8;
                let scans = period(&self.plots, &self.flags, &self.counts, ns);
                for (s, ((plots, flags, n), &own)) in scans.zip(tr.plots.iter()).enumerate() {
                    let hit = effective(plots, flags, n).any(|(p, k)| {
                        if usize::from(own) == k
                            && tracks.iter().any(|o| o.plots.get(s) == Some(&own))
                        {
                            return false;
                        }
                        let (xq, yq) = self.dmht.quantise(p.x, p.y);
                        self.dmht.rho_index_q(xq, yq, a) == r
                    });
                    resid = resid.saturating_add(u8::from(hit));
                }
                if resid < gamma1 {
                    det.residual += 1;
                    continue;
                }
            }
            if let Some(t) = self.tracks.get_mut(nt) {
                *t = tr;
                nt += 1;
            }
        }
        self.ntracks = nt;
        det.tracks = nt as u16;
        det
    }
}

impl<
        const PLOTS: usize,
        const SCANS: usize,
        const RHO_CELLS: usize,
        const THETA_CELLS: usize,
        const TRACKS: usize,
    > Detector for MhtTbd<PLOTS, SCANS, RHO_CELLS, THETA_CELLS, TRACKS>
{
    type Frame = [Plot];
    type Config = MhtConfig;
    type Report = MhtReport;
    const STATE: &'static [&'static str] = &["x_m", "y_m", "vx_m_per_scan", "vy_m_per_scan"];
    const SCORE: ScoreKind = ScoreKind::Count;
    const UNCONFIGURED: Self = Self::new_unconfigured();

    /// Validates `cfg` against the capacities (`n_scans <= NS`, `0 < P <= 65535`,
    /// `T > 0`), builds the geometry and starts a new period, in place (no large copy,
    /// usable on a `static`). MHT-TBD draws no random numbers: `seed` is unused.
    fn configure(&mut self, cfg: &MhtConfig, _seed: u64) -> Result<()> {
        cfg.validate()?;
        if cfg.n_scans > SCANS {
            return Err(Error::InvalidConfig("n_scans"));
        }
        if PLOTS > usize::from(u16::MAX) || PLOTS == 0 || TRACKS == 0 {
            return Err(Error::InvalidConfig("capacity"));
        }
        self.cfg = *cfg;
        self.msht = Geometry::for_area(cfg.area);
        self.dmht = self.msht;
        self.counts = [0; SCANS];
        self.ntracks = 0;
        self.scan = 0;
        self.period = None;
        Ok(())
    }

    fn config(&self) -> &MhtConfig {
        &self.cfg
    }

    /// Starts a new period (an unconfigured detector stays unconfigured).
    fn reset(&mut self, _seed: u64) {
        if self.scan < SCANS {
            self.counts = [0; SCANS];
            self.ntracks = 0;
            self.scan = 0;
            self.period = None;
        }
    }

    fn step(&mut self, scan_plots: &[Plot]) -> Result<MhtReport> {
        self.step_scan(scan_plots)
    }

    /// The confirmed tracks when the last step completed a period, none otherwise.
    fn detection_count(&self) -> usize {
        if self.period.is_some() {
            self.ntracks
        } else {
            0
        }
    }

    /// Track `i`: its last associated plot `[x, y]` and the velocity from its first to
    /// its last plot, `(p_last - p_first) / (s_last - s_first)` (m per scan, 0 for a
    /// single-scan track); scored by the peak cell's binary-integration count; track id
    /// `i` (strongest first), length the associated plots.
    fn detection(&self, i: usize) -> Option<Detection> {
        if i >= self.detection_count() {
            return None;
        }
        let t = self.tracks.get(i)?;
        let n = self.cfg.n_scans.min(SCANS);
        let plot_of = |s: usize| {
            let k = *t.plots.get(s)?;
            if k == NO_PLOT {
                return None;
            }
            self.scan_plots(s).get(usize::from(k)).map(|p| (s, *p))
        };
        let first = (0..n).find_map(plot_of)?;
        let last = (0..n).rev().find_map(plot_of)?;
        let ds = (last.0 - first.0) as f32;
        let (vx, vy) = if ds > 0.0 {
            ((last.1.x - first.1.x) / ds, (last.1.y - first.1.y) / ds)
        } else {
            (0.0, 0.0)
        };
        Some(Detection::new(
            &[last.1.x, last.1.y, vx, vy],
            f32::from(t.peak.raw),
            Some(TrackInfo {
                id: i as u32,
                len: u32::from(t.n_plots),
            }),
        ))
    }
}
