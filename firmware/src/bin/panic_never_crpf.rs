//! Link-time proof that the Doppler-frame detectors, CRPF-TBD (Lu, Wang, Zhang 2017) and
//! its comparators PF-TBD (Ristic et al. 2004), JOTT (Ristic et al. 2013) and PF-LRT
//! (Boers and Driessen 2003), contain no reachable panic: `new`, `configure`, `reset`,
//! `step` (good frames, NaN/inf frames, frames of the wrong length, huge finite values),
//! `set_noise_variance`, the detections and every other public query, with the
//! independent-bin likelihood (Hamming window) and the window-aware one (`unwindow`,
//! then a rectangular-window model), and the public model functions they use
//! (`check_frame`, `estimate_noise_variance`, `DopplerModel` projections and response,
//! `Motion`, `PriorBox`), at N = 64 and at the firmware's N = 1000 and 6000, on inputs
//! hidden from the optimiser. As in `panic_never.rs`, the panic handler calls a function
//! that does not exist, so the fat-LTO link fails with an undefined reference to
//! `faint_core_panic_path_survived` if any panic path survives:
//!
//! ```sh
//! cd firmware && cargo run --profile firmware --features panic-never --bin panic-never-crpf
//! ```
//!
//! The binary then runs the calls once and exits with status 0 (1 if a result was not
//! the expected `Ok` or `Err`). It prints without `core::fmt`.
#![no_std]
#![no_main]

faint_firmware::panic_never!();

use core::hint::black_box;

use cortex_m_rt::entry;
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd, CrpfTbd1000, CrpfTbd6000, Weighting};
use faint_core::detect::jott::{JottTbd, JottTbd1000, JottTbd6000};
use faint_core::detect::pf_lrt::{PfLrt, PfLrt1000, PfLrt6000};
use faint_core::detect::pf_tbd::{BirthProposal, GaussConfig, PfTbd, PfTbd1000, PfTbd6000};
use faint_core::detect::{run as run_frames, Detector, Validate};
use faint_core::model::doppler::{
    check_frame, dtft, estimate_noise_variance, max_amplitude, unwindow, DopplerModel, Likelihood,
    ModelConfig, Phase, ProjectionCache, Window, MAX_BINS, SPAN,
};
use faint_core::rng::Rng;
use faint_core::Complex32;
use faint_firmware::semihosting::finish;
use faint_firmware::statics::only_ref;

/// Bins per frame of the preset.
const M: usize = 32;
/// Per-bin noise variance of the test frames (unit time-domain noise, Hamming window:
/// `sum w_n^2` of the 32-point window, about 12.1).
const BIN_VAR: f32 = 12.1;

static mut CRPF_64: CrpfTbd<64> = <CrpfTbd<64>>::new_unconfigured();
static mut PF_64: PfTbd<64> = <PfTbd<64>>::new_unconfigured();
static mut JOTT_64: JottTbd<64> = <JottTbd<64>>::new_unconfigured();
static mut LRT_64: PfLrt<64> = <PfLrt<64>>::new_unconfigured();
static mut CRPF_1000: CrpfTbd1000 = CrpfTbd1000::new_unconfigured();
static mut PF_1000: PfTbd1000 = PfTbd1000::new_unconfigured();
static mut JOTT_1000: JottTbd1000 = JottTbd1000::new_unconfigured();
static mut LRT_1000: PfLrt1000 = PfLrt1000::new_unconfigured();
static mut CRPF_6000: CrpfTbd6000 = CrpfTbd6000::new_unconfigured();
static mut PF_6000: PfTbd6000 = PfTbd6000::new_unconfigured();
static mut JOTT_6000: JottTbd6000 = JottTbd6000::new_unconfigured();
static mut LRT_6000: PfLrt6000 = PfLrt6000::new_unconfigured();
static mut CACHE: ProjectionCache = ProjectionCache::new();

#[entry]
fn main() -> ! {
    finish(
        run(),
        b"panic-never-crpf: CRPF-TBD, PF-TBD, JOTT and PF-LRT linked without a panic path and ran ok\n",
        b"panic-never-crpf: a call did not return the expected Ok or Err\n",
    )
}

