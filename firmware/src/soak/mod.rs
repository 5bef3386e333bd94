//! The soak loop: one detector configured once and streamed `frames` frames without a
//! reset, counting the frames, the errors, the steps with a NaN/inf output, the executed
//! instructions per frame of every block of `frames / 20` frames (first, last, worst
//! block: a drift shows as their ratio) and the peak stack; one Markdown row per
//! detector. The binary `src/bin/soak.rs` holds the detectors, their sizes and frames.
//!
//! **Counts.** Each `step` is counted with the harness's fine counter (exact executed
//! instructions) and the coarse dual timer for the fine counter's wraps ([`count`]). A
//! block line gives the block's mean and largest count per frame and two
//! detector-specific block means (work counters: `w1`, `w2`, see [`Spec`]).
//!
//! **Peak stack** ([`stack`]): the deepest write into a painted 16 KiB window below the
//! soak loop's frame, read after every `step` and painted again after the output check:
//! the deeper of the frame generator's and `step`'s stack (the generator's is 172 B).
//! The output check is left out: it formats the report's floats, which on a few values
//! goes ~1.6 KB deeper than on the others (most likely `core::fmt`'s Dragon4 fallback
//! when Grisu fails). `phases=1` measures generator, `step` and check apart (a
//! diagnostic: one paint and one scan per phase) and prints each one's peak with the
//! first frame that reached it.

pub mod args;
pub mod check;
pub mod stack;

use core::fmt::Debug;
use core::hint::black_box;
use core::mem::size_of;

use cortex_m_semihosting::hprintln;
use faint_core::detect::Detector;
use faint_core::rng::Rng;

use crate::harness::{lowest_touched, paint, raw_instructions, PAINT_MARGIN};
use crate::timer;
use args::Args;
use check::bad_output;
use stack::{phase, Peak, WINDOW};

/// Blocks a run is cut into.
pub const BLOCKS: u32 = 20;

/// Instructions of an empty [`count`] (subtracted).
static mut BASELINE: u64 = 0;

/// Starts the coarse counter and measures [`count`]'s baseline. Call once, after
/// [`crate::harness::init`] and before any [`soak`].
#[inline]
pub fn start() {
    timer::coarse_start();
    let ((), base) = count(|| ());
    // SAFETY: single-threaded, before any other read.
    unsafe { BASELINE = base };
}

/// Runs `f`, returning its result and executed instructions (baseline subtracted), the
/// fine counter's wraps counted by the coarse one.
#[inline(always)]
pub fn count<R>(f: impl FnOnce() -> R) -> (R, u64) {
    let c0 = timer::coarse();
    let (r, fine) = raw_instructions(f);
    let c1 = timer::coarse();
    let (total, _) = timer::unwrap(u64::from(fine), c0, c1);
    // SAFETY: written once before any detector runs; single-threaded.
    let base = unsafe { BASELINE };
    (r, total.saturating_sub(base))
}

/// What a detector's soak needs besides the detector.
#[allow(missing_debug_implementations)] // holds a `dyn FnMut`
pub struct Spec<'a, T: 'static, R> {
    /// Name as in `faint detect --list`.
    pub name: &'a str,
    /// Size as printed in the table.
    pub shape: &'a str,
    /// Draws one frame into the buffer, returns its length.
    pub frame: &'a mut dyn FnMut(&mut Rng, &mut [T]) -> usize,
    /// The frame buffer.
    pub buf: &'a mut [T],
    /// Two work counters of a step (block means are printed, in thousandths).
    pub work: fn(&R) -> (f32, f32),
    /// What the work counters are.
    pub work_names: (&'a str, &'a str),
}

#[derive(Default)]
struct Block {
    n: u64,
    sum: u64,
    max: u64,
    w1: f64,
    w2: f64,
}

#[inline]
fn milli(x: f64) -> i64 {
    (x * 1000.0) as i64
}

/// Prints the table's header.
#[inline]
pub fn table_header() {
    hprintln!("| detector | shape | frames | errors | NaN/inf outputs | instructions/frame, first block | last block | worst block | worst frame | peak stack (B) | static RAM (B) |");
    hprintln!("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
}

/// Streams `args.frames` frames through `det` (configured here with `cfg` and `seed`,
/// the frames drawn from `Rng::seed_from_u64(seed)`), printing a line per block and the
/// detector's row.
#[inline(never)]
pub fn soak<D, T>(
    args: &Args,
    seed: u64,
    det: &mut D,
    cfg: &D::Config,
    spec: Spec<'_, T, D::Report>,
) where
    D: Detector<Frame = [T]>,
    D::Report: Debug,
{
    let frames = args.frames;
    if let Err(e) = det.configure(cfg, seed) {
        hprintln!("soak {}: configure failed: {:?}", spec.name, e);
        return;
    }
    let mut rng = Rng::seed_from_u64(seed);
    let per_block = u64::from((frames / BLOCKS).max(1));
    let (mut errors, mut bad) = (0u64, 0u64);
    let (mut first, mut last, mut worst, mut worst_frame) = (0u64, 0u64, 0u64, 0u64);
    let mut blocks = 0u32;
    let mut b = Block::default();
    let sp = cortex_m::register::msp::read() as usize;
    let lo = sp - WINDOW;
    let hi = sp - PAINT_MARGIN;
    paint(lo, hi);
    let mut deepest = hi;
    let phases = args.phases;
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
