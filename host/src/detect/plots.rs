//! The plot detectors: MHT-TBD and the classic Hough TBD.

use anyhow::{anyhow, ensure, Result};
use faint_core::detect::mht::{ClassicHoughConfig, MhtConfig};

use faint_core::detect::Detector;

use faint_core::model::plot::Plot;
use serde::{Deserialize, Serialize};

use super::{drive, find_default, json, load, valid, InputView, Outcome, Request, XY_POSITION};
use crate::analysis::mht::{classic_gamma, max_count};
use crate::instances::mht::{Classic, Mht, ANGLE_CELLS, RANGE_CELLS, SCANS};
use crate::io::input::read_plots;
use crate::simulate::mht::SeaClutter;
use crate::stats::noise::median;
use crate::timing::thread_cpu_seconds as cpu;

/// A plot detector's configuration file.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlotFile<C> {
    /// Whole-grid false-alarm probability per integration period, in `(0, 1)`: the
    /// count threshold (`config.gamma1`, `config.gamma`) is set from the clutter density
    /// measured in the input ([`clutter_density`]) by the grid false-alarm model of the
    /// detector. `null` keeps the configuration's threshold.
    pub gamma_grid_pfa: Option<f64>,
    /// The core configuration.
    pub config: C,
}

/// The false-alarm probability per integration period of the defaults: the smallest
/// that MHT-TBD's simulation ([`mht_gamma`], `10 / pfa` periods) sets in seconds to a
/// minute.
pub const DEFAULT_GRID_PFA: f64 = 1e-2;

/// MHT-TBD's default configuration file: the sea-clutter preset, its threshold set from
/// the input's clutter density.
pub(super) fn default_mht() -> String {
    json(&PlotFile {
        gamma_grid_pfa: Some(DEFAULT_GRID_PFA),
        config: MhtConfig::sea_clutter(),
    })
}

/// The classic Hough TBD's default configuration file ([`default_classic`]), its
/// threshold set from the input's clutter density.
pub(super) fn default_hough() -> String {
    json(&PlotFile {
        gamma_grid_pfa: Some(DEFAULT_GRID_PFA),
        config: default_classic(),
    })
}

/// Clutter plots per scan of `scans`: the median count, which the few plots of targets
/// do not move the way they move the mean.
pub fn clutter_density(scans: &[Vec<Plot>]) -> f64 {
    let mut counts: Vec<f64> = scans.iter().map(|s| s.len() as f64).collect();
    median(&mut counts).unwrap_or(0.0)
}

/// Clutter-only periods simulated per unit of `1 / pfa` by [`mht_gamma`]: at the chosen
/// `gamma_1` at most `pfa T` of `T = 10 / pfa` periods have a confirmed track.
pub const PERIODS_PER_PFA: f64 = 10.0;

/// `gamma_1` of MHT-TBD for a whole-grid false-track probability `pfa` per period at
/// `lambda` clutter plots per scan, measured by simulation with `config` itself:
/// `T = ceil(10 / pfa)` periods of Poisson(`lambda`) plots uniform over the area (period
/// `i` from `Rng::from_stream(seed, i)`), each integrated once and re-thresholded at
/// every candidate ([`MhtTbd::redetect`](faint_core::detect::mht::MhtTbd::redetect)); the
/// smallest `g` such that every `g' >= g` has at most `pfa T` periods with a confirmed
/// track; `N + 1` (no confirmation) if even `N` fails. The grid models are conservative
/// here (they ignore the track confirmation: at lambda 398 the compound model gives 29
/// where the paper and this simulation give 21-22, see docs/mht.md).
pub fn mht_gamma(config: &MhtConfig, lambda: f64, pfa: f64, seed: u64) -> Result<usize> {
    let n = config.n_scans;
    let periods = (PERIODS_PER_PFA / pfa).ceil() as usize;
    let [x0, x1, y0, y1] = config.area;
    let mut step_cfg = *config;
    step_cfg.gamma1 = (n + 1).min(255) as u8;
    let counts: Vec<Result<Vec<bool>>> =
        crate::montecarlo::run_trials(seed, periods, "gamma_1 from clutter", |_, rng| {
            let mut m = crate::instances::boxed::<Mht>(&step_cfg, 0)?;
            let mut with = vec![false; n + 2];
            for _ in 0..n {
                let k = crate::simulate::mht::poisson(rng, lambda as f32);
                let plots: Vec<Plot> = (0..k)
                    .map(|_| Plot::new(1.0, rng.uniform_range(x0, x1), rng.uniform_range(y0, y1)))
                    .collect();
                m.step(&plots)
                    .map_err(|e| anyhow!("simulated clutter: {e}"))?;
            }
            let top = usize::from(max_count(m.accumulator())).min(n);
            for (g, w) in with.iter_mut().enumerate().take(top + 1).skip(1) {
                if let Ok(d) = m.redetect(g as u8) {
                    *w = d.tracks > 0;
                }
            }
            Ok(with)
        });
    let mut with_track = vec![0usize; n + 2];
    for c in counts {
        for (t, w) in with_track.iter_mut().zip(c?) {
            *t += usize::from(w);
        }
    }
    let allowed = pfa * periods as f64;
    let mut g = n + 1;
    while g > 1 && with_track[g - 1] as f64 <= allowed {
        g -= 1;
    }
    Ok(g)
}

