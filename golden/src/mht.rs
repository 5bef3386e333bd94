//! MHT-TBD (Bao et al. 2022): censoring flags, DMHT geometry and recovered tracks of a small
//! scene (1.5 km square, 10 scans, 40 clutter plots per scan, 2 targets), and the classic
//! detector's peaks on the same scans. Stack use ~14 KiB (the detector lives on the stack).

use crate::{Fold, ERR, SEED};
use faint_core::detect::mht::{ClassicHough, ClassicHoughConfig, MhtConfig, MhtTbd};
use faint_core::detect::Detector;
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;
use faint_core::simulate;

type Det = MhtTbd<48, 10, 32, 30, 4>;

/// Seed of the firmware's MHT-TBD cost scene ([`cost_scan`]).
pub const COST_SEED: u64 = 0x0003_F4DA_C96F_92B1;

/// Clutter plots per scan of [`cost_scan`]: the sea-clutter preset's densest clutter (a
/// fixed count, the Poisson mean).
pub const COST_CLUTTER: usize = 398;

/// Target `i` (0..5) of [`cost_scan`] at scan `s`: fixed starts and velocities inside
/// the 6 km x 6 km area.
fn cost_target(i: usize, s: usize) -> (f32, f32) {
    const T: [[f32; 4]; 5] = [
        [1000.0, 1200.0, 12.0, 5.0],
        [4800.0, 900.0, -6.0, 14.0],
        [3000.0, 3000.0, 3.0, -3.0],
        [1500.0, 5000.0, 15.0, -8.0],
        [5200.0, 4200.0, -11.0, -10.0],
    ];
    let t = T[i % 5];
    let dt = 5.0 * s as f32;
    (t[0] + t[2] * dt, t[1] + t[3] * dt)
}

/// Scan `s` of the firmware's MHT-TBD cost scene (its instruction rows and the cycle
/// image): [`COST_CLUTTER`] clutter plots uniform over 6 km x 6 km, then the 5 targets,
/// each detected with probability 0.85 and 5 m noise. Writes `out[..n]`, returns `n`
/// (`out` needs `COST_CLUTTER + 5` plots; a shorter one gets fewer).
pub fn cost_scan(rng: &mut Rng, s: usize, out: &mut [Plot]) -> usize {
    let k = COST_CLUTTER.min(out.len());
    let mut n = simulate::clutter_plots(rng, [0.0, 6000.0, 0.0, 6000.0], &mut out[..k], |_| 1.0);
    for i in 0..5 {
        let (x, y) = cost_target(i, s);
        if let Some((x, y)) = simulate::detection(rng, 0.85, x, y, 5.0) {
            if let Some(o) = out.get_mut(n) {
                *o = Plot::new(9.0, x, y);
                n += 1;
            }
        }
    }
    n
}

fn scan(rng: &mut Rng, s: usize, out: &mut [Plot; 48]) -> usize {
    let n = simulate::clutter_plots(rng, [0.0, 1500.0, 0.0, 1500.0], &mut out[..40], |_| 1.0);
    let t = s as f32;
    out[n] = Plot::new(5.0, 200.0 + 60.0 * t + 4.0 * rng.normal(), 300.0 + 40.0 * t);
    out[n + 1] = Plot::new(
        5.0,
        1200.0 - 30.0 * t,
        200.0 + 70.0 * t + 4.0 * rng.normal(),
    );
    n + 2
}

pub(crate) fn cases(emit: &mut dyn FnMut(&str, &[u32])) {
    let mut cfg = MhtConfig::sea_clutter();
    cfg.area = [0.0, 1500.0, 0.0, 1500.0];
    cfg.n_scans = 10;
    cfg.gamma1 = 6;
    let mut det = Det::new_unconfigured();
    let ccfg = ClassicHoughConfig {
        area: cfg.area,
        n_scans: 10,
        gamma: 8,
    };
    let (Ok(()), Ok(mut classic)) = (det.configure(&cfg, 0), ClassicHough::<32, 30, 4>::new(ccfg))
    else {
        emit("mht.detection", &[ERR]);
        return;
    };
    let mut rng = Rng::from_stream(SEED, 3);
    let mut buf = [Plot::default(); 48];
    let mut detection = None;
    for s in 0..10 {
        let n = scan(&mut rng, s, &mut buf);
        match (det.step(&buf[..n]), classic.step(&buf[..n])) {
            (Ok(r), Ok(_)) => detection = r.detection.or(detection),
            _ => {
                emit("mht.detection", &[ERR]);
                return;
            }
        }
    }
    let mut flags = Fold::new();
    for s in 0..10 {
        for k in 0..det.scan_plots(s).len() {
            flags.push(u32::from(det.is_effective(s, k)));
        }
    }
    emit("mht.effective_flags", &[flags.value()]);
    match detection {
        Some(d) => emit(
            "mht.detection",
            &[
                d.effective_plots,
                d.origin.0.to_bits(),
                d.origin.1.to_bits(),
                d.drho.to_bits(),
                u32::from(d.condense.peaks),
                u32::from(d.tracks),
            ],
        ),
        None => emit("mht.detection", &[ERR]),
    }
    let mut tracks = Fold::new();
    for tr in det.tracks() {
        tracks.push(tr.theta.to_bits());
        tracks.push(tr.c.to_bits());
        tracks.push(u32::from(tr.peak.r) << 16 | u32::from(tr.peak.a));
        for &k in &tr.plots {
            tracks.push(u32::from(k));
        }
    }
    emit("mht.tracks", &[tracks.value()]);
    let mut peaks = Fold::new();
    for p in classic.peaks() {
        peaks.push(u32::from(p.r) << 16 | u32::from(p.a));
        peaks.push(u32::from(p.raw));
    }
    emit(
        "mht.classic_peaks",
        &[classic.peaks().len() as u32, peaks.value()],
    );
}
