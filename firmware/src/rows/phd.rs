//! Cost of PHD-TBD, PSO-PHD-TBD (K-means) and PSO-PHD-TBD (DBSCAN) (Pei et al. 2019) on the
//! Cortex-M4F, in a configuration that fits 1 MiB of RAM: `SmcPhdTbdM4`
//! (6144 particles, e.g. five targets at the preset's 1000 plus 500 births; a 1024-entry
//! swarm, so the preset's 512 particles move; 8 measurement points, 8 targets) with the
//! `six-targets` preset's particle counts (1000 per target, 500 births), on the shared three-target 9 dB scene of `faint_golden::phd` in its
//! 32 x 32 x 32-cell firmware window (range x Doppler x azimuth around the targets).
//!
//! Each variant restarts the one static filter with `reconfigure` and runs the scene's
//! frames; every `step` is measured (cube generation is not). Rows: mean and worst frame,
//! per frame and per particle updated (survivors plus births). The filter (`.bss`,
//! all-zero, set up in place) and the cube window are the static RAM of the rows. The
//! swarm runs the paper's `gen = 10` generations before its stop test, so PSO frames run
//! past the harness timer's 167.8 M-instruction wrap: every `step` here is measured with
//! `harness::measure_long`, which counts the wraps with the board's dual timer.

use core::hint::black_box;
use core::mem::size_of;
use faint_core::detect::Detector;

use cortex_m_semihosting::hprintln;
use faint_core::detect::phd::{PhdConfig, SmcPhdTbdM4};
use faint_core::rng::Rng;
use faint_golden::phd::{config, cube, ALGORITHMS, FIRMWARE_WINDOW, FRAMES};

use faint_firmware::harness::{check, measure_long, row, Measurement};
use faint_firmware::statics::Static;
use faint_firmware::text::Text;
use faint_firmware::timer::coarse_start;

const SEED: u64 = 0x0002_0019_9E1D_7BD0;
/// Particles per estimated target and birth particles (the preset's).
const PER_TARGET: usize = 1000;
const BIRTHS: usize = 500;
const CELLS: usize = FIRMWARE_WINDOW.len();

type Det = SmcPhdTbdM4;

// All-zero bits (in `.bss`); `configure` sets it up before any `step`.
static DET: Static<Det> = Static::new(Det::new_unconfigured());
static CUBE: Static<[f32; CELLS]> = Static::new([0.0; CELLS]);

/// Bytes of static RAM the rows need: the filter and one cube window.
pub const RAM: usize = size_of::<Det>() + size_of::<[f32; CELLS]>();

/// Prints the three variants' rows. Call once (it takes the statics).
pub fn run() {
    let det = DET.take();
    let buf = CUBE.take();
    hprintln!(
        "PHD-TBD statics: SmcPhdTbd<6144, 1024, 8, 8> {} B + cube window ({} cells) {} B = {} B",
        size_of::<Det>(),
        CELLS,
        size_of::<[f32; CELLS]>(),
        RAM
    );
    coarse_start();
    for alg in ALGORITHMS {
        let cfg = config(FIRMWARE_WINDOW, alg, PER_TARGET, BIRTHS, 8);
        variant(det, buf, alg.name, cfg, FRAMES);
    }
}

/// Runs `frames` frames of the scene with `cfg` from a restart, measuring every `step`.
fn variant(det: &mut Det, buf: &mut [f32; CELLS], name: &str, cfg: PhdConfig, frames: usize) {
    check(det.configure(&cfg, SEED));
    let mut rng = Rng::from_stream(SEED, 1);
    let mut sum = 0u64;
    let mut parts = 0u32;
    let mut worst = Measurement {
        instructions: 0,
        stack_bytes: 0,
    };
    let mut worst_parts = 0u32;
    let mut stack = 0u32;
    let mut n_prev = 0u32;
    let mut counts = [0usize; FRAMES];
    let mut gens = [0usize; FRAMES];
    let mut swarm = [0usize; FRAMES];
    let frames = frames.min(FRAMES);
    for k in 0..frames {
        cube(&FIRMWARE_WINDOW, k, &mut rng, buf);
        let (r, m) = measure_long(|| det.step(black_box(&buf[..])));
        let r = check(r);
        // Particles the frame updated: the survivors of the last frame plus births.
        let n_in = n_prev + BIRTHS as u32;
        n_prev = r.particles as u32;
        counts[k] = r.n_hat;
        gens[k] = r.pso_generations;
        swarm[k] = r.swarm;
        sum += m.instructions;
        parts += n_in;
        stack = stack.max(m.stack_bytes);
        if m.instructions > worst.instructions {
            worst = m;
            worst_parts = n_in;
        }
    }
    let nf = frames.max(1) as u32;
    let mean = Measurement {
        instructions: sum / u64::from(nf),
        stack_bytes: stack,
    };
    hprintln_row(name, "mean of frames", frames, parts / nf, mean);
    hprintln_row(name, "worst of frames", frames, worst_parts, worst);
    hprintln!(
        "{}: N_hat per frame {:?}, swarm particles {:?}, generations {:?}",
        name,
        &counts[..frames],
        &swarm[..frames],
        &gens[..frames]
    );
}

fn hprintln_row(name: &str, what: &str, frames: usize, n: u32, m: Measurement) {
    let mut label = Text::<128>::new();
    let _ = core::fmt::Write::write_fmt(
        &mut label,
        format_args!("{name} step, {what} 0-{} (32^3 cells)", frames - 1),
    );
    row(label.as_str(), n, "particle", m, RAM);
}
