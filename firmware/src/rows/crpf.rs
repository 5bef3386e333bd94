//! Instruction counts of CRPF-TBD and its comparators (PF-TBD, JOTT, PF-LRT) per frame,
//! at N = 1000 and N = 6000, on synthetic OTHR frames (32 bins).
//!
//! Each detector runs 6 warm-up frames of the golden sequence (target present from frame
//! 4), then one `step` on frame 7 (target present) is measured. The detectors live in
//! `static` memory: each is its `new_unconfigured()` constant (all-zero bits, in `.bss`)
//! set up in place by `configure`, so nothing of size `N` is built on the stack. The static-RAM column is
//! their `size_of`.
//!
//! CRPF-TBD also gets three rows over 32 detector seeds (frames 1, 6 and 8, see
//! `crpf_rows`), because its cost depends on the random fraction of present particles.
//! At N = 1000, CRPF-TBD and PF-TBD get one more single-frame row each with
//! `phase: unknown` (the phase-insensitive observation).

use core::hint::black_box;
use core::mem::size_of;

use faint_core::detect::crpf::{CrpfConfig, CrpfTbd, CrpfTbd1000, CrpfTbd6000};
use faint_core::detect::jott::{JottTbd, JottTbd1000, JottTbd6000};
use faint_core::detect::pf_lrt::{PfLrt, PfLrt1000, PfLrt6000};
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd, PfTbd1000, PfTbd6000};
use faint_core::detect::Detector;
use faint_core::model::doppler::{DopplerModel, DopplerReport, Likelihood, Phase, Window};
use faint_core::rng::Rng;
use faint_core::Complex32;
use faint_golden::crpf::{frame, target, BIN_VAR};

use cortex_m_semihosting::hprintln;
use faint_firmware::harness::{check, measure, row, Measurement};
use faint_firmware::statics::only_ref;

const SEED: u64 = 0x00C0_57F1_17E2_2017;

/// One detector's single-frame row. `step` is `Detector::step` behind a `dyn` call, so
/// the step is not inlined into the harness (the counts stay those of the detector's own
/// code).
fn measure_one(
    name: &str,
    n: u32,
    step: &mut dyn FnMut(&[Complex32]) -> faint_core::Result<DopplerReport>,
    model: &DopplerModel,
    ram: usize,
) {
    let mut rng = Rng::from_stream(SEED, 1);
    let mut z = [Complex32::new(0.0, 0.0); 32];
    for k in 0..6 {
        let (fd, amp) = target(k);
        frame(model, fd, amp, BIN_VAR, &mut rng, &mut z);
        check(step(&z));
    }
    let (fd, amp) = target(6);
    frame(model, fd, amp, BIN_VAR, &mut rng, &mut z);
    let (r, m) = measure(|| step(black_box(&z)));
    check(r);
    row(name, n, "particle", m, ram);
}

/// CRPF-TBD over `SEEDS` detector seeds on the frames of [`measure_one`] (target present
/// in frames 3..=8, 0-based). The instructions of a step grow with the fraction of
/// present particles, which is random, so one seed's count says as much about that
/// seed's lock-on as about the code. Three rows, each the sum over seeds (unit: one
/// particle-frame, so the per-unit column is the mean): frame 1 (no target, almost every
/// particle absent: the floor), frame 6 (the frame of the single-seed row) and frame 8
/// (the sixth frame with the target, mostly locked on); each followed by the mean
/// existence after that frame.
fn crpf_rows<const N: usize>(crpf: &mut CrpfTbd<N>, model: &DopplerModel) {
    const SEEDS: u64 = 32;
    const FRAMES: [usize; 3] = [1, 6, 8];
    let mut total = [0u64; 3];
    let mut stack = 0u32;
    let mut present = [0u64; 3];
    for s in 0..SEEDS {
        check(crpf.configure(&CrpfConfig::othr(), SEED + s));
        let mut rng = Rng::from_stream(SEED, 1);
        let mut z = [Complex32::new(0.0, 0.0); 32];
        for k in 0..=8 {
            let (fd, amp) = target(k);
            frame(model, fd, amp, BIN_VAR, &mut rng, &mut z);
            match FRAMES.iter().position(|&f| f == k) {
                Some(j) => {
                    let (r, m) = measure(|| crpf.step(black_box(&z)));
                    let rep = check(r);
                    total[j] += m.instructions;
                    stack = stack.max(m.stack_bytes);
                    present[j] += (rep.existence * N as f32 + 0.5) as u64;
                }
                None => {
                    check(crpf.step(&z));
                }
            }
        }
    }
    let units = (N as u64 * SEEDS) as u32;
    let ram = size_of::<CrpfTbd<N>>();
    let names = [
        "CRPF-TBD frame 1 (no target), 32 seeds",
        "CRPF-TBD frame 6, 32 seeds",
        "CRPF-TBD frame 8 (locked), 32 seeds",
    ];
    for j in 0..3 {
        let m = Measurement {
            instructions: total[j],
            stack_bytes: stack,
        };
        row(names[j], units, "particle", m, ram);
        hprintln!(
            "crpf N = {}: mean existence after frame {} over 32 seeds = {} / {}",
            N,
            FRAMES[j],
            present[j],
            N as u64 * SEEDS
        );
    }
}

