//! Golden cases of CRPF-TBD and its comparators (PF-TBD, JOTT, PF-LRT): the per-frame
//! existence probabilities (and PF-LRT's log LR) of `N = 64` particles over 10 synthetic
//! OTHR frames, bit for bit.

use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::jott::JottTbd;
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::detect::Detector;
use faint_core::math;
use faint_core::model::doppler::{DopplerModel, DopplerReport, Window, SPAN};
use faint_core::rng::Rng;
use faint_core::Complex32;

use crate::{Fold, ERR, SEED};

/// Per-bin noise variance of the synthetic frames (unit time-domain noise through a
/// 32-point Hamming window: `sum w^2 = 12.7`).
pub const BIN_VAR: f32 = 12.7;

/// A synthetic OTHR frame: the model's 5-bin response of a target `(fd, amp)` (`amp = 0`:
/// none) plus independent complex Gaussian bins of variance `s2`. Shared with the
/// firmware's instruction-count rows.
pub fn frame(
    model: &DopplerModel,
    fd: f32,
    amp: f32,
    s2: f32,
    rng: &mut Rng,
    out: &mut [Complex32],
) {
    let s = math::sqrt(0.5 * s2);
    for o in out.iter_mut() {
        *o = Complex32::new(s * rng.normal(), s * rng.normal());
    }
    if amp > 0.0 {
        let mut r = [Complex32::new(0.0, 0.0); SPAN];
        let first = model.response(fd, amp, &mut r);
        let m = out.len();
        for (j, v) in r.iter().enumerate() {
            if let Some(o) = out.get_mut((first + j) % m) {
                *o += *v;
            }
        }
    }
}

/// Target of frame `k` (0-based) of the synthetic sequence: present in frames 3..=8,
/// Doppler 5.3 Hz drifting 0.2 Hz per frame, amplitude 1.0 (about 15 dB by eq. 18).
pub fn target(k: usize) -> (f32, f32) {
    if (3..=8).contains(&k) {
        (5.3 + 0.2 * k as f32, 1.0)
    } else {
        (0.0, 0.0)
    }
}

fn run<D: Detector<Frame = [Complex32], Report = DopplerReport>>(
    det: &mut D,
    model: &DopplerModel,
) -> [u32; 3] {
    let mut rng = Rng::from_stream(SEED, 300);
    let mut z = [Complex32::new(0.0, 0.0); 32];
    let mut fold_e = Fold::new();
    let mut fold_l = Fold::new();
    let mut last = 0u32;
    for k in 0..10 {
        let (fd, amp) = target(k);
        frame(model, fd, amp, BIN_VAR, &mut rng, &mut z);
        match det.step(&z) {
            Ok(r) => {
                fold_e.push_f32(r.existence);
                fold_l.push_f32(r.log_lr);
                last = r.existence.to_bits();
            }
            Err(_) => return [ERR; 3],
        }
    }
    [fold_e.value(), fold_l.value(), last]
}

pub(crate) fn cases(emit: &mut dyn FnMut(&str, &[u32])) {
    let Ok(model) = DopplerModel::new(32, 0.02, Window::Hamming) else {
        emit("crpf.model", &[ERR]);
        return;
    };
    let g = GaussConfig::othr(BIN_VAR);
    match CrpfTbd::<64>::new(CrpfConfig::othr(), SEED) {
        Ok(mut d) => emit("crpf.crpf_tbd", &run(&mut d, &model)),
        Err(_) => emit("crpf.crpf_tbd", &[ERR]),
    }
    match PfTbd::<64>::new(g, SEED) {
        Ok(mut d) => emit("crpf.pf_tbd", &run(&mut d, &model)),
        Err(_) => emit("crpf.pf_tbd", &[ERR]),
    }
    match JottTbd::<64>::new(g, SEED) {
        Ok(mut d) => emit("crpf.jott", &run(&mut d, &model)),
        Err(_) => emit("crpf.jott", &[ERR]),
    }
    match PfLrt::<64>::new(g, SEED) {
        Ok(mut d) => emit("crpf.pf_lrt", &run(&mut d, &model)),
        Err(_) => emit("crpf.pf_lrt", &[ERR]),
    }
}
