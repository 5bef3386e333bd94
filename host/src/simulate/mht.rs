//! Scenario preset `sea-clutter` (Bao et al. 2022, §5.1): plot lists out of a low-threshold
//! pre-detector over a 6 km x 6 km sea area, Poisson clutter plots of mean `lambda` per scan
//! uniform over the area, 5 constant-velocity targets with random start, heading and
//! speed `U(0, V_max)`, detection probability `Pd0`, 5 m rms position noise.
//!
//! Documented choices: a target's start is drawn uniformly and redrawn (with its velocity)
//! until the whole noise-free track stays at least 20 m inside the area, so every target
//! is observable for all `N` scans; target plots falling outside the area after noise are
//! clamped to the boundary; the plots of a scan are shuffled so their order carries no
//! information.

use faint_core::model::plot::Plot;
use faint_core::rng::Rng;
use faint_core::simulate;

/// Who made a plot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Origin {
    /// A clutter (false) plot.
    Clutter,
    /// Target `i`.
    Target(usize),
}

/// The preset's parameters.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct SeaClutter {
    /// `[x_min, x_max, y_min, y_max]` (m).
    pub area: [f32; 4],
    /// Resolution cell side (m): `A = 200 x 200 = 4e4` cells.
    pub resolution: f32,
    /// Scan period (s).
    pub t_scan: f32,
    /// Scans per integration period `N`.
    pub n_scans: usize,
    /// Largest target speed (m/s).
    pub v_max: f32,
    /// Targets per trial.
    pub n_targets: usize,
    /// Target plot detection probability `Pd0`.
    pub pd0: f32,
    /// Plot position noise (m rms per axis).
    pub sigma: f32,
    /// Mean clutter plots per scan.
    pub lambda: f32,
}

impl SeaClutter {
    /// The paper's values at clutter density `lambda`.
    pub fn paper(lambda: f32) -> Self {
        Self {
            area: [0.0, 6000.0, 0.0, 6000.0],
            resolution: 30.0,
            t_scan: 5.0,
            n_scans: 30,
            v_max: 20.0,
            n_targets: 5,
            pd0: 0.85,
            sigma: 5.0,
            lambda,
        }
    }

    /// Resolution cells in the area (`A` of the model).
    pub fn cells(&self) -> f64 {
        f64::from((self.area[1] - self.area[0]) / self.resolution)
            * f64::from((self.area[3] - self.area[2]) / self.resolution)
    }

    /// Draw one trial.
    pub fn generate(&self, rng: &mut Rng) -> Trial {
        let margin = 20.0f32;
        let dur = self.t_scan * (self.n_scans.saturating_sub(1)) as f32;
        let mut targets = Vec::with_capacity(self.n_targets);
        for _ in 0..self.n_targets {
            loop {
                let x0 = rng.uniform_range(self.area[0] + margin, self.area[1] - margin);
                let y0 = rng.uniform_range(self.area[2] + margin, self.area[3] - margin);
                let v = self.v_max * rng.uniform();
                let h = 2.0 * core::f32::consts::PI * rng.uniform();
                let vx = v * faint_core::math::cos(h);
                let vy = v * faint_core::math::sin(h);
                let (x1, y1) = (x0 + vx * dur, y0 + vy * dur);
                if x1 >= self.area[0] + margin
                    && x1 <= self.area[1] - margin
                    && y1 >= self.area[2] + margin
                    && y1 <= self.area[3] - margin
                {
                    targets.push(TargetTruth { x0, y0, vx, vy });
                    break;
                }
            }
        }
        let mut scans = Vec::with_capacity(self.n_scans);
        for s in 0..self.n_scans {
            let nc = poisson(rng, self.lambda);
            let mut items: Vec<(Plot, Origin)> = Vec::with_capacity(nc + self.n_targets);
            let mut clutter = vec![Plot::new(0.0, 0.0, 0.0); nc];
            simulate::clutter_plots(rng, self.area, &mut clutter, |r| 1.0 + r.exponential());
            items.extend(clutter.into_iter().map(|p| (p, Origin::Clutter)));
            for (i, t) in targets.iter().enumerate() {
                let (x, y) = t.position(s as f32 * self.t_scan);
                if let Some((x, y)) = simulate::detection(rng, self.pd0, x, y, self.sigma) {
                    let x = x.clamp(self.area[0], self.area[1]);
                    let y = y.clamp(self.area[2], self.area[3]);
                    let a = 1.0 + 8.0 * rng.exponential();
                    items.push((Plot::new(a, x, y), Origin::Target(i)));
                }
            }
            // Fisher-Yates shuffle
            for i in (1..items.len()).rev() {
                let j = rng.below(i as u32 + 1) as usize;
                items.swap(i, j);
            }
            scans.push(ScanData {
                plots: items.iter().map(|x| x.0).collect(),
                origin: items.iter().map(|x| x.1).collect(),
            });
        }
        Trial { targets, scans }
    }
}

/// Poisson(`mean`) by counting unit-rate exponential arrivals in `[0, mean)`.
pub fn poisson(rng: &mut Rng, mean: f32) -> usize {
    if mean.is_nan() || mean <= 0.0 {
        return 0;
    }
    let mut t = 0.0f64;
    let mut k = 0usize;
    loop {
        t += f64::from(rng.exponential());
        if t >= f64::from(mean) {
            return k;
        }
        k += 1;
    }
}

/// A target's constant-velocity motion.
#[derive(Debug, Clone, Copy)]
pub struct TargetTruth {
    /// Start x (m).
    pub x0: f32,
    /// Start y (m).
    pub y0: f32,
    /// Velocity x (m/s).
    pub vx: f32,
    /// Velocity y (m/s).
    pub vy: f32,
}

impl TargetTruth {
    /// Position at time `t` (s).
    pub fn position(&self, t: f32) -> (f32, f32) {
        (self.x0 + self.vx * t, self.y0 + self.vy * t)
    }
}

/// One scan: plots and who made each.
#[derive(Debug, Clone)]
pub struct ScanData {
    /// Pre-detection plots.
    pub plots: Vec<Plot>,
    /// `origin[k]` made `plots[k]`.
    pub origin: Vec<Origin>,
}

/// One trial: truth and `N` scans.
#[derive(Debug, Clone)]
pub struct Trial {
    /// Target motions.
    pub targets: Vec<TargetTruth>,
    /// The scans.
    pub scans: Vec<ScanData>,
}
