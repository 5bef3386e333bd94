//! Intensity images from the physics: a point target blurred by the optics and sampled by
//! pixels, in Gaussian noise.
//!
//! Image `H x W`, row-major; pixel `(x, y)` = (column, row) covers `[x, x+1) x [y, y+1)`
//! with its centre at `(x + 0.5, y + 0.5)`. A target at the continuous position
//! `(px, py)` of amplitude `a_k` adds
//!
//! ```text
//! a_k [Phi((x + 1 - px) / s) - Phi((x - px) / s)] [Phi((y + 1 - py) / s) - Phi((y - py) / s)]
//! ```
//!
//! to pixel `(x, y)`: a Gaussian point-spread of std `s` (px) integrated over the pixel
//! (`Phi` the standard normal CDF), so the spot sums to `a_k` away from the edges. Each
//! pixel adds `N(0, sigma^2)` noise and a constant `background`. `SNR = a / sigma`
//! (amplitude ratio, the definition of the dim-point preset, Wang and Zhang 2016, eq. 29;
//! in dB `20 log10(a / sigma)`): the whole spot's amplitude over the pixel noise.
//!
//! Motion: start uniform in `[0, W) x [0, H)`, heading uniform in `[0, 2 pi)`, constant
//! speed `speed` px/frame, redrawn until the last frame's position is inside too. Truth
//! columns `x_px,y_px`: the continuous position. Amplitude: Swerling 0/1/3 per frame.

use anyhow::{ensure, Result};
use faint_core::rng::Rng;

use super::Swerling;

/// The image simulator's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImagePhysics {
    /// Image width `W` (px, columns).
    pub width: usize,
    /// Image height `H` (px, rows).
    pub height: usize,
    /// Point-spread std `s` (px).
    pub psf_sigma: f64,
    /// Noise std per pixel.
    pub sigma: f64,
    /// Constant background added to every pixel.
    pub background: f64,
    /// Target speed (px/frame).
    pub speed: f64,
    /// Amplitude fluctuation.
    pub swerling: Swerling,
}

/// The standard normal CDF, from `erfc` (f64).
fn phi(x: f64) -> f64 {
    0.5 * statrs::function::erf::erfc(-x / std::f64::consts::SQRT_2)
}

impl ImagePhysics {
    /// 128 x 128, PSF std 0.5 px, noise std 1.5 (the DP default configuration's sigma),
    /// no background, 1 px/frame, Swerling 0.
    pub fn new(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            psf_sigma: 0.5,
            sigma: 1.5,
            background: 0.0,
            speed: 1.0,
            swerling: Swerling::Zero,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        ensure!(
            (1..=4096).contains(&self.width) && (1..=4096).contains(&self.height),
            "image {} x {}: each side must be in 1..=4096",
            self.width,
            self.height
        );
        for (n, v) in [
            ("psf_sigma", self.psf_sigma),
            ("sigma", self.sigma),
            ("speed", self.speed),
        ] {
            ensure!(
                v.is_finite() && v >= 0.0,
                "{n} {v}: must be finite and >= 0"
            );
        }
        ensure!(self.psf_sigma > 0.0, "psf_sigma: must be > 0");
        ensure!(self.background.is_finite(), "background: must be finite");
        Ok(())
    }

    /// The spot's share in the pixel interval `[i, i + 1)` of an axis, target at `p`.
    pub fn share(&self, i: usize, p: f64) -> f64 {
        let s = self.psf_sigma;
        phi((i as f64 + 1.0 - p) / s) - phi((i as f64 - p) / s)
    }

