//! Plot lists from the physics: the output of a cell-by-cell square-law detector over an
//! area, scan after scan.
//!
//! The area `[x_min, x_max] x [y_min, y_max]` (m) is cut into square resolution cells of
//! side `cell` (m); `n = cells` of them. Each cell's noise power (in units of the noise
//! power) is exponential with mean 1; a cell makes a plot when it exceeds
//! `T = -ln(p_fa)`, so the clutter plots of a scan are Binomial(n, p_fa), i.e. Poisson
//! with mean `lambda = n p_fa` (the stated density per scan), uniform over the area.
//! A clutter plot's power is `T + E`, `E ~ Exp(1)` (the exponential law above `T`).
//!
//! The target (Swerling 1, mean SNR `snr` per cell) is a point moving on a straight line
//! at constant velocity. Its cell exceeds `T` with probability `Pd = p_fa^(1 / (1 + snr))`
//! (the closed form of a Swerling-1 square-law detector); its power is then
//! `T + E (1 + snr)`. Its plot is the true position plus Gaussian noise of std
//! `sigma` (m) per axis, clamped to the area. The amplitude column is `sqrt(power)`
//! (noise-std units): a target's plots are brighter on average than clutter's.
//!
//! Conventions: columns `scan,amplitude,x,y`, scans from 0, x and y in metres; the
//! truth columns are `x_m,y_m` (the noise-free position at the scan). Motion: start
//! uniform in the area, heading uniform in `[0, 2 pi)`, speed uniform in
//! `[0, v_max]` (m/s), redrawn until the whole noise-free track of the run stays inside
//! the area (every scan observable); scan period `t_scan` (s). Plots of a scan are in
//! random order.

use anyhow::{ensure, Result};
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;

/// The plot simulator's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlotPhysics {
    /// `[x_min, x_max, y_min, y_max]` (m).
    pub area: [f32; 4],
    /// Resolution cell side (m).
    pub cell: f64,
    /// Mean clutter plots per scan `lambda`.
    pub lambda: f64,
    /// Position noise (m, std per axis).
    pub sigma: f64,
    /// Largest target speed (m/s).
    pub v_max: f64,
    /// Scan period (s).
    pub t_scan: f64,
}

/// A Poisson draw of mean `mu` (inversion for small means, a sum of Poissons of mean
/// at most 30 otherwise: exact in law).
pub fn poisson(mu: f64, rng: &mut Rng) -> usize {
    let mut left = mu;
    let mut total = 0usize;
    while left > 0.0 {
        let m = left.min(30.0);
        left -= m;
        let u = f64::from(rng.uniform());
        let mut p = (-m).exp();
        let mut cdf = p;
        let mut k = 0usize;
        while u > cdf && k < 1000 {
            k += 1;
            p *= m / k as f64;
            cdf += p;
        }
        total += k;
    }
    total
}

