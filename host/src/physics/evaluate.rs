//! `faint evaluate`: one detector on data from the physics simulator of its input kind,
//! at a calibrated false-alarm rate.
//!
//! 1. Calibration: `runs` noise-only (clutter-only) runs of `L` frames, simulated from
//!    [`Physics`] and written as one file, go through `faint calibrate`
//!    ([`crate::calibrate::run`], `--input`, `--run-frames L`): thresholds per frame index.
//! 2. False alarms: `runs` fresh noise-only runs through `faint detect`'s machinery
//!    ([`Request::restart_every`] `= L`); a run is a false alarm when its final frame
//!    `L - 1` declares a detection (a score above the threshold). The rate has a
//!    Clopper-Pearson 95 % interval. The calibration predicts that count: its threshold's
//!    true exceedance probability is `Beta(e + 1, n - e)` when `e` of its `n` runs exceed
//!    it (`e = n - ceil(n (1 - pfa))` for a continuous score, fewer for a discrete one that
//!    ties at the threshold), so the count is beta-binomial; the measurement is
//!    consistent when it falls in that law's central 95 % ([`calibration_prediction`]).
//! 3. Detection: for each SNR, `runs` runs with one target born anywhere in the region;
//!    Pd is the share whose final frame declares a detection and, where the detector
//!    reports positions, one within the kind's gate of the truth ([`Physics::gate`]).
//! 4. The SNR at Pd 0.9 by linear interpolation of Pd against SNR.
//!
//! Runs are simulated and detected in groups of [`GROUP`] runs (one file each, the
//! detector restarted every `L` frames), the groups in parallel on the Monte Carlo pool.
//! Run `i` of the calibration, the false-alarm and the detection sets draws from
//! `Rng::from_stream(derive_seed(seed, s), i)`, `s` = 1, 2, 3 (the detection set shares its
//! streams across SNR points); group `g`'s detector stream is `derive_seed(derive_seed(seed,
//! 10 + s), g)`. The results do not depend on the thread count.

use std::path::{Path, PathBuf};

use anyhow::{ensure, Context, Result};
use faint_core::rng::{derive_seed, Rng};
use serde::Serialize;
use statrs::distribution::{Beta, ContinuousCDF};

use super::{Phase, Physics, Swerling};
use crate::calibrate;
use crate::detect::calibration::Calibration;
use crate::detect::{self, Entry, Request};
use crate::stats::detection::{proportion, snr_at_pd, PdPoint, Proportion};

/// What a calibration predicts for the false alarms of fresh noise runs at frame `k`.
///
/// `e` of the calibration's `n` runs exceed frame `k`'s threshold (`e = n - r` for a
/// continuous score, the threshold being the order statistic of rank
/// `r = ceil(n (1 - pfa))`; fewer for a discrete score that ties at it). The threshold's
/// true exceedance probability is then `p ~ Beta(e + 1, n - e)` (exactly so for the order
/// statistic of a continuous score), and the count of `m` fresh runs that exceed it is
/// beta-binomial `BB(m, e + 1, n - e)`. Returns the 95 % interval of `p` and the central
/// 95 % interval `[k_lo, k_hi]` of that count.
pub fn calibration_prediction(
    cal: &Calibration,
    k: usize,
    pfa: f64,
    m: usize,
) -> Result<((f64, f64), (usize, usize))> {
    let n = cal.runs;
    let r = ((n as f64) * (1.0 - pfa)).ceil() as usize;
    let e = cal
        .exceedances_at(k)
        .unwrap_or(n.saturating_sub(r))
        .min(n.saturating_sub(1));
    let (a, b) = ((e + 1) as f64, (n - e) as f64);
    let beta = Beta::new(a, b)?;
    let p = (beta.inverse_cdf(0.025), beta.inverse_cdf(0.975));
    Ok((p, beta_binomial_interval(m, a, b)))
}

