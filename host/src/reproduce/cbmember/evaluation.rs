//! Monte Carlo evaluation of `faint reproduce cbmember`: the filters of a set, one run
//! of the scene through them scored against the truth ([`Row`] per curve point), a set's
//! runs over the SNR grid, and the curves' Pd points.

use anyhow::Result;
use faint_core::detect::cbmember::{CbmemberConfig, Likelihood};
use faint_core::detect::Detector;
use faint_core::model::range_doppler::{quantise, Dequant, PointModel};
use faint_core::rng::Rng;
use serde::Serialize;

use crate::instances::boxed;
use crate::instances::cbmember::{HostFilter, HostFilterU8};
use crate::montecarlo::run_trial_range;
use crate::simulate::cbmember::{MapSource, RotorUav};
use crate::stats::detection::{proportion, PdPoint, Proportion};
use crate::stats::ospa::ospa;

/// Input kind of a filter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Input {
    Power,
    Quantised,
}

/// One filter of a set.
#[derive(Debug, Clone)]
pub(super) struct FilterSpec {
    pub(super) name: String,
    pub(super) cfg: CbmemberConfig,
    pub(super) input: Input,
}

/// Per run and filter.
#[derive(Debug, Clone, Copy, Default, Serialize, serde::Deserialize)]
pub(super) struct RunStats {
    hits: usize,
    scored: usize,
    reported: usize,
    ospa_all: f64,
    ospa_burn: f64,
    err_r2: f64,
    err_v2: f64,
    n_err: usize,
}

/// One point of a curve (a CSV row).
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct Row {
    /// Set and curve.
    pub set: String,
    /// Curve name.
    pub curve: String,
    /// SNR (dB).
    pub snr_db: f64,
    /// Runs.
    pub runs: usize,
    /// Scored (run, frame) pairs.
    pub frames: usize,
    /// Detections among them.
    pub hits: usize,
    /// Pd.
    pub pd: f64,
    /// Clopper-Pearson 95 % interval.
    pub pd_lo: f64,
    /// Upper end.
    pub pd_hi: f64,
    /// Standard error of `pd` over runs: the standard deviation of the runs' detected
    /// fractions over `sqrt(runs)`, which, unlike the Clopper-Pearson interval, allows for
    /// the correlation of a run's frames. Absent (0) in an older `curves.csv`.
    #[serde(default)]
    pub pd_se_runs: f64,
    /// Reported components per scored frame (target-free runs: false alarms per frame).
    pub reported_per_frame: f64,
    /// Mean OSPA over all frames.
    pub ospa: f64,
    /// Standard error of `ospa`: the standard deviation of the runs' mean OSPA over
    /// `sqrt(runs)` (runs are independent, a run's frames are not). Absent (0) in a
    /// `curves.csv` written before it existed.
    #[serde(default)]
    pub ospa_se: f64,
    /// Mean OSPA after the burn-in.
    pub ospa_after_burn_in: f64,
    /// RMSE of the matched component's range (m).
    pub rmse_range_m: f64,
    /// RMSE of its velocity (m/s).
    pub rmse_velocity_mps: f64,
}

