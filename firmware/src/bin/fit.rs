//! One detector configuration for one part: the image whose link says whether the
//! configuration fits the part's RAM regions, and whose run gives its cost per frame.
//!
//! `build.rs` reads the configuration from the environment: `FAINT_FIT` (the detector
//! and its sizes, e.g. `crpf:1000`, `phd:2048:256:16`), `FAINT_FIT_STATE` and
//! `FAINT_FIT_FRAME` (the output sections of the detector's state and of its input
//! frame), `FAINT_BOARD` (the part's `memory.x`, under `boards/`). `boards/fit.py` builds
//! the matrix of detectors and parts and prints the tables (firmware/README.md,
//! "Boards").
//!
//! The detector and its frame are `static`s in their sections, NOLOAD (the start-up code
//! neither loads nor zeroes them): the image zeroes them, then `configure` sets the
//! detector up in place (an all-zero value of every type used here is valid: the `const`
//! items below make the compiler check it). The frames, seeds and measured frames are the
//! instruction table's (`src/rows/*.rs`), and every measured `step` is bracketed by the
//! cycle model's markers, so `faint-cycles run` costs this image too. Output: one
//! `region` line per measured frame, then
//! `fit | <spec> | <board> | <frames> | <mean> | <worst> | <stack> | <hash>`: the count
//! per frame (mean and worst), the step's peak stack and a hash of the reports' `Debug`
//! text (equal on every board that runs the image); then `fit stack | run <B> | ...`, the
//! whole run's deepest stack below its top (set-up, frame generation and steps, each
//! measured where it runs).
#![no_std]
#![no_main]

use core::fmt::Debug;
use core::hint::black_box;
use core::mem::MaybeUninit;

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use faint_firmware::board::{self, Fnv};
use faint_firmware::harness::check;
use faint_firmware::semihosting::exit_success;

faint_firmware::report_panics!();

#[allow(dead_code, unused_macros)]
#[macro_use]
mod fit {
    include!(concat!(env!("OUT_DIR"), "/fit.rs"));
}
#[allow(unused_imports)] // the classic Hough TBD takes no sizes
use fit::P;

/// Start of a traced region (`faint-cycles` finds it by name).
#[no_mangle]
#[inline(never)]
pub extern "C" fn faint_cycles_begin() {
    // SAFETY: a `nop`; the two markers' bodies differ, so the linker keeps both.
    unsafe { core::arch::asm!("nop", options(nostack, preserves_flags)) }
}

/// End of a traced region.
#[no_mangle]
#[inline(never)]
pub extern "C" fn faint_cycles_end() {
    // SAFETY: as above.
    unsafe { core::arch::asm!("nop", "nop", options(nostack, preserves_flags)) }
}

/// The per-frame counts of one run.
struct Stats {
    frames: u32,
    sum: u64,
    worst: u64,
    stack: u32,
    /// Deepest stack below its top of every call measured (steps, and the set-up and
    /// unmeasured calls of [`Stats::setup`]).
    deepest: usize,
    hash: Fnv,
}

impl Stats {
    const fn new() -> Self {
        Self {
            frames: 0,
            sum: 0,
            worst: 0,
            stack: 0,
            deepest: 0,
            hash: Fnv::new(),
        }
    }

    /// Runs a set-up call (`configure`, a frame generator, an unmeasured `step`) and keeps
    /// its depth below the stack's top: each measured step repaints the 16 KiB below its
    /// caller, which erases the marks of deeper set-up calls made before it, so every
    /// call whose stack counts for the run is measured where it runs.
    fn setup<R>(&mut self, f: impl FnOnce() -> R) -> R {
        let sp = cortex_m::register::msp::read() as usize;
        let (r, _, stack) = board::measure(f);
        self.deepest = self.deepest.max(depth(sp, stack));
        r
    }