/// The central 95 % interval of a beta-binomial `BB(m, a, b)` count:
/// `P(k) = C(m, k) B(k + a, m - k + b) / B(a, b)`, summed in the log domain.
fn beta_binomial_interval(m: usize, a: f64, b: f64) -> (usize, usize) {
    use statrs::function::gamma::ln_gamma;
    let ln_beta = |x: f64, y: f64| ln_gamma(x) + ln_gamma(y) - ln_gamma(x + y);
    let mf = m as f64;
    let (mut cdf, mut lo, mut hi) = (0.0, None, m);
    for k in 0..=m {
        let kf = k as f64;
        let ln_p = ln_gamma(mf + 1.0) - ln_gamma(kf + 1.0) - ln_gamma(mf - kf + 1.0)
            + ln_beta(kf + a, mf - kf + b)
            - ln_beta(a, b);
        cdf += ln_p.exp();
        if lo.is_none() && cdf >= 0.025 {
            lo = Some(k);
        }
        if cdf >= 0.975 {
            hi = k;
            break;
        }
    }
    (lo.unwrap_or(0), hi)
}

/// Runs per file (and per parallel task).
pub const GROUP: usize = 25;

/// Largest calibration set (bytes of `f32` frames) `faint evaluate` simulates: it is held
/// in memory and written as one file.
pub const MAX_CALIBRATION_BYTES: f64 = 2e9;

/// Command line of `faint evaluate`.
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Detector, as listed by `faint detect --list`.
    pub detector: String,
    /// False-alarm probability per run's final frame, in (0, 1); needs runs * pfa >= 10.
    #[arg(long)]
    pub pfa: f64,
    /// SNR points in dB: a list `0,3,6` or a grid `a:b:step` [default: 0:15:3 (images
    /// 0:10:2)]; the meaning per kind is in the table's SNR column.
    #[arg(long, allow_hyphen_values = true)]
    pub snr_db: Option<String>,
    /// Runs of the calibration, of the false-alarm check and per SNR point.
    #[arg(long, default_value_t = 200)]
    pub runs: usize,
    /// Frames per run `L` [default: 20 Doppler frames, the configuration's n_scans for
    /// plots, 40 images, 10 power cubes or maps].
    #[arg(long)]
    pub frames: Option<usize>,
    /// Frames from the start that declare nothing.
    #[arg(long, default_value_t = 0)]
    pub burn_in: usize,
    /// Seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// The detector's JSON configuration [default: its defaults].
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Also write the Pd curve and the row as CSV here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Carrier phase from frame to frame (Doppler frames): random (independent dwells),
    /// continuous (one coherent signal) or zero (the presets' assumption; diagnosis only).
    #[arg(long, value_enum, default_value = "random")]
    pub phase: PhaseArg,
    /// Swerling case of the target's amplitude, 0, 1 or 3 (all but plots).
    #[arg(long, default_value_t = 0)]
    pub swerling: u8,
    /// Response of the power cubes' axes to a point target: `sinc` (a resolution-limited
    /// axis) or `gauss:SR,SD,SB`, the point spread of eq. 3 of Pei et al. (2019) with
    /// these standard deviations in cells (range, Doppler, azimuth). Power cubes only.
    #[arg(long, default_value = "sinc")]
    pub cube_spread: String,
    /// Power maps: rotor blades on the target (eq. 11 of the rotor-UAV paper, 2023; blade
    /// velocity 10 m/s, rotor rate 0.06 pi rad/s, wavelength 0.03 m), 0 for a point target.
    #[arg(long, default_value_t = 0)]
    pub rotor_blades: u32,
}

/// `--phase`.
#[derive(clap::ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum PhaseArg {
    /// Uniform per frame.
    Random,
    /// Continuous across frames.
    Continuous,
    /// Zero every frame.
    Zero,
}

/// One point of the Pd curve.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PdRow {
    /// SNR (dB).
    pub snr_db: f64,
    /// Runs whose final frame declared a detection (anywhere).
    pub declared: Proportion,
    /// Runs whose final frame declared one within the gate (= `declared` without
    /// positions).
    pub pd: Proportion,
}

