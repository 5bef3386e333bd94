//! The run's ends through semihosting: exit statuses, plain messages, the command line,
//! and the two panic handlers a binary chooses between (see the crate's macros).

use cortex_m_semihosting::{debug, hio, hprintln};

/// Ends the QEMU run with exit status 0.
#[inline]
pub fn exit_success() -> ! {
    debug::exit(debug::EXIT_SUCCESS);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// Ends the QEMU run with exit status 1.
#[inline]
pub fn exit_failure() -> ! {
    debug::exit(debug::EXIT_FAILURE);
    #[allow(clippy::empty_loop)]
    loop {}
}

/// Prints `ok_msg` or `fail_msg` (without `core::fmt`) and exits QEMU with the matching
/// status.
#[inline]
pub fn finish(ok: bool, ok_msg: &[u8], fail_msg: &[u8]) -> ! {
    say(if ok { ok_msg } else { fail_msg });
    if ok {
        exit_success()
    } else {
        exit_failure()
    }
}

/// Writes `msg` to the host's stdout without `core::fmt` (ignored if semihosting is
/// unavailable).
#[inline]
pub fn say(msg: &[u8]) {
    if let Ok(mut out) = hio::hstdout() {
        let _ = out.write_all(msg);
    }
}

/// The command line (`SYS_GET_CMDLINE`: the kernel's path, then QEMU's `-append`), read
/// into `buf`; empty when the host does not give it.
#[inline]
pub fn cmdline(buf: &mut [u8]) -> &str {
    let mut block = [buf.as_mut_ptr() as usize, buf.len()];
    // SAFETY: the block is the buffer's address and length, which the host fills with
    // the command line and its length.
    let rc = unsafe {
        cortex_m_semihosting::syscall1(
            cortex_m_semihosting::nr::GET_CMDLINE,
            block.as_mut_ptr() as usize,
        )
    };
    if rc != 0 {
        return "";
    }
    let n = block[1].min(buf.len());
    core::str::from_utf8(&buf[..n]).unwrap_or("")
}

/// Prints the panic and exits with status 1 (the measuring binaries' panic handler,
/// installed by [`crate::report_panics!`]).
#[inline]
pub fn report_panic(info: &core::panic::PanicInfo) -> ! {
    hprintln!("PANIC: {}", info);
    exit_failure()
}

/// Prints the hard fault's frame and exits with status 1.
#[inline]
pub fn report_hard_fault(ef: &cortex_m_rt::ExceptionFrame) -> ! {
    hprintln!("HARDFAULT: {:?}", ef);
    exit_failure()
}
