//! # faint-firmware
//!
//! The kit the firmware's binaries share to run `faint-core` on QEMU's `mps2-an386`
//! (Cortex-M4F) and count what it costs: the board's counters ([`timer`]), the
//! measurement harness and its Markdown table ([`harness`]), `static` storage for the
//! large states ([`statics`]), a fixed-capacity string ([`text`]), the run's exits and
//! command line through semihosting ([`semihosting`]), the soak loop ([`soak`]), and the
//! per-board counter of the `fit` images ([`board`]).
//!
//! The binaries (the layout of idsp's embedded tests):
//! - `src/main.rs`, the instruction table (one module per detector family under
//!   `src/rows/`) and the golden lines;
//! - `src/bin/cycles.rs`, the regions of the cycle model (`tools/cycles`);
//! - `src/bin/golden.rs`, the golden lines alone (the Cortex-M3, M33 and M7 boards);
//! - `src/bin/soak.rs`, every detector streamed frames without a reset;
//! - `src/bin/fit.rs`, one detector configuration built for one part's memory map
//!   (`boards/`, [`board`]);
//! - `src/bin/panic_never*.rs`, link-time proofs that no panic path survives.
//!
//! Each binary picks its panic handler: [`report_panics!`] (print, exit status 1) for
//! the measuring ones, [`panic_never!`] (a link error if any panic path survives) for the
//! proofs. A library cannot hold the handler, since the two kinds of binary need
//! different ones.
#![no_std]

pub mod board;
pub mod harness;
pub mod semihosting;
pub mod soak;
pub mod statics;
pub mod text;
pub mod timer;

/// Prints one `golden <name> <hex words>` line per case of `faint_golden::cases` through
/// semihosting (the lines `.ci/run` diffs against the host's).
pub fn print_golden_lines() {
    let mut line = text::Text::<1024>::new();
    faint_golden::cases(&mut |name, words| {
        line.clear();
        if faint_golden::write_line(&mut line, name, words).is_err() {
            cortex_m_semihosting::hprintln!("golden {} <line too long>", name);
        } else {
            cortex_m_semihosting::hprintln!("{}", line.as_str());
        }
    });
}

/// Installs the measuring binaries' panic handler and hard-fault handler: print the
/// message or the exception frame, exit QEMU with status 1.
#[macro_export]
macro_rules! report_panics {
    () => {
        #[panic_handler]
        fn panic(info: &core::panic::PanicInfo) -> ! {
            $crate::semihosting::report_panic(info)
        }

        #[cortex_m_rt::exception]
        unsafe fn HardFault(ef: &cortex_m_rt::ExceptionFrame) -> ! {
            $crate::semihosting::report_hard_fault(ef)
        }
    };
}

/// Installs the panic handler of a `panic-never` binary: it calls a function that does
/// not exist, so the fat-LTO link fails (undefined reference to
/// `faint_core_panic_path_survived`) unless the optimiser removed every panic path.
#[macro_export]
macro_rules! panic_never {
    () => {
        #[panic_handler]
        fn panic(_: &core::panic::PanicInfo) -> ! {
            extern "Rust" {
                // Deliberately undefined: referencing it is the link error.
                fn faint_core_panic_path_survived() -> !;
            }
            // SAFETY: never linked; a successful link proves this call is unreachable.
            unsafe { faint_core_panic_path_survived() }
        }
    };
}