/// What `faint evaluate` measured.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Evaluation {
    /// Detector.
    pub detector: String,
    /// Its input kind.
    pub input: String,
    /// Nominal Pfa.
    pub pfa: f64,
    /// Measured false-alarm rate at the final frame.
    pub pfa_measured: Proportion,
    /// The calibration's 95 % interval of its threshold's exceedance probability.
    pub calibration_interval: (f64, f64),
    /// The central 95 % of the false-alarm count the calibration predicts for `runs`
    /// fresh noise runs.
    pub predicted_false_alarms: (usize, usize),
    /// The rate the final frame's threshold achieved on the calibration's own runs
    /// (below `pfa` when a discrete score ties at it).
    pub pfa_achieved: f64,
    /// Runs per set.
    pub runs: usize,
    /// Frames per run.
    pub frames: usize,
    /// Gate of a correct position (`None`: the detector reports no positions).
    pub gate: Option<f64>,
    /// Its unit.
    pub gate_unit: String,
    /// The Pd curve.
    pub curve: Vec<PdRow>,
    /// SNR (dB) at Pd 0.9 (`None`: not reached).
    pub snr_at_09: Option<f64>,
    /// SNR definition of the kind.
    pub snr_definition: String,
    /// What the user set beyond the detector's defaults.
    pub user_set: String,
}

impl Evaluation {
    /// True if the fresh runs' false-alarm count lies in the central 95 % of the count
    /// the calibration predicts.
    pub fn consistent(&self) -> bool {
        let (lo, hi) = self.predicted_false_alarms;
        (lo..=hi).contains(&self.pfa_measured.k)
    }

    /// The Markdown table's header.
    pub fn header() -> &'static str {
        "| detector | input | SNR at Pd 0.9 (dB) | Pfa nominal (achieved) | Pfa measured [95 %] | as the calibration predicts [95 %] | runs | set by the user |\n|---|---|---|---|---|---|---|---|"
    }

    /// One Markdown row.
    pub fn row(&self) -> String {
        let top = self.curve.last().map_or(f64::NAN, |c| c.snr_db);
        let snr = match self.snr_at_09 {
            Some(s) => format!("{s:.1}"),
            None if self.curve.first().is_some_and(|c| c.pd.p >= 0.9) => {
                format!("below {:.1}", self.curve[0].snr_db)
            }
            None => format!("not reached up to {top:.1}"),
        };
        let (k_lo, k_hi) = self.predicted_false_alarms;
        let m = self.pfa_measured.n.max(1) as f64;
        let (lo, hi) = (k_lo as f64 / m, k_hi as f64 / m);
        format!(
            "| {} | {} | {snr} | {} ({:.3}) | {:.4} [{:.4}, {:.4}] | {} ([{lo:.4}, {hi:.4}]) | {} x {} frames | {} |",
            self.detector,
            self.input,
            self.pfa,
            self.pfa_achieved,
            self.pfa_measured.p,
            self.pfa_measured.lo,
            self.pfa_measured.hi,
            if self.consistent() { "yes" } else { "no" },
            self.runs,
            self.frames,
            self.user_set
        )
    }
}

/// The SNR list of `--snr-db`: a grid `a:b:step` or a comma list, each in [-60, 60].
pub fn snr_list(s: &str) -> Result<Vec<f64>> {
    let v = if s.contains(':') {
        crate::cli::grid("--snr-db", s)?
    } else {
        s.split(',')
            .map(|x| crate::cli::number("--snr-db", x.trim()))
            .collect::<Result<Vec<f64>>>()?
    };
    ensure!(!v.is_empty(), "--snr-db: no SNR given");
    for &x in &v {
        crate::cli::snr_db("--snr-db", x)?;
    }
    ensure!(
        v.windows(2).all(|w| w[0] < w[1]),
        "--snr-db '{s}': must increase"
    );
    Ok(v)
}