fn run() -> bool {
    let mut rng = Rng::from_stream(black_box(0x0C4F_2017), black_box(5));
    let mut ok = true;
    ok &= model_functions(&mut rng);
    // SAFETY: single-threaded, `run` is called once: each `&mut` is the only reference
    // to its static.
    unsafe {
        ok &= family::<64>(
            only_ref(&raw mut CRPF_64),
            only_ref(&raw mut PF_64),
            only_ref(&raw mut JOTT_64),
            only_ref(&raw mut LRT_64),
            &mut rng,
        );
        ok &= family::<1000>(
            only_ref(&raw mut CRPF_1000),
            only_ref(&raw mut PF_1000),
            only_ref(&raw mut JOTT_1000),
            only_ref(&raw mut LRT_1000),
            &mut rng,
        );
        ok &= family::<6000>(
            only_ref(&raw mut CRPF_6000),
            only_ref(&raw mut PF_6000),
            only_ref(&raw mut JOTT_6000),
            only_ref(&raw mut LRT_6000),
            &mut rng,
        );
    }
    // `new` by value (small N: the detector is built on the stack).
    ok &= by_value(&mut rng);
    ok
}

/// The frames a detector sees, in order: good, huge finite (an overflowing energy and a
/// finite one), NaN, infinity, short, long, empty, good again.
#[derive(Clone, Copy)]
enum Kind {
    Good,
    Overflow,
    Large,
    Nan,
    Inf,
    Short,
    Long,
    Empty,
}

const KINDS: [Kind; 12] = [
    Kind::Good,
    Kind::Good,
    Kind::Good,
    Kind::Overflow,
    Kind::Good,
    Kind::Large,
    Kind::Nan,
    Kind::Inf,
    Kind::Short,
    Kind::Long,
    Kind::Empty,
    Kind::Good,
];

/// Writes a frame of `kind` into `buf` (complex Gaussian noise of variance `BIN_VAR`
/// plus the response of a target at `fd`, `amp`, in bins `first..first + SPAN` mod `m`)
/// and returns the part a detector gets.
fn make_frame<'a>(
    kind: Kind,
    model: &DopplerModel,
    fd: f32,
    amp: f32,
    rng: &mut Rng,
    buf: &'a mut [Complex32; MAX_BINS],
) -> &'a mut [Complex32] {
    let m = black_box(model.bins());
    let s = faint_core::math::sqrt(0.5 * BIN_VAR);
    for c in buf.iter_mut() {
        *c = Complex32::new(s * rng.normal(), s * rng.normal());
    }
    let mut h = [Complex32::new(0.0, 0.0); SPAN];
    let first = model.response(fd, amp, &mut h);
    for (j, v) in h.iter().enumerate() {
        if let Some(c) = buf.get_mut((first + j) % m.max(1)) {
            *c += *v;
        }
    }
    let at = black_box(7usize);
    let len = match kind {
        Kind::Short => m.saturating_sub(1),
        Kind::Long => m + 1,
        Kind::Empty => 0,
        _ => m,
    };
    if let Some(c) = buf.get_mut(at) {
        match kind {
            Kind::Overflow => c.re = black_box(3.0e30),
            Kind::Large => c.im = black_box(1.0e17),
            Kind::Nan => c.re = black_box(f32::NAN),
            Kind::Inf => c.im = black_box(f32::NEG_INFINITY),
            _ => {}
        }
    }
    let len = black_box(len);
    match buf.get_mut(..len) {
        Some(s) => s,
        None => &mut [],
    }
}

/// Steps `det` through [`KINDS`] (each frame `unwindow`ed first when `whiten` is
/// `Some`), checks each result is the expected `Ok` or `Err`, then queries the
/// detections, resets and steps once more.
fn exercise<D>(det: &mut D, model: &DopplerModel, whiten: Option<Window>, rng: &mut Rng) -> bool
where
    D: Detector<Frame = [Complex32], Report = faint_core::model::doppler::DopplerReport>,
{
    let mut ok = true;
    let mut acc = 0.0f32;
    let mut buf = [Complex32::new(0.0, 0.0); MAX_BINS];
    let frames = black_box(KINDS);
    for (k, &kind) in frames.iter().enumerate() {
        let fd = black_box(-23.0 + 3.7 * k as f32);
        let amp = black_box(1.2f32);
        let z = make_frame(kind, model, fd, amp, rng, &mut buf);
        if let Some(w) = whiten {
            // `unwindow` checks the frame as `step` does, but its length is the frame's.
            let fine = matches!(kind, Kind::Good | Kind::Large | Kind::Short | Kind::Long);
            ok &= unwindow(z, w).is_ok() == fine;
        }
        let expect_ok = matches!(kind, Kind::Good | Kind::Large);
        match det.step(black_box(&*z)) {
            Ok(r) => {
                ok &= expect_ok;
                acc += r.existence + r.log_lr + r.frame as f32;
                if let Some(e) = r.estimate {
                    acc += e[0] + e[1] + e[2];
                }
                if let Some(e) = r.min_cost_estimate {
                    acc += e[0];
                }
            }
            Err(_) => ok &= !expect_ok,
        }
        for d in det.detections() {
            acc += d.score + d.state().iter().sum::<f32>();
        }
        let i = black_box(k % 3);
        if let Some(d) = det.detection(i) {
            acc += d.score;
        }
        acc += det.detection_count() as f32;
    }
    acc += det.config().validate().is_ok() as u32 as f32;
    det.reset(black_box(9));
    let z = make_frame(Kind::Good, model, black_box(24.9), 0.3, rng, &mut buf);
    if let Some(w) = whiten {
        ok &= unwindow(z, w).is_ok();
    }
    ok &= det.step(black_box(&*z)).is_ok();
    black_box(acc);
    ok
}

