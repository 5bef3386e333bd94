//! The golden lines alone: prints every `golden <name> <hex words>` line of
//! `faint_golden::cases`, then `done`, and nothing else. It is how CI checks that a
//! Cortex-M target other than the Cortex-M4F computes bit for bit what the host computes
//! (the instruction table's image, `src/main.rs`, prints the same lines on `mps2-an386`).
//!
//! ```sh
//! cd firmware && cargo run -q --profile firmware --bin golden --target thumbv7m-none-eabi
//! cd firmware && cargo run -q --profile firmware --bin golden --target thumbv8m.main-none-eabihf
//! ```
//!
//! The runners (`.cargo/config.toml`): `thumbv7m-none-eabi` (Cortex-M3, no FPU: soft
//! float) on QEMU `mps2-an385`, `thumbv8m.main-none-eabihf` (Cortex-M33) on `mps2-an505`
//! (its memory map: `targets/mps2-an505/memory.x`, picked by `build.rs`). It reads no
//! timer, so it needs nothing of a board but RAM and semihosting.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use faint_firmware::semihosting::exit_success;

faint_firmware::report_panics!();

#[entry]
fn main() -> ! {
    faint_firmware::print_golden_lines();
    hprintln!("done");
    exit_success()
}
