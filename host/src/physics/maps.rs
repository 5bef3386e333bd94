//! Range x velocity power maps from the physics: a point target's echo over `Nv` pulses
//! of slow time per range cell, windowed and transformed across the pulses, in complex
//! white Gaussian noise. Optionally ([`Rotor`]) the target also carries `B` rotor blade
//! tips (eq. 11 of the rotor-UAV paper, below); without it the map holds the body line
//! only.
//!
//! Map `(Nr, Nv)` per frame, row-major (range rows, velocity columns); pixel `(i, j)`
//! centred at `r_i = range_start + (i + 0.5) range_bin`,
//! `v_j = velocity_start + (j + 0.5) velocity_bin` (the configuration's `geometry`).
//! The map spans one velocity ambiguity `Va = Nv velocity_bin` (`Va = lambda / (2 Tr)`,
//! `Tr` the pulse interval), and the slow-time samples of range cell `i` are
//!
//! ```text
//! y_in = a_k S((r_i - r_k) / dR) exp(j (phi_k - 2 pi v_k n / Va)) + w_in,   n = 0..Nv-1
//! Y_ij = sum_n w(n) y_in exp(+j 2 pi v_j n / Va),   z_ij = |Y_ij|^2
//! ```
//!
//! `S(u) = sin(pi u) / (pi u)` is the compressed pulse in range (resolution `dR`,
//! `range_resolution`, by default one range bin), cut 8 cells from the target's row;
//! `-2 pi v n / Va = 2 pi fd n Tr` with the Doppler `fd = -2 v / lambda` (a receding
//! target, `v > 0`, has a negative Doppler); `Y_ij` is the DFT (kernel `exp(-j 2 pi f n
//! Tr)`) evaluated at the Doppler `f_j = -2 v_j / lambda` of pixel `j`'s centre, computed
//! by one FFT of `w(n) y_in exp(j 2 pi v_0 n / Va)`, `v_0` the centre of column 0.
//! Velocities alias: `v` and `v + Va` give the same samples, so a target outside the
//! span shows at `v` wrapped into `[velocity_start, velocity_start + Va)`. `w(n)` is the
//! configuration's `window` (Hamming when it names none), written from its formula;
//! `w_in` complex white Gaussian with `E|w|^2 = sigma^2`, independent over range cells
//! and pulses; `phi_k` uniform in `[0, 2 pi)`, independent per frame; range migration
//! within a frame's pulses is neglected.
//!
//! **Rotor** (eq. 10-11): blade `b = 0..B-1`, a point of amplitude `a_k` (that of the
//! body) at radius `R = V / omega` turning at `omega`, adds
//! `a_k exp(j (phi - 2 pi v n / Va - 4 pi R cos(omega t_n + theta_0 + 2 pi b / B) / lambda))`,
//! `t_n = k dt + n lambda / (2 Va)` (pulse interval `Tr = lambda / (2 Va)`), its
//! instantaneous velocity `v - V sin(omega t + theta_b)` (eq. 13's sign); `theta_0`
//! uniform per run. Within a CPI of `Nv Tr` s a blade's velocity sweeps up to
//! `V omega Nv Tr` m/s, so its peak is wider than the body's.
//!
//! SNR = the peak-pixel power over the noise power per pixel for a target at a pixel
//! centre, the peak SNR of eq. 19 of the rotor-UAV paper (Journal of Radars, 2023):
//!
//! ```text
//! SNR = a^2 (sum w)^2 / (sigma^2 sum w^2),   noise power per pixel P = sigma^2 sum w^2
//! ```
//!
//! `P` is `2 noise_var` of the configuration (1 with `"noise": "estimate"`). The
//! amplitude does not change with range (the map spans a few hundred metres at tens of
//! kilometres: the `r^-4` law moves it by a fraction of a dB).
//!
//! Motion: constant radial velocity, `r_{k+1} = r_k + v dt` (`v > 0` receding). `v` is
//! uniform in `velocity_range` (by default the map's span) and the start uniform over
//! the ranges that keep every frame's range inside the map (`v` redrawn when none does;
//! after 10 000 draws the target stands still). Truth columns `range_m,velocity_m_per_s`
//! (`v` itself, not wrapped). Amplitude: Swerling 0/1/3, one draw per frame.

