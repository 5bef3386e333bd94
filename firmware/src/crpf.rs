//! Instruction counts of CRPF-TBD and its comparators (PF-TBD, JOTT, PF-LRT) per frame,
//! at N = 1000 and N = 6000, on synthetic OTHR frames (32 bins).
//!
//! Each detector runs 6 warm-up frames of the golden sequence (target present from frame
//! 4), then one `step` on frame 7 (target present) is measured. The detectors are built
//! on the stack (the board's stack has the whole 4 MiB RAM below it; they have no
//! `const` constructor for a `static` yet); the static-RAM column is their `size_of`.

use core::hint::black_box;
use core::mem::size_of;

use faint_core::detect::bernoulli::BernoulliTbd;
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::model::doppler::{DopplerModel, FrameDetector, Window};
use faint_core::rng::Rng;
use faint_core::Complex32;
use faint_golden::crpf::{frame, target, BIN_VAR};

use crate::harness::{check, measure, row};

const SEED: u64 = 0x00C0_57F1_17E2_2017;

fn measure_one(name: &str, n: u32, det: &mut dyn FrameDetector, model: &DopplerModel, ram: usize) {
    let mut rng = Rng::from_stream(SEED, 1);
    let mut z = [Complex32::new(0.0, 0.0); 32];
    for k in 0..6 {
        let (fd, amp) = target(k);
        frame(model, fd, amp, BIN_VAR, &mut rng, &mut z);
        check(det.step(&z));
    }
    let (fd, amp) = target(6);
    frame(model, fd, amp, BIN_VAR, &mut rng, &mut z);
    let (r, m) = measure(|| det.step(black_box(&z)));
    check(r);
    row(name, n, "particle", m, ram);
}

#[inline(never)]
fn rows<const N: usize>(model: &DopplerModel) {
    let g = GaussConfig::othr(BIN_VAR);
    let n = N as u32;
    {
        let mut d = check(CrpfTbd::<N>::new(CrpfConfig::othr(), SEED));
        measure_one(
            "CRPF-TBD step (32 bins)",
            n,
            &mut d,
            model,
            size_of::<CrpfTbd<N>>(),
        );
    }
    {
        let mut d = check(PfTbd::<N>::new(g, SEED));
        measure_one(
            "PF-TBD step (32 bins)",
            n,
            &mut d,
            model,
            size_of::<PfTbd<N>>(),
        );
    }
    {
        let mut d = check(BernoulliTbd::<N>::new(g, SEED));
        measure_one(
            "JOTT step (32 bins)",
            n,
            &mut d,
            model,
            size_of::<BernoulliTbd<N>>(),
        );
    }
    {
        let mut d = check(PfLrt::<N>::new(g, SEED));
        measure_one(
            "PF-LRT step (32 bins)",
            n,
            &mut d,
            model,
            size_of::<PfLrt<N>>(),
        );
    }
}

/// Prints the four detectors' rows at N = 1000 and N = 6000.
pub fn run() {
    let model = check(DopplerModel::new(32, 0.02, Window::Hamming));
    rows::<1000>(&model);
    rows::<6000>(&model);
}