fn one_run(sc: &RotorUav, filters: &[FilterSpec], rng: &mut Rng) -> Result<Vec<RunStats>> {
    let truth = sc.truth();
    let mut map_rng = rng.fork(1);
    let mut src = MapSource::new(sc);
    let mut power: Vec<Box<HostFilter>> = Vec::new();
    let mut quant: Vec<Box<HostFilterU8>> = Vec::new();
    for (k, f) in filters.iter().enumerate() {
        let seed = rng.fork(10 + k as u64).next_u64();
        let e = |e| anyhow::anyhow!("{}: {e}", f.name);
        match f.input {
            Input::Power => power.push(boxed::<HostFilter>(&f.cfg, seed).map_err(e)?),
            Input::Quantised => quant.push(boxed::<HostFilterU8>(&f.cfg, seed).map_err(e)?),
        }
    }
    let dq = Dequant::new(sc.filter.noise_var, sc.filter.quant_step);
    let mut stats = vec![RunStats::default(); filters.len()];
    let mut map = Vec::new();
    let mut qmap = Vec::new();
    let bin = sc.geometry().range_bin as f64;
    let (c, p) = sc.ospa;
    for (k, t) in truth.iter().enumerate() {
        src.power(sc, t, k, &mut map_rng, &mut map);
        if !quant.is_empty() {
            qmap.clear();
            qmap.extend(
                map.iter()
                    .map(|&z| quantise(z * dq.scale, sc.filter.quant_step)),
            );
        }
        let (mut ip, mut iq) = (0usize, 0usize);
        for (f, st) in filters.iter().zip(stats.iter_mut()) {
            let dets: Vec<[f64; 2]> = match f.input {
                Input::Power => {
                    let d = &mut power[ip];
                    ip += 1;
                    d.step(&map[..])
                        .map_err(|e| anyhow::anyhow!("{}: {e}", f.name))?;
                    d.detections()
                        .map(|x| [x.state()[0] as f64, x.state()[1] as f64])
                        .collect()
                }
                Input::Quantised => {
                    let d = &mut quant[iq];
                    iq += 1;
                    d.step(&qmap[..])
                        .map_err(|e| anyhow::anyhow!("{}: {e}", f.name))?;
                    d.detections()
                        .map(|x| [x.state()[0] as f64, x.state()[1] as f64])
                        .collect()
                }
            };
            let tr: Vec<[f64; 2]> = if sc.present {
                vec![[t.range, t.velocity]]
            } else {
                vec![]
            };
            let o = ospa(&dets, &tr, c, p).distance;
            st.ospa_all += o;
            if k < sc.burn_in {
                continue;
            }
            st.ospa_burn += o;
            st.scored += 1;
            st.reported += dets.len();
            if sc.present {
                let best = dets
                    .iter()
                    .filter(|d| {
                        (d[0] - t.range).abs() <= sc.gate[0] * bin
                            && (d[1] - t.velocity).abs() <= sc.gate[1]
                    })
                    .min_by(|a, b| {
                        let da = (a[0] - t.range).powi(2) + (a[1] - t.velocity).powi(2);
                        let db = (b[0] - t.range).powi(2) + (b[1] - t.velocity).powi(2);
                        da.total_cmp(&db)
                    });
                if let Some(d) = best {
                    st.hits += 1;
                    st.err_r2 += (d[0] - t.range).powi(2);
                    st.err_v2 += (d[1] - t.velocity).powi(2);
                    st.n_err += 1;
                }
            }
        }
    }
    Ok(stats)
}

/// A set's runs `range` at one SNR point of scene `sc` through `filters`: run `i`
/// draws from `Rng::from_stream(master, i)`, whichever range (shard) runs it.
pub(super) fn run_point(
    sc: &RotorUav,
    filters: &[FilterSpec],
    range: std::ops::Range<usize>,
    master: u64,
    label: &str,
) -> Result<Vec<Vec<RunStats>>> {
    let all: Vec<Result<Vec<RunStats>>> = crate::montecarlo::pool()
        .install(|| run_trial_range(master, range, label, |_, rng| one_run(sc, filters, rng)));
    all.into_iter().collect()
}

