//! The board's counters: the fine one every measurement reads (the CMSDK timer0 of the
//! MPS2 board under QEMU, or the DWT cycle counter on silicon with the `dwt` feature)
//! and the coarse dual timer that counts the fine timer's wraps in long calls.
//!
//! **Fine counter.** Run with `-icount shift=10,align=off,sleep=off` (the runner in
//! `.cargo/config.toml`), every guest instruction advances QEMU's virtual time by exactly
//! 2^10 ns and timer0 (25 MHz, one tick = 40 ns) by 25.6 ticks, so
//!
//! ```text
//! instructions = round(ticks * 40 / 1024) = (ticks * 40 + 512) >> 10
//! ```
//!
//! With the `dwt` feature the same reads return DWT `CYCCNT` cycles (enabled by
//! [`start`]: `DEMCR.TRCENA`, then `DWT_CTRL.CYCCNTENA`, ARMv7-M C1.6.5, C1.8.7).
//!
//! **Coarse counter.** Timer0 wraps every 2^32 ticks, 167.8 M instructions. The dual
//! timer's first counter with the /256 prescaler advances 0.1 tick per instruction (10
//! instructions per tick, a wrap after 4.3e10 instructions); read around a long call,
//! it gives the fine count's number of wraps ([`unwrap`]).

use core::ptr::{read_volatile, write_volatile};

/// CMSDK APB timer0 of the MPS2 board (not used with the `dwt` feature).
#[cfg(not(feature = "dwt"))]
const TIMER0: usize = 0x4000_0000;
#[cfg(not(feature = "dwt"))]
const TIMER_CTRL: *mut u32 = TIMER0 as *mut u32;
#[cfg(not(feature = "dwt"))]
const TIMER_VALUE: *mut u32 = (TIMER0 + 0x4) as *mut u32;
#[cfg(not(feature = "dwt"))]
const TIMER_RELOAD: *mut u32 = (TIMER0 + 0x8) as *mut u32;

/// Debug Exception and Monitor Control Register (TRCENA is bit 24).
#[cfg(feature = "dwt")]
const DEMCR: *mut u32 = 0xE000_EDFC as *mut u32;
/// DWT control register (CYCCNTENA is bit 0) and the cycle counter.
#[cfg(feature = "dwt")]
const DWT_CTRL: *mut u32 = 0xE000_1000 as *mut u32;
#[cfg(feature = "dwt")]
const DWT_CYCCNT: *mut u32 = 0xE000_1004 as *mut u32;

/// Timer 1 of the CMSDK dual timer (SP804-like) of the MPS2 board: load, value, control.
const DUAL_LOAD: *mut u32 = 0x4000_2000 as *mut u32;
const DUAL_VALUE: *mut u32 = 0x4000_2004 as *mut u32;
const DUAL_CONTROL: *mut u32 = 0x4000_2008 as *mut u32;

/// Instructions per wrap of the fine counter: `2^32` ticks at 25.6 ticks each.
pub const WRAP: u64 = (1 << 32) * 10 / 256;

/// Starts the fine counter: timer0 as a free-running 32-bit down-counter, or (`dwt`)
/// the cycle counter.
#[inline]
pub fn start() {
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
}

/// The fine counter's value.
#[cfg(not(feature = "dwt"))]
#[inline(always)]
pub fn now() -> u32 {
    // SAFETY: read of a device register.
    unsafe { read_volatile(TIMER_VALUE) }
}

/// The cycle counter (`dwt` feature: on silicon; QEMU does not count DWT cycles).
#[cfg(feature = "dwt")]
#[inline(always)]
pub fn now() -> u32 {
    // SAFETY: read of a debug register.
    unsafe { read_volatile(DWT_CYCCNT) }
}

/// Counts between two [`now`] reads: instructions from timer0 (a down-counter), or
/// cycles from CYCCNT (an up-counter) with the `dwt` feature. One wrap is handled by the
/// wrapping subtraction.
#[inline(always)]
pub fn elapsed(t0: u32, t1: u32) -> u32 {
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
pub const fn ticks_to_instructions(ticks: u32) -> u32 {
    ((ticks as u64 * 40 + 512) >> 10) as u32
}

/// Starts the dual timer's first counter as a free-running 32-bit down-counter with the
/// /256 prescaler (control: enable, 32-bit, prescale 256, no interrupt).
#[inline]
pub fn coarse_start() {
    // SAFETY: the dual timer's registers on the MPS2 memory map; nothing else uses it.
    unsafe {
        write_volatile(DUAL_CONTROL, 0);
        write_volatile(DUAL_LOAD, u32::MAX);
        write_volatile(DUAL_CONTROL, 0x80 | (2 << 2) | 0x02);
    }
}

/// The dual timer's value (a down-counter, 10 instructions per tick).
#[inline(always)]
pub fn coarse() -> u32 {
    // SAFETY: read of a device register.
    unsafe { read_volatile(DUAL_VALUE) }
}

/// The whole count of a call whose fine count `fine` may have wrapped, from the coarse
/// reads `c0` before and `c1` after it: `(fine + wraps WRAP, coarse count)`, the number of
/// wraps being the one that brings `fine` nearest the coarse count.
#[inline(always)]
pub fn unwrap(fine: u64, c0: u32, c1: u32) -> (u64, u64) {
    let approx = u64::from(c0.wrapping_sub(c1)) * 10;
    let wraps = (approx + WRAP / 2).saturating_sub(fine) / WRAP;
    (fine + wraps * WRAP, approx)
}
