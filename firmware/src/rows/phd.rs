//! Cost of PHD-TBD, PSO-PHD-TBD (K-means) and PSO-PHD-TBD (DBSCAN) (Pei et al. 2019) on the
//! Cortex-M4F, in a configuration that fits 1 MiB of RAM: `SmcPhdTbdM4`
//! (6144 particles, e.g. five targets at the preset's 1000 plus 500 births; a 1024-entry
//! swarm, so the preset's 512 particles move; 8 measurement points, 8 targets) with the
//! `six-targets` preset's particle counts (1000 per target, 500 births), on the shared three-target 9 dB scene of `faint_golden::phd` in its
//! 32 x 32 x 32-cell firmware window (range x Doppler x azimuth around the targets).
//!
//! The two swarm variants run again with the swarm of the Cortex-M4 budget
//! (`PsoConfig::cortex_m4`: at most 128 particles move per frame instead of 512), rows
//! tagged "swarm cap 128".
//!
//! Each variant restarts the one static filter with `reconfigure` and runs the scene's
//! frames; every `step` is measured (cube generation is not). Rows: mean and worst frame,
//! per frame and per particle updated (survivors plus births). The filter (`.bss`,
//! all-zero, set up in place) and the cube window are the static RAM of the rows. The
//! swarm runs the paper's `gen = 10` generations before its stop test, so PSO frames run
//! past the harness timer's 167.8 M-instruction wrap: every `step` here is measured with
//! `harness::measure_long`, which counts the wraps with the board's dual timer.

use core::hint::black_box;
use core::mem::{size_of, MaybeUninit};
use core::sync::atomic::{AtomicBool, Ordering};
use faint_core::detect::Detector;

use cortex_m_semihosting::hprintln;
use faint_core::detect::phd::{
    PhdConfig, PhdStage, PsoConfig, SmcPhdTbd, SmcPhdTbdM4, SmcPhdTbdM4Half,
};
use faint_core::math;
use faint_core::model::power_cube::{exp_neg, log_i0, PointSpread, PowerCube, RadarCoords};
use faint_core::rng::Rng;
use faint_golden::phd::{config, cube, ALGORITHMS, FIRMWARE_WINDOW, FRAMES};

use faint_firmware::harness::{check, measure, measure_long, row, Measurement};
use faint_firmware::statics::Static;
use faint_firmware::text::Text;
use faint_firmware::timer::{self, coarse_start};

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

/// The configuration within 512 KiB (`SmcPhdTbdM4Half`, 2048 particles): 500 particles
/// per target, 500 births.
type Half = SmcPhdTbdM4Half;
const HALF_PER_TARGET: usize = 500;
/// Bytes of static RAM of the 512 KiB rows: that filter and one cube window.
pub const RAM_HALF: usize = size_of::<Half>() + size_of::<[f32; CELLS]>();
const _: () = assert!(RAM_HALF <= 512 * 1024);

/// In the board's PSRAM (not zeroed by the start-up code; [`half`] zeroes it), so that
/// the second filter does not crowd the 4 MiB of RAM the other rows share.
#[link_section = ".psram"]
static mut HALF_BUF: MaybeUninit<Half> = MaybeUninit::uninit();
static HALF_TAKEN: AtomicBool = AtomicBool::new(false);
// The const evaluator rejects an all-zero bit pattern that is not a valid `Half`.
const _: Half = unsafe { MaybeUninit::zeroed().assume_init() };

