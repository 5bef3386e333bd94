//! Soak on the emulated Cortex-M4F: every detector of `faint detect --list` streamed
//! `frames` plausible frames without a reset, in the sizes below, counting per detector the
//! frames, the errors, the steps with a NaN/inf output, the executed instructions per frame
//! of every block of `frames / 20` frames (first, last, worst block: a drift shows as their
//! ratio) and the peak stack.
//!
//! ```sh
//! cd firmware && cargo run -q --profile firmware --bin soak
//! cd firmware && cargo run -q --profile firmware --bin soak -- -append "frames=200000 only=pf-lrt"
//! ```
//!
//! Arguments (QEMU's `-append`, read through semihosting): `frames=N` (default 10 000)
//! and `only=a,b` (names as in `faint detect --list`; default all). The diagnostic
//! variants `pf-lrt-fixed-rate` and `pf-lrt-fixed-amp` run only when named.
//!
//! **Frames** are those of the host's `faint soak` (`host/src/reliability/frames.rs`,
//! mode `Plausible`, one stream `Rng::seed_from_u64(1)`, detector seed 1): noise at the
//! preset's scale, one value in 8 with a strong return added (ten times the noise std);
//! Doppler frames of 32 complex bins, power maps and cubes `|x|^2`, DP images of signed
//! values (std 1.5), and plot lists of 0 to twice the capacity. The Doppler-frame filters
//! (1000 particles), MHT-TBD and the classic Hough TBD have the host's types and
//! configuration, so they see the host soak's frames bit for bit.
//!
//! **Sizes** (the preset would take hours under QEMU for some):
//! - CRPF-TBD, PF-TBD, JOTT, PF-LRT: `N = 1000`, the OTHR preset (noise variance 1).
//! - MHT-TBD `MhtTbd<640, 30, 256, 180, 32>` and `ClassicHough<256, 180, 64>` with the
//!   host's sea-clutter configurations.
//! - PHD-TBD, PSO-PHD-TBD (K-means, DBSCAN): `SmcPhdTbd<1024, 64, 8, 16>` with the golden
//!   scene's filter settings (`faint_golden::phd::config`: 50 particles per target, 25
//!   births, at most 32 swarm particles) on an 8 x 8 x 4 window of the golden scene's cells
//!   (the sizes of the host's `faint soak --shape reduced`, the golden scene's settings).
//! - CBMeMBer (joint, Doppler-only): `CbmemberTbd<4, 100, 128>`, the `rotor-uav` preset on
//!   a 32 x 64 map over the preset's extent, `L_max = 100`, `L_min = 30`, 30 births
//!   (the host's `faint soak --shape reduced`).
//! - DP-TBD: the first order on 128 x 128 images (the preset), Pulford and the second order
//!   on 32 x 32 images (the host's `--shape reduced`); `q_B = 9`, `L = 40`.
//!
//! **Counts.** Each `step` is counted with the harness's timer (exact executed
//! instructions, see `harness.rs`) and the board's dual timer for the wraps of the 32-bit
//! timer. A block line gives the block's mean and largest count per frame and two
//! detector-specific block means (work counters: `w1`, `w2`, see [`Spec`]). The peak
//! stack is the deepest write into a painted 16 KiB window below the soak loop's frame,
//! read after every `step` and painted again after the output check: the deeper of the
//! frame generator's and `step`'s stack (the generator's is 172 B). The output check is
//! left out: it formats the report's floats, which on a few values goes ~1.6 KB deeper
//! than on the others (most likely `core::fmt`'s Dragon4 fallback when Grisu fails).
//! `phases=1` measures generator, `step` and check apart (a diagnostic: one paint and one
//! scan per phase) and prints each one's peak with the first frame that reached it.
#![no_std]
#![no_main]

#[path = "../harness.rs"]
#[allow(dead_code)]
mod harness;

