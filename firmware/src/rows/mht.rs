//! Cost of MHT-TBD (Bao et al. 2022) on the Cortex-M4F at the sea-clutter preset's densest
//! clutter: 398 clutter plots per scan (a fixed count, the Poisson mean), uniform over the
//! 6 km x 6 km area, plus 5 constant-velocity targets detected with Pd0 = 0.85 and 5 m
//! noise, 30 scans, `M = 3`, `256 x 180` grid, `gamma_1 = 22`. Scenes are generated from a
//! fixed seed before each measured step (not measured; `faint_golden::mht::cost_scan`,
//! shared with the cycle image).

use core::mem::size_of;
use faint_core::detect::Detector;

use faint_core::detect::mht::{MhtConfig, MhtTbd};
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;
use faint_golden::mht::{cost_scan, COST_SEED};

use faint_firmware::harness::{check, measure, row, Measurement};
use faint_firmware::statics::Static;

const P: usize = 512;

type Det = MhtTbd<P, 30, 256, 180, 32>;

static DET: Static<Det> = Static::new(Det::new_unconfigured());
static SCAN: Static<[Plot; P]> = Static::new([Plot::new(0.0, 0.0, 0.0); P]);

/// Prints the MHT-TBD rows.
pub fn run() {
    let det = DET.take();
    let buf = SCAN.take();
    let mut cfg = MhtConfig::sea_clutter();
    cfg.gamma1 = 22;
    check(det.configure(&cfg, 0));
    let mut rng = Rng::from_stream(COST_SEED, 0);
    let ram = size_of::<Det>() + size_of::<[Plot; P]>();
    let mut worst = Measurement {
        instructions: 0,
        stack_bytes: 0,
    };
    let mut sum = 0u64;
    let mut plots = 0u32;
    for s in 0..29 {
        let n = cost_scan(&mut rng, s, buf);
        let (r, m) = measure(|| det.step(&buf[..n]));
        check(r);
        if s >= 2 {
            sum += m.instructions;
            plots += n as u32;
            if m.instructions > worst.instructions {
                worst = m;
            }
        }
    }
    let mean = Measurement {
        instructions: sum / 27,
        stack_bytes: worst.stack_bytes,
    };
    row(
        "MHT-TBD censoring step, mean of scans 2..28 (lambda 398)",
        plots / 27,
        "plot",
        mean,
        ram,
    );
    row(
        "MHT-TBD censoring step, worst scan (lambda 398)",
        plots / 27,
        "plot",
        worst,
        ram,
    );
    let n = cost_scan(&mut rng, 29, buf);
    let (r, m) = measure(|| det.step(&buf[..n]));
    let rep = check(r);
    let eff = rep.detection.map_or(0, |d| d.effective_plots);
    row(
        "MHT-TBD period end: censoring + DMHT + peaks + association",
        eff,
        "effective plot",
        m,
        ram,
    );
    let tracks = det.tracks().len();
    cortex_m_semihosting::hprintln!(
        "MHT-TBD period: {} effective plots, {} confirmed tracks",
        eff,
        tracks
    );
}
