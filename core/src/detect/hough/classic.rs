//! Baseline: the classic two-stage Carlson Hough TBD (Carlson, Evans, Wilson 1994;
//! paper 003 §2): standard Hough transform of every pre-detected plot (origin at the area
//! centre), binary integration over `N` scans, fixed threshold, condensing into peaks.
//! Same grid and accumulator as MHT-TBD, no censoring, no smoothing.

use super::dmht::{Accumulator, CondenseStats, Peak};
use super::geometry::Geometry;
use super::{in_area, validate_area};
use crate::model::plot::Plot;
use crate::{Error, Result};

/// Configuration of the classic detector.
#[derive(Debug, Clone, Copy)]
pub struct ClassicConfig {
    /// Surveillance area `[x_min, x_max, y_min, y_max]` (m).
    pub area: [f32; 4],
    /// Scans per integration period `N` (blocked periods).
    pub n_scans: usize,
    /// Threshold on the binary-integration count.
    pub gamma: u8,
}

impl ClassicConfig {
    /// Check the values.
    pub fn validate(&self) -> Result<()> {
        validate_area(self.area)?;
        if self.n_scans == 0 || self.n_scans > 255 {
            return Err(Error::InvalidConfig("n_scans"));
        }
        if self.gamma == 0 {
            return Err(Error::InvalidConfig("gamma"));
        }
        Ok(())
    }
}

/// One step's report.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClassicReport {
    /// Index of the scan within its period.
    pub scan_in_period: u16,
    /// Plots used from this scan.
    pub plots_used: u16,
    /// Plots ignored: non-finite or outside the area.
    pub invalid: u16,
    /// True when this scan completed a period; `peaks` holds its detections.
    pub period_complete: bool,
    /// Condensing counters of the completed period.
    pub condense: CondenseStats,
}

/// Streaming classic Hough TBD with up to `T` peaks per period.
#[derive(Debug, Clone)]
pub struct ClassicHough<const R: usize, const A: usize, const T: usize> {
    cfg: ClassicConfig,
    geom: Geometry<R, A>,
    acc: Accumulator<R, A>,
    scan: usize,
    peaks: [Peak; T],
    npeaks: usize,
}

impl<const R: usize, const A: usize, const T: usize> ClassicHough<R, A, T> {
    /// A detector for a validated configuration.
    pub fn new(cfg: ClassicConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            geom: Geometry::for_area(cfg.area),
            acc: Accumulator::new(),
            scan: 0,
            peaks: [Peak::default(); T],
            npeaks: 0,
        })
    }

    /// Geometry (origin, rho cells).
    pub fn geometry(&self) -> &Geometry<R, A> {
        &self.geom
    }

    /// Accumulator (counts of the current/last period).
    pub fn accumulator(&self) -> &Accumulator<R, A> {
        &self.acc
    }

    /// Peaks of the last completed period, strongest first.
    pub fn peaks(&self) -> &[Peak] {
        &self.peaks[..self.npeaks]
    }

    /// Feed one scan. Invalid plots (non-finite, outside the area) are skipped and counted.
    pub fn step(&mut self, plots: &[Plot]) -> Result<ClassicReport> {
        if self.scan == 0 {
            self.acc.reset();
            self.npeaks = 0;
        }
        let mut rep = ClassicReport {
            scan_in_period: self.scan as u16,
            ..Default::default()
        };
        let tag = (self.scan + 1) as u8;
        for p in plots {
            if !in_area(p, self.cfg.area) {
                rep.invalid = rep.invalid.saturating_add(1);
                continue;
            }
            self.acc.add_point(&self.geom, tag, p.x, p.y);
            rep.plots_used = rep.plots_used.saturating_add(1);
        }
        self.scan += 1;
        if self.scan == self.cfg.n_scans {
            self.scan = 0;
            self.acc.finish(false);
            rep.condense = self.acc.condense(self.cfg.gamma, &mut self.peaks);
            self.npeaks = usize::from(rep.condense.peaks);
            rep.period_complete = true;
        }
        Ok(rep)
    }
}
