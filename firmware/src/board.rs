//! The `fit` image's counter and measurement, per board profile (`FAINT_BOARD`, read by
//! `build.rs`): what a frame costs, the peak stack in a small painted window (a real
//! part's RAM has no room for the harness's 64 KiB one), and a hash of the reports.
//!
//! Counters:
//! - no board (QEMU `mps2-an386`): the harness's timer0, with the dual timer for the
//!   wraps ([`crate::timer`]): executed instructions under `-icount shift=10`;
//! - `stm32f407` (run on QEMU `netduinoplus2`, whose STM32F405 has the same map): TIM2,
//!   a 32-bit up-counter, with the prescaler at 1023. QEMU clocks it from virtual time at
//!   1 GHz / (PSC + 1), so under `-icount shift=10` (1024 ns per instruction) it counts
//!   one tick per executed instruction (checked at start-up by [`calibrate`]);
//! - `stm32h743`, `atsame70q21` (linked, not run: QEMU models neither part): DWT
//!   `CYCCNT`, the core's cycle counter (ARMv7-M C1.8.7), so on silicon the counts are
//!   cycles.

use core::fmt::Write;
use core::hint::black_box;
use core::sync::atomic::{compiler_fence, AtomicU32, Ordering};

/// Bytes painted below the stack pointer to find a call's peak stack (the soak's window;
/// never below the end of the statics in RAM, `__euninit`).
pub const STACK_WINDOW: usize = 16 * 1024;
const MARGIN: usize = 64;

#[cfg(faint_board = "stm32f407")]
mod counter {
    use core::ptr::{read_volatile, write_volatile};
    /// TIM2 of the STM32F4 (RM0090 section 18.4): CR1, PSC, ARR, CNT, EGR.
    const TIM2: usize = 0x4000_0000;
    const CR1: *mut u32 = TIM2 as *mut u32;
    const EGR: *mut u32 = (TIM2 + 0x14) as *mut u32;
    const CNT: *mut u32 = (TIM2 + 0x24) as *mut u32;
    const PSC: *mut u32 = (TIM2 + 0x28) as *mut u32;
    const ARR: *mut u32 = (TIM2 + 0x2C) as *mut u32;
    /// What the counts are.
    pub const UNIT: &str = "instructions (QEMU netduinoplus2, TIM2)";

    pub fn start() {
        // SAFETY: TIM2's registers on the STM32F4 memory map; nothing else uses TIM2.
        // (On silicon RCC_APB1ENR.TIM2EN must be set first; QEMU has no RCC gate.)
        unsafe {
            write_volatile(CR1, 0);
            write_volatile(PSC, 1023);
            write_volatile(ARR, u32::MAX);
            write_volatile(EGR, 1);
            write_volatile(CNT, 0);
            write_volatile(CR1, 1);
        }
    }

    #[inline(always)]
    pub fn now() -> u64 {
        // SAFETY: read of a device register.
        u64::from(unsafe { read_volatile(CNT) })
    }

    #[inline(always)]
    pub fn elapsed(t0: u64, t1: u64) -> u64 {
        (t1 as u32).wrapping_sub(t0 as u32).into()
    }
}

#[cfg(any(faint_board = "stm32h743", faint_board = "atsame70q21"))]
mod counter {
    use core::ptr::{read_volatile, write_volatile};
    const DEMCR: *mut u32 = 0xE000_EDFC as *mut u32;
    const DWT_CTRL: *mut u32 = 0xE000_1000 as *mut u32;
    const DWT_CYCCNT: *mut u32 = 0xE000_1004 as *mut u32;
    /// What the counts are.
    pub const UNIT: &str = "cycles (DWT CYCCNT, silicon)";

    pub fn start() {
        // SAFETY: the architecture's debug registers (ARMv7-M C1.6.5, C1.8.7).
        unsafe {
            write_volatile(DEMCR, read_volatile(DEMCR) | 1 << 24);
            write_volatile(DWT_CYCCNT, 0);
            write_volatile(DWT_CTRL, read_volatile(DWT_CTRL) | 1);
        }
    }

    #[inline(always)]
    pub fn now() -> u64 {
        // SAFETY: read of a debug register.
        u64::from(unsafe { read_volatile(DWT_CYCCNT) })
    }

