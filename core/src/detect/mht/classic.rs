//! Baseline: the classic two-stage Carlson Hough TBD (Carlson, Evans, Wilson 1994; as
//! described by Bao et al. 2022, §2): standard Hough transform of every pre-detected plot (origin at the area
//! centre), binary integration over `N` scans, fixed threshold, condensing into peaks.
//! Same grid and accumulator as MHT-TBD, no censoring, no smoothing.

use super::dmht::{Accumulator, CondenseStats, Peak};
use super::geometry::Geometry;
use super::{in_area, validate_area};
use crate::detect::interface::unconfigured_is_zero;
use crate::detect::{Detection, Detector, ScoreKind, Validate};
use crate::model::plot::Plot;
use crate::{Error, Result};

/// Configuration of the classic detector.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct ClassicHoughConfig {
    /// Surveillance area `[x_min, x_max, y_min, y_max]` (m), `|coordinates| <= 1e18`.
    pub area: [f32; 4],
    /// Scans per integration period `N` (blocked periods).
    pub n_scans: usize,
    /// Threshold on the binary-integration count.
    pub gamma: u8,
}

impl Validate for ClassicHoughConfig {
    fn validate(&self) -> Result<()> {
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
#[cfg_attr(feature = "serde", derive(serde::Serialize))]
pub struct ClassicHoughReport {
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

/// The host's classic detector (`faint reproduce mht`, the soak run): a 256 x 180 grid,
/// 64 peaks.
pub type ClassicHoughHost = ClassicHough<256, 180, 64>;
/// The golden case's classic detector: a 32 x 30 grid, 4 peaks.
pub type ClassicHoughSmall = ClassicHough<32, 30, 4>;

/// Streaming classic Hough TBD on a `RHO_CELLS x THETA_CELLS` grid with up to `PEAKS`
/// peaks per period.
#[derive(Debug, Clone)]
pub struct ClassicHough<const RHO_CELLS: usize, const THETA_CELLS: usize, const PEAKS: usize> {
    cfg: ClassicHoughConfig,
    geom: Geometry<RHO_CELLS, THETA_CELLS>,
    acc: Accumulator<RHO_CELLS, THETA_CELLS>,
    scan: usize,
    peaks: [Peak; PEAKS],
    npeaks: usize,
    /// The last step completed a period.
    done: bool,
}

impl<const RHO_CELLS: usize, const THETA_CELLS: usize, const PEAKS: usize>
    ClassicHough<RHO_CELLS, THETA_CELLS, PEAKS>
{
    /// The unconfigured detector (a compile-time constant, [`Detector::UNCONFIGURED`]):
    /// every call but [`Detector::configure`] returns a typed error or nothing until a
    /// configuration succeeds. For a `static` or a `Box`.
    pub const fn new_unconfigured() -> Self {
        <Self as Detector>::UNCONFIGURED
    }

    /// A detector for a validated configuration.
    pub fn new(cfg: ClassicHoughConfig) -> Result<Self> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            geom: Geometry::for_area(cfg.area),
            acc: Accumulator::new(),
            scan: 0,
            peaks: [Peak::default(); PEAKS],
            npeaks: 0,
            done: false,
        })
    }

    /// Geometry (origin, rho cells).
    pub fn geometry(&self) -> &Geometry<RHO_CELLS, THETA_CELLS> {
        &self.geom
    }

    /// Accumulator (counts of the current/last period).
    pub fn accumulator(&self) -> &Accumulator<RHO_CELLS, THETA_CELLS> {
        &self.acc
    }

    /// Peaks of the last completed period, strongest first.
    pub fn peaks(&self) -> &[Peak] {
        self.peaks.get(..self.npeaks).unwrap_or(&[])
    }

    /// One scan (the [`Detector::step`]). Invalid plots (non-finite, outside the area)
    /// are skipped and counted.
    fn step_scan(&mut self, plots: &[Plot]) -> Result<ClassicHoughReport> {
        self.done = false;
        if self.scan == 0 {
            self.acc.reset();
            self.npeaks = 0;
        }
        let mut rep = ClassicHoughReport {
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
            self.done = true;
        }
        Ok(rep)
    }
}

impl<const RHO_CELLS: usize, const THETA_CELLS: usize, const PEAKS: usize> Detector
    for ClassicHough<RHO_CELLS, THETA_CELLS, PEAKS>
{
    type Frame = [Plot];
    type Config = ClassicHoughConfig;
    type Report = ClassicHoughReport;
    const STATE: &'static [&'static str] = &["rho_m", "theta_rad"];
    const SCORE: ScoreKind = ScoreKind::Count;
    unconfigured_is_zero!();

    /// Validates `cfg`, builds the geometry and starts a new period. The classic Hough
    /// TBD draws no random numbers: `seed` is unused.
    fn configure(&mut self, cfg: &ClassicHoughConfig, _seed: u64) -> Result<()> {
        cfg.validate()?;
        self.cfg = *cfg;
        self.geom = Geometry::for_area(cfg.area);
        self.reset(0);
        Ok(())
    }

    fn config(&self) -> &ClassicHoughConfig {
        &self.cfg
    }

    /// Starts a new period.
    fn reset(&mut self, _seed: u64) {
        self.scan = 0;
        self.npeaks = 0;
        self.done = false;
    }

    fn step(&mut self, plots: &[Plot]) -> Result<ClassicHoughReport> {
        self.step_scan(plots)
    }

    /// The peaks when the last step completed a period, none otherwise.
    fn detection_count(&self) -> usize {
        if self.done {
            self.npeaks
        } else {
            0
        }
    }

    /// Peak `i` (strongest first) as the line `x cos(theta) + y sin(theta) = rho` about
    /// the area centre (its cell's centre values), scored by its binary-integration count.
    fn detection(&self, i: usize) -> Option<Detection> {
        if i >= self.detection_count() {
            return None;
        }
        let p = self.peaks.get(i)?;
        let (r, a) = (usize::from(p.r), usize::from(p.a));
        if r >= RHO_CELLS || a >= THETA_CELLS {
            return None;
        }
        Some(Detection::new(
            &[self.geom.rho_center(r), self.geom.theta(a)],
            f32::from(p.raw),
            None,
        ))
    }
}
