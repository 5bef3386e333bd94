//! Measurement harness: instruction counts from the board's fine counter ([`timer`]),
//! peak stack from a painted window, a Markdown table on semihosting.
//!
//! **What is counted.** QEMU does not model Cortex-M4 timing (DWT `CYCCNT` reads 0); under
//! `-icount` the fine counter counts executed instructions (see [`timer`]), minus the
//! count of an empty measurement. The result is an **executed-instruction count**, not
//! Cortex-M4 cycles: loads, taken branches, divisions and FPU divides take more than one
//! cycle on silicon and flash wait states add more. The cycle model (`tools/cycles`, the
//! `cycles` binary) estimates Cortex-M4 and M7 cycles from QEMU's trace; on a board, build
//! with the `dwt` feature and the same calls count cycles with DWT `CYCCNT`. It is exact
//! and deterministic: two runs print the same numbers. [`calibrate`] checks the
//! conversion against a hand-written loop of known length at start-up.
//!
//! **Use from a row module** (`firmware/src/rows/<name>.rs`, one `pub fn run()` called
//! from `main.rs`):
//!
//! ```ignore
//! static STATE: Static<MyDetector<4096>> = Static::new(MyDetector::ZERO);
//! let det = STATE.take();                     // &'static mut, once
//! let (report, m) = measure(|| det.step(black_box(&frame)));
//! check(report); // panics (exit status 1) on Err
//! row("mydet step, 64x64 frame", 1, "frame", m, size_of::<MyDetector<4096>>());
//! ```
//!
//! Wrap inputs in `core::hint::black_box` when they are compile-time constants, or the
//! optimiser may fold the work out of the measured region.
//!
//! [`timer`]: crate::timer

use core::hint::black_box;
use core::ptr::{read_volatile, write_volatile};
use core::sync::atomic::{compiler_fence, AtomicU32, Ordering};

use cortex_m_semihosting::hprintln;

use crate::timer;

/// Bytes below the stack pointer painted by [`measure`] to find the closure's peak
/// stack. A closure that uses more is reported as `>= STACK_WINDOW`.
pub const STACK_WINDOW: usize = 64 * 1024;
const PAINT: u32 = 0x5AA5_C33C;
/// Unpainted bytes right below the caller's SP (room for `paint`'s own frame): stack use
/// that stays within this margin reads as the margin.
pub const PAINT_MARGIN: usize = 64;

static BASELINE: AtomicU32 = AtomicU32::new(0);

/// Starts the fine counter ([`timer::start`]) and measures the empty baseline.
#[inline]
pub fn init() {
    timer::start();
    BASELINE.store(0, Ordering::Relaxed);
    let ((), base) = raw_instructions(|| ());
    BASELINE.store(base, Ordering::Relaxed);
}

/// Calls `f` in a frame of its own. Without it a `step` with one call site is inlined
/// into the measuring function, whose frame (allocated on entry, above the stack pointer
/// [`measure`] reads) then holds the step's locals: the peak stack missed them (the DP
/// rows read "at most 64").
#[inline(never)]
pub fn call<R>(f: impl FnOnce() -> R) -> R {
    f()
}

/// Runs `f` and returns its result and executed instructions, baseline not subtracted.
#[inline(always)]
pub fn raw_instructions<R>(f: impl FnOnce() -> R) -> (R, u32) {
    compiler_fence(Ordering::SeqCst);
    let t0 = timer::now();
    compiler_fence(Ordering::SeqCst);
    let r = black_box(call(f));
    compiler_fence(Ordering::SeqCst);
    let t1 = timer::now();
    compiler_fence(Ordering::SeqCst);
    // One wrap (167 M instructions, or 2^32 cycles) is handled by the wrapping sub.
    (r, timer::elapsed(t0, t1))
}

/// Result of one [`measure`].
#[derive(Debug, Clone, Copy)]
pub struct Measurement {
    /// Executed instructions of the closure (empty-closure baseline subtracted).
    pub instructions: u64,
    /// Peak stack below the caller's frame while the closure ran, in bytes (includes a
    /// few words of harness overhead; values up to 64 mean "at most 64").
    pub stack_bytes: u32,
}

/// Runs `f` once and returns its result with its instruction count and peak stack use.
#[inline(always)]
pub fn measure<R>(f: impl FnOnce() -> R) -> (R, Measurement) {
    let sp = cortex_m::register::msp::read() as usize;
    let lo = sp - STACK_WINDOW;
    paint(lo, sp - PAINT_MARGIN);
    let (r, total) = raw_instructions(f);
    let stack_bytes = (sp - lowest_touched(lo, sp - PAINT_MARGIN)) as u32;
    let m = Measurement {
        instructions: u64::from(total.saturating_sub(BASELINE.load(Ordering::Relaxed))),
        stack_bytes,
    };
    (r, m)
}