/// Every detector of the family at `N` on the configurations users run: CRPF-TBD with
/// the paper's values (the ln-free weights), a non-power-of-two exponent, forgetting
/// (`lambda > 0`, the log-domain weights) and eq. 5's weights; the Gaussian comparators
/// on Hamming frames (independent bins) and on `unwindow`ed frames (rectangular model,
/// variance `m s2`); configurations that must be rejected.
fn family<const N: usize>(
    crpf: &mut CrpfTbd<N>,
    pf: &mut PfTbd<N>,
    jott: &mut JottTbd<N>,
    lrt: &mut PfLrt<N>,
    rng: &mut Rng,
) -> bool {
    let mut ok = true;
    let hamming = black_box(ModelConfig::othr());
    let rect = ModelConfig {
        window: black_box(Window::Rectangular),
        ..hamming
    };
    let Ok(model_h) = DopplerModel::new(M, hamming.ts, hamming.window) else {
        return false;
    };
    let Ok(model_r) = DopplerModel::new(M, rect.ts, rect.window) else {
        return false;
    };
    let paper = black_box(CrpfConfig::othr());
    let crpf_cfgs = [
        paper,
        CrpfConfig {
            q: black_box(1.5),
            ..paper
        },
        CrpfConfig {
            lambda: black_box(0.3),
            q: black_box(2.0),
            ..paper
        },
        CrpfConfig {
            weighting: Weighting::Shifted {
                gamma: black_box(0.5),
            },
            r_th: black_box(0.0),
            ..paper
        },
        CrpfConfig {
            model: rect,
            p: black_box(2.0),
            ..paper
        },
        CrpfConfig {
            model: ModelConfig {
                phase: black_box(Phase::Unknown),
                ..hamming
            },
            ..paper
        },
    ];
    for (i, cfg) in crpf_cfgs.iter().enumerate() {
        ok &= crpf.configure(cfg, black_box(i as u64)).is_ok();
        // The rectangular-window configuration gets `unwindow`ed Hamming frames.
        let (model, whiten) = if cfg.model.window == Window::Rectangular {
            (&model_r, Some(Window::Hamming))
        } else {
            (&model_h, None)
        };
        ok &= exercise(crpf, model, whiten, rng);
        black_box(crpf.frame());
    }
    // Rejected configurations leave the detector as it was.
    ok &= crpf
        .configure(
            &CrpfConfig {
                p: black_box(f32::NAN),
                ..paper
            },
            0,
        )
        .is_err();
    ok &= crpf
        .configure(
            &CrpfConfig {
                jitter_std: [black_box(1e30), 0.1, 0.02],
                ..paper
            },
            0,
        )
        .is_err();

    let ham = black_box(GaussConfig::othr(BIN_VAR));
    let white = GaussConfig {
        model: rect,
        noise_var: black_box(M as f32) * black_box(1.0),
        birth: Default::default(),
        likelihood: Default::default(),
    };
    // The window-aware likelihood on the detector's path (frames whitened in the step).
    let aware = GaussConfig {
        likelihood: black_box(Likelihood::Window),
        ..ham
    };
    let shared = GaussConfig {
        birth: BirthProposal::FixedShare(black_box(0.1)),
        ..ham
    };
    let unknown = GaussConfig {
        model: ModelConfig {
            phase: black_box(Phase::Unknown),
            ..hamming
        },
        ..shared
    };
    for (cfg, model, whiten) in [
        (ham, &model_h, None),
        (white, &model_r, Some(Window::Hamming)),
        (shared, &model_h, None),
        (unknown, &model_h, None),
        (aware, &model_h, None),
    ] {
        ok &= pf.configure(&cfg, black_box(1)).is_ok();
        ok &= exercise(pf, model, whiten, rng);
        ok &= jott.configure(&cfg, black_box(2)).is_ok();
        ok &= exercise(jott, model, whiten, rng);
        ok &= lrt.configure(&cfg, black_box(3)).is_ok();
        ok &= exercise(lrt, model, whiten, rng);
        black_box(lrt.log_likelihood_ratio());
    }
    let bad = black_box(-1.0f32);
    ok &= pf.set_noise_variance(bad).is_err();
    ok &= jott.set_noise_variance(black_box(f32::INFINITY)).is_err();
    ok &= lrt.set_noise_variance(black_box(0.5)).is_ok();
    ok &= exercise(lrt, &model_h, None, rng);
    ok &= pf
        .configure(
            &GaussConfig {
                noise_var: black_box(0.0),
                ..ham
            },
            0,
        )
        .is_err();
    ok &= jott
        .configure(
            &GaussConfig {
                birth: BirthProposal::FixedShare(black_box(1.0)),
                ..ham
            },
            0,
        )
        .is_err();
    ok &= jott
        .configure(
            &GaussConfig {
                model: ModelConfig {
                    bins: black_box(MAX_BINS + 1),
                    ..hamming
                },
                ..ham
            },
            0,
        )
        .is_err();
    ok
}