use anyhow::{ensure, Result};
use faint_core::model::doppler::Window;
use faint_core::rng::Rng;
use rustfft::num_complex::Complex64;
use rustfft::FftPlanner;

use super::cubes::{sinc, Axis, REACH};
use super::doppler::{window_coefficient, window_sums};
use super::Swerling;

/// The power-map simulator's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapPhysics {
    /// Range axis (m).
    pub range: Axis,
    /// Velocity axis (m/s, positive receding); its cell count is the pulse count `Nv`.
    pub velocity: Axis,
    /// Range resolution `dR` of the sinc (m).
    pub range_resolution: f64,
    /// Window across the pulses.
    pub window: Window,
    /// Frame interval `dt` (s).
    pub dt: f64,
    /// Noise power per pixel `P = sigma^2 sum w^2`.
    pub noise_power: f64,
    /// Range of the target's radial velocity (m/s).
    pub velocity_range: (f64, f64),
    /// Amplitude fluctuation.
    pub swerling: Swerling,
    /// Rotor blades on the target (`None`: a point target).
    pub rotor: Option<Rotor>,
}

/// Rotor blade tips of eq. 11 (rotor-UAV paper, 2023).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rotor {
    /// Blade count `B`.
    pub blades: u32,
    /// Maximum blade velocity `V = omega R` (m/s).
    pub blade_speed: f64,
    /// Rotor rate `omega` (rad/s).
    pub omega: f64,
    /// Wavelength `lambda` (m).
    pub wavelength: f64,
}

impl Rotor {
    /// The rotor-UAV preset's rotor: `B = 2`, `V = 10` m/s, `omega = 0.06 pi` rad/s,
    /// `lambda = 0.03` m.
    pub fn rotor_uav(blades: u32) -> Self {
        Self {
            blades,
            blade_speed: 10.0,
            omega: 0.06 * std::f64::consts::PI,
            wavelength: 0.03,
        }
    }
}

/// One simulated target's state at a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MapTruth {
    /// Range (m).
    pub range: f64,
    /// Radial velocity (m/s, not wrapped).
    pub velocity: f64,
    /// Amplitude of this frame `a_k`.
    pub amplitude: f64,
}