use core::fmt::{self, Debug, Write};
use core::hint::black_box;
use core::mem::{size_of, MaybeUninit};
use core::ptr::{read_volatile, write_volatile};
use core::sync::atomic::{AtomicBool, Ordering};

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use faint_core::detect::cbmember::{CbmemberConfig, CbmemberTbdSoak};
use faint_core::detect::crpf::{CrpfConfig, CrpfTbd};
use faint_core::detect::dp::{
    arnold_words, pulford_words, second_order_words, ArnoldDp, DpConfig, Method, PulfordDp,
    SecondOrderDp,
};
use faint_core::detect::jott::JottTbd;
use faint_core::detect::mht::{ClassicHoughConfig, ClassicHoughHost, MhtConfig, MhtTbdHost};
use faint_core::detect::pf_lrt::PfLrt;
use faint_core::detect::pf_tbd::{GaussConfig, PfTbd};
use faint_core::detect::phd::{PhdConfig, SmcPhdTbdSoak};
use faint_core::detect::{Detector, ScoreKind};
use faint_core::model::doppler::DopplerReport;
use faint_core::model::plot::Plot;
use faint_core::model::power_cube::CubeGeometry;
use faint_core::model::range_doppler::PointModel;
use faint_core::rng::Rng;
use faint_core::Complex32;

use harness::{lowest_touched, paint, raw_instructions, Static, Text};

/// Frames per detector unless `frames=` says otherwise.
const DEFAULT_FRAMES: u32 = 10_000;
/// Blocks a run is cut into.
const BLOCKS: u32 = 20;
/// Seed of the frames and of the detectors (the host soak's default).
const SEED: u64 = 1;

/// The run's arguments, from the semihosting command line (QEMU's `-append`):
/// `frames=N` and `only=name,name`.
struct Args {
    frames: u32,
    only: Text<256>,
}

/// `phases=1`: the peak stack of each phase of a frame (generator, `step`, output check)
/// is measured on its own, the window painted before each (a diagnostic: it costs a
/// paint and a scan of the 64 KiB window per phase), and reported per detector with the
/// frame that first reached it.
static PHASES: AtomicBool = AtomicBool::new(false);

static mut CMDLINE: [u8; 256] = [0; 256];

impl Args {
    /// Reads the command line (`SYS_GET_CMDLINE`: the kernel's path, then `-append`).
    fn read() -> Self {
        let mut args = Args {
            frames: DEFAULT_FRAMES,
            only: Text::new(),
        };
        // SAFETY: single-threaded; the block is the buffer's address and length, which
        // the host fills with the command line and its length.
        let line = unsafe {
            let buf = &mut *core::ptr::addr_of_mut!(CMDLINE);
            let mut block = [buf.as_mut_ptr() as usize, buf.len()];
            let rc = cortex_m_semihosting::syscall1(
                cortex_m_semihosting::nr::GET_CMDLINE,
                block.as_mut_ptr() as usize,
            );
            if rc != 0 {
                return args;
            }
            let n = block[1].min(buf.len());
            core::str::from_utf8(&buf[..n]).unwrap_or("")
        };
        for word in line.split_ascii_whitespace().skip(1) {
            if let Some(v) = word.strip_prefix("frames=") {
                if let Ok(f) = v.parse::<u32>() {
                    args.frames = f.max(1);
                }
            } else if word == "phases=1" {
                PHASES.store(true, Ordering::Relaxed);
            } else if let Some(v) = word.strip_prefix("only=") {
                args.only.clear();
                let _ = args.only.write_str(v);
            }
        }
        args
    }

    /// True when `name` is selected (`only=` unset: every detector but the diagnostic
    /// variants).
    fn selected(&self, name: &str) -> bool {
        let list = self.only.as_str();
        list.is_empty() || list == "all" || self.named(name)
    }

    /// True when `name` is in `only=` (the diagnostic variants run only so).
    fn named(&self, name: &str) -> bool {
        self.only.as_str().split(',').any(|n| n == name)
    }
}

// ---------------------------------------------------------------------------------------
// Counting: timer0 (exact, wraps every 167.8 M instructions) and the dual timer (/256
// prescaler, 10 instructions per tick) for the wraps, as the PHD rows of the table do.

const DUAL_LOAD: *mut u32 = 0x4000_2000 as *mut u32;
const DUAL_VALUE: *mut u32 = 0x4000_2004 as *mut u32;
const DUAL_CONTROL: *mut u32 = 0x4000_2008 as *mut u32;
/// Instructions per wrap of timer0: `2^32` ticks at 25.6 ticks each.
const WRAP: u64 = (1 << 32) * 10 / 256;

fn coarse_start() {
    // SAFETY: the dual timer's registers on the MPS2 memory map; nothing else uses it.
    unsafe {
        write_volatile(DUAL_CONTROL, 0);
        write_volatile(DUAL_LOAD, u32::MAX);
        write_volatile(DUAL_CONTROL, 0x80 | (2 << 2) | 0x02);
    }
}

