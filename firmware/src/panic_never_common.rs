//! The zeroed-`static` macro of the `panic-never*` binaries (their exit, messages, `&mut`
//! to a static and panic handler are the `faint_firmware` library's).
//!
//! Included by each binary that uses it with
//! `#[path = "../panic_never_common.rs"] #[macro_use] mod common;`.

/// An all-zero `static mut`: the const evaluator rejects (compile error) a zero bit
/// pattern that is not a valid value of every field; `configure` sets it up.
#[allow(unused_macros)]
macro_rules! zeroed {
    ($name:ident: $t:ty) => {
        // SAFETY: validity of the all-zero value is checked by const evaluation.
        static mut $name: $t = unsafe { core::mem::MaybeUninit::zeroed().assume_init() };
    };
}