    #[inline(always)]
    pub fn elapsed(t0: u64, t1: u64) -> u64 {
        (t1 as u32).wrapping_sub(t0 as u32).into()
    }
}

#[cfg(not(faint_board))]
mod counter {
    use crate::timer;
    /// What the counts are.
    pub const UNIT: &str = "instructions (QEMU mps2-an386, timer0)";

    pub fn start() {
        timer::start();
        timer::coarse_start();
    }

    /// The fine timer in the low 32 bits, the coarse one in the high 32.
    #[inline(always)]
    pub fn now() -> u64 {
        let c = timer::coarse();
        let f = timer::now();
        (u64::from(c) << 32) | u64::from(f)
    }

    #[inline(always)]
    pub fn elapsed(t0: u64, t1: u64) -> u64 {
        let fine = u64::from(timer::elapsed(t0 as u32, t1 as u32));
        timer::unwrap(fine, (t0 >> 32) as u32, (t1 >> 32) as u32).0
    }
}

pub use counter::UNIT;

static BASELINE: AtomicU32 = AtomicU32::new(0);

/// Starts the counter and measures the empty call (subtracted from every count).
pub fn init() {
    counter::start();
    let (_, base, _) = raw(|| ());
    BASELINE.store(base as u32, Ordering::Relaxed);
}

/// Calls `f` in a frame of its own (so the window sees its locals).
#[inline(never)]
fn call<R>(f: impl FnOnce() -> R) -> R {
    f()
}

extern "C" {
    /// End of `.uninit`, the last statics in RAM below the stack (cortex-m-rt's `link.x`).
    static __euninit: u32;
}

#[inline(always)]
fn raw<R>(f: impl FnOnce() -> R) -> (R, u64, u32) {
    let sp = cortex_m::register::msp::read() as usize;
    let lo = (sp - STACK_WINDOW).max(&raw const __euninit as usize);
    crate::harness::paint(lo, sp - MARGIN);
    compiler_fence(Ordering::SeqCst);
    let t0 = counter::now();
    compiler_fence(Ordering::SeqCst);
    let r = black_box(call(f));
    compiler_fence(Ordering::SeqCst);
    let t1 = counter::now();
    compiler_fence(Ordering::SeqCst);
    let stack = (sp - crate::harness::lowest_touched(lo, sp - MARGIN)) as u32;
    (r, counter::elapsed(t0, t1), stack)
}

/// Runs `f` once: its result, its count (instructions or cycles, [`UNIT`]; the empty
/// call's count subtracted) and its peak stack in bytes. Fails (panics) when the stack
/// reaches the bottom of the painted window or the statics.
#[inline(always)]
pub fn measure<R>(f: impl FnOnce() -> R) -> (R, u64, u32) {
    let sp = cortex_m::register::msp::read() as usize;
    let floor = (sp - STACK_WINDOW).max(&raw const __euninit as usize);
    let (r, n, stack) = raw(f);
    assert!(
        (stack as usize) < sp - floor,
        "peak stack reached the bottom of the painted window (or the statics)"
    );
    let base = u64::from(BASELINE.load(Ordering::Relaxed));
    (r, n.saturating_sub(base), stack)
}

/// Checks the counter against a `subs; bne` loop: 10 000 extra iterations must count
/// exactly 20 000 more instructions under QEMU (cycles on silicon: printed only).
pub fn calibrate() -> (u64, u64) {
    let short = spin_count(1_000);
    let long = spin_count(11_000);
    (short, long)
}

#[inline(never)]
fn spin_count(n: u32) -> u64 {
    let n = black_box(n);
    measure(|| {
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
    })
    .1
}

/// FNV-1a over text written into it: the hash of the reports' `Debug` text, which the
/// runs on two boards compare.
#[derive(Debug, Clone, Copy)]
pub struct Fnv(pub u64);

impl Fnv {
    /// The empty hash.
    pub const fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    /// Folds `v`'s `Debug` text in.
    pub fn fold<T: core::fmt::Debug>(&mut self, v: &T) {
        let _ = write!(self, "{v:?}");
    }
}

impl Default for Fnv {
    fn default() -> Self {
        Self::new()
    }
}

impl Write for Fnv {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        for b in s.bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
        Ok(())
    }
}