impl PlotPhysics {
    /// The sea-clutter geometry (6 km square, 30 m cells, 80 clutter plots per scan,
    /// 5 m position noise, speeds up to 20 m/s, 5 s scans) over `area`.
    pub fn new(area: [f32; 4]) -> Self {
        Self {
            area,
            cell: 30.0,
            lambda: 80.0,
            sigma: 5.0,
            v_max: 20.0,
            t_scan: 5.0,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        let [x0, x1, y0, y1] = self.area.map(f64::from);
        ensure!(
            [x0, x1, y0, y1].iter().all(|v| v.is_finite()) && x1 > x0 && y1 > y0,
            "area {:?}: must be finite with x_max > x_min and y_max > y_min",
            self.area
        );
        ensure!(
            self.cell.is_finite() && self.cell > 0.0,
            "cell {}: must be > 0",
            self.cell
        );
        ensure!(
            self.lambda.is_finite() && self.lambda >= 0.0 && self.lambda < self.cells(),
            "lambda {}: must be in [0, cells = {})",
            self.lambda,
            self.cells()
        );
        for (n, v) in [
            ("sigma", self.sigma),
            ("v_max", self.v_max),
            ("t_scan", self.t_scan),
        ] {
            ensure!(
                v.is_finite() && v >= 0.0,
                "{n} {v}: must be finite and >= 0"
            );
        }
        Ok(())
    }

    /// Resolution cells over the area.
    pub fn cells(&self) -> f64 {
        let [x0, x1, y0, y1] = self.area.map(f64::from);
        ((x1 - x0) / self.cell).floor().max(1.0) * ((y1 - y0) / self.cell).floor().max(1.0)
    }

    /// False-alarm probability per cell `p_fa = lambda / cells`.
    pub fn cell_pfa(&self) -> f64 {
        self.lambda / self.cells()
    }

    /// Per-scan detection probability of a target of mean SNR `snr` (linear).
    pub fn pd(&self, snr: f64) -> f64 {
        self.cell_pfa().powf(1.0 / (1.0 + snr))
    }

    /// Simulates `scans` scans; `snr = None` is clutter only. Returns the scans and the
    /// target's noise-free `[x, y]` per scan.
    pub fn simulate(
        &self,
        scans: usize,
        snr: Option<f64>,
        rng: &mut Rng,
    ) -> (Vec<Vec<Plot>>, Vec<[f64; 2]>) {
        let [x0, x1, y0, y1] = self.area.map(f64::from);
        let t = -self.cell_pfa().max(f64::MIN_POSITIVE).ln();
        let u = |rng: &mut Rng, a: f64, b: f64| a + (b - a) * f64::from(rng.uniform());
        let inside = |x: f64, y: f64| x >= x0 && x <= x1 && y >= y0 && y <= y1;
        let target = snr.map(|snr| {
            let span = (scans.max(1) - 1) as f64 * self.t_scan;
            let mut draw = || {
                let (x, y) = (u(rng, x0, x1), u(rng, y0, y1));
                let h = u(rng, 0.0, 2.0 * std::f64::consts::PI);
                let s = u(rng, 0.0, self.v_max);
                (x, y, s * h.cos(), s * h.sin())
            };
            let mut st = draw();
            for _ in 0..10_000 {
                if inside(st.0 + st.2 * span, st.1 + st.3 * span) {
                    break;
                }
                st = draw();
            }
            (st, snr)
        });
        let mut out = Vec::with_capacity(scans);
        let mut truth = Vec::new();
        for k in 0..scans {
            let mut plots = Vec::new();
            let n = poisson(self.lambda, rng);
            for _ in 0..n {
                let (x, y) = (u(rng, x0, x1), u(rng, y0, y1));
                let p = t + f64::from(rng.exponential());
                plots.push(Plot::new(p.sqrt() as f32, x as f32, y as f32));
            }
            if let Some(((x, y, vx, vy), snr)) = target {
                let tk = k as f64 * self.t_scan;
                let (px, py) = (x + vx * tk, y + vy * tk);
                truth.push([px, py]);
                if f64::from(rng.uniform()) < self.pd(snr) {
                    let p = t + f64::from(rng.exponential()) * (1.0 + snr);
                    let nx = (px + self.sigma * f64::from(rng.normal())).clamp(x0, x1);
                    let ny = (py + self.sigma * f64::from(rng.normal())).clamp(y0, y1);
                    plots.push(Plot::new(p.sqrt() as f32, nx as f32, ny as f32));
                }
            }
            // Random order: a Fisher-Yates shuffle.
            for i in (1..plots.len()).rev() {
                let j = rng.below(i as u32 + 1) as usize;
                plots.swap(i, j);
            }
            out.push(plots);
        }
        (out, truth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Clutter plots per scan are Poisson(lambda): mean and variance both lambda. 20 000
    /// scans at lambda = 80: the sample mean has std sqrt(80 / 20 000) = 0.063 (0.3
    /// tolerance, about 5 std); the sample variance has std about
    /// lambda sqrt(2 / n) = 0.8 (4 tolerance, 5 std).
    #[test]
    fn clutter_count_is_poisson() {
        let p = PlotPhysics::new([0.0, 6000.0, 0.0, 6000.0]);
        let mut rng = Rng::seed_from_u64(21);
        let (scans, _) = p.simulate(20_000, None, &mut rng);
        let c: Vec<f64> = scans.iter().map(|s| s.len() as f64).collect();
        let n = c.len() as f64;
        let mean = c.iter().sum::<f64>() / n;
        let var = c.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0);
        assert!((mean - 80.0).abs() < 0.3, "mean {mean}");
        assert!((var - 80.0).abs() < 4.0, "variance {var}");
        // Uniform over the area: a quarter of the plots in the lower-left quadrant
        // (1.6 M plots, std 3.4e-4; 2e-3 tolerance).
        let all: Vec<&Plot> = scans.iter().flatten().collect();
        let q = all.iter().filter(|p| p.x < 3000.0 && p.y < 3000.0).count() as f64;
        assert!((q / all.len() as f64 - 0.25).abs() < 2e-3);
    }

    /// The target's detection rate is `p_fa^(1/(1+snr))` and its track stays inside:
    /// 2000 runs of 10 scans at snr = 10 (Pd = 0.462 at lambda = 80; 20 000 scans, std
    /// 0.0035, 0.02 tolerance). A target plot is one within 25 m (5 sigma) of the truth;
    /// the clutter expected there (0.0044 per scan) is subtracted.
    #[test]
    fn target_detection_rate_matches_swerling_1() {
        let p = PlotPhysics::new([0.0, 6000.0, 0.0, 6000.0]);
        let mut rng = Rng::seed_from_u64(4);
        let snr = 10.0;
        let mut hits = 0usize;
        let runs = 2000;
        for _ in 0..runs {
            let (scans, truth) = p.simulate(10, Some(snr), &mut rng);
            for (s, t) in scans.iter().zip(&truth) {
                assert!(t[0] >= 0.0 && t[0] <= 6000.0 && t[1] >= 0.0 && t[1] <= 6000.0);
                hits += s
                    .iter()
                    .filter(|q| (f64::from(q.x) - t[0]).hypot(f64::from(q.y) - t[1]) < 25.0)
                    .count();
            }
        }
        let clutter = 80.0 * std::f64::consts::PI * 625.0 / 36e6;
        let rate = hits as f64 / (runs * 10) as f64 - clutter;
        assert!((rate - p.pd(snr)).abs() < 0.02, "{rate} vs {}", p.pd(snr));
    }
}