    /// Measures one `step` (with the markers) and prints its `region` line.
    fn step<R: Debug>(&mut self, label: &str, k: usize, f: impl FnOnce() -> R) -> R {
        let sp = cortex_m::register::msp::read() as usize;
        let (r, n, stack) = board::measure(|| {
            faint_cycles_begin();
            let r = f();
            faint_cycles_end();
            r
        });
        hprintln!("region | step | {} frame {} | - | {} |", label, k, n);
        self.frames += 1;
        self.sum += n;
        self.worst = self.worst.max(n);
        self.stack = self.stack.max(stack);
        self.deepest = self.deepest.max(depth(sp, stack));
        self.hash.fold(&r);
        r
    }

    /// Folds an unmeasured step's report into the hash (the PHD images measure every
    /// frame).
    #[allow(dead_code)]
    fn fold<R: Debug>(&mut self, r: &R) {
        self.hash.fold(r);
    }

    fn print(&self) {
        hprintln!(
            "fit | {} | {} | {} | {} | {} | {} | {:016x} |",
            fit::SPEC,
            fit::BOARD,
            self.frames,
            self.sum / u64::from(self.frames.max(1)),
            self.worst,
            self.stack,
            self.hash.0
        );
    }
}

/// Depth below the stack's top of a call measured at `sp` that used `stack` bytes.
fn depth(sp: usize, stack: u32) -> usize {
    (&raw const _stack_start as usize) - sp + stack as usize
}

/// Zeroes a NOLOAD static and hands out its only `&mut`.
///
/// # Safety
/// Called once per static; an all-zero `T` is a valid value.
unsafe fn zeroed<T>(p: *mut MaybeUninit<T>) -> &'static mut T {
    // SAFETY: the caller's contract; `p` points to a static of `T`'s size.
    unsafe {
        core::ptr::write_bytes(p, 0, 1);
        (*p).assume_init_mut()
    }
}

/// Sizes of the state, the frame and the harness's statics that go with the frame (the
/// CRPF family's frame-generation model; 0 for the others), printed for the tables.
fn sizes(state: usize, frame: usize, harness: usize) {
    hprintln!(
        "fit sizes | state {} B in {} | frame {} B in {} | harness {} B in {} |",
        state,
        fit::SECTIONS[0],
        frame,
        fit::SECTIONS[1],
        harness,
        fit::SECTIONS[1]
    );
}

// ---- CRPF-TBD and its comparators ---------------------------------------------------

#[cfg(any(
    faint_fit = "crpf",
    faint_fit = "pf-tbd",
    faint_fit = "jott",
    faint_fit = "pf-lrt"
))]
mod det {
    use super::*;
    use faint_core::detect::Detector;
    use faint_core::model::doppler::{DopplerModel, Window};
    use faint_core::rng::Rng;
    use faint_core::Complex32;
    use faint_golden::crpf::{frame, target, BIN_VAR};

    const N: usize = P[0];
    #[cfg(faint_fit = "crpf")]
    type Det = faint_core::detect::crpf::CrpfTbd<N>;
    #[cfg(faint_fit = "pf-tbd")]
    type Det = faint_core::detect::pf_tbd::PfTbd<N>;
    #[cfg(faint_fit = "jott")]
    type Det = faint_core::detect::jott::JottTbd<N>;
    #[cfg(faint_fit = "pf-lrt")]
    type Det = faint_core::detect::pf_lrt::PfLrt<N>;
    const _: Det = unsafe { MaybeUninit::zeroed().assume_init() };

    state_static! { static mut STATE: MaybeUninit<Det> = MaybeUninit::uninit(); }
    frame_static! { static mut FRAME: MaybeUninit<[Complex32; 32]> = MaybeUninit::uninit(); }
    // The harness's model of the frames it generates (not the detector's), built in place
    // rather than on the stack, in the frame's section: on the STM32F407 the frame and
    // this model can go to CCM together and leave the RAM to the detector.
    frame_static! { static mut FRAME_MODEL: MaybeUninit<DopplerModel> = MaybeUninit::uninit(); }
    const _: DopplerModel = unsafe { MaybeUninit::zeroed().assume_init() };

    /// `src/rows/crpf.rs`'s seeds: `SEEDS` detector seeds on the golden frames 0..=8,
    /// frames 1, 6 and 8 measured (CRPF-TBD's rows over 32 seeds; the comparators the same).
    const SEED: u64 = 0x00C0_57F1_17E2_2017;
    const SEEDS: u64 = 32;
    const MEASURED: [usize; 3] = [1, 6, 8];