/// `new` by value for a small `N` (and `N = 0`, an error), then a few frames.
fn by_value(rng: &mut Rng) -> bool {
    let mut ok = true;
    let Ok(model) = DopplerModel::new(M, 0.02, Window::Hamming) else {
        return false;
    };
    let seed = black_box(11u64);
    ok &= CrpfTbd::<0>::new(CrpfConfig::othr(), seed).is_err();
    ok &= PfTbd::<0>::new(GaussConfig::othr(BIN_VAR), seed).is_err();
    match CrpfTbd::<8>::new(black_box(CrpfConfig::othr()), seed) {
        Ok(mut d) => ok &= exercise(&mut d, &model, None, rng),
        Err(_) => ok = false,
    }
    let g = black_box(GaussConfig::othr(BIN_VAR));
    match PfTbd::<8>::new(g, seed) {
        Ok(mut d) => ok &= exercise(&mut d, &model, None, rng),
        Err(_) => ok = false,
    }
    match JottTbd::<8>::new(g, seed) {
        Ok(mut d) => ok &= exercise(&mut d, &model, None, rng),
        Err(_) => ok = false,
    }
    match PfLrt::<8>::new(g, seed) {
        Ok(mut d) => {
            ok &= exercise(&mut d, &model, None, rng);
            // The frame loop of the interface: stops at the NaN frame (index 1).
            let mut a = [Complex32::new(0.0, 0.0); MAX_BINS];
            let mut b = a;
            let za = &*make_frame(Kind::Good, &model, 3.0, 1.0, rng, &mut a);
            let zb = &*make_frame(Kind::Nan, &model, 3.0, 1.0, rng, &mut b);
            let frames: [&[Complex32]; 3] = [za, zb, za];
            let mut acc = 0.0f32;
            let r = run_frames(&mut d, black_box(frames).iter().copied(), |_, det, rep| {
                acc += rep.existence + det.detection_count() as f32;
            });
            ok &= matches!(r, Err(e) if e.frame == 1);
            black_box(acc);
        }
        Err(_) => ok = false,
    }
    ok
}