/// The 512 KiB filter, zeroed (unconfigured). Panics on a second call.
fn half() -> &'static mut Half {
    assert!(
        !HALF_TAKEN.swap(true, Ordering::AcqRel),
        "half() called twice"
    );
    // SAFETY: the swap above makes this the only reference ever made to `HALF_BUF`; the
    // zeroed bytes are a valid `Half` (checked above).
    unsafe {
        let p = (&raw mut HALF_BUF).cast::<Half>();
        core::ptr::write_bytes(p, 0, 1);
        &mut *p
    }
}

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
        variant(det, buf, alg.name, "", RAM, cfg, FRAMES);
    }
    // The Cortex-M4 budget: the same filter and scene, the swarm capped at 128
    // particles per frame (`PsoConfig::cortex_m4`).
    for alg in ALGORITHMS.iter().filter(|a| a.pso) {
        let cfg = m4_budget(config(FIRMWARE_WINDOW, *alg, PER_TARGET, BIRTHS, 8));
        variant(det, buf, alg.name, M4_TAG, RAM, cfg, FRAMES);
    }
    let small = half();
    hprintln!(
        "PHD-TBD statics within 512 KiB: SmcPhdTbd<2048, 1024, 8, 8> {} B + cube window {} B = {} B",
        size_of::<Half>(),
        size_of::<[f32; CELLS]>(),
        RAM_HALF
    );
    for alg in ALGORITHMS {
        let cfg = config(FIRMWARE_WINDOW, alg, HALF_PER_TARGET, BIRTHS, 8);
        variant(
            small,
            buf,
            alg.name,
            " 512 KiB (N 2048)",
            RAM_HALF,
            cfg,
            FRAMES,
        );
    }
    for alg in ALGORITHMS {
        let cfg = config(FIRMWARE_WINDOW, alg, PER_TARGET, BIRTHS, 8);
        stages(det, buf, alg.name, cfg, FRAMES);
    }
    for (alg, name) in ALGORITHMS.iter().filter(|a| a.pso).zip(M4_NAMES) {
        let cfg = m4_budget(config(FIRMWARE_WINDOW, *alg, PER_TARGET, BIRTHS, 8));
        stages(det, buf, name, cfg, FRAMES);
    }
    kernels(det, buf);
}

/// Tag of the Cortex-M4 budget rows, and the names of their `phd stage` lines (K-means,
/// DBSCAN).
const M4_TAG: &str = " swarm cap 128";
const M4_NAMES: [&str; 2] = [
    "PSO-PHD-TBD (K-means) swarm cap 128",
    "PSO-PHD-TBD (DBSCAN) swarm cap 128",
];

/// `cfg` with the swarm settings of `PsoConfig::cortex_m4` (the points kept).
fn m4_budget(mut cfg: PhdConfig) -> PhdConfig {
    if let Some(p) = cfg.pso.as_mut() {
        *p = PsoConfig {
            points: p.points,
            ..PsoConfig::cortex_m4()
        };
    }
    cfg
}

/// Where a frame's instructions go: the same run as [`variant`], with
/// `step_probed` reading the timer as each stage ends. Prints, per stage, the mean
/// instructions per frame, per particle updated, and its share of the frame.
fn stages(det: &mut Det, buf: &mut [f32; CELLS], name: &str, cfg: PhdConfig, frames: usize) {
    check(det.configure(&cfg, SEED));
    let mut rng = Rng::from_stream(SEED, 1);
    let mut sums = [0u64; PhdStage::ALL.len()];
    let mut parts = 0u64;
    let mut n_prev = 0u64;
    let frames = frames.min(FRAMES);
    for k in 0..frames {
        cube(&FIRMWARE_WINDOW, k, &mut rng, buf);
        let mut t = timer::now();
        let r = check(det.step_probed(black_box(&buf[..]), |s| {
            let now = timer::now();
            if let Some(v) = sums.get_mut(s as usize) {
                *v += u64::from(timer::elapsed(t, now));
            }
            t = timer::now();
        }));
        parts += n_prev + BIRTHS as u64;
        n_prev = r.particles as u64;
    }
    let nf = frames.max(1) as u64;
    let total: u64 = sums.iter().sum();
    hprintln!(
        "{} stages: mean of frames 0-{}, {} particles updated per frame, {} instructions per frame",
        name,
        frames - 1,
        parts / nf,
        total / nf
    );
    for (s, &v) in PhdStage::ALL.iter().zip(&sums) {
        if v == 0 {
            continue;
        }
        let per_frame = v / nf;
        let per_part10 = (v * 10 + parts / 2) / parts.max(1);
        let pct10 = (v * 1000 + total / 2) / total.max(1);
        hprintln!(
            "phd stage | {} | {} | {} | {}.{} | {}.{} % |",
            name,
            s.name(),
            per_frame,
            per_part10 / 10,
            per_part10 % 10,
            pct10 / 10,
            pct10 % 10
        );
    }
}

