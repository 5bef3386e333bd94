//! Scenario preset `othr`: sky-wave over-the-horizon radar, one range cell, slow
//! Doppler-manoeuvring target (Lu, Wang, Zhang 2017, §3-§4).
//!
//! Every value, including those the paper leaves open (marked "choice"):
//! - `ts = 0.02 s`, `K = 32` frames of `m = 32` samples (1024 samples, 20.48 s),
//!   `dT = m ts = 0.64 s`.
//! - State `[fd, fda, A]`, motion eq. 16 with `v1 ~ N(0, 0.2^2)` Hz/s^2 and
//!   `v2 ~ N(0, 0.02^2)` 1/s (choice: "small"; the Doppler moves about 0.04 Hz and its
//!   rate 0.13 Hz/s per frame by noise, against a bin width of 1/dT = 1.5625 Hz).
//! - Target present in frames 7..=26 (1-based). At frame 7: `fd ~ U[-25, 25)` Hz (the
//!   whole unambiguous band, choice), `fda ~ U(-0.5, 0.5)` Hz/s (paper), amplitude from
//!   the SNR; phase 0 at the start of every frame (paper: `phi_k = 0`), or with
//!   `random_phase` uniform in `[0, 2 pi)` and independent per frame (independent
//!   dwells; not the paper's).
//! - Observation eq. 17: `z_k = DFT_W(A exp(j 2 pi fd n ts) + wbar_k)`, Hamming window
//!   (choice), `z_b = sum_n w_n s_n exp(-j 2 pi b n / m)`. Noise is added in time,
//!   white, with unit variance `E|wbar_n|^2 = 1`, so the bins are correlated and each has
//!   variance `sigma0^2 = sum_n w_n^2`.
//! - SNR (eq. 18), exact definition used: `SNR = 10 log10(A^2 (sum_n w_n)^2 / sigma0^2)`,
//!   i.e. the largest bin power `max_b |h_b|^2` a bin-centred target of amplitude `A`
//!   would give, over the per-bin noise variance; equivalently
//!   `A^2 = SNR (sum w^2) / (sum w)^2` (time-domain SNR about 13.7 dB below eq. 18's).
//!   The SNR is that of the amplitude at frame 7; the amplitude then drifts by `v2`.
//! - Noise: complex white Gaussian, or circular complex generalized Gaussian (CGG,
//!   Novey, Adali, Roy 2010) of shape `c = 0.1` scaled to the same variance.
//! - Birth box of the detectors: `fd in [-25, 25)`, `fda in [-0.5, 0.5]`,
//!   `A in [0.05, 1.5]` (choice: SNR from -13 dB to +17 dB), `Pb = Pd = 0.05`,
//!   `P(E_0 = 1) = 0.05` (see `faint_core::model::doppler::ModelConfig::othr`).

use faint_core::model::doppler::{ModelConfig, Window};
use faint_core::rng::Rng;
use faint_core::Complex32;
use serde::{Deserialize, Serialize};

/// Background noise model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Noise {
    /// Complex white Gaussian ("known statistics").
    Gaussian,
    /// Complex generalized Gaussian, shape 0.1 ("unknown statistics").
    Cgg,
}

/// The `othr` preset.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Othr {
    /// Sample interval (s).
    pub ts: f64,
    /// Samples per frame = bins.
    pub m: usize,
    /// Frames per run.
    pub frames: usize,
    /// First frame with the target (1-based).
    pub first: usize,
    /// Last frame with the target (1-based, inclusive).
    pub last: usize,
    /// Std of `v1` (Hz/s^2).
    pub accel_std: f64,
    /// Std of `v2` (1/s).
    pub amp_std: f64,
    /// Initial Doppler range (Hz).
    pub fd0: (f64, f64),
    /// Initial Doppler-rate range (Hz/s).
    pub fda0: (f64, f64),
    /// Time-domain noise variance.
    pub noise_var: f64,
    /// Shape of the CGG noise.
    pub cgg_shape: f64,
    /// Analysis window (the preset: Hamming).
    pub window: Window,
    /// The target's phase at each frame's start uniform and independent per frame
    /// (`false`, the preset: zero, eq. 17).
    pub random_phase: bool,
}

impl Default for Othr {
    fn default() -> Self {
        Self {
            ts: 0.02,
            m: 32,
            frames: 32,
            first: 7,
            last: 26,
            accel_std: 0.2,
            amp_std: 0.02,
            fd0: (-25.0, 25.0),
            fda0: (-0.5, 0.5),
            noise_var: 1.0,
            cgg_shape: 0.1,
            window: Window::Hamming,
            random_phase: false,
        }
    }
}

