//! The soak's arguments, from the semihosting command line (QEMU's `-append`):
//! `frames=N` (default [`DEFAULT_FRAMES`]), `only=a,b` (names as in
//! `faint detect --list`; default all) and `phases=1` (the stack diagnostic, see
//! [`super::stack`]).

use core::fmt::Write;

use crate::semihosting::cmdline;
use crate::text::Text;

/// Frames per detector unless `frames=` says otherwise.
pub const DEFAULT_FRAMES: u32 = 10_000;

static mut CMDLINE: [u8; 256] = [0; 256];

/// The run's arguments.
#[derive(Debug)]
pub struct Args {
    /// Frames per detector (at least 1).
    pub frames: u32,
    /// `phases=1`: the peak stack of each phase of a frame (generator, `step`, output
    /// check) is measured on its own.
    pub phases: bool,
    only: Text<256>,
}

impl Args {
    /// Reads the command line (the kernel's path, then `-append`). Call once.
    #[inline]
    pub fn read() -> Self {
        let mut args = Args {
            frames: DEFAULT_FRAMES,
            phases: false,
            only: Text::new(),
        };
        // SAFETY: single-threaded, and `read` is called once: the only reference.
        let buf = unsafe { &mut *core::ptr::addr_of_mut!(CMDLINE) };
        for word in cmdline(buf).split_ascii_whitespace().skip(1) {
            if let Some(v) = word.strip_prefix("frames=") {
                if let Ok(f) = v.parse::<u32>() {
                    args.frames = f.max(1);
                }
            } else if word == "phases=1" {
                args.phases = true;
            } else if let Some(v) = word.strip_prefix("only=") {
                args.only.clear();
                let _ = args.only.write_str(v);
            }
        }
        args
    }

    /// True when `name` is selected (`only=` unset: every detector but the diagnostic
    /// variants).
    #[inline]
    pub fn selected(&self, name: &str) -> bool {
        let list = self.only.as_str();
        list.is_empty() || list == "all" || self.named(name)
    }

    /// True when `name` is in `only=` (the diagnostic variants run only so).
    #[inline]
    pub fn named(&self, name: &str) -> bool {
        self.only.as_str().split(',').any(|n| n == name)
    }
}
