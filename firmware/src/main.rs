//! Cortex-M4F firmware on QEMU `mps2-an386`: counts the instructions `faint-core` needs on
//! the target and prints the golden lines CI compares with the host.
//!
//! Run: `cd firmware && cargo run --profile firmware` (needs `qemu-system-arm`). Output
//! goes to stdout via semihosting; the exit status is 0 on success and 1 on any panic.
//!
//! Adding a detector: write `firmware/src/rows/<name>.rs` with `pub fn run()` that takes
//! its state from a `statics::Static`, measures `step` with `harness::measure` and prints
//! rows with `harness::row`; then add `pub mod <name>;` to `rows` and `<name>::run();`
//! below.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use faint_firmware::harness;
use faint_firmware::semihosting::exit_success;

/// The instruction table's rows, one module per detector family.
mod rows {
    pub mod cbmember;
    pub mod crpf;
    pub mod dp;
    pub mod mht;
    pub mod phd;
    pub mod primitives;
}

use rows::{cbmember, crpf, dp, mht, phd, primitives};

faint_firmware::report_panics!();

#[entry]
fn main() -> ! {
    harness::init();
    hprintln!("faint firmware: Cortex-M4F on QEMU mps2-an386, -icount shift=10");
    hprintln!("counts are executed instructions (not Cortex-M4 cycles), deterministic");
    harness::calibrate();
    hprintln!();
    harness::table_header();
    primitives::run();
    // Detectors: one `<name>::run();` line each, here.
    mht::run();
    crpf::run();
    phd::run();
    cbmember::run();
    dp::run();
    hprintln!();
    hprintln!(
        "static RAM of this image (.data + .bss, all rows): {} bytes",
        harness::static_ram()
    );
    hprintln!();
    faint_firmware::print_golden_lines();
    hprintln!("done");
    exit_success()
}