static mut CRPF_1000: CrpfTbd1000 = CrpfTbd1000::new_unconfigured();
static mut PF_1000: PfTbd1000 = PfTbd1000::new_unconfigured();
static mut JOTT_1000: JottTbd1000 = JottTbd1000::new_unconfigured();
static mut LRT_1000: PfLrt1000 = PfLrt1000::new_unconfigured();
static mut CRPF_6000: CrpfTbd6000 = CrpfTbd6000::new_unconfigured();
static mut PF_6000: PfTbd6000 = PfTbd6000::new_unconfigured();
static mut JOTT_6000: JottTbd6000 = JottTbd6000::new_unconfigured();
static mut LRT_6000: PfLrt6000 = PfLrt6000::new_unconfigured();

#[inline(never)]
fn rows<const N: usize>(
    model: &DopplerModel,
    crpf: &mut CrpfTbd<N>,
    pf: &mut PfTbd<N>,
    jott: &mut JottTbd<N>,
    lrt: &mut PfLrt<N>,
) {
    let g = GaussConfig::othr(BIN_VAR);
    let n = N as u32;
    check(crpf.configure(&CrpfConfig::othr(), SEED));
    measure_one(
        "CRPF-TBD step (32 bins)",
        n,
        &mut |z| crpf.step(z),
        model,
        size_of::<CrpfTbd<N>>(),
    );
    crpf_rows(crpf, model);
    // The unknown-phase observation (`faint detect`'s default) at N = 1000: the cost
    // `||z||^2 - 2 |<z,h>| + ||h||^2` needs the full projection and a hypot per particle.
    if N == 1000 {
        let mut unknown = CrpfConfig::othr();
        unknown.model.phase = Phase::Unknown;
        check(crpf.configure(&unknown, SEED));
        measure_one(
            "CRPF-TBD step, phase unknown (32 bins)",
            n,
            &mut |z| crpf.step(z),
            model,
            size_of::<CrpfTbd<N>>(),
        );
    }
    check(pf.configure(&g, SEED));
    measure_one(
        "PF-TBD step (32 bins)",
        n,
        &mut |z| pf.step(z),
        model,
        size_of::<PfTbd<N>>(),
    );
    // The Rician log-LR `ln I0(2 |<z,h>| / s2) - ||h||^2 / s2` at N = 1000.
    if N == 1000 {
        let mut unknown = g;
        unknown.model.phase = Phase::Unknown;
        check(pf.configure(&unknown, SEED));
        measure_one(
            "PF-TBD step, phase unknown (32 bins)",
            n,
            &mut |z| pf.step(z),
            model,
            size_of::<PfTbd<N>>(),
        );
        // `faint detect`'s default: the Rician log-LR on frames whitened in the step
        // (the window-aware likelihood: m^2 = 1024 complex multiply-adds per frame).
        unknown.likelihood = Likelihood::Window;
        check(pf.configure(&unknown, SEED));
        measure_one(
            "PF-TBD step, phase unknown, window likelihood (32 bins)",
            n,
            &mut |z| pf.step(z),
            model,
            size_of::<PfTbd<N>>(),
        );
    }
    check(jott.configure(&g, SEED));
    measure_one(
        "JOTT step (32 bins)",
        n,
        &mut |z| jott.step(z),
        model,
        size_of::<JottTbd<N>>(),
    );
    check(lrt.configure(&g, SEED));
    measure_one(
        "PF-LRT step (32 bins)",
        n,
        &mut |z| lrt.step(z),
        model,
        size_of::<PfLrt<N>>(),
    );
}

/// Prints the four detectors' rows at N = 1000 and N = 6000. Call once: it takes the
/// only `&mut` to each static detector.
pub fn run() {
    let model = check(DopplerModel::new(32, 0.02, Window::Hamming));
    // SAFETY: single-threaded firmware, no interrupt touches these statics, and `run`
    // is called once, so each `&mut` is the only reference to its static.
    unsafe {
        rows::<1000>(
            &model,
            only_ref(&raw mut CRPF_1000),
            only_ref(&raw mut PF_1000),
            only_ref(&raw mut JOTT_1000),
            only_ref(&raw mut LRT_1000),
        );
        rows::<6000>(
            &model,
            only_ref(&raw mut CRPF_6000),
            only_ref(&raw mut PF_6000),
            only_ref(&raw mut JOTT_6000),
            only_ref(&raw mut LRT_6000),
        );
    }
}