/// A scratch folder removed when dropped.
struct Scratch(PathBuf);

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs `faint evaluate`.
pub fn run(a: &Args) -> Result<Evaluation> {
    let entry = detect::find(&a.detector)?;
    crate::cli::probability("--pfa", a.pfa)?;
    crate::cli::runs("--runs", a.runs)?;
    let need = calibrate::runs_needed(a.pfa);
    ensure!(
        a.runs >= need,
        "--runs {}: --pfa {} needs at least {need} runs (runs * pfa >= 10)",
        a.runs,
        a.pfa
    );
    let text = match &a.config {
        Some(p) => std::fs::read_to_string(p)
            .with_context(|| format!("--config {}: cannot read", p.display()))?,
        None => (entry.default_config)(),
    };
    let config: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("--config: not JSON ({})", entry.name))?;
    let mut phys = Physics::for_detector(entry.input, &config)
        .with_context(|| format!("{}: its input kind", entry.name))?;
    let swerling = match a.swerling {
        0 => Swerling::Zero,
        1 => Swerling::One,
        3 => Swerling::Three,
        s => anyhow::bail!("--swerling {s}: must be 0, 1 or 3"),
    };
    match &mut phys {
        Physics::Doppler(p) => {
            p.swerling = swerling;
            p.phase = match a.phase {
                PhaseArg::Random => Phase::Random,
                PhaseArg::Continuous => Phase::Continuous,
                PhaseArg::Zero => Phase::Zero,
            };
        }
        Physics::Images(p) => p.swerling = swerling,
        Physics::Cubes(p) => {
            p.swerling = swerling;
            p.response = super::cubes::Response::parse(&a.cube_spread)?;
        }
        Physics::Maps(p) => {
            p.swerling = swerling;
            if a.rotor_blades > 0 {
                p.rotor = Some(super::maps::Rotor::rotor_uav(a.rotor_blades));
            }
        }
        Physics::Plots(_) => {}
    }
    ensure!(
        a.cube_spread == "sinc" || matches!(phys, Physics::Cubes(_)),
        "--cube-spread {}: only for power-cube detectors ({} reads {:?})",
        a.cube_spread,
        entry.name,
        entry.input
    );
    ensure!(
        a.rotor_blades == 0 || matches!(phys, Physics::Maps(_)),
        "--rotor-blades {}: only for power-map detectors (cbmember, cbmember-doppler)",
        a.rotor_blades
    );
    phys.validate()?;
    let l = match (a.frames, &phys) {
        (Some(l), _) => l,
        (None, Physics::Doppler(_)) => 20,
        (None, Physics::Plots(_)) => config
            .get("config")
            .and_then(|c| c.get("n_scans"))
            .and_then(serde_json::Value::as_u64)
            .unwrap_or(30) as usize,
        (None, Physics::Images(_)) => 40,
        (None, Physics::Cubes(_) | Physics::Maps(_)) => 10,
    };
    crate::cli::count("--frames", l, 1..=100_000)?;
    if let Some(shape) = phys.frame_shape() {
        // The calibration's runs are held in memory and written as one file.
        let bytes = 4.0 * a.runs as f64 * l as f64 * shape.iter().product::<usize>() as f64;
        ensure!(
            bytes <= MAX_CALIBRATION_BYTES,
            "--runs {} x --frames {l} frames of {shape:?} cells: the calibration file would \
             hold {:.1} GB (at most {:.0}); use fewer runs or frames, or a smaller geometry \
             in --config",
            a.runs,
            bytes / 1e9,
            MAX_CALIBRATION_BYTES / 1e9
        );
    }
    ensure!(
        a.burn_in < l,
        "--burn-in {} must be below --frames {l}",
        a.burn_in
    );
    let snrs = match &a.snr_db {
        Some(s) => snr_list(s)?,
        None => match phys {
            Physics::Images(_) => snr_list("0:10:2")?,
            _ => snr_list("0:15:3")?,
        },
    };
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let scratch = Scratch(std::env::temp_dir().join(format!(
        "faint-evaluate-{}-{call}-{}-{}",
        std::process::id(),
        entry.name,
        a.seed
    )));
    std::fs::create_dir_all(&scratch.0)
        .with_context(|| format!("cannot create {}", scratch.0.display()))?;
    let ext = if matches!(phys, Physics::Plots(_)) {
        "csv"
    } else {
        "npy"
    };

    // 1. Calibration on simulated noise.
    let cal_runs: Vec<_> = crate::montecarlo::run_trials(
        derive_seed(a.seed, 1),
        a.runs,
        "simulate noise",
        |_, rng| phys.simulate(l, None, rng),
    );
    let noise = scratch.0.join(format!("noise.{ext}"));
    phys.write(&cal_runs, &noise, None)?;
    drop(cal_runs);
    let cal_path = scratch.0.join("cal.json");
    let cal = calibrate::run(&calibrate::Args {
        detector: entry.name.to_string(),
        input: Some(noise),
        from_input: None,
        config: a.config.clone(),
        pfa: a.pfa,
        run_frames: Some(l),
        burn_in: a.burn_in,
        runs: None,
        seed: derive_seed(a.seed, 10),
        out: cal_path,
    })?;
    let (interval, predicted) = calibration_prediction(&cal, l - 1, a.pfa, a.runs)?;
    let pfa_achieved = cal
        .exceedances_at(l - 1)
        .map_or(a.pfa, |e| e as f64 / cal.runs.max(1) as f64);

    // 2. False alarms on fresh noise.
    let set = |s: u64, snr: Option<f64>| -> Result<Vec<(bool, bool)>> {
        measure(entry, &phys, a, &text, &cal, l, s, snr, &scratch.0)
    };
    let fa = set(2, None)?;
    let pfa_measured = proportion(fa.iter().filter(|x| x.0).count(), fa.len());

    // 3. Pd per SNR.
    let mut curve = Vec::with_capacity(snrs.len());
    for &snr in &snrs {
        let res = set(3, Some(snr))?;
        curve.push(PdRow {
            snr_db: snr,
            declared: proportion(res.iter().filter(|x| x.0).count(), res.len()),
            pd: proportion(res.iter().filter(|x| x.1).count(), res.len()),
        });
    }
    let points: Vec<PdPoint> = curve
        .iter()
        .map(|c| PdPoint {
            snr_db: c.snr_db,
            pd: c.pd,
        })
        .collect();
    let snr_at_09 = snr_at_pd(&points, 0.9).snr_db;
    let probe = detect_positions(entry);
    let mut user_set = format!("--pfa {}", a.pfa);
    if let Some(c) = &a.config {
        user_set.push_str(&format!(", --config {}", c.display()));
    }
    if a.phase != PhaseArg::Random {
        user_set.push_str(&format!(", --phase {:?}", a.phase).to_lowercase());
    }
    if a.swerling != 0 {
        user_set.push_str(&format!(", --swerling {}", a.swerling));
    }
    if a.cube_spread != "sinc" {
        user_set.push_str(&format!(", --cube-spread {}", a.cube_spread));
    }
    if a.burn_in > 0 {
        user_set.push_str(&format!(", --burn-in {}", a.burn_in));
    }
    if a.rotor_blades > 0 {
        user_set.push_str(&format!(", --rotor-blades {}", a.rotor_blades));
    }
    let ev = Evaluation {
        detector: entry.name.to_string(),
        input: format!("{:?}", entry.input),
        pfa: a.pfa,
        pfa_measured,
        calibration_interval: interval,
        predicted_false_alarms: predicted,
        pfa_achieved,
        runs: a.runs,
        frames: l,
        gate: probe.then(|| phys.gate()),
        gate_unit: phys.gate_unit().to_string(),
        curve,
        snr_at_09,
        snr_definition: phys.snr_definition().to_string(),
        user_set,
    };
    if let Some(out) = &a.out {
        let rows: Vec<CurveCsv> = ev
            .curve
            .iter()
            .map(|c| CurveCsv {
                detector: ev.detector.clone(),
                snr_db: c.snr_db,
                pd: c.pd.p,
                pd_lo: c.pd.lo,
                pd_hi: c.pd.hi,
                declared: c.declared.p,
                runs: c.pd.n,
                pfa: ev.pfa,
                pfa_measured: ev.pfa_measured.p,
                pfa_lo: ev.pfa_measured.lo,
                pfa_hi: ev.pfa_measured.hi,
            })
            .collect();
        crate::io::write_csv(out, &rows)?;
    }
    Ok(ev)
}