    /// Simulates `frames` images (frame-major, `frames * H * W` values); `amplitude =
    /// None` is noise only. Returns the pixels and the target's `[x, y]` per frame.
    pub fn simulate(
        &self,
        frames: usize,
        amplitude: Option<f64>,
        rng: &mut Rng,
    ) -> (Vec<f32>, Vec<[f64; 2]>) {
        let (w, h) = (self.width, self.height);
        let (wf, hf) = (w as f64, h as f64);
        let u = |rng: &mut Rng| f64::from(rng.uniform());
        let span = (frames.max(1) - 1) as f64;
        let target = amplitude.map(|a| {
            let mut st = (0.0, 0.0, 0.0, 0.0);
            for _ in 0..10_000 {
                let (x, y) = (wf * u(rng), hf * u(rng));
                let hd = 2.0 * std::f64::consts::PI * u(rng);
                let (vx, vy) = (self.speed * hd.cos(), self.speed * hd.sin());
                st = (x, y, vx, vy);
                let (ex, ey) = (x + vx * span, y + vy * span);
                if ex >= 0.0 && ex < wf && ey >= 0.0 && ey < hf {
                    break;
                }
            }
            (st, a)
        });
        let mut out = Vec::with_capacity(frames * w * h);
        let mut truth = Vec::new();
        // Spot support: 6 std each side covers all but 2e-9 of it.
        let reach = (6.0 * self.psf_sigma).ceil() as isize + 1;
        for k in 0..frames {
            let start = out.len();
            for _ in 0..w * h {
                out.push((self.background + self.sigma * f64::from(rng.normal())) as f32);
            }
            if let Some(((x, y, vx, vy), a)) = target {
                let (px, py) = (x + vx * k as f64, y + vy * k as f64);
                truth.push([px, py]);
                let ak = a * self.swerling.draw(rng);
                let (cx, cy) = (px.floor() as isize, py.floor() as isize);
                for row in (cy - reach).max(0)..(cy + reach + 1).min(h as isize) {
                    let sy = self.share(row as usize, py);
                    for col in (cx - reach).max(0)..(cx + reach + 1).min(w as isize) {
                        let v = ak * sy * self.share(col as usize, px);
                        let i = start + row as usize * w + col as usize;
                        out[i] = (f64::from(out[i]) + v) as f32;
                    }
                }
            }
        }
        (out, truth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The PSF integrated over the pixels sums to the amplitude (noise off): the shares
    /// of one axis telescope to `Phi((W - p)/s) - Phi(-p/s)`, which is 1 to 1e-12 for a
    /// target 8 std from the edges; f32 pixels sum to 1e-5 of it.
    #[test]
    fn psf_total_energy_is_the_amplitude() {
        let p = ImagePhysics {
            sigma: 0.0,
            psf_sigma: 0.7,
            ..ImagePhysics::new(64, 48)
        };
        let mut rng = Rng::seed_from_u64(2);
        for _ in 0..50 {
            let (img, t) = p.simulate(1, Some(3.0), &mut rng);
            let total: f64 = img.iter().map(|&v| f64::from(v)).sum();
            let [x, y] = t[0];
            if x > 6.0 && x < 58.0 && y > 6.0 && y < 42.0 {
                assert!((total - 3.0).abs() < 3e-5, "total {total} at ({x}, {y})");
            }
            // Pixel-centred target: the central pixel gets (2 Phi(0.5/s) - 1)^2 of it.
            let c = (2.0 * phi(0.5 / 0.7) - 1.0).powi(2);
            assert!((0.0..=c * 3.0 + 1e-6)
                .contains(&f64::from(img.iter().copied().fold(0.0f32, f32::max))));
        }
    }

    /// Noise only: pixel mean is the background, std sigma (131 072 pixels; the mean's
    /// std is 1.5/362 = 0.004, tolerance 0.02; the std's relative std 0.2 %, tolerance 1 %).
    #[test]
    fn noise_pixels_have_the_stated_mean_and_std() {
        let p = ImagePhysics {
            background: 4.0,
            ..ImagePhysics::new(128, 128)
        };
        let mut rng = Rng::seed_from_u64(8);
        let (img, _) = p.simulate(8, None, &mut rng);
        let n = img.len() as f64;
        let mean = img.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let sd = (img
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / n)
            .sqrt();
        assert!((mean - 4.0).abs() < 0.02, "{mean}");
        assert!((sd / 1.5 - 1.0).abs() < 0.01, "{sd}");
    }
}
