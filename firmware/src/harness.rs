//! Measurement harness: instruction counts from QEMU's virtual clock, peak stack from a
//! painted window, `static` buffers, a Markdown table on semihosting.
//!
//! **What is counted.** QEMU does not model Cortex-M4 timing (DWT `CYCCNT` reads 0). Run
//! with `-icount shift=10,align=off,sleep=off` (the runner in `.cargo/config.toml`),
//! every guest instruction advances virtual time by exactly 2^10 ns, and the CMSDK
//! timer0 (25 MHz, one tick = 40 ns) advances 25.6 ticks per instruction. So
//!
//! ```text
//! instructions = round(ticks * 40 / 1024) = (ticks * 40 + 512) >> 10
//! ```
//!
//! minus the count of an empty measurement. The result is an **executed-instruction
//! count**, not Cortex-M4 cycles: loads, taken branches, divisions and FPU divides take
//! more than one cycle on silicon and flash wait states add more. The cycle model
//! (`tools/cycles`, the `cycles` binary) estimates Cortex-M4 and M7 cycles from QEMU's
//! trace; on a board, build with the `dwt` feature and the same calls count cycles with
//! DWT `CYCCNT` (enabled by `init`: `DEMCR.TRCENA`, then `DWT_CTRL.CYCCNTENA`). It is
//! exact and deterministic: two runs print the same numbers. [`calibrate`] checks the
//! conversion against a hand-written loop of known length at start-up.
//!
//! **Use from a detector module** (`firmware/src/<name>.rs`, one `pub fn run()` called
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

use core::cell::UnsafeCell;
use core::hint::black_box;
use core::ptr::{read_volatile, write_volatile};
use core::sync::atomic::{compiler_fence, AtomicBool, AtomicU32, Ordering};

use cortex_m_rt::{exception, ExceptionFrame};
use cortex_m_semihosting::{debug, hprintln};

/// CMSDK APB timer0 of the MPS2 board (not used with the `dwt` feature).
#[cfg(not(feature = "dwt"))]
const TIMER0: usize = 0x4000_0000;
#[cfg(not(feature = "dwt"))]
const TIMER_CTRL: *mut u32 = TIMER0 as *mut u32;
#[cfg(not(feature = "dwt"))]
const TIMER_VALUE: *mut u32 = (TIMER0 + 0x4) as *mut u32;
#[cfg(not(feature = "dwt"))]
const TIMER_RELOAD: *mut u32 = (TIMER0 + 0x8) as *mut u32;

/// Bytes below the stack pointer painted by [`measure`] to find the closure's peak
/// stack. A closure that uses more is reported as `>= STACK_WINDOW`.
pub const STACK_WINDOW: usize = 64 * 1024;
const PAINT: u32 = 0x5AA5_C33C;
/// Unpainted bytes right below the caller's SP (room for `paint`'s own frame): stack use
/// that stays within this margin reads as the margin.
pub const PAINT_MARGIN: usize = 64;

static BASELINE: AtomicU32 = AtomicU32::new(0);

/// A `static` buffer handed out once as `&'static mut T` (large detector states live
/// here, not on the stack). Zero-initialised values land in `.bss`.
pub struct Static<T> {
    taken: AtomicBool,
    cell: UnsafeCell<T>,
}

// SAFETY: `take` hands out the only reference, at most once (atomic swap).
unsafe impl<T: Send> Sync for Static<T> {}

impl<T> Static<T> {
    /// A buffer holding `value` (evaluated at compile time).
    pub const fn new(value: T) -> Self {
        Self {
            taken: AtomicBool::new(false),
            cell: UnsafeCell::new(value),
        }
    }