    pub fn run(st: &mut Stats) {
        // SAFETY: one call each; all-zero values are valid (checked above).
        let (det, z, model) = unsafe {
            (
                zeroed(&raw mut STATE),
                zeroed(&raw mut FRAME),
                zeroed(&raw mut FRAME_MODEL),
            )
        };
        sizes(
            size_of::<Det>(),
            size_of::<[Complex32; 32]>(),
            size_of::<DopplerModel>(),
        );
        check(st.setup(|| model.build_into(32, 0.02, Window::Hamming)));
        for s in 0..SEEDS {
            #[cfg(faint_fit = "crpf")]
            let cfg = faint_core::detect::crpf::CrpfConfig::othr();
            #[cfg(not(faint_fit = "crpf"))]
            let cfg = faint_core::detect::pf_tbd::GaussConfig::othr(BIN_VAR);
            check(st.setup(|| det.configure(&cfg, SEED + s)));
            let mut rng = Rng::from_stream(SEED, 1);
            for k in 0..=8 {
                let (fd, amp) = target(k);
                st.setup(|| frame(model, fd, amp, BIN_VAR, &mut rng, z));
                if MEASURED.contains(&k) {
                    check(st.step(fit::SPEC, k, || det.step(black_box(&z[..]))));
                } else {
                    let r = check(st.setup(|| det.step(&z[..])));
                    st.fold(&r);
                }
            }
        }
    }
}

// ---- MHT-TBD and the classic Hough TBD ------------------------------------------------

#[cfg(any(faint_fit = "mht", faint_fit = "hough"))]
mod det {
    use super::*;
    use faint_core::detect::Detector;
    use faint_core::model::plot::Plot;
    use faint_core::rng::Rng;
    use faint_golden::mht::{cost_scan, COST_SEED};

    /// Plots per scan (the cost scans hold 398 clutter plots and up to 5 targets).
    #[cfg(faint_fit = "mht")]
    const PLOTS: usize = P[0];
    #[cfg(faint_fit = "hough")]
    const PLOTS: usize = 512;
    #[cfg(faint_fit = "mht")]
    type Det = faint_core::detect::mht::MhtTbd<PLOTS, 30, 256, 180, 32>;
    #[cfg(faint_fit = "hough")]
    type Det = faint_core::detect::mht::ClassicHough<256, 180, 64>;
    const _: Det = unsafe { MaybeUninit::zeroed().assume_init() };

    state_static! { static mut STATE: MaybeUninit<Det> = MaybeUninit::uninit(); }
    frame_static! { static mut FRAME: MaybeUninit<[Plot; PLOTS]> = MaybeUninit::uninit(); }

    /// `src/rows/mht.rs`: 30 scans of the sea-clutter cost scene (`gamma_1 = 22`), scans
    /// 2..=29 measured (29 ends the period: censoring, DMHT, peaks, association).
    pub fn run(st: &mut Stats) {
        // SAFETY: one call each; all-zero values are valid (checked above).
        let (det, buf) = unsafe { (zeroed(&raw mut STATE), zeroed(&raw mut FRAME)) };
        // MHT-TBD's unconfigured value is not all zero bits (its censor and accumulator
        // start from other values, which `configure` keeps): copy it from flash, where
        // the image carries it (as the instruction table's image carries it in `.data`),
        // not through the stack.
        #[cfg(faint_fit = "mht")]
        {
            static INIT: Det = Det::new_unconfigured();
            // SAFETY: `det` is the only reference to the static; `INIT` is a valid `Det`
            // in flash; the two do not overlap.
            unsafe { core::ptr::copy_nonoverlapping(&INIT, &raw mut *det, 1) };
        }
        sizes(size_of::<Det>(), size_of::<[Plot; PLOTS]>(), 0);
        #[cfg(faint_fit = "mht")]
        let cfg = {
            let mut c = faint_core::detect::mht::MhtConfig::sea_clutter();
            c.gamma1 = 22;
            c
        };
        #[cfg(faint_fit = "hough")]
        let cfg = faint_golden::soak::CLASSIC;
        check(st.setup(|| det.configure(&cfg, 0)));
        let mut rng = Rng::from_stream(COST_SEED, 0);
        for s in 0..30 {
            let n = st.setup(|| cost_scan(&mut rng, s, buf));
            if s >= 2 {
                check(st.step(fit::SPEC, s, || det.step(black_box(&buf[..n]))));
            } else {
                let r = check(st.setup(|| det.step(&buf[..n])));
                st.fold(&r);
            }
        }
    }
}