/// [`measure`] for calls longer than the fine counter's wrap (167.8 M instructions, which
/// PSO-PHD-TBD's 10-generation swarm frames reach): the coarse counter read around the
/// measurement gives the number of wraps, the fine count the rest ([`timer::unwrap`]).
/// Call [`timer::coarse_start`] first.
pub fn measure_long<R>(f: impl FnOnce() -> R) -> (R, Measurement) {
    let c0 = timer::coarse();
    let (r, mut m) = measure(f);
    let c1 = timer::coarse();
    let fine = m.instructions;
    let (total, approx) = timer::unwrap(fine, c0, c1);
    // Self-check: the corrected count agrees with the coarse one to its resolution (plus
    // painting and scanning the 64 KiB stack window, ~150 k), else the dual timer is not
    // what we assume.
    assert!(
        total.abs_diff(approx) <= 250_000 + approx / 1000,
        "coarse timer check failed: fine {fine}, coarse {approx}"
    );
    m.instructions = total;
    (r, m)
}

/// Paints `[lo, hi)` (unused stack below the live frames) with the marker word.
#[inline(never)]
pub fn paint(lo: usize, hi: usize) {
    let mut a = lo;
    while a < hi {
        // SAFETY: [lo, hi) is unused stack below the live frames (hi is PAINT_MARGIN bytes
        // under the caller's SP; this leaf function needs no stack frame).
        unsafe { write_volatile(a as *mut u32, PAINT) };
        a += 4;
    }
}

/// The lowest address in `[lo, hi)` whose marker word was overwritten (`hi`: none).
#[inline(never)]
pub fn lowest_touched(lo: usize, hi: usize) -> usize {
    let mut a = lo;
    // SAFETY: reads of the window painted above.
    while a < hi && unsafe { read_volatile(a as *const u32) } == PAINT {
        a += 4;
    }
    a
}

/// Checks the tick-to-instruction conversion against a loop of known length: 10 000
/// extra iterations of `subs; bne` must count exactly 20 000 more instructions. Panics
/// otherwise (e.g. QEMU run without `-icount shift=10`).
#[inline]
pub fn calibrate() {
    let short = measure_spin(1_000);
    let long = measure_spin(11_000);
    let diff = long.wrapping_sub(short);
    hprintln!(
        "calibration: subs/bne loop of 1000 iterations = {} instructions, 11000 = {}, difference {} (expected 20000)",
        short,
        long,
        diff
    );
    // On silicon (`dwt`) the loop costs 1 + (1 + P) cycles per iteration: no fixed value.
    #[cfg(not(feature = "dwt"))]
    assert!(
        diff == 20_000,
        "instruction counting is off: run QEMU with -icount shift=10,align=off,sleep=off"
    );
}

/// One copy of the measuring code for both loop lengths, so they differ only in `n`.
#[inline(never)]
fn measure_spin(n: u32) -> u64 {
    let n = black_box(n);
    measure(|| spin(n)).1.instructions
}

/// `n` iterations of a two-instruction loop (`n >= 1`).
#[inline(always)]
fn spin(n: u32) {
    // SAFETY: register-only loop.
    unsafe {
        core::arch::asm!(
            "1:",
            "subs {0}, {0}, #1",
            "bne 1b",
            inout(reg) n => _,
            options(nomem, nostack),
        );
    }
}

/// Prints the table header (Markdown).
#[inline]
pub fn table_header() {
    hprintln!("| measurement | n | instructions / call | instructions / unit | peak stack (B) | static RAM (B) |");
    hprintln!("|---|---:|---:|---:|---:|---:|");
}

/// Prints one table row: `m` measured over `n` units of `unit` (e.g. 1000 "particle"),
/// with `ram_bytes` of static buffers (`core::mem::size_of` of what the call needs).
#[inline]
pub fn row(name: &str, n: u32, unit: &str, m: Measurement, ram_bytes: usize) {
    let n = n.max(1);
    // One decimal, in integers (no float formatting differences between runs).
    let tenths = (m.instructions * 10 + n as u64 / 2) / n as u64;
    hprintln!(
        "| {} | {} | {} | {}.{} / {} | {} | {} |",
        name,
        n,
        m.instructions,
        tenths / 10,
        tenths % 10,
        unit,
        m.stack_bytes,
        ram_bytes
    );
}

extern "C" {
    static __sdata: u32;
    static __edata: u32;
    static __sbss: u32;
    static __ebss: u32;
}

/// Bytes of `.data` + `.bss` in this firmware image (all static buffers of all rows).
#[inline]
pub fn static_ram() -> usize {
    // Linker-provided section bounds from cortex-m-rt's link.x; only addresses are taken.
    (&raw const __edata as usize - &raw const __sdata as usize)
        + (&raw const __ebss as usize - &raw const __sbss as usize)
}

/// Unwraps a measured `Result`, exiting with failure (via panic) on `Err`.
pub fn check<T, E: core::fmt::Debug>(r: Result<T, E>) -> T {
    match r {
        Ok(v) => v,
        Err(e) => panic!("measured call failed: {e:?}"),
    }
}