/// The public model functions the detectors are built from, on hidden inputs: frame
/// checks, the noise-variance estimate, `unwindow` (good, bad length, Hann), models of
/// every size and window, projections (direct, real-only, cached), the response, the
/// DTFT, the motion and the birth box.
fn model_functions(rng: &mut Rng) -> bool {
    let mut ok = true;
    let mut acc = 0.0f32;
    let mut buf = [Complex32::new(0.0, 0.0); MAX_BINS + 1];
    for c in buf.iter_mut() {
        *c = Complex32::new(rng.normal(), rng.normal());
    }
    let m = black_box(M);
    let len = black_box(MAX_BINS + 1);
    let z = buf.get(..m).unwrap_or(&[]);
    ok &= check_frame(z, m).is_ok();
    ok &= check_frame(buf.get(..len).unwrap_or(&[]), m).is_err();
    let frames = [z, z, buf.get(..black_box(3)).unwrap_or(&[])];
    ok &= estimate_noise_variance(frames.iter().copied().take(black_box(2)), m).is_ok();
    ok &= estimate_noise_variance(frames.iter().copied(), m).is_err();
    ok &= estimate_noise_variance(frames.iter().copied().take(black_box(0)), m).is_err();
    let mut w = buf;
    ok &= unwindow(
        w.get_mut(..m).unwrap_or(&mut []),
        black_box(Window::Hamming),
    )
    .is_ok();
    ok &= unwindow(w.get_mut(..len).unwrap_or(&mut []), Window::Hamming).is_err();
    ok &= unwindow(w.get_mut(..m).unwrap_or(&mut []), black_box(Window::Hann)).is_err();
    ok &= unwindow(&mut [], Window::Rectangular).is_err();
    let one = black_box(1usize);
    ok &= unwindow(w.get_mut(..one).unwrap_or(&mut []), Window::Hamming).is_ok();
    acc += w.iter().map(|c| c.re + c.im).sum::<f32>();

    // SAFETY: single-threaded, the only reference to this static.
    let cache = unsafe { only_ref(&raw mut CACHE) };
    let sizes = black_box([SPAN, 7, 31, M, 33, MAX_BINS, SPAN - 1, MAX_BINS + 1]);
    let windows = black_box([Window::Hamming, Window::Rectangular, Window::Hann]);
    for (i, &bins) in sizes.iter().enumerate() {
        let win = windows.get(i % 3).copied().unwrap_or_default();
        let ts = black_box(0.02f32);
        let model = match DopplerModel::new(bins, ts, win) {
            Ok(model) => model,
            Err(_) => {
                ok &= !(SPAN..=MAX_BINS).contains(&bins);
                continue;
            }
        };
        acc += model.ts() + model.frame_time() + model.window_sum() + model.window_energy();
        acc += model.bins() as f32 + (model.window() == win) as u32 as f32;
        let (lo, hi) = model.band();
        let zs = buf.get(..bins).unwrap_or(&[]);
        cache.new_frame();
        let fds = black_box([
            lo,
            hi,
            0.0,
            13.3,
            -24.99,
            1e30,
            f32::NAN,
            f32::INFINITY,
            -3e9,
        ]);
        for &fd in fds.iter() {
            let mut h = [Complex32::new(0.0, 0.0); SPAN];
            acc += model.response(fd, 1.0, &mut h) as f32 + h[0].re;
            let p = model.project(zs, fd, 0.7);
            let r = model.project_re(buf.get(..black_box(2)).unwrap_or(&[]), fd, 0.7);
            let c = model.project_cached::<true>(cache, zs, fd, 0.7);
            let c2 = model.project_cached::<false>(cache, zs, fd, 0.7);
            acc += p.zh.im + r.hh + c.zh.re + c2.hh;
            acc += p.residual_norm2(black_box(3.0)) + r.log_lr(black_box(0.1));
            acc += p.residual_norm2_unknown_phase(black_box(3.0))
                + c.log_lr_unknown_phase(black_box(0.1))
                + faint_core::math::ln_i0(black_box(acc));
        }
        let (re, im) = dtft(win, bins, black_box(0.3));
        acc += (re + im) as f32;
    }
    ok &= DopplerModel::new(M, black_box(-1.0), Window::Hamming).is_err();

    let cfg = black_box(ModelConfig::othr());
    match cfg.build() {
        Ok(model) => {
            let mut x = model.prior.sample(rng);
            for _ in 0..black_box(4) {
                x = model.motion.propagate(x, rng);
                x = model.motion.predict(x);
            }
            acc += x[0] + model.motion.wrap(black_box(1e30)) + model.motion.wrap(f32::NAN);
            acc += faint_core::model::doppler::Motion::wrap_offset(x[0], 24.0, 50.0);
            ok &= model.motion.validate().is_ok() && model.prior.validate().is_ok();
        }
        Err(_) => ok = false,
    }
    acc += max_amplitude(black_box(0)) + max_amplitude(m);
    ok &= CrpfConfig::othr().validate().is_ok();
    ok &= GaussConfig::othr(black_box(f32::NAN)).validate().is_err();
    black_box(acc);
    ok
}