/// The per-particle likelihood's parts on the particles left by the last run (the DBSCAN
/// variant's last frame) and that frame's cube: one `log_lr_argmax` per particle
/// (the likelihood stage's kernel, without the state conversion), `from_state`, and the
/// scalar functions it calls per covered cell (`log_i0`, `math::sqrt`) or per axis
/// (`math::exp`), each over the same arguments the likelihood gives them.
fn kernels(det: &mut Det, buf: &mut [f32; CELLS]) {
    let cfg = *faint_core::detect::Detector::config(det);
    let (psf, s2) = (cfg.psf, cfg.noise_var);
    let Ok(cube) = PowerCube::new(&buf[..], FIRMWARE_WINDOW) else {
        return;
    };
    let (x, _) = det.particles();
    let n = x.len().min(1000);
    let x = &x[..n];
    let mut cells = 0u32;
    let mut args = [0.0f32; 1024];
    let mut zs = [0.0f32; 1024];
    let mut na = 0usize;
    for s in x {
        let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
        let amp = math::sqrt(s[4].max(0.0));
        psf.for_each_cell(&FIRMWARE_WINDOW, &c, |idx, h| {
            cells += 1;
            let z = buf.get(idx).copied().unwrap_or(0.0);
            if let (Some(a), Some(zz)) = (args.get_mut(na), zs.get_mut(na)) {
                *a = amp * h * math::sqrt(z) / s2;
                *zz = z;
                na += 1;
            }
        });
    }
    hprintln!(
        "PHD-TBD likelihood kernels: {} particles, {} covered cells ({}.{} per particle)",
        n,
        cells,
        cells / n.max(1) as u32,
        (cells * 10 / n.max(1) as u32) % 10
    );
    let (r, m) = measure(|| {
        let mut acc = 0.0f32;
        for s in black_box(x) {
            let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
            acc += cube
                .log_lr_argmax(&psf, &c, math::sqrt(s[4].max(0.0)), s2)
                .0;
        }
        acc
    });
    black_box(r);
    row(
        "PHD-TBD likelihood of one particle (from_state + log_lr_argmax)",
        n as u32,
        "particle",
        m,
        RAM,
    );
    let (r, m) = measure(|| {
        let mut acc = 0.0f32;
        for s in black_box(x) {
            acc += RadarCoords::from_state(s[0], s[1], s[2], s[3]).range;
        }
        acc
    });
    black_box(r);
    row(
        "PHD-TBD RadarCoords::from_state",
        n as u32,
        "particle",
        m,
        RAM,
    );
    let psf1 = PointSpread {
        half_width: [0, 0, 0],
        ..psf
    };
    let (r, m) = measure(|| {
        let mut acc = 0.0f32;
        for s in black_box(x) {
            let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
            acc += cube
                .log_lr_argmax(&psf1, &c, math::sqrt(s[4].max(0.0)), s2)
                .0;
        }
        acc
    });
    black_box(r);
    row(
        "PHD-TBD likelihood of one particle over its own cell only (half widths 0)",
        n as u32,
        "particle",
        m,
        RAM,
    );
    let (r, m) = measure(|| {
        black_box(zs)
            .iter()
            .map(|&z| exp_neg(-0.1 * z))
            .sum::<f32>()
    });
    black_box(r);
    row("PHD-TBD exp_neg (-z / 10)", na as u32, "call", m, 0);
    let (r, m) = measure(|| {
        let mut acc = 0.0f32;
        for s in black_box(x) {
            let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
            let (fr, fd, fb) = FIRMWARE_WINDOW.fractional(&c);
            let w = [
                psf.axis_weights(0, fr, FIRMWARE_WINDOW.n_range),
                psf.axis_weights(1, fd, FIRMWARE_WINDOW.n_doppler),
                psf.axis_weights(2, fb, FIRMWARE_WINDOW.n_azimuth),
            ];
            acc += black_box(&w).len() as f32;
        }
        acc
    });
    black_box(r);
    row(
        "PHD-TBD from_state + three PointSpread::axis_weights (17 slots each)",
        n as u32,
        "particle",
        m,
        RAM,
    );
    let (r, m) = measure(|| {
        let mut acc = 0.0f32;
        for s in black_box(x) {
            let c = RadarCoords::from_state(s[0], s[1], s[2], s[3]);
            psf.for_each_cell(&FIRMWARE_WINDOW, &c, |i, h| acc += h * buf[i & (CELLS - 1)]);
        }
        acc
    });
    black_box(r);
    row(
        "PHD-TBD from_state + PointSpread::for_each_cell (17 slots, 27 products)",
        n as u32,
        "particle",
        m,
        RAM,
    );
    let args = &args[..na];
    let zs = &zs[..na];
    let (r, m) = measure(|| black_box(args).iter().map(|&a| log_i0(a)).sum::<f32>());
    black_box(r);
    row(
        "PHD-TBD log_i0 (the likelihood's arguments)",
        na as u32,
        "call",
        m,
        0,
    );
    let (r, m) = measure(|| black_box(zs).iter().map(|&z| math::sqrt(z)).sum::<f32>());
    black_box(r);
    row(
        "PHD-TBD math::sqrt (the cells' powers)",
        na as u32,
        "call",
        m,
        0,
    );
    let (r, m) = measure(|| {
        black_box(zs)
            .iter()
            .map(|&z| math::ln(z + 1.0))
            .sum::<f32>()
    });
    black_box(r);
    row(
        "PHD-TBD math::ln (1 + the cells' powers)",
        na as u32,
        "call",
        m,
        0,
    );
    let (r, m) = measure(|| black_box(zs).iter().map(|&z| math::ln1p(z)).sum::<f32>());
    black_box(r);
    row(
        "PHD-TBD math::ln1p (the cells' powers)",
        na as u32,
        "call",
        m,
        0,
    );
    let (r, m) = measure(|| {
        black_box(zs)
            .iter()
            .map(|&z| math::exp(-0.1 * z))
            .sum::<f32>()
    });
    black_box(r);
    row("PHD-TBD math::exp (-z / 10)", na as u32, "call", m, 0);
    let (r, m) = measure(|| {
        black_box(x)
            .iter()
            .map(|s| math::atan2(s[2], s[0]))
            .sum::<f32>()
    });
    black_box(r);
    row(
        "PHD-TBD math::atan2 (particle positions)",
        n as u32,
        "call",
        m,
        0,
    );
}

