//! Cost of MHT-TBD (Bao et al. 2022) on the Cortex-M4F at the sea-clutter preset's densest
//! clutter: 398 clutter plots per scan (a fixed count, the Poisson mean), uniform over the
//! 6 km x 6 km area, plus 5 constant-velocity targets detected with Pd0 = 0.85 and 5 m
//! noise, 30 scans, `M = 3`, `256 x 180` grid, `gamma_1 = 22`. Scenes are generated from a
//! fixed seed before each measured step (not measured).

use core::mem::size_of;
use faint_core::detect::Detector;

use faint_core::detect::mht::{MhtConfig, MhtTbd};
use faint_core::model::plot::Plot;
use faint_core::rng::Rng;
use faint_core::scene;

use crate::harness::{check, measure, row, Measurement, Static};

const SEED: u64 = 0x0003_F4DA_C96F_92B1;
const LAMBDA: usize = 398;
const P: usize = 512;

type Det = MhtTbd<P, 30, 256, 180, 16>;

static DET: Static<Det> = Static::new(Det::unconfigured());
static SCAN: Static<[Plot; P]> = Static::new([Plot::new(0.0, 0.0, 0.0); P]);

/// Target `i` at scan `s`: fixed starts and velocities inside the area.
fn target(i: usize, s: usize) -> (f32, f32) {
    const T: [[f32; 4]; 5] = [
        [1000.0, 1200.0, 12.0, 5.0],
        [4800.0, 900.0, -6.0, 14.0],
        [3000.0, 3000.0, 3.0, -3.0],
        [1500.0, 5000.0, 15.0, -8.0],
        [5200.0, 4200.0, -11.0, -10.0],
    ];
    let t = T[i];
    let dt = 5.0 * s as f32;
    (t[0] + t[2] * dt, t[1] + t[3] * dt)
}

fn fill(rng: &mut Rng, s: usize, buf: &mut [Plot; P]) -> usize {
    let mut n = scene::clutter_plots(rng, [0.0, 6000.0, 0.0, 6000.0], &mut buf[..LAMBDA], |_| 1.0);
    for i in 0..5 {
        let (x, y) = target(i, s);
        if let Some((x, y)) = scene::detection(rng, 0.85, x, y, 5.0) {
            buf[n] = Plot::new(9.0, x, y);
            n += 1;
        }
    }
    n
}

/// Prints the MHT-TBD rows.
pub fn run() {
    let det = DET.take();
    let buf = SCAN.take();
    let mut cfg = MhtConfig::sea_clutter();
    cfg.gamma1 = 22;
    check(det.configure(&cfg, 0));
    let mut rng = Rng::from_stream(SEED, 0);
    let ram = size_of::<Det>() + size_of::<[Plot; P]>();
    let mut worst = Measurement {
        instructions: 0,
        stack_bytes: 0,
    };
    let mut sum = 0u64;
    let mut plots = 0u32;
    for s in 0..29 {
        let n = fill(&mut rng, s, buf);
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
    let n = fill(&mut rng, 29, buf);
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