impl MapPhysics {
    /// The axes as given, range resolution one range bin, Hamming, `dt` 1 s, unit noise
    /// power per pixel, velocity uniform over the map's span, Swerling 0.
    pub fn new(range: Axis, velocity: Axis) -> Self {
        Self {
            range,
            velocity,
            range_resolution: range.size,
            window: Window::Hamming,
            dt: 1.0,
            noise_power: 1.0,
            velocity_range: (velocity.start, velocity.end()),
            swerling: Swerling::Zero,
            rotor: None,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        ensure!(
            (1..=1 << 16).contains(&self.range.n),
            "range: {} cells, must be in 1..=65536",
            self.range.n
        );
        ensure!(
            (2..=1 << 16).contains(&self.velocity.n),
            "velocity: {} cells (pulses), must be in 2..=65536",
            self.velocity.n
        );
        for (n, a) in [("range", self.range), ("velocity", self.velocity)] {
            ensure!(
                a.start.is_finite() && a.size.is_finite() && a.size > 0.0,
                "{n}: start {} and cell size {} must be finite, the size > 0",
                a.start,
                a.size
            );
        }
        ensure!(
            self.range.n * self.velocity.n <= 1 << 26,
            "map of {} pixels: at most 2^26 per frame",
            self.range.n * self.velocity.n
        );
        for (n, v) in [("range resolution", self.range_resolution), ("dt", self.dt)] {
            ensure!(v.is_finite() && v > 0.0, "{n} {v}: must be finite and > 0");
        }
        ensure!(
            self.noise_power.is_finite() && self.noise_power >= 0.0,
            "noise power {}: must be finite and >= 0",
            self.noise_power
        );
        if let Some(r) = self.rotor {
            ensure!(
                (1..=8).contains(&r.blades),
                "rotor: {} blades, must be in 1..=8",
                r.blades
            );
            for (n, v) in [
                ("blade speed", r.blade_speed),
                ("rotor rate", r.omega),
                ("wavelength", r.wavelength),
            ] {
                ensure!(
                    v.is_finite() && v > 0.0,
                    "rotor {n} {v}: must be finite and > 0"
                );
            }
        }
        ensure!(
            self.velocity_range.0.is_finite()
                && self.velocity_range.1.is_finite()
                && self.velocity_range.0 <= self.velocity_range.1,
            "velocity range {:?}: must be finite and ordered",
            self.velocity_range
        );
        Ok(())
    }

    /// Pixels per frame.
    pub fn pixels(&self) -> usize {
        self.range.n * self.velocity.n
    }

    /// The velocity ambiguity `Va = Nv velocity_bin` (m/s).
    pub fn ambiguity(&self) -> f64 {
        self.velocity.n as f64 * self.velocity.size
    }

    /// `v` wrapped into `[-Va / 2, Va / 2)`.
    pub fn wrap(&self, v: f64) -> f64 {
        let va = self.ambiguity();
        let r = (v + 0.5 * va).rem_euclid(va) - 0.5 * va;
        if r >= 0.5 * va {
            r - va
        } else {
            r
        }
    }

    /// `sum w` and `sum w^2` of the window over the `Nv` pulses.
    pub fn window_sums(&self) -> (f64, f64) {
        window_sums(self.window, self.velocity.n)
    }

    /// Amplitude `a` of the peak SNR `snr_db`: `a = sqrt(SNR P) / sum w`.
    pub fn amplitude(&self, snr_db: f64) -> f64 {
        let (s, _) = self.window_sums();
        (10f64.powf(snr_db / 10.0) * self.noise_power).sqrt() / s
    }

    /// Draws a start range and velocity that keep the target in the map's range span
    /// for `frames` frames.
    fn draw_path(&self, frames: usize, rng: &mut Rng) -> (f64, f64) {
        let u = |rng: &mut Rng| f64::from(rng.uniform());
        let span = (frames.max(1) - 1) as f64 * self.dt;
        let (lo, hi) = (self.range.start, self.range.end());
        let (v0, v1) = self.velocity_range;
        for _ in 0..10_000 {
            let v = v0 + (v1 - v0) * u(rng);
            let (a, b) = (lo + (-v * span).max(0.0), hi - (v * span).max(0.0));
            if b > a {
                return (a + (b - a) * u(rng), v);
            }
        }
        (lo + (hi - lo) * u(rng), 0.0)
    }

    /// Simulates `frames` maps (frame-major, `frames * Nr * Nv` powers); `amplitude =
    /// None` is noise only. Returns the powers and, with a target, its state per frame.
    pub fn simulate(
        &self,
        frames: usize,
        amplitude: Option<f64>,
        rng: &mut Rng,
    ) -> (Vec<f32>, Vec<MapTruth>) {
        let path = amplitude.map(|a| (a, self.draw_path(frames, rng)));
        let theta0 = match (path, self.rotor) {
            (Some(_), Some(_)) => 2.0 * std::f64::consts::PI * f64::from(rng.uniform()),
            _ => 0.0,
        };
        let mut out = Vec::with_capacity(frames * self.pixels());
        let mut truth = Vec::new();
        let kernel = self.kernel();
        let fft = FftPlanner::<f64>::new().plan_fft_inverse(self.velocity.n);
        for k in 0..frames {
            let echo = path.map(|(a, (r0, v))| {
                let r = r0 + v * k as f64 * self.dt;
                let ak = a * self.swerling.draw(rng);
                truth.push(MapTruth {
                    range: r,
                    velocity: v,
                    amplitude: ak,
                });
                (ak, r, v)
            });
            let t0 = k as f64 * self.dt;
            self.push_frame(echo, (t0, theta0), &kernel, fft.as_ref(), rng, &mut out);
        }
        (out, truth)
    }

    /// One map of a target of amplitude `a` (before its Swerling draw) at range `r` and
    /// velocity `v` (for tests and diagnosis).
    pub fn frame_at(&self, r: f64, v: f64, a: f64, rng: &mut Rng) -> Vec<f32> {
        let ak = a * self.swerling.draw(rng);
        let mut out = Vec::with_capacity(self.pixels());
        let fft = FftPlanner::<f64>::new().plan_fft_inverse(self.velocity.n);
        self.push_frame(
            Some((ak, r, v)),
            (0.0, 0.0),
            &self.kernel(),
            fft.as_ref(),
            rng,
            &mut out,
        );
        out
    }

    /// `w(n) exp(j 2 pi v_0 n / Va)`: the window and the shift that puts column `j` at
    /// `v_j` for the (`+j`-kernel) FFT.
    fn kernel(&self) -> Vec<Complex64> {
        let m = self.velocity.n;
        let c = (self.velocity.start + 0.5 * self.velocity.size) / self.ambiguity();
        (0..m)
            .map(|n| {
                let ph = 2.0 * std::f64::consts::PI * (c * n as f64).rem_euclid(1.0);
                Complex64::from_polar(window_coefficient(self.window, n, m), ph)
            })
            .collect()
    }

    /// Appends one map: noise, plus the echo `(a_k, r, v)` with a fresh random phase (and
    /// its rotor's blades at time `t0` of the frame's first pulse, rotor phase `theta0`).
    fn push_frame(
        &self,
        echo: Option<(f64, f64, f64)>,
        (t0, theta0): (f64, f64),
        kernel: &[Complex64],
        fft: &dyn rustfft::Fft<f64>,
        rng: &mut Rng,
        out: &mut Vec<f32>,
    ) {
        let m = self.velocity.n;
        let (_, s2) = self.window_sums();
        let sd = (0.5 * self.noise_power / s2).sqrt();
        let two_pi = 2.0 * std::f64::consts::PI;
        // Rows of the echo, its complex slow-time tone `a_k exp(j (phi - 2 pi v n / Va))`.
        let echo = echo.map(|(ak, r, v)| {
            let phi = two_pi * f64::from(rng.uniform());
            let u = self.range.coord(r);
            let c = u.round() as isize;
            let tone: Vec<Complex64> = (0..m)
                .map(|n| {
                    let cycles = (v * n as f64 / self.ambiguity()).rem_euclid(1.0);
                    let mut t = Complex64::from_polar(ak, phi - two_pi * cycles);
                    if let Some(rot) = self.rotor {
                        let tr = rot.wavelength / (2.0 * self.ambiguity());
                        let radius = rot.blade_speed / rot.omega;
                        let tn = t0 + n as f64 * tr;
                        for b in 0..rot.blades {
                            let tb = theta0 + two_pi * f64::from(b) / f64::from(rot.blades);
                            let c = 2.0 * radius * (rot.omega * tn + tb).cos() / rot.wavelength;
                            let ph = phi - two_pi * (cycles + c.rem_euclid(1.0));
                            t += Complex64::from_polar(ak, ph);
                        }
                    }
                    t
                })
                .collect();
            (u, c, tone)
        });
        let mut x = vec![Complex64::new(0.0, 0.0); m];
        let mut scratch = vec![Complex64::new(0.0, 0.0); fft.get_inplace_scratch_len()];
        for i in 0..self.range.n {
            for xn in x.iter_mut() {
                *xn = Complex64::new(sd * f64::from(rng.normal()), sd * f64::from(rng.normal()));
            }
            if let Some((u, c, tone)) = &echo {
                if (i as isize - c).abs() <= REACH {
                    let g = sinc((i as f64 - u) * self.range.size / self.range_resolution);
                    for (xn, t) in x.iter_mut().zip(tone) {
                        *xn += t * g;
                    }
                }
            }
            for (xn, kn) in x.iter_mut().zip(kernel) {
                *xn *= kn;
            }
            fft.process_with_scratch(&mut x, &mut scratch);
            out.extend(x.iter().map(|z| z.norm_sqr() as f32));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 12 range bins of 0.78125 m from 19 910 m, 64 velocity bins of 0.625 m/s from
    /// -20 m/s (`Va` = 40 m/s), Hamming.
    fn small() -> MapPhysics {
        MapPhysics::new(
            Axis {
                n: 12,
                start: 19_910.0,
                size: 0.78125,
            },
            Axis {
                n: 64,
                start: -20.0,
                size: 0.625,
            },
        )
    }

    fn argmax(f: &[f32]) -> usize {
        f.iter()
            .enumerate()
            .fold((0, f32::MIN), |b, (i, &v)| if v > b.1 { (i, v) } else { b })
            .0
    }

    /// Noise only: each pixel is complex Gaussian with `E|Y|^2 = sigma^2 sum w^2 = P`, so
    /// `|Y|^2` is exponential with mean `P`. 1000 frames of 768 pixels: the mean's
    /// relative std is 1/sqrt(768 000) = 0.11 %, widened less than 2x by the window's
    /// correlation of neighbouring columns (tolerance 0.6 %). The law from one pixel per
    /// row of each frame (12 000 independent values; std of each exceedance probability
    /// at most 0.0046, tolerance 0.02).
    #[test]
    fn noise_pixel_power_is_exponential_with_mean_p() {
        let p = MapPhysics {
            noise_power: 3.0,
            ..small()
        };
        let mut rng = Rng::seed_from_u64(21);
        let (z, t) = p.simulate(1000, None, &mut rng);
        assert!(t.is_empty());
        let mean = z.iter().map(|&v| f64::from(v)).sum::<f64>() / z.len() as f64;
        assert!((mean / 3.0 - 1.0).abs() < 0.006, "{mean}");
        let one: Vec<f64> = z
            .chunks(64)
            .enumerate()
            .map(|(r, row)| f64::from(row[(r * 7) % 64]) / 3.0)
            .collect();
        for th in [0.5, 1.0, 2.0, 3.0] {
            let got = one.iter().filter(|&&v| v > th).count() as f64 / one.len() as f64;
            assert!((got - (-th).exp()).abs() < 0.02, "P(>{th}) = {got}");
        }
    }

    /// A target at a pixel centre, noise off: the peak pixel holds `a^2 (sum w)^2`, so
    /// `amplitude(snr)` gives `snr P` there (f32 rounding: 1e-5). Pixel centres in range
    /// give one row (`S(n) = 0`).
    #[test]
    fn a_pixel_centred_target_has_the_stated_peak_snr() {
        let p = MapPhysics {
            noise_power: 0.0,
            ..small()
        };
        let snr = 10f64.powf(1.3);
        let a = MapPhysics {
            noise_power: 1.0,
            ..p
        }
        .amplitude(13.0);
        let mut rng = Rng::seed_from_u64(2);
        let (i, j) = (5usize, 40usize);
        let r = p.range.start + (i as f64 + 0.5) * p.range.size;
        let v = p.velocity.start + (j as f64 + 0.5) * p.velocity.size;
        let z = p.frame_at(r, v, a, &mut rng);
        let peak = f64::from(z[i * 64 + j]);
        assert!((peak / snr - 1.0).abs() < 1e-5, "{peak} vs {snr}");
        assert_eq!(argmax(&z), i * 64 + j);
        let other_rows: f64 = z
            .iter()
            .enumerate()
            .filter(|(k, _)| k / 64 != i)
            .map(|(_, &x)| f64::from(x))
            .sum();
        assert!(other_rows < 1e-9 * snr, "{other_rows}");
    }

    /// With noise at 12 dB: `E z_peak = SNR P + P` at a pixel centre; 3000 frames,
    /// `z_peak / P` has mean 16.85 and std sqrt(1 + 2 * 15.85) = 5.7, so the mean's std
    /// is 0.10; tolerance 0.4 (4 std).
    #[test]
    fn the_peak_snr_holds_in_noise() {
        let p = small();
        let a = p.amplitude(12.0);
        let mut rng = Rng::seed_from_u64(5);
        let (i, j) = (3usize, 10usize);
        let r = p.range.start + (i as f64 + 0.5) * p.range.size;
        let v = p.velocity.start + (j as f64 + 0.5) * p.velocity.size;
        let n = 3000;
        let sum: f64 = (0..n)
            .map(|_| f64::from(p.frame_at(r, v, a, &mut rng)[i * 64 + j]))
            .sum();
        let want = 10f64.powf(1.2) + 1.0;
        assert!((sum / n as f64 - want).abs() < 0.4, "{}", sum / n as f64);
    }

    /// Doppler sign and aliasing: a receding target (`v > 0`) peaks in the column whose
    /// centre is nearest `v` (higher columns are faster receding), and `v + Va`, `v - Va`
    /// peak in that same column; drawn targets (velocities over three ambiguities) peak
    /// in the truth's pixel, its velocity wrapped into the map.
    #[test]
    fn velocity_sign_and_aliasing() {
        let p = MapPhysics {
            noise_power: 0.0,
            ..small()
        };
        let mut rng = Rng::seed_from_u64(3);
        let r = p.range.start + 6.5 * p.range.size;
        for v in [7.3, -7.3, 19.9, -19.9, 0.1] {
            let j = p.velocity.coord(v).round() as usize;
            for alias in [-1.0, 0.0, 1.0] {
                let z = p.frame_at(r, v + alias * p.ambiguity(), 1.0, &mut rng);
                assert_eq!(argmax(&z), 6 * 64 + j, "v {v} alias {alias}");
            }
        }
        let q = MapPhysics {
            velocity_range: (-60.0, 60.0),
            noise_power: 1.0,
            ..small()
        };
        let a = q.amplitude(40.0);
        for _ in 0..50 {
            let (z, t) = q.simulate(3, Some(a), &mut rng);
            for (k, tr) in t.iter().enumerate() {
                let f = &z[k * q.pixels()..(k + 1) * q.pixels()];
                let i = q.range.coord(tr.range).round() as usize;
                let vw =
                    q.velocity.start + (tr.velocity - q.velocity.start).rem_euclid(q.ambiguity());
                let (ui, uj) = (q.range.coord(tr.range), q.velocity.coord(vw));
                let j = (uj.round() as usize) % 64;
                let best = argmax(f);
                // Clear of a pixel boundary by 0.05 pixel: the nearest pixel wins by
                // about 5 noise std at 40 dB (see the cube test); else one pixel off.
                if [ui, uj].iter().all(|x| (x - x.round()).abs() < 0.45) {
                    assert_eq!(best, i * 64 + j, "{tr:?}");
                } else {
                    let dj = (best % 64) as isize - j as isize;
                    assert!((best / 64).abs_diff(i) <= 1, "{tr:?}");
                    assert!(dj.abs() <= 1 || dj.abs() == 63, "{tr:?}");
                }
            }
            assert!((t[2].range - 2.0 * t[1].range + t[0].range).abs() < 1e-9);
        }
    }
}