fn coarse() -> u32 {
    // SAFETY: read of a device register.
    unsafe { read_volatile(DUAL_VALUE) }
}

/// Stack window painted below the soak loop's frame (every detector's step measured so
/// far stays under 4.5 KiB; a row at `WINDOW` means at least that much).
const WINDOW: usize = 16 * 1024;

/// Instructions of an empty [`count`] (subtracted).
static mut BASELINE: u64 = 0;

/// Runs `f`, returning its result and executed instructions (baseline subtracted).
#[inline(always)]
fn count<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let c0 = coarse();
    let (r, fine) = raw_instructions(f);
    let c1 = coarse();
    let approx = u64::from(c0.wrapping_sub(c1)) * 10;
    let fine = u64::from(fine);
    let wraps = (approx + WRAP / 2).saturating_sub(fine) / WRAP;
    // SAFETY: written once before any detector runs; single-threaded.
    let base = unsafe { BASELINE };
    (r, (fine + wraps * WRAP).saturating_sub(base))
}

/// The deepest stack one phase of a frame reached and the first frame that reached it.
#[derive(Default, Clone, Copy)]
struct Peak {
    bytes: usize,
    frame: u64,
}

/// Runs one phase of frame `frame` on a freshly painted window `[lo, hi)` and raises
/// `peak` to its stack below `top` (`phases=1`).
fn phase<R>(
    top: usize,
    lo: usize,
    hi: usize,
    peak: &mut Peak,
    frame: u64,
    f: impl FnOnce() -> R,
) -> R {
    paint(lo, hi);
    let r = f();
    let bytes = top - lowest_touched(lo, hi);
    if bytes > peak.bytes {
        *peak = Peak { bytes, frame };
    }
    r
}

// ---------------------------------------------------------------------------------------
// Frames: the host's `Mode::Plausible` generators, call for call.

/// One plausible value: `N(0, s^2)` plus, one time in 8, `10 s` (`|.|^2` of both when
/// `positive`).
#[inline]
fn plausible(rng: &mut Rng, s: f32, positive: bool) -> f32 {
    let x = rng.normal() * s;
    let strong = if rng.below(8) == 0 { 10.0 * s } else { 0.0 };
    if positive {
        x * x + strong * strong
    } else {
        x + strong
    }
}

fn reals(rng: &mut Rng, out: &mut [f32], s: f32, positive: bool) -> usize {
    for o in out.iter_mut() {
        *o = plausible(rng, s, positive);
    }
    out.len()
}

fn complex(rng: &mut Rng, out: &mut [Complex32]) -> usize {
    for o in out.iter_mut() {
        let re = plausible(rng, 1.0, false);
        let im = plausible(rng, 1.0, false);
        *o = Complex32::new(re, im);
    }
    out.len()
}

/// A scan of 0 to `2 capacity + 1` plots inside `area` (`out` holds at least that many).
fn plots(rng: &mut Rng, area: [f32; 4], capacity: usize, out: &mut [Plot]) -> usize {
    let n = match rng.below(8) {
        0 => 0,
        1 => capacity + 1 + rng.below(capacity as u32 + 1) as usize,
        _ => rng.below(capacity.min(64) as u32 + 1) as usize,
    };
    let n = n.min(out.len());
    let (x0, x1) = (area[0].min(area[1]), area[1].max(area[0]));
    let (y0, y1) = (area[2].min(area[3]), area[3].max(area[2]));
    for o in out[..n].iter_mut() {
        let a = 1.0 + rng.exponential();
        let x = rng.uniform_range(x0, x1);
        let y = rng.uniform_range(y0, y1);
        *o = Plot::new(a, x, y);
    }
    n
}

// ---------------------------------------------------------------------------------------
// Output check: the host's (`check_outputs`): "NaN" or "inf" anywhere in the report's
// Debug text, a non-finite detection, or an existence score outside [0, 1].

/// A `fmt::Write` that only notes whether "NaN" or "inf" was written.
struct NonFinite(bool);

impl Write for NonFinite {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        if s.contains("NaN") || s.contains("inf") {
            self.0 = true;
        }
        Ok(())
    }
}