// ---- PHD-TBD and PSO-PHD-TBD (K-means) -----------------------------------------------

#[cfg(any(faint_fit = "phd", faint_fit = "pso-phd"))]
mod det {
    use super::*;
    use faint_core::detect::Detector;
    use faint_core::model::power_cube::CubeGeometry;
    use faint_core::rng::Rng;
    use faint_golden::phd::{config, cube, ALGORITHMS, FIRMWARE_WINDOW, FRAMES};

    /// Particles, swarm entries, cube side (cells per axis).
    const N: usize = P[0];
    const S: usize = P[1];
    const W: usize = P[2];
    const CELLS: usize = W * W * W;
    type Det = faint_core::detect::phd::SmcPhdTbd<N, S, 8, 8>;
    const _: Det = unsafe { MaybeUninit::zeroed().assume_init() };

    state_static! { static mut STATE: MaybeUninit<Det> = MaybeUninit::uninit(); }
    frame_static! { static mut FRAME: MaybeUninit<[f32; CELLS]> = MaybeUninit::uninit(); }

    /// The firmware window (32 cells a side, 1 cell = 20 m x 1 m/s x 1 deg) cut to `W`
    /// cells a side around its centre (`W = 16` is the golden case's window).
    const fn window() -> CubeGeometry {
        let cut = (FIRMWARE_WINDOW.n_range - W) as f32 / 2.0;
        CubeGeometry {
            n_range: W,
            n_doppler: W,
            n_azimuth: W,
            range_start: FIRMWARE_WINDOW.range_start + cut * FIRMWARE_WINDOW.range_cell,
            doppler_start: FIRMWARE_WINDOW.doppler_start + cut * FIRMWARE_WINDOW.doppler_cell,
            azimuth_start_deg: FIRMWARE_WINDOW.azimuth_start_deg
                + cut * FIRMWARE_WINDOW.azimuth_cell_deg,
            ..FIRMWARE_WINDOW
        }
    }
    const _: () = assert!(W <= 32 && W.is_multiple_of(2));

    /// Particles per target and birth particles: the firmware rows' configurations at
    /// `N = 6144` (1000 and 500) and `N = 2048` (the 512 KiB configuration: 500 and 500,
    /// whose accuracy the host tests check); other `N` scale the first by `N / 6144`.
    const PER_TARGET_BIRTHS: (usize, usize) = match N {
        6144 => (1000, 500),
        2048 => (500, 500),
        _ => (N * 1000 / 6144, N * 500 / 6144),
    };

    /// `src/rows/phd.rs`: the scene's 10 frames from a restart, every frame measured.
    pub fn run(st: &mut Stats) {
        const SEED: u64 = 0x0002_0019_9E1D_7BD0;
        // SAFETY: one call each; all-zero values are valid (checked above).
        let (det, buf) = unsafe { (zeroed(&raw mut STATE), zeroed(&raw mut FRAME)) };
        sizes(size_of::<Det>(), size_of::<[f32; CELLS]>(), 0);
        #[cfg(faint_fit = "phd")]
        let alg = ALGORITHMS[0];
        #[cfg(faint_fit = "pso-phd")]
        let alg = ALGORITHMS[1];
        let (per_target, births) = PER_TARGET_BIRTHS;
        let cfg = config(window(), alg, per_target, births, 8);
        check(st.setup(|| det.configure(&cfg, SEED)));
        let mut rng = Rng::from_stream(SEED, 1);
        let g = window();
        for k in 0..FRAMES {
            st.setup(|| cube(&g, k, &mut rng, &mut buf[..]));
            check(st.step(fit::SPEC, k, || det.step(black_box(&buf[..]))));
        }
    }
}