/// A row of `--out`.
#[derive(Serialize)]
struct CurveCsv {
    detector: String,
    snr_db: f64,
    pd: f64,
    pd_lo: f64,
    pd_hi: f64,
    declared: f64,
    runs: usize,
    pfa: f64,
    pfa_measured: f64,
    pfa_lo: f64,
    pfa_hi: f64,
}

/// True if the detector reports positions (hough-classic reports lines).
fn detect_positions(entry: &Entry) -> bool {
    entry.name != "hough-classic"
}

/// `a.runs` runs of set `s` (noise only when `snr` is `None`) through the detector with
/// `cal`; per run: (final frame declared a detection, one declared within the gate).
#[allow(clippy::too_many_arguments)]
fn measure(
    entry: &Entry,
    phys: &Physics,
    a: &Args,
    text: &str,
    cal: &Calibration,
    l: usize,
    s: u64,
    snr: Option<f64>,
    dir: &Path,
) -> Result<Vec<(bool, bool)>> {
    let groups = a.runs.div_ceil(GROUP);
    let sim_seed = derive_seed(a.seed, s);
    let det_seed = derive_seed(a.seed, 10 + s);
    let tag = match snr {
        None => "h0".to_string(),
        Some(x) => format!("snr{x}"),
    };
    let ext = if matches!(phys, Physics::Plots(_)) {
        "csv"
    } else {
        "npy"
    };
    let gated = detect_positions(entry);
    let out = crate::montecarlo::run_trials(det_seed, groups, entry.name, |g, _| {
        let first = g * GROUP;
        let count = GROUP.min(a.runs - first);
        let runs: Vec<_> = (0..count)
            .map(|i| {
                let mut rng = Rng::from_stream(sim_seed, (first + i) as u64);
                phys.simulate(l, snr, &mut rng)
            })
            .collect();
        let path = dir.join(format!("{tag}-{g}.{ext}"));
        phys.write(&runs, &path, None)?;
        let req = Request {
            input: &path,
            config: a.config.as_deref().zip(Some(text)),
            seed: derive_seed(det_seed, g as u64),
            reports: false,
            restart_every: Some(l),
            runs: None,
        };
        let outcome = (entry.run)(&req);
        let _ = std::fs::remove_file(&path);
        let outcome = outcome?;
        let mut res = vec![(false, false); count];
        for row in &outcome.rows {
            let (r, k) = (row.frame / l, row.frame % l);
            if r >= count || k != l - 1 || !cal.declares(k, row.score) {
                continue;
            }
            res[r].0 = true;
            let hit = match runs[r].truth.last() {
                Some(t) if gated => {
                    let est: Vec<f64> = outcome
                        .position
                        .iter()
                        .filter_map(|&i| row.state.get(i).map(|&v| f64::from(v)))
                        .collect();
                    phys.distance(&est, t) <= phys.gate()
                }
                Some(_) => true,
                None => false,
            };
            res[r].1 |= hit;
        }
        Ok::<_, anyhow::Error>(res)
    });
    let mut all = Vec::with_capacity(a.runs);
    for g in out {
        all.extend(g?);
    }
    Ok(all)
}

#[cfg(test)]
mod tests {
    use super::beta_binomial_interval;
    use statrs::distribution::{Binomial, DiscreteCDF};

    /// `BB(m, 1, 1)` is uniform on `0..=m`: with `m = 99` each count has 0.01, so the
    /// 2.5 % point is 2 (cdf 0.03) and the 97.5 % point 97 (cdf 0.98).
    #[test]
    fn beta_binomial_with_a_flat_prior_is_uniform() {
        assert_eq!(beta_binomial_interval(99, 1.0, 1.0), (2, 97));
    }

    /// With `a + b` large and `a / (a + b) = p` the law tends to Binomial(m, p): with
    /// `a + b = 10^6` the extra variance is `m / (a + b)` of the binomial's, so the
    /// quantiles agree with the binomial's.
    #[test]
    fn beta_binomial_tends_to_the_binomial() {
        let (m, p) = (400u64, 0.05);
        let bin = Binomial::new(p, m).unwrap();
        let want = (
            bin.inverse_cdf(0.025) as usize,
            bin.inverse_cdf(0.975) as usize,
        );
        assert_eq!(beta_binomial_interval(400, p * 1e6, (1.0 - p) * 1e6), want);
    }
}
