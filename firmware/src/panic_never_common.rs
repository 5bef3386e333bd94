//! What every `panic-never*` binary shares: the exit through semihosting, the message
//! writer, the zeroed-`static` macro, the `&mut` to a static, and the panic handler that
//! turns any surviving panic path into a link error.
//!
//! Included by each binary with `#[path = "../panic_never_common.rs"] #[macro_use] mod common;`
//! (the firmware has no library target).

use cortex_m_semihosting::{debug, hio};

/// Prints `ok_msg` or `fail_msg` and exits QEMU with the matching status.
pub fn finish(ok: bool, ok_msg: &[u8], fail_msg: &[u8]) -> ! {
    say(if ok { ok_msg } else { fail_msg });
    debug::exit(if ok {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    #[allow(clippy::empty_loop)]
    loop {}
}

/// Writes `msg` to the host's stdout (ignored if semihosting is unavailable).
pub fn say(msg: &[u8]) {
    if let Ok(mut out) = hio::hstdout() {
        let _ = out.write_all(msg);
    }
}

/// The `&mut` to a static.
///
/// # Safety
/// `p` points to a static that nothing else references while the result lives.
#[allow(dead_code)]
pub unsafe fn only_ref<T>(p: *mut T) -> &'static mut T {
    // SAFETY: the caller's contract.
    unsafe { &mut *p }
}

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    extern "Rust" {
        // Deliberately undefined: referencing it is the link error.
        fn faint_core_panic_path_survived() -> !;
    }
    // SAFETY: never linked; a successful link proves this call is unreachable.
    unsafe { faint_core_panic_path_survived() }
}