/// One simulated run: `K` frames of `m` bins and the true state per frame.
#[derive(Debug, Clone)]
pub struct Run {
    /// Frames `z_1..z_K`.
    pub frames: Vec<Vec<Complex32>>,
    /// True `[fd, fda, A]` per frame (`None` when absent).
    pub truth: Vec<Option<[f64; 3]>>,
}

/// Window coefficients of the preset (Hamming).
pub fn window(m: usize) -> Vec<f64> {
    window_of(Window::Hamming, m)
}

/// Coefficients of an `m`-point `w` window.
pub fn window_of(w: Window, m: usize) -> Vec<f64> {
    (0..m).map(|n| w.coefficient(n, m)).collect()
}

impl Othr {
    /// The detectors' shared model for this preset (with the scene's window).
    pub fn model(&self) -> ModelConfig {
        ModelConfig {
            window: self.window,
            ..ModelConfig::othr()
        }
    }

    /// Per-bin noise variance `sigma0^2 = noise_var * sum w^2`.
    pub fn bin_noise_var(&self) -> f64 {
        self.noise_var
            * window_of(self.window, self.m)
                .iter()
                .map(|w| w * w)
                .sum::<f64>()
    }

    /// Amplitude `A` of eq. 18's SNR (see the module docs).
    pub fn amplitude(&self, snr_db: f64) -> f64 {
        let w = window_of(self.window, self.m);
        let s: f64 = w.iter().sum();
        (10f64.powf(snr_db / 10.0) * self.bin_noise_var()).sqrt() / s
    }

    /// Simulates one run; `snr_db = None` is H0 (no target).
    pub fn simulate(&self, snr_db: Option<f64>, noise: Noise, rng: &mut Rng) -> Run {
        let m = self.m;
        let w = window_of(self.window, m);
        let dt = self.ts * m as f64;
        let mut state = snr_db.map(|s| {
            [
                self.fd0.0 + (self.fd0.1 - self.fd0.0) * uniform64(rng),
                self.fda0.0 + (self.fda0.1 - self.fda0.0) * uniform64(rng),
                self.amplitude(s),
            ]
        });
        let band = (-0.5 / self.ts, 0.5 / self.ts);
        let mut frames = Vec::with_capacity(self.frames);
        let mut truth = Vec::with_capacity(self.frames);
        let mut time = vec![(0.0f64, 0.0f64); m];
        let tw = twiddles(m);
        let ln_alpha = cgg_ln_alpha(self.cgg_shape, self.noise_var);
        for k in 1..=self.frames {
            let present = k >= self.first && k <= self.last;
            if present && k > self.first {
                if let Some(x) = state.as_mut() {
                    let v1 = rng.normal() as f64 * self.accel_std;
                    let v2 = rng.normal() as f64 * self.amp_std;
                    let mut fd = x[0] + dt * x[1] + 0.5 * dt * dt * v1;
                    let width = band.1 - band.0;
                    fd -= width * ((fd - band.0) / width).floor();
                    x[0] = fd;
                    x[1] += dt * v1;
                    x[2] = (x[2] + dt * v2).abs();
                }
            }
            for t in time.iter_mut() {
                *t = match noise {
                    Noise::Gaussian => complex_gaussian(self.noise_var, rng),
                    Noise::Cgg => cgg_with(self.cgg_shape, ln_alpha, rng),
                };
            }
            let tr = if present { state } else { None };
            if let Some(x) = tr {
                // One draw per frame with a target, only for a random phase (the preset's
                // streams are unchanged).
                let phi0 = if self.random_phase {
                    2.0 * std::f64::consts::PI * uniform64(rng)
                } else {
                    0.0
                };
                for (n, t) in time.iter_mut().enumerate() {
                    let ph = phi0 + 2.0 * std::f64::consts::PI * x[0] * n as f64 * self.ts;
                    t.0 += x[2] * ph.cos();
                    t.1 += x[2] * ph.sin();
                }
            }
            frames.push(windowed_dft_with(&time, &w, &tw));
            truth.push(tr);
        }
        Run { frames, truth }
    }
}

/// `z_b = sum_n w_n s_n exp(-j 2 pi b n / m)` in `f64`, rounded to `Complex32`.
pub fn windowed_dft(s: &[(f64, f64)], w: &[f64]) -> Vec<Complex32> {
    let tw = twiddles(s.len());
    windowed_dft_with(s, w, &tw)
}

/// `exp(-j 2 pi t / m)` for `t = 0..m`.
pub fn twiddles(m: usize) -> Vec<(f64, f64)> {
    (0..m)
        .map(|t| {
            let ph = -2.0 * std::f64::consts::PI * t as f64 / m as f64;
            (ph.cos(), ph.sin())
        })
        .collect()
}