/// Runs `frames` frames of the scene with `cfg` from a restart, measuring every `step`.
fn variant<const N: usize, const S: usize, const M: usize, const K: usize>(
    det: &mut SmcPhdTbd<N, S, M, K>,
    buf: &mut [f32; CELLS],
    name: &str,
    tag: &str,
    ram: usize,
    cfg: PhdConfig,
    frames: usize,
) {
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
    hprintln_row(name, tag, "mean of frames", frames, parts / nf, mean, ram);
    hprintln_row(
        name,
        tag,
        "worst of frames",
        frames,
        worst_parts,
        worst,
        ram,
    );
    hprintln!(
        "{}{}: N_hat per frame {:?}, swarm particles {:?}, generations {:?}",
        name,
        tag,
        &counts[..frames],
        &swarm[..frames],
        &gens[..frames]
    );
}

fn hprintln_row(
    name: &str,
    tag: &str,
    what: &str,
    frames: usize,
    n: u32,
    m: Measurement,
    ram: usize,
) {
    let mut label = Text::<128>::new();
    let _ = core::fmt::Write::write_fmt(
        &mut label,
        format_args!("{name}{tag} step, {what} 0-{} (32^3 cells)", frames - 1),
    );
    row(label.as_str(), n, "particle", m, ram);
}