// ---- CBMeMBer TBD -------------------------------------------------------------------

#[cfg(faint_fit = "cbmember")]
mod det {
    use super::*;
    use faint_core::detect::Detector;
    use faint_core::model::range_doppler::PointModel;
    use faint_core::rng::Rng;
    use faint_golden::cbmember::{config, map};

    /// Particles per Bernoulli component (4 components, 8192 block sums).
    const N: usize = P[0];
    const PIXELS: usize = 256 * 512;
    type Cell = f32;
    type Det = faint_core::detect::cbmember::CbmemberTbd<4, N, 8192, [Cell]>;
    const _: Det = unsafe { MaybeUninit::zeroed().assume_init() };

    state_static! { static mut STATE: MaybeUninit<Det> = MaybeUninit::uninit(); }
    frame_static! { static mut FRAME: MaybeUninit<[Cell; PIXELS]> = MaybeUninit::uninit(); }

    /// `src/rows/cbmember.rs`: the 256 x 512 rotor-UAV map at -10 dB (`f32`, 512 KiB),
    /// joint model, 450 births, 6 frames, frames 1-5 measured.
    pub fn run(st: &mut Stats) {
        const SEED: u64 = 0x0003_CB3E_3BE7_2023;
        // SAFETY: one call each; all-zero values are valid (checked above).
        let (det, z) = unsafe { (zeroed(&raw mut STATE), zeroed(&raw mut FRAME)) };
        sizes(size_of::<Det>(), size_of::<[Cell; PIXELS]>(), 0);
        let g = faint_core::detect::cbmember::CbmemberConfig::rotor_uav().geometry;
        let cfg = config(g, PointModel::Joint, N, 450);
        check(st.setup(|| det.configure(&cfg, SEED)));
        let mut rng = Rng::from_stream(SEED, 1);
        for k in 0..6 {
            st.setup(|| map(&cfg.geometry, k, &mut rng, &mut z[..]));
            if k >= 1 {
                check(st.step(fit::SPEC, k, || det.step(black_box(&z[..]))));
            } else {
                let r = check(st.setup(|| det.step(&z[..])));
                st.fold(&r);
            }
        }
    }
}

// ---- DP-TBD -------------------------------------------------------------------------

#[cfg(any(
    faint_fit = "dp-first",
    faint_fit = "dp-pulford",
    faint_fit = "dp-second"
))]
mod det {
    use super::*;
    use faint_core::detect::dp::{DpConfig, Method};
    use faint_core::dp_tbd;
    use faint_core::rng::Rng;
    use faint_golden::dp::{frame, SIGMA};

    /// Image side, merit cell bits (16 or 8; Pulford: 16).
    const M: usize = P[0];
    const L: usize = 8;
    #[cfg(faint_fit = "dp-first")]
    const BITS: usize = P[1];
    #[cfg(faint_fit = "dp-second")]
    const BITS: usize = P[1];
    #[cfg(faint_fit = "dp-pulford")]
    const BITS: usize = 16;
    const _: () = assert!(
        BITS == 8 || BITS == 16,
        "DP-TBD merit cells are 8 or 16 bits"
    );

    #[cfg(faint_fit = "dp-first")]
    type D16 = dp_tbd!(Arnold, M, 9, L);
    #[cfg(faint_fit = "dp-first")]
    type D8 = dp_tbd!(Arnold, M, 9, L, i8);
    #[cfg(faint_fit = "dp-second")]
    type D16 = dp_tbd!(SecondOrder, M, 9, L);
    #[cfg(faint_fit = "dp-second")]
    type D8 = dp_tbd!(SecondOrder, M, 9, L, i8);
    #[cfg(faint_fit = "dp-pulford")]
    type D16 = dp_tbd!(Pulford, M, 9, L);
    #[cfg(faint_fit = "dp-pulford")]
    type D8 = D16;