/// The rows (one per filter) of a set's SNR point from its runs `all`, summed in run
/// order.
pub(super) fn point_rows(
    set: &str,
    snr: f64,
    sc: &RotorUav,
    fs: &[FilterSpec],
    all: &[Vec<RunStats>],
) -> Vec<Row> {
    let runs = all.len();
    let mut rows = Vec::new();
    for (k, f) in fs.iter().enumerate() {
        let mut s = RunStats::default();
        let per_run: Vec<f64> = all
            .iter()
            .map(|r| r[k].ospa_all / sc.frames.max(1) as f64)
            .collect();
        let pd_per_run: Vec<f64> = all
            .iter()
            .map(|r| r[k].hits as f64 / r[k].scored.max(1) as f64)
            .collect();
        for r in all {
            let x = r[k];
            s.hits += x.hits;
            s.scored += x.scored;
            s.reported += x.reported;
            s.ospa_all += x.ospa_all;
            s.ospa_burn += x.ospa_burn;
            s.err_r2 += x.err_r2;
            s.err_v2 += x.err_v2;
            s.n_err += x.n_err;
        }
        let pd = proportion(s.hits, s.scored);
        let n_err = s.n_err.max(1) as f64;
        rows.push(Row {
            set: set.to_string(),
            curve: f.name.clone(),
            snr_db: snr,
            runs,
            frames: s.scored,
            hits: s.hits,
            pd: pd.p,
            pd_lo: pd.lo,
            pd_hi: pd.hi,
            pd_se_runs: standard_error(&pd_per_run),
            reported_per_frame: s.reported as f64 / s.scored.max(1) as f64,
            ospa: s.ospa_all / (runs * sc.frames) as f64,
            ospa_se: standard_error(&per_run),
            ospa_after_burn_in: s.ospa_burn / s.scored.max(1) as f64,
            rmse_range_m: if s.n_err > 0 {
                (s.err_r2 / n_err).sqrt()
            } else {
                f64::NAN
            },
            rmse_velocity_mps: if s.n_err > 0 {
                (s.err_v2 / n_err).sqrt()
            } else {
                f64::NAN
            },
        });
    }
    rows
}

/// Standard error of the mean of `x` (sample standard deviation over `sqrt(n)`; 0 for
/// fewer than two values).
fn standard_error(x: &[f64]) -> f64 {
    let n = x.len();
    if n < 2 {
        return 0.0;
    }
    let m = x.iter().sum::<f64>() / n as f64;
    let v = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1) as f64;
    (v / n as f64).sqrt()
}

pub(super) fn joint(sc: &RotorUav, particles: usize) -> FilterSpec {
    FilterSpec {
        name: format!("joint {particles}"),
        cfg: sc.config(PointModel::Joint, particles),
        input: Input::Power,
    }
}

pub(super) fn doppler(sc: &RotorUav, particles: usize) -> FilterSpec {
    FilterSpec {
        name: format!("Doppler-only {particles}"),
        cfg: sc.config(PointModel::DopplerOnly, particles),
        input: Input::Power,
    }
}

/// The filter with `zeta_v` matched to the physical generator's peak (about one FFT bin
/// plus the blades' smear within a CPI): `zeta_v = 0.2` m/s, exact likelihood (the
/// support is about 11 bins wide, narrower than a 16-bin block).
pub(super) fn matched(mut f: FilterSpec) -> FilterSpec {
    f.cfg.spread.zeta_v = 0.2;
    f.cfg.likelihood = Likelihood::Exact;
    f.name = format!("{} (zeta_v 0.2)", f.name);
    f
}

/// Points of a curve.
pub(super) fn curve(rows: &[Row], set: &str, name: &str) -> Vec<PdPoint> {
    rows.iter()
        .filter(|r| r.set == set && r.curve == name)
        .map(|r| PdPoint {
            snr_db: r.snr_db,
            pd: Proportion {
                k: r.hits,
                n: r.frames,
                p: r.pd,
                lo: r.pd_lo,
                hi: r.pd_hi,
            },
        })
        .collect()
}

/// Runs per point of `set` (the sets of a run merged with `--previous` can differ).
pub(super) fn runs_per_point(rows: &[Row], set: &str) -> usize {
    rows.iter()
        .filter(|r| r.set == set)
        .map(|r| r.runs)
        .max()
        .unwrap_or(0)
}