    /// The buffer, exclusively. Panics (firmware exits with failure) on a second call.
    // The atomic flag makes this the one `&mut` ever handed out (a `singleton!` pattern).
    #[allow(clippy::mut_from_ref)]
    pub fn take(&'static self) -> &'static mut T {
        assert!(
            !self.taken.swap(true, Ordering::AcqRel),
            "Static::take called twice"
        );
        // SAFETY: the swap above guarantees this is the only `&mut` ever created.
        unsafe { &mut *self.cell.get() }
    }
}

/// Debug Exception and Monitor Control Register (TRCENA is bit 24).
#[cfg(feature = "dwt")]
const DEMCR: *mut u32 = 0xE000_EDFC as *mut u32;
/// DWT control register (CYCCNTENA is bit 0) and the cycle counter.
#[cfg(feature = "dwt")]
const DWT_CTRL: *mut u32 = 0xE000_1000 as *mut u32;
#[cfg(feature = "dwt")]
const DWT_CYCCNT: *mut u32 = 0xE000_1004 as *mut u32;

/// Starts timer0 as a free-running 32-bit down-counter and measures the empty baseline.
/// With the `dwt` feature (silicon) it enables the cycle counter instead.
pub fn init() {
    #[cfg(not(feature = "dwt"))]
    // SAFETY: timer0's registers on the MPS2 memory map; nothing else uses the timer.
    unsafe {
        write_volatile(TIMER_CTRL, 0);
        write_volatile(TIMER_RELOAD, u32::MAX);
        write_volatile(TIMER_VALUE, u32::MAX);
        write_volatile(TIMER_CTRL, 1);
    }
    #[cfg(feature = "dwt")]
    // SAFETY: the architecture's debug registers (ARMv7-M C1.6.5, C1.8.7): TRCENA powers
    // the DWT, CYCCNTENA starts the counter.
    unsafe {
        write_volatile(DEMCR, read_volatile(DEMCR) | 1 << 24);
        write_volatile(DWT_CYCCNT, 0);
        write_volatile(DWT_CTRL, read_volatile(DWT_CTRL) | 1);
    }
    BASELINE.store(0, Ordering::Relaxed);
    let ((), base) = raw_instructions(|| ());
    BASELINE.store(base, Ordering::Relaxed);
}

#[cfg(not(feature = "dwt"))]
#[inline(always)]
fn timer() -> u32 {
    // SAFETY: read of a device register.
    unsafe { read_volatile(TIMER_VALUE) }
}

/// The cycle counter (`dwt` feature: on silicon; QEMU does not count DWT cycles).
#[cfg(feature = "dwt")]
#[inline(always)]
fn timer() -> u32 {
    // SAFETY: read of a debug register.
    unsafe { read_volatile(DWT_CYCCNT) }
}

/// Counts between two [`timer`] reads: instructions from timer0 (a down-counter), or
/// cycles from CYCCNT (an up-counter) with the `dwt` feature.
#[inline(always)]
fn elapsed(t0: u32, t1: u32) -> u32 {
    #[cfg(not(feature = "dwt"))]
    {
        ticks_to_instructions(t0.wrapping_sub(t1))
    }
    #[cfg(feature = "dwt")]
    {
        t1.wrapping_sub(t0)
    }
}

/// Timer ticks (25 MHz) to instructions at `-icount shift=10` (1024 ns each).
#[cfg_attr(feature = "dwt", allow(dead_code))]
pub const fn ticks_to_instructions(ticks: u32) -> u32 {
    ((ticks as u64 * 40 + 512) >> 10) as u32
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
    let t0 = timer();
    compiler_fence(Ordering::SeqCst);
    let r = black_box(call(f));
    compiler_fence(Ordering::SeqCst);
    let t1 = timer();
    compiler_fence(Ordering::SeqCst);
    // One wrap (167 M instructions, or 2^32 cycles) is handled by the wrapping sub.
    (r, elapsed(t0, t1))
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
pub fn table_header() {
    hprintln!("| measurement | n | instructions / call | instructions / unit | peak stack (B) | static RAM (B) |");
    hprintln!("|---|---:|---:|---:|---:|---:|");
}

/// Prints one table row: `m` measured over `n` units of `unit` (e.g. 1000 "particle"),
/// with `ram_bytes` of static buffers (`core::mem::size_of` of what the call needs).
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

/// Ends the QEMU run with exit status 0.
pub fn exit_success() -> ! {
    debug::exit(debug::EXIT_SUCCESS);
    #[allow(clippy::empty_loop)]
    loop {}
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("PANIC: {}", info);
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

#[exception]
unsafe fn HardFault(ef: &ExceptionFrame) -> ! {
    hprintln!("HARDFAULT: {:?}", ef);
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// A fixed-capacity string for golden lines and row labels (`core::fmt::Write`; writing
/// past `CAP` bytes is a `fmt::Error`, never a panic).
pub struct Text<const CAP: usize> {
    buf: [u8; CAP],
    len: usize,
}

impl<const CAP: usize> Text<CAP> {
    /// Empty text.
    pub const fn new() -> Self {
        Self {
            buf: [0; CAP],
            len: 0,
        }
    }

    /// Empties the text (keeps the buffer).
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// The text written so far.
    pub fn as_str(&self) -> &str {
        core::str::from_utf8(&self.buf[..self.len]).unwrap_or("<utf8>")
    }
}

impl<const CAP: usize> core::fmt::Write for Text<CAP> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len + s.len();
        let dst = self.buf.get_mut(self.len..end).ok_or(core::fmt::Error)?;
        dst.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}
