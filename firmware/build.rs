//! Puts the board's `memory.x` where cortex-m-rt's `link.x` looks for it: `memory.x`
//! (QEMU `mps2-an385`, `an386`, `an500`) for every target but the Cortex-M33
//! (`thumbv8m.main-*`), which runs on `mps2-an505` (`targets/mps2-an505/memory.x`).
//! No `memory.x` may sit at the workspace root: the linker runs there and would take it
//! before this one.

use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").expect("cargo sets OUT_DIR"));
    let target = env::var("TARGET").unwrap_or_default();
    let memory = if target.starts_with("thumbv8m.main-") {
        "targets/mps2-an505/memory.x"
    } else {
        "memory.x"
    };
    fs::copy(memory, out.join("memory.x")).expect("copy the board's memory.x into OUT_DIR");
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed={memory}");
    println!("cargo:rerun-if-changed=build.rs");
}