fn bad_output<D: Detector + ?Sized>(det: &D, report: &D::Report) -> bool
where
    D::Report: Debug,
{
    let mut probe = NonFinite(false);
    let _ = write!(probe, "{report:?}");
    if probe.0 {
        return true;
    }
    det.detections().any(|d| {
        !(d.score.is_finite() && d.state().iter().all(|x| x.is_finite()))
            || (D::SCORE == ScoreKind::Existence && !(0.0..=1.0).contains(&d.score))
    })
}

// ---------------------------------------------------------------------------------------
// The soak loop.

/// What a detector's soak needs besides the detector.
struct Spec<'a, T: 'static, R> {
    name: &'a str,
    /// Size as printed in the table.
    shape: &'a str,
    /// Draws one frame into the buffer, returns its length.
    frame: &'a mut dyn FnMut(&mut Rng, &mut [T]) -> usize,
    /// The frame buffer.
    buf: &'a mut [T],
    /// Two work counters of a step (block means are printed, in thousandths).
    work: fn(&R) -> (f32, f32),
    /// What the work counters are.
    work_names: (&'a str, &'a str),
}

#[derive(Default)]
struct Block {
    n: u64,
    sum: u64,
    max: u64,
    w1: f64,
    w2: f64,
}

fn milli(x: f64) -> i64 {
    (x * 1000.0) as i64
}

