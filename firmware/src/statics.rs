//! `static` storage for the large states (detectors, frames), which never live on the
//! stack: [`Static`], handed out once, and [`only_ref`] for a `static mut`.

use core::cell::UnsafeCell;
use core::sync::atomic::{AtomicBool, Ordering};

/// A `static` buffer handed out once as `&'static mut T` (large detector states live
/// here, not on the stack). Zero-initialised values land in `.bss`.
pub struct Static<T> {
    taken: AtomicBool,
    cell: UnsafeCell<T>,
}

impl<T> core::fmt::Debug for Static<T> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Static")
            .field("taken", &self.taken.load(Ordering::Relaxed))
            .finish_non_exhaustive()
    }
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

/// The `&mut` to a `static mut`.
///
/// # Safety
/// `p` points to a static that nothing else references while the result lives.
pub unsafe fn only_ref<T>(p: *mut T) -> &'static mut T {
    // SAFETY: the caller's contract.
    unsafe { &mut *p }
}
