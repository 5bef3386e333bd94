//! Doppler frames from the physics: a complex tone in white Gaussian noise, windowed and
//! transformed, frame after frame.
//!
//! Frame `k` holds `m` time samples `t_n = n ts`, `n = 0..m-1`:
//!
//! ```text
//! x_n = a_k exp(j (2 pi (fd_k t_n + fda_k t_n^2 / 2) + phi_k)) + w_n,   E|w_n|^2 = sigma^2
//! z_b = sum_n w(n) x_n exp(-j 2 pi b n / m),   b = 0..m-1
//! ```
//!
//! `w(n)` is the window (written here from its formula, not taken from the core), `w_n`
//! complex white Gaussian (each of I and Q `N(0, sigma^2 / 2)`), the DFT an `f64` FFT.
//!
//! Conventions (those of the readers and of the core's Doppler model): the DFT kernel is
//! `exp(-j 2 pi b n / m)`; bins are in natural order, bin `b` at `b / (m ts)` Hz aliased
//! into `[-1/(2 ts), 1/(2 ts))` (bin 0 is 0 Hz, bin `m/2` is `-1/(2 ts)`); a positive
//! Doppler is `exp(+j 2 pi fd t)`, an approaching target. The truth column is `fd_hz`
//! (Hz, wrapped into the band) at the frame's first sample.
//!
//! Motion between frames (frame interval `T = m ts`): constant Doppler rate plus a white
//! acceleration, `fd_{k+1} = fd_k + fda_k T + e T^2 / 2`, `fda_{k+1} = fda_k + e T`,
//! `e ~ N(0, accel_std^2)`. The start is uniform over the whole band and the rate
//! uniform in `fda_range`.
//!
//! Phase `phi_k`: [`Phase::Random`] draws it uniform in `[0, 2 pi)` each frame (frames
//! from separate dwells); [`Phase::Continuous`] carries it on,
//! `phi_{k+1} = phi_k + 2 pi (fd_k T + fda_k T^2 / 2)` (one coherent signal cut into
//! frames), from a uniform `phi_0`; [`Phase::Zero`] sets it to 0 (the presets'
//! assumption, for diagnosis only).
//!
//! Amplitude (Swerling, scan to scan): case 0 `a_k = a`; case 1 `a_k^2` exponential with
//! mean `a^2`; case 3 `a_k^2` chi-square with 4 degrees of freedom and mean `a^2`.
//!
//! SNR. Per sample `snr_1 = a^2 / sigma^2`. The peak bin of a bin-centred tone has
//! power `a^2 (sum w)^2` over a noise power per bin `sigma^2 sum w^2`, so the SNR after
//! integration (eq. 18 of Lu et al. 2017, the definition of the OTHR preset) is
//!
//! ```text
//! SNR = a^2 (sum w)^2 / (sigma^2 sum w^2) = snr_1 G,   G = (sum w)^2 / sum w^2
//! ```
//!
//! (`G = m` for the rectangular window, 19.57 for the 32-point Hamming: `snr_1` is
//! 12.9 dB below SNR). `--snr-db` of `faint evaluate` is this SNR.

use anyhow::{ensure, Result};
use faint_core::model::doppler::Window;
use faint_core::rng::Rng;
use faint_core::Complex32;
use rustfft::num_complex::Complex64;
use rustfft::FftPlanner;

use super::Swerling;

/// How the carrier phase goes from frame to frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Uniform in `[0, 2 pi)`, independent per frame.
    Random,
    /// Continuous across frames (one coherent signal).
    Continuous,
    /// `phi_k = 0` every frame: what the presets (and the detectors' models) assume; not
    /// physical, kept to tell a phase mismatch from other causes.
    Zero,
}

/// The Doppler-frame simulator's parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DopplerPhysics {
    /// Samples (and bins) per frame `m`.
    pub bins: usize,
    /// Sample interval `ts` (s).
    pub ts: f64,
    /// Window before the DFT.
    pub window: Window,
    /// Noise power per complex time sample `sigma^2` (0: no noise).
    pub noise_var: f64,
    /// Amplitude fluctuation.
    pub swerling: Swerling,
    /// Phase from frame to frame.
    pub phase: Phase,
    /// Range of the initial Doppler rate (Hz/s).
    pub fda_range: (f64, f64),
    /// Std of the white acceleration `e` (Hz/s^2).
    pub accel_std: f64,
}