/// Streams `frames` frames through `det` (configured here with `cfg`, seed 1).
#[inline(never)]
fn soak<D, T>(frames: u32, det: &mut D, cfg: &D::Config, spec: Spec<'_, T, D::Report>)
where
    D: Detector<Frame = [T]>,
    D::Report: Debug,
{
    if let Err(e) = det.configure(cfg, SEED) {
        hprintln!("soak {}: configure failed: {:?}", spec.name, e);
        return;
    }
    let mut rng = Rng::seed_from_u64(SEED);
    let per_block = u64::from((frames / BLOCKS).max(1));
    let (mut errors, mut bad) = (0u64, 0u64);
    let (mut first, mut last, mut worst, mut worst_frame) = (0u64, 0u64, 0u64, 0u64);
    let mut blocks = 0u32;
    let mut b = Block::default();
    let sp = cortex_m::register::msp::read() as usize;
    let lo = sp - WINDOW;
    let hi = sp - harness::PAINT_MARGIN;
    paint(lo, hi);
    let mut deepest = hi;
    let phases = PHASES.load(Ordering::Relaxed);
    let mut peaks = [Peak::default(); 3];
    for i in 0..u64::from(frames) {
        let [gen, stepped, checked] = &mut peaks;
        let n = if phases {
            phase(sp, lo, hi, gen, i, || (spec.frame)(&mut rng, spec.buf))
        } else {
            (spec.frame)(&mut rng, spec.buf)
        };
        let frame = &spec.buf[..n];
        let (r, instr) = if phases {
            phase(sp, lo, hi, stepped, i, || {
                count(|| det.step(black_box(frame)))
            })
        } else {
            count(|| det.step(black_box(frame)))
        };
        // Generator and step only: the output check's float formatting goes ~1.6 KB
        // deeper on a few values (located with `phases=1`).
        if !phases {
            deepest = deepest.min(lowest_touched(lo, hi));
        }
        let mut check = || match r {
            Ok(rep) => {
                if bad_output(det, &rep) {
                    bad += 1;
                }
                let (w1, w2) = (spec.work)(&rep);
                b.w1 += f64::from(w1);
                b.w2 += f64::from(w2);
            }
            Err(_) => errors += 1,
        };
        if phases {
            phase(sp, lo, hi, checked, i, check);
        } else {
            check();
        }
        b.n += 1;
        b.sum += instr;
        b.max = b.max.max(instr);
        if b.n == per_block {
            let mean = b.sum / b.n;
            let nf = b.n as f64;
            if blocks == 0 {
                first = mean;
            }
            last = mean;
            worst = worst.max(mean);
            worst_frame = worst_frame.max(b.max);
            hprintln!(
                "block {} {} frames {} instr/frame {} max {} {} {} {} {} (x1000) errors {} nan {}",
                spec.name,
                blocks,
                b.n,
                mean,
                b.max,
                spec.work_names.0,
                milli(b.w1 / nf),
                spec.work_names.1,
                milli(b.w2 / nf),
                errors,
                bad
            );
            blocks += 1;
            b = Block::default();
        }
        // What the check and the block line wrote is not the detector's: repaint.
        if !phases {
            paint(lo, hi);
        }
    }
    if phases {
        let [g, s, c] = peaks;
        hprintln!(
            "stack phases {}: frame generator {} B (first at frame {}), step {} B (frame {}), output check {} B (frame {})",
            spec.name, g.bytes, g.frame, s.bytes, s.frame, c.bytes, c.frame
        );
    }
    hprintln!(
        "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
        spec.name,
        spec.shape,
        frames,
        errors,
        bad,
        first,
        last,
        worst,
        worst_frame,
        if phases {
            peaks.iter().map(|p| p.bytes).max().unwrap_or(0)
        } else {
            sp - deepest
        },
        size_of::<D>()
    );
}

// ---------------------------------------------------------------------------------------
// The detectors, each a `static` of its unconfigured constant set up in place by
// `configure` (all-zero bits, in `.bss`, but MHT-TBD's).

/// The DP detectors' all-zero `static`s (the const evaluator rejects a zero bit pattern
/// that is not a valid value of every field).
macro_rules! zero_static {
    ($name:ident: $t:ty) => {
        static $name: Static<$t> = Static::new(
            // SAFETY: checked by const evaluation (above).
            unsafe { MaybeUninit::zeroed().assume_init() },
        );
    };
}

const N: usize = 1000;
type Mht = MhtTbdHost;
type Classic = ClassicHoughHost;
type Phd = SmcPhdTbdSoak;
type Cbm = CbmemberTbdSoak;
const SIDE: usize = 128;
const SMALL: usize = 32;
const L: usize = 40;
type Arnold = ArnoldDp<SIDE, 9, L, { arnold_words(SIDE, 9, L) }>;
type Pulford = PulfordDp<SMALL, 9, L, { pulford_words(SMALL, 9, L) }>;
type Second = SecondOrderDp<SMALL, 9, L, { second_order_words(SMALL, 9, L) }>;

static CRPF: Static<CrpfTbd<N>> = Static::new(CrpfTbd::new_unconfigured());
static PF: Static<PfTbd<N>> = Static::new(PfTbd::new_unconfigured());
static JOTT: Static<JottTbd<N>> = Static::new(JottTbd::new_unconfigured());
static LRT: Static<PfLrt<N>> = Static::new(PfLrt::new_unconfigured());
static LRT_FIXED_RATE: Static<PfLrt<N>> = Static::new(PfLrt::new_unconfigured());
static LRT_FIXED_AMP: Static<PfLrt<N>> = Static::new(PfLrt::new_unconfigured());
static MHT: Static<Mht> = Static::new(Mht::new_unconfigured());
static CLASSIC: Static<Classic> = Static::new(Classic::new_unconfigured());
static PHD: Static<Phd> = Static::new(Phd::new_unconfigured());
static CBM: Static<Cbm> = Static::new(Cbm::new_unconfigured());
zero_static!(ARNOLD: Arnold);
zero_static!(PULFORD: Pulford);
zero_static!(SECOND: Second);

const PHD_CELLS: usize = 8 * 8 * 4;
const MAP: usize = 32 * 64;
static DOPPLER_BUF: Static<[Complex32; 32]> = Static::new([Complex32::new(0.0, 0.0); 32]);
static PLOT_BUF: Static<[Plot; 2 * 640 + 1]> = Static::new([Plot::new(0.0, 0.0, 0.0); 1281]);
static REAL_BUF: Static<[f32; SIDE * SIDE]> = Static::new([0.0; SIDE * SIDE]);

fn doppler_work(r: &DopplerReport) -> (f32, f32) {
    match r.estimate {
        Some(x) => (if x[1] < 0.0 { -x[1] } else { x[1] }, x[2]),
        None => (0.0, 0.0),
    }
}

/// The classic Hough TBD's default (`faint detect hough-classic`'s configuration): the
/// sea-clutter area and period and the threshold of the binomial strip model at 80 plots
/// per scan.
const CLASSIC_CFG: ClassicHoughConfig = ClassicHoughConfig {
    area: [0.0, 6000.0, 0.0, 6000.0],
    n_scans: 30,
    gamma: 28,
};

/// The golden PHD scene's 8 x 8 x 4 cells around its targets.
const PHD_WINDOW: CubeGeometry = CubeGeometry {
    n_range: 8,
    n_doppler: 8,
    n_azimuth: 4,
    ..faint_golden::phd::GOLDEN_WINDOW
};

fn phd_config(alg: usize) -> PhdConfig {
    let mut c =
        faint_golden::phd::config(PHD_WINDOW, faint_golden::phd::ALGORITHMS[alg], 50, 25, 8);
    if let Some(p) = c.pso.as_mut() {
        p.max_members = 32;
    }
    c
}

fn cbmember_config(model: PointModel) -> CbmemberConfig {
    let mut c = CbmemberConfig {
        model,
        ..CbmemberConfig::rotor_uav()
    };
    let g = &mut c.geometry;
    g.range_bin *= g.n_range as f32 / 32.0;
    g.velocity_bin *= g.n_velocity as f32 / 64.0;
    g.n_range = 32;
    g.n_velocity = 64;
    c.max_particles = 100;
    c.min_particles = 30;
    c.birth.particles = 30;
    c
}

#[entry]
fn main() -> ! {
    harness::init();
    coarse_start();
    let ((), base) = count(|| ());
    // SAFETY: single-threaded, before any other read.
    unsafe { BASELINE = base };
    let args = Args::read();
    let c_start = coarse();
    hprintln!(
        "faint soak on QEMU mps2-an386 (-icount shift=10): {} frames per detector, {} blocks",
        args.frames,
        BLOCKS
    );
    hprintln!("| detector | shape | frames | errors | NaN/inf outputs | instructions/frame, first block | last block | worst block | worst frame | peak stack (B) | static RAM (B) |");
    hprintln!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    let zb = DOPPLER_BUF.take();
    let pb = PLOT_BUF.take();
    let rb = REAL_BUF.take();

    let gauss = GaussConfig::othr(1.0);
    let mut dframe = |rng: &mut Rng, out: &mut [Complex32]| complex(rng, out);
    if args.selected("crpf") {
        soak(
            args.frames,
            CRPF.take(),
            &CrpfConfig::othr(),
            Spec {
                name: "crpf",
                shape: "N = 1000, 32 bins",
                frame: &mut dframe,
                buf: &mut zb[..],
                work: doppler_work,
                work_names: ("|fda|", "A"),
            },
        );
    }
    if args.selected("pf-tbd") {
        soak(
            args.frames,
            PF.take(),
            &gauss,
            Spec {
                name: "pf-tbd",
                shape: "N = 1000, 32 bins",
                frame: &mut dframe,
                buf: &mut zb[..],
                work: doppler_work,
                work_names: ("|fda|", "A"),
            },
        );
    }
    if args.selected("jott") {
        soak(
            args.frames,
            JOTT.take(),
            &gauss,
            Spec {
                name: "jott",
                shape: "N = 1000, 32 bins",
                frame: &mut dframe,
                buf: &mut zb[..],
                work: doppler_work,
                work_names: ("|fda|", "A"),
            },
        );
    }
    if args.selected("pf-lrt") {
        soak(
            args.frames,
            LRT.take(),
            &gauss,
            Spec {
                name: "pf-lrt",
                shape: "N = 1000, 32 bins",
                frame: &mut dframe,
                buf: &mut zb[..],
                work: doppler_work,
                work_names: ("|fda|", "A"),
            },
        );
    }
    // Diagnostic variants of PF-LRT (only when named): no Doppler-rate random walk
    // (`accel_std = 0`: every particle keeps the Doppler rate of its prior draw), and no
    // amplitude random walk (`amp_std = 0`).
    for (name, det, cfg) in [
        (
            "pf-lrt-fixed-rate",
            &LRT_FIXED_RATE,
            GaussConfig {
                model: faint_core::model::doppler::ModelConfig {
                    accel_std: 0.0,
                    ..gauss.model
                },
                ..gauss
            },
        ),
        (
            "pf-lrt-fixed-amp",
            &LRT_FIXED_AMP,
            GaussConfig {
                model: faint_core::model::doppler::ModelConfig {
                    amp_std: 0.0,
                    ..gauss.model
                },
                ..gauss
            },
        ),
    ] {
        if args.named(name) {
            soak(
                args.frames,
                det.take(),
                &cfg,
                Spec {
                    name,
                    shape: "N = 1000, 32 bins",
                    frame: &mut dframe,
                    buf: &mut zb[..],
                    work: doppler_work,
                    work_names: ("|fda|", "A"),
                },
            );
        }
    }
    if args.selected("mht") {
        let cfg = MhtConfig::sea_clutter();
        let area = cfg.area;
        let mut f = |rng: &mut Rng, out: &mut [Plot]| plots(rng, area, 640, out);
        soak(
            args.frames,
            MHT.take(),
            &cfg,
            Spec {
                name: "mht",
                shape: "P = 640, 256 x 180",
                frame: &mut f,
                buf: &mut pb[..],
                work: |r| (r.plots_kept as f32, r.censor.chains as f32),
                work_names: ("plots kept", "chains"),
            },
        );
    }
    if args.selected("hough-classic") {
        let area = CLASSIC_CFG.area;
        let mut f = |rng: &mut Rng, out: &mut [Plot]| plots(rng, area, 64, out);
        soak(
            args.frames,
            CLASSIC.take(),
            &CLASSIC_CFG,
            Spec {
                name: "hough-classic",
                shape: "256 x 180",
                frame: &mut f,
                buf: &mut pb[..],
                work: |r| (r.plots_used as f32, r.condense.peaks as f32),
                work_names: ("plots", "peaks"),
            },
        );
    }
    let phd_names = ["phd-tbd", "pso-phd-kmeans", "pso-phd-dbscan"];
    if phd_names.iter().any(|n| args.selected(n)) {
        let det = PHD.take();
        for (alg, name) in phd_names.iter().enumerate() {
            if !args.selected(name) {
                continue;
            }
            let mut f =
                |rng: &mut Rng, out: &mut [f32]| reals(rng, &mut out[..PHD_CELLS], 1.0, true);
            soak(
                args.frames,
                det,
                &phd_config(alg),
                Spec {
                    name,
                    shape: "8 x 8 x 4 cells, 50 per target",
                    frame: &mut f,
                    buf: &mut rb[..],
                    work: |r| (r.particles as f32, r.n_hat as f32),
                    work_names: ("particles", "N_hat"),
                },
            );
        }
    }
    let cbm_names = [
        ("cbmember", PointModel::Joint),
        ("cbmember-doppler", PointModel::DopplerOnly),
    ];
    if cbm_names.iter().any(|(n, _)| args.selected(n)) {
        let det = CBM.take();
        for (name, model) in cbm_names {
            if !args.selected(name) {
                continue;
            }
            let mut f = |rng: &mut Rng, out: &mut [f32]| reals(rng, &mut out[..MAP], 1.0, true);
            soak(
                args.frames,
                det,
                &cbmember_config(model),
                Spec {
                    name,
                    shape: "32 x 64 map, L_max 100",
                    frame: &mut f,
                    buf: &mut rb[..],
                    work: |r| (r.components as f32, r.particles as f32),
                    work_names: ("components", "particles"),
                },
            );
        }
    }
    if args.selected("dp-arnold") {
        let mut f =
            |rng: &mut Rng, out: &mut [f32]| reals(rng, &mut out[..SIDE * SIDE], 1.5, false);
        soak(
            args.frames,
            ARNOLD.take(),
            &DpConfig::dim_point(Method::Arnold, 1),
            Spec {
                name: "dp-arnold",
                shape: "128 x 128",
                frame: &mut f,
                buf: &mut rb[..],
                work: |r| (r.best.merit, r.clamped as f32),
                work_names: ("best merit", "clamped"),
            },
        );
    }
    let mut small =
        |rng: &mut Rng, out: &mut [f32]| reals(rng, &mut out[..SMALL * SMALL], 1.5, false);
    if args.selected("dp-pulford") {
        soak(
            args.frames,
            PULFORD.take(),
            &DpConfig::dim_point(Method::Pulford, 1),
            Spec {
                name: "dp-pulford",
                shape: "32 x 32",
                frame: &mut small,
                buf: &mut rb[..],
                work: |r| (r.best.merit, r.clamped as f32),
                work_names: ("best merit", "clamped"),
            },
        );
    }
    if args.selected("dp-second") {
        soak(
            args.frames,
            SECOND.take(),
            &DpConfig::dim_point(Method::SecondOrder, 1),
            Spec {
                name: "dp-second",
                shape: "32 x 32",
                frame: &mut small,
                buf: &mut rb[..],
                work: |r| (r.best.merit, r.clamped as f32),
                work_names: ("best merit", "clamped"),
            },
        );
    }
    hprintln!("static RAM (.data + .bss): {} bytes", harness::static_ram());
    hprintln!(
        "instructions executed in all (dual timer, 10 per tick): {}",
        u64::from(c_start.wrapping_sub(coarse())) * 10
    );
    hprintln!("done");
    harness::exit_success()
}