    /// The `BITS` variant (one is linked; the other is a zero-sized placeholder).
    type Pick<A, B> = <Sel<{ BITS == 16 }> as Choose<A, B>>::T;
    struct Sel<const C: bool>;
    trait Choose<A, B> {
        type T;
    }
    impl<A, B> Choose<A, B> for Sel<true> {
        type T = A;
    }
    impl<A, B> Choose<A, B> for Sel<false> {
        type T = B;
    }
    type Det = Pick<D16, D8>;
    const _: Det = unsafe { MaybeUninit::zeroed().assume_init() };

    state_static! { static mut STATE: MaybeUninit<Det> = MaybeUninit::uninit(); }
    frame_static! { static mut FRAME: MaybeUninit<[f32; M * M]> = MaybeUninit::uninit(); }

    /// `src/rows/dp.rs`: 8 frames of the dim-point scene (SNR 2), frames 3-8 measured;
    /// `i8` merits with the coarser LSB 0.25 the rows use.
    pub fn run(st: &mut Stats) {
        use faint_core::detect::Detector;
        // SAFETY: one call each; all-zero values are valid (checked above).
        let (det, image) = unsafe { (zeroed(&raw mut STATE), zeroed(&raw mut FRAME)) };
        sizes(size_of::<Det>(), size_of::<[f32; M * M]>(), 0);
        #[cfg(faint_fit = "dp-first")]
        let method = Method::Arnold;
        #[cfg(faint_fit = "dp-pulford")]
        let method = Method::Pulford;
        #[cfg(faint_fit = "dp-second")]
        let method = Method::SecondOrder;
        let mut cfg = DpConfig::dim_point(method, 1);
        if BITS == 8 {
            cfg.lsb = 0.25;
        }
        check(st.setup(|| det.configure(&cfg, 0)));
        let mut rng = Rng::from_stream(0x0004_D9B8_CDB8_7468, 1);
        for k in 0..8 {
            st.setup(|| frame(M, k, 2.0 * SIGMA, &mut rng, &mut image[..]));
            if k >= 2 {
                check(st.step(fit::SPEC, k + 1, || det.step(black_box(&image[..]))));
            } else {
                let r = check(st.setup(|| det.step(&image[..])));
                st.fold(&r);
            }
        }
    }
}

extern "C" {
    /// End of `.uninit`, the last RAM section below the stack, and the stack's top
    /// (cortex-m-rt's `link.x`).
    static __euninit: u32;
    static _stack_start: u32;
}

#[entry]
fn main() -> ! {
    // The whole run's peak stack (set-up included) below the stack's top: paint from the
    // end of the statics (at most 1 MiB) up to this frame, scan at the end.
    let top = &raw const _stack_start as usize;
    let sp = cortex_m::register::msp::read() as usize;
    let lo = (&raw const __euninit as usize).max(top.saturating_sub(1 << 20));
    faint_firmware::harness::paint(lo, sp - 256);
    board::init();
    hprintln!(
        "fit | board {} | {} | counts: {} |",
        fit::BOARD,
        fit::SPEC,
        board::UNIT
    );
    let (short, long) = board::calibrate();
    hprintln!(
        "calibration: subs/bne loop of 1000 iterations = {}, 11000 = {}, difference {} (20000 instructions under QEMU)",
        short,
        long,
        long.wrapping_sub(short)
    );
    #[cfg(not(any(faint_board = "stm32h743", faint_board = "atsame70q21")))]
    assert!(
        long.wrapping_sub(short) == 20_000,
        "counter is not counting instructions: run QEMU with -icount shift=10,align=off,sleep=off"
    );
    // The empty region the cycle model subtracts (the marker calls).
    let ((), n, _) = board::measure(|| {
        faint_cycles_begin();
        faint_cycles_end();
    });
    hprintln!("region | base | empty | - | {} |", n);
    let mut st = Stats::new();
    det::run(&mut st);
    st.print();
    let run = top - faint_firmware::harness::lowest_touched(lo, sp - 256);
    hprintln!(
        "fit stack | run {} B | step {} B | room {} B |",
        run.max(st.deepest),
        st.stack,
        top - lo
    );
    hprintln!("done");
    exit_success()
}