/// The classic Hough threshold for a whole-grid `pfa` per period at `lambda` plots per
/// scan (the binomial strip model over the square of the area's mean side); `N + 1` when
/// no count holds it.
pub fn classic_threshold(config: &ClassicHoughConfig, lambda: f64, pfa: f64) -> usize {
    let [x0, x1, y0, y1] = config.area.map(f64::from);
    let side = ((x1 - x0) * (y1 - y0)).sqrt();
    classic_gamma(side, RANGE_CELLS, ANGLE_CELLS, config.n_scans, lambda, pfa)
}

fn check_grid_pfa(p: Option<f64>) -> Result<()> {
    if let Some(p) = p {
        ensure!(
            p > 0.0 && p < 1.0,
            "gamma_grid_pfa = {p}: must be in (0, 1), or null to keep the config's threshold"
        );
    }
    Ok(())
}

/// The classic Hough TBD's default: the sea-clutter area and period, and the threshold
/// the binomial strip model gives for a whole-grid false-alarm rate of 1e-4 at a clutter
/// density of 80 plots per scan (28 counts; the reproduction's value at that density).
pub fn default_classic() -> ClassicHoughConfig {
    let sc = SeaClutter::paper(80.0);
    let gamma = crate::analysis::mht::classic_gamma(
        f64::from(sc.area[1] - sc.area[0]),
        RANGE_CELLS,
        ANGLE_CELLS,
        sc.n_scans,
        f64::from(sc.lambda),
        1e-4,
    );
    ClassicHoughConfig {
        area: sc.area,
        n_scans: sc.n_scans,
        gamma: gamma.min(255) as u8,
    }
}

pub(super) fn run_mht(req: &Request) -> Result<Outcome> {
    let t = cpu();
    let file: PlotFile<MhtConfig> = load(req, find_default("mht"), |f: &PlotFile<MhtConfig>| {
        check_grid_pfa(f.gamma_grid_pfa)?;
        valid(&f.config)?;
        ensure!(
            f.config.n_scans <= SCANS,
            "invalid configuration value: n_scans (at most {} here)",
            SCANS
        );
        Ok(())
    })?;
    let scans = read_plots(req.input)?;
    let mut cfg = file.config;
    let mut notes = Vec::new();
    if let Some(pfa) = file.gamma_grid_pfa {
        let lambda = clutter_density(&scans);
        let g = mht_gamma(&cfg, lambda, pfa, req.seed)?;
        cfg.gamma1 = g.min(cfg.n_scans + 1) as u8;
        notes.push(format!(
            "clutter density {lambda} plots per scan (median): gamma_1 = {} for at most \
             {pfa} periods of {} scans with a false track ({} clutter-only periods simulated)",
            cfg.gamma1,
            cfg.n_scans,
            (PERIODS_PER_PFA / pfa).ceil()
        ));
    }
    let read = cpu() - t;
    let mut det = crate::instances::boxed::<Mht>(&cfg, req.seed)?;
    let mut out = drive(
        "mht",
        det.as_mut(),
        scans.iter().map(|s| s.as_slice()),
        req,
        XY_POSITION,
    )?;
    out.view = InputView::Plots(scans);
    out.read_seconds = read;
    out.notes = notes;
    Ok(out)
}

pub(super) fn run_classic(req: &Request) -> Result<Outcome> {
    let t = cpu();
    let file: PlotFile<ClassicHoughConfig> = load(
        req,
        find_default("hough-classic"),
        |f: &PlotFile<ClassicHoughConfig>| {
            check_grid_pfa(f.gamma_grid_pfa)?;
            valid(&f.config)
        },
    )?;
    let scans = read_plots(req.input)?;
    let mut cfg = file.config;
    let mut notes = Vec::new();
    let mut warnings = Vec::new();
    if let Some(pfa) = file.gamma_grid_pfa {
        let lambda = clutter_density(&scans);
        let g = classic_threshold(&cfg, lambda, pfa);
        if g > cfg.n_scans {
            warnings.push(format!(
                "hough-classic: at the measured clutter density of {lambda} plots per scan \
                 no count threshold up to {} scans holds a grid Pfa of {pfa} per period: \
                 nothing will be declared (MHT-TBD holds it, see docs/mht.md)",
                cfg.n_scans
            ));
        }
        cfg.gamma = g.min(255) as u8;
        notes.push(format!(
            "clutter density {lambda} plots per scan (median): gamma = {} for a grid Pfa \
             of {pfa} per period of {} scans",
            cfg.gamma, cfg.n_scans
        ));
    }
    let read = cpu() - t;
    let mut det = crate::instances::boxed::<Classic>(&cfg, 0)?;
    det.configure(&cfg, req.seed).map_err(|e| anyhow!("{e}"))?;
    let mut out = drive(
        "hough-classic",
        det.as_mut(),
        scans.iter().map(|s| s.as_slice()),
        req,
        &[],
    )?;
    out.view = InputView::Plots(scans);
    out.read_seconds = read;
    out.notes = notes;
    out.warnings = warnings;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The classic threshold rises with the density and, on the preset's area and
    /// period, no count holds a 0.01 grid Pfa per period from some density on: the
    /// density the docs quote for the warning (printed with `--nocapture`).
    #[test]
    fn classic_threshold_rises_then_cannot_hold() {
        let h = default_classic();
        let mut last = 0;
        let mut first_fail = None;
        for lambda in (10..=400).step_by(10) {
            let g = classic_threshold(&h, f64::from(lambda), DEFAULT_GRID_PFA);
            assert!(g >= last, "lambda {lambda}: {g} < {last}");
            last = g;
            if g > h.n_scans && first_fail.is_none() {
                first_fail = Some(lambda);
            }
        }
        println!("classic: no threshold from lambda {first_fail:?}");
        assert!(first_fail.is_some_and(|l| (50..=400).contains(&l)));
    }
}
