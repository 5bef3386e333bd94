//! Cortex-M4F firmware on QEMU `mps2-an386`: counts the instructions `faint-core` needs on
//! the target and prints the golden lines CI compares with the host.
//!
//! Run: `cd firmware && cargo run --profile firmware` (needs `qemu-system-arm`). Output
//! goes to stdout via semihosting; the exit status is 0 on success and 1 on any panic.
//!
//! Adding a detector: write `firmware/src/<name>.rs` with `pub fn run()` that takes its
//! state from a `harness::Static`, measures `step` with `harness::measure` and prints
//! rows with `harness::row`; then add `mod <name>;` and `<name>::run();` below.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;

mod crpf;
mod harness;
mod mht;
mod phd;
mod primitives;

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
    hprintln!();
    hprintln!(
        "static RAM of this image (.data + .bss, all rows): {} bytes",
        harness::static_ram()
    );
    hprintln!();
    let mut line = Line::new();
    faint_golden::cases(&mut |name, words| {
        line.len = 0;
        if faint_golden::write_line(&mut line, name, words).is_err() {
            hprintln!("golden {} <line too long>", name);
        } else {
            hprintln!("{}", line.as_str());
        }
    });
    hprintln!("done");
    harness::exit_success()
}

/// Fixed buffer for one golden line (so the host and the firmware share the formatter).
struct Line {
    buf: [u8; 1024],
    len: usize,
}

impl Line {
    const fn new() -> Self {
        Self {
            buf: [0; 1024],
            len: 0,
        }
    }

    fn as_str(&self) -> &str {
        core::str::from_utf8(&self.buf[..self.len]).unwrap_or("<utf8>")
    }
}

impl core::fmt::Write for Line {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let end = self.len + s.len();
        let dst = self.buf.get_mut(self.len..end).ok_or(core::fmt::Error)?;
        dst.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
    }
}