/// The window's coefficient `w(n)` of an `m`-point symmetric window, from its formula.
pub fn window_coefficient(window: Window, n: usize, m: usize) -> f64 {
    let x = if m > 1 {
        2.0 * std::f64::consts::PI * n as f64 / (m - 1) as f64
    } else {
        0.0
    };
    match window {
        Window::Rectangular => 1.0,
        Window::Hamming => 0.54 - 0.46 * x.cos(),
        Window::Hann => 0.5 - 0.5 * x.cos(),
    }
}

/// `sum w` and `sum w^2` of an `m`-point window ([`window_coefficient`]).
pub fn window_sums(window: Window, m: usize) -> (f64, f64) {
    (0..m).fold((0.0, 0.0), |(s, s2), n| {
        let w = window_coefficient(window, n, m);
        (s + w, s2 + w * w)
    })
}

/// One simulated target's state at a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DopplerTruth {
    /// Doppler at the frame's first sample (Hz, wrapped into the band).
    pub fd: f64,
    /// Doppler rate (Hz/s).
    pub fda: f64,
    /// Amplitude of this frame `a_k`.
    pub amplitude: f64,
    /// Carrier phase `phi_k` (rad).
    pub phase: f64,
}

impl DopplerPhysics {
    /// The OTHR geometry of the detectors' default configuration (`m = 32`,
    /// `ts = 0.02 s`, Hamming), unit noise, Swerling 0, random phase, `fda` in
    /// `[-0.5, 0.5]` Hz/s, acceleration std 0.2 Hz/s^2.
    pub fn new(bins: usize, ts: f64, window: Window) -> Self {
        Self {
            bins,
            ts,
            window,
            noise_var: 1.0,
            swerling: Swerling::Zero,
            phase: Phase::Random,
            fda_range: (-0.5, 0.5),
            accel_std: 0.2,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<()> {
        ensure!(
            (1..=1 << 16).contains(&self.bins),
            "bins {}: must be in 1..=65536",
            self.bins
        );
        ensure!(
            self.ts.is_finite() && self.ts > 0.0,
            "ts {}: must be finite and > 0",
            self.ts
        );
        ensure!(
            self.noise_var.is_finite() && self.noise_var >= 0.0,
            "noise variance {}: must be finite and >= 0",
            self.noise_var
        );
        ensure!(
            self.fda_range.0.is_finite()
                && self.fda_range.1.is_finite()
                && self.fda_range.0 <= self.fda_range.1,
            "Doppler-rate range {:?}: must be finite and ordered",
            self.fda_range
        );
        ensure!(
            self.accel_std.is_finite() && self.accel_std >= 0.0,
            "acceleration std {}: must be finite and >= 0",
            self.accel_std
        );
        Ok(())
    }

    /// `sum w` and `sum w^2` of the window.
    pub fn window_sums(&self) -> (f64, f64) {
        window_sums(self.window, self.bins)
    }

    /// Processing gain `G = (sum w)^2 / sum w^2`.
    pub fn gain(&self) -> f64 {
        let (s, s2) = self.window_sums();
        s * s / s2
    }

    /// Amplitude `a` giving the post-integration SNR `snr_db` (see the module docs).
    pub fn amplitude(&self, snr_db: f64) -> f64 {
        (10f64.powf(snr_db / 10.0) * self.noise_var / self.gain()).sqrt()
    }

    /// The band `[-1/(2 ts), 1/(2 ts))` (Hz).
    pub fn band(&self) -> (f64, f64) {
        (-0.5 / self.ts, 0.5 / self.ts)
    }

    /// `f` wrapped into the band.
    pub fn wrap(&self, f: f64) -> f64 {
        let w = 1.0 / self.ts;
        let lo = -0.5 * w;
        let r = (f - lo).rem_euclid(w) + lo;
        // rem_euclid may round up to w itself.
        if r >= 0.5 * w {
            r - w
        } else {
            r
        }
    }

    /// Simulates `frames` frames; `amplitude = None` is noise only. Returns the frames
    /// and, with a target, its state per frame.
    pub fn simulate(
        &self,
        frames: usize,
        amplitude: Option<f64>,
        rng: &mut Rng,
    ) -> (Vec<Vec<Complex32>>, Vec<DopplerTruth>) {
        let m = self.bins;
        let t_frame = m as f64 * self.ts;
        let w: Vec<f64> = (0..m)
            .map(|n| window_coefficient(self.window, n, m))
            .collect();
        let fft = FftPlanner::<f64>::new().plan_fft_forward(m);
        let sd = (0.5 * self.noise_var).sqrt();
        let two_pi = 2.0 * std::f64::consts::PI;
        let (lo, hi) = self.band();
        let mut target = amplitude.map(|a| {
            let fd = lo + (hi - lo) * f64::from(rng.uniform());
            let fda =
                self.fda_range.0 + (self.fda_range.1 - self.fda_range.0) * f64::from(rng.uniform());
            let phase = two_pi * f64::from(rng.uniform());
            (a, fd, fda, phase)
        });
        let mut out = Vec::with_capacity(frames);
        let mut truth = Vec::new();
        for _ in 0..frames {
            let mut x: Vec<Complex64> = (0..m)
                .map(|_| Complex64::new(sd * f64::from(rng.normal()), sd * f64::from(rng.normal())))
                .collect();
            if let Some((a, fd, fda, phase)) = target.as_mut() {
                let phi = match self.phase {
                    Phase::Random => two_pi * f64::from(rng.uniform()),
                    Phase::Continuous => *phase,
                    Phase::Zero => 0.0,
                };
                let ak = *a * self.swerling.draw(rng);
                for (n, xn) in x.iter_mut().enumerate() {
                    let t = n as f64 * self.ts;
                    let arg = two_pi * (*fd * t + *fda * t * t / 2.0) + phi;
                    *xn += Complex64::from_polar(ak, arg);
                }
                truth.push(DopplerTruth {
                    fd: *fd,
                    fda: *fda,
                    amplitude: ak,
                    phase: phi,
                });
                // Carry the phase and move to the next frame.
                let advance = two_pi * (*fd * t_frame + *fda * t_frame * t_frame / 2.0);
                *phase = (phi + advance).rem_euclid(two_pi);
                let e = self.accel_std * f64::from(rng.normal());
                *fd = self.wrap(*fd + *fda * t_frame + e * t_frame * t_frame / 2.0);
                *fda += e * t_frame;
            }
            for (xn, wn) in x.iter_mut().zip(&w) {
                *xn *= *wn;
            }
            fft.process(&mut x);
            out.push(
                x.iter()
                    .map(|z| Complex32::new(z.re as f32, z.im as f32))
                    .collect(),
            );
        }
        (out, truth)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn othr() -> DopplerPhysics {
        DopplerPhysics::new(32, 0.02, Window::Hamming)
    }

    /// Noise only: each bin is complex Gaussian with `E|z|^2 = sigma^2 sum w^2`, so
    /// `|z|^2` is exponential. 20 000 frames, one bin each for the law (independent),
    /// every bin for the mean (640 000 values: the mean's relative std is 1/sqrt(640 000)
    /// = 0.13 %, correlation between bins of one frame widens it less than 3x; 1 %
    /// tolerance). The exceedance probabilities `exp(-t)` at t = 0.5, 1, 2, 3 have std at
    /// most 0.0035 on 20 000 draws: 0.015 is over 4 std.
    #[test]
    fn noise_bin_power_is_exponential_with_the_window_energy() {
        let p = DopplerPhysics {
            noise_var: 2.5,
            ..othr()
        };
        let (_, s2) = p.window_sums();
        let mean_want = 2.5 * s2;
        let mut rng = Rng::seed_from_u64(11);
        let (frames, _) = p.simulate(20_000, None, &mut rng);
        let all: f64 = frames
            .iter()
            .flatten()
            .map(|z| f64::from(z.norm_sqr()))
            .sum::<f64>()
            / (frames.len() * 32) as f64;
        assert!((all / mean_want - 1.0).abs() < 0.01, "{all} vs {mean_want}");
        let one: Vec<f64> = frames
            .iter()
            .enumerate()
            .map(|(k, f)| f64::from(f[k % 32].norm_sqr()) / mean_want)
            .collect();
        for t in [0.5, 1.0, 2.0, 3.0] {
            let got = one.iter().filter(|&&x| x > t).count() as f64 / one.len() as f64;
            assert!((got - (-t).exp()).abs() < 0.015, "P(>{t}) = {got}");
        }
    }

    /// Noise-free tone: the peak bin of a bin-centred tone is `a sum w`, and a tone half a
    /// bin off gives `a |W(1/(2m))|`; references: the closed forms `sum w = 0.54 m - 0.46`
    /// and `sum w^2 = 0.2916 m - 0.4968 + 0.2116 (m + 1) / 2` of the symmetric Hamming
    /// window, and the DTFT summed in f64. The tolerance is f32 rounding of the output.
    #[test]
    fn processing_gain_and_scalloping_match_the_closed_forms() {
        let m = 32.0;
        let (s, s2) = othr().window_sums();
        assert!((s - (0.54 * m - 0.46)).abs() < 1e-12);
        assert!((s2 - (0.2916 * m - 0.4968 + 0.2116 * (m + 1.0) / 2.0)).abs() < 1e-12);
        let p = DopplerPhysics {
            noise_var: 0.0,
            fda_range: (0.0, 0.0),
            accel_std: 0.0,
            ..othr()
        };
        let bin_hz = 1.0 / (32.0 * 0.02);
        for (offset, want) in [
            (0.0, s),
            (0.5, {
                let (re, im) = (0..32).fold((0.0, 0.0), |(re, im), n| {
                    let w = window_coefficient(Window::Hamming, n, 32);
                    let ph = 2.0 * std::f64::consts::PI * 0.5 * n as f64 / 32.0;
                    (re + w * ph.cos(), im + w * ph.sin())
                });
                (re * re + im * im).sqrt()
            }),
        ] {
            // Start at bin 5 + offset: draw a run and overwrite its start by hand.
            let fd = (5.0 + offset) * bin_hz;
            let x: Vec<Complex64> = (0..32)
                .map(|n| {
                    let t = n as f64 * 0.02;
                    Complex64::from_polar(0.7, 2.0 * std::f64::consts::PI * fd * t)
                        * window_coefficient(Window::Hamming, n, 32)
                })
                .collect();
            let mut y = x.clone();
            FftPlanner::<f64>::new()
                .plan_fft_forward(32)
                .process(&mut y);
            let peak = y.iter().map(|z| z.norm()).fold(0.0, f64::max);
            assert!((peak - 0.7 * want).abs() < 1e-9, "offset {offset}: {peak}");
        }
        // The simulator's own peak at a bin centre (f32 output).
        let mut rng = Rng::seed_from_u64(3);
        let (f, t) = p.simulate(1, Some(0.7), &mut rng);
        let b0 = (t[0].fd / bin_hz).round().rem_euclid(32.0) as usize;
        let frac = t[0].fd / bin_hz - (t[0].fd / bin_hz).round();
        let w_at = |u: f64| {
            let (re, im) = (0..32).fold((0.0, 0.0), |(re, im), n| {
                let w = window_coefficient(Window::Hamming, n, 32);
                let ph = 2.0 * std::f64::consts::PI * u * n as f64 / 32.0;
                (re + w * ph.cos(), im + w * ph.sin())
            });
            (re * re + im * im).sqrt()
        };
        let got = f64::from(f[0][b0].norm());
        assert!((got - 0.7 * w_at(frac)).abs() < 1e-5 * s, "{got}");
        // Processing gain G = (sum w)^2 / sum w^2: eq. 18 SNR of amplitude(snr) is snr.
        let a = othr().amplitude(10.0);
        assert!((a * a * s * s / s2 - 10.0).abs() < 1e-9);
    }

    /// Random phase: `phi_k` uniform; the mean resultant `|mean exp(j phi)|` of n draws
    /// has std about 1/sqrt(n) (0.007 at n = 20 000: 0.03 is over 4 std), and each of 8
    /// sectors holds 1/8 (std 0.0023; 0.012 tolerance). Continuous phase: the increment
    /// is `2 pi (fd T + fda T^2 / 2)` exactly (no acceleration noise), checked from the
    /// truth to 1e-9 rad.
    #[test]
    fn phase_is_uniform_or_continuous() {
        let p = DopplerPhysics {
            noise_var: 0.0,
            ..othr()
        };
        let mut rng = Rng::seed_from_u64(5);
        let (_, t) = p.simulate(20_000, Some(1.0), &mut rng);
        let n = t.len() as f64;
        let (c, s) = t.iter().fold((0.0, 0.0), |(c, s), x| {
            (c + x.phase.cos(), s + x.phase.sin())
        });
        assert!((c * c + s * s).sqrt() / n < 0.03);
        let mut sectors = [0usize; 8];
        for x in &t {
            let i = (x.phase / (std::f64::consts::PI / 4.0)).floor() as usize;
            sectors[i.min(7)] += 1;
        }
        for c in sectors {
            assert!((c as f64 / n - 0.125).abs() < 0.012, "{sectors:?}");
        }
        let q = DopplerPhysics {
            phase: Phase::Continuous,
            accel_std: 0.0,
            ..p
        };
        let (_, t) = q.simulate(50, Some(1.0), &mut rng);
        let big_t = 32.0 * 0.02;
        for w in t.windows(2) {
            let adv =
                2.0 * std::f64::consts::PI * (w[0].fd * big_t + w[0].fda * big_t * big_t / 2.0);
            let d = (w[1].phase - w[0].phase - adv).rem_euclid(2.0 * std::f64::consts::PI);
            assert!(d.min(2.0 * std::f64::consts::PI - d) < 1e-9, "{d}");
        }
    }

    /// Swerling 1: `a_k^2 / a^2` exponential with mean 1 (20 000 frames; std of the
    /// mean 0.007, of each exceedance probability at most 0.0035: 0.03 and 0.015 are
    /// over 4 std). Swerling 3: chi-square 4, mean 1, `P(> t) = (1 + 2 t) exp(-2 t)`.
    #[test]
    fn swerling_amplitude_laws() {
        let mut rng = Rng::seed_from_u64(9);
        for (sw, sf) in [
            (Swerling::One, (|t: f64| (-t).exp()) as fn(f64) -> f64),
            (Swerling::Three, |t: f64| (1.0 + 2.0 * t) * (-2.0 * t).exp()),
        ] {
            let p = DopplerPhysics {
                noise_var: 0.0,
                swerling: sw,
                ..othr()
            };
            let (_, t) = p.simulate(20_000, Some(2.0), &mut rng);
            let pw: Vec<f64> = t.iter().map(|x| x.amplitude * x.amplitude / 4.0).collect();
            let mean = pw.iter().sum::<f64>() / pw.len() as f64;
            assert!((mean - 1.0).abs() < 0.03, "{sw:?} mean {mean}");
            for th in [0.25, 1.0, 2.0] {
                let got = pw.iter().filter(|&&x| x > th).count() as f64 / pw.len() as f64;
                assert!((got - sf(th)).abs() < 0.015, "{sw:?} P(>{th}) = {got}");
            }
        }
    }

    #[test]
    fn window_formulas_match_the_core_windows() {
        for w in [Window::Rectangular, Window::Hamming, Window::Hann] {
            for n in 0..16 {
                let a = window_coefficient(w, n, 16);
                let b = w.coefficient(n, 16);
                assert!((a - b).abs() < 1e-15, "{w:?} {n}");
            }
        }
    }
}