/// [`windowed_dft`] with precomputed [`twiddles`].
pub fn windowed_dft_with(s: &[(f64, f64)], w: &[f64], tw: &[(f64, f64)]) -> Vec<Complex32> {
    let m = s.len();
    (0..m)
        .map(|b| {
            let (mut re, mut im) = (0.0f64, 0.0f64);
            for n in 0..m {
                let (c, sn) = tw[(b * n) % m];
                let (xr, xi) = (w[n] * s[n].0, w[n] * s[n].1);
                re += xr * c - xi * sn;
                im += xr * sn + xi * c;
            }
            Complex32::new(re as f32, im as f32)
        })
        .collect()
}

/// Uniform in `[0, 1)` with 53 random bits.
pub fn uniform64(rng: &mut Rng) -> f64 {
    (rng.next_u64() >> 11) as f64 * (1.0 / 9_007_199_254_740_992.0)
}

/// Standard normal in `f64` (Box-Muller on 53-bit uniforms).
pub fn normal64(rng: &mut Rng) -> f64 {
    let u1 = 1.0 - uniform64(rng); // (0, 1]
    let u2 = uniform64(rng);
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// Circular complex Gaussian of variance `s2 = E|w|^2`.
pub fn complex_gaussian(s2: f64, rng: &mut Rng) -> (f64, f64) {
    let s = (0.5 * s2).sqrt();
    (s * normal64(rng), s * normal64(rng))
}

/// `Gamma(shape, 1)` by Marsaglia and Tsang (2000), `shape >= 1` (boosted below 1).
pub fn gamma(shape: f64, rng: &mut Rng) -> f64 {
    if shape < 1.0 {
        let u = 1.0 - uniform64(rng);
        return gamma(shape + 1.0, rng) * u.powf(1.0 / shape);
    }
    let d = shape - 1.0 / 3.0;
    let c = 1.0 / (9.0 * d).sqrt();
    loop {
        let x = normal64(rng);
        let v = 1.0 + c * x;
        if v <= 0.0 {
            continue;
        }
        let v = v * v * v;
        let u = 1.0 - uniform64(rng);
        if u.ln() < 0.5 * x * x + d - d * v + d * v.ln() {
            return d * v;
        }
    }
}

/// Circular complex generalized Gaussian of shape `c` and variance `s2` (pdf
/// proportional to `exp(-(alpha |w|^2)^c)`, Novey et al. 2010): `g ~ Gamma(1/c, 1)`,
/// `|w|^2 = g^(1/c) / alpha`, `alpha = Gamma(2/c) / (s2 Gamma(1/c))`, uniform phase.
/// Then `E|w|^2 = s2` and `E|w|^4 / (E|w|^2)^2 = Gamma(3/c) Gamma(1/c) / Gamma(2/c)^2`.
pub fn complex_generalized_gaussian(c: f64, s2: f64, rng: &mut Rng) -> (f64, f64) {
    cgg_with(c, cgg_ln_alpha(c, s2), rng)
}

/// `ln alpha = ln Gamma(2/c) - ln Gamma(1/c) - ln s2` of the CGG.
pub fn cgg_ln_alpha(c: f64, s2: f64) -> f64 {
    use statrs::function::gamma::ln_gamma;
    ln_gamma(2.0 / c) - ln_gamma(1.0 / c) - s2.ln()
}

/// [`complex_generalized_gaussian`] with a precomputed [`cgg_ln_alpha`].
pub fn cgg_with(c: f64, ln_alpha: f64, rng: &mut Rng) -> (f64, f64) {
    let g = gamma(1.0 / c, rng);
    let r2 = (g.ln() / c - ln_alpha).exp();
    let r = r2.sqrt();
    let ph = 2.0 * std::f64::consts::PI * uniform64(rng);
    (r * ph.cos(), r * ph.sin())
}

/// `E|w|^4 / (E|w|^2)^2` of the CGG of shape `c`.
pub fn cgg_kurtosis(c: f64) -> f64 {
    use statrs::function::gamma::ln_gamma;
    (ln_gamma(3.0 / c) + ln_gamma(1.0 / c) - 2.0 * ln_gamma(2.0 / c)).exp()
}

/// The preset as JSON (for `faint scenario othr`).
pub fn describe() -> serde_json::Value {
    let o = Othr::default();
    serde_json::json!({
        "preset": o,
        "window": "Hamming (symmetric)",
        "snr_definition": "SNR = 10 log10(A^2 (sum w)^2 / (noise_var sum w^2)) (eq. 18, bin-centred peak)",
        "bin_noise_var": o.bin_noise_var(),
        "amplitude_at_0db": o.amplitude(0.0),
        "cgg_kurtosis": cgg_kurtosis(o.cgg_shape),
        "detector_model": format!("{:?}", o.model()),
    })
}
