//! Selects the Cortex-M4F assembly kernels of `detect::dp` (`cfg(faint_m4_asm)`): only on
//! `thumbv7em-*-eabihf`, ARMv7E-M with the DSP extension (`ssub16`, `sel`, `qadd16`) and a
//! single-precision FPU (`vcvtr`, `vpush`). Every other target, other ARM targets
//! included (`thumbv7em-none-eabi` has no FPU registers, `thumbv7m` no DSP), builds the
//! portable code, which gives the same results.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(faint_m4_asm)");
    println!("cargo::rerun-if-changed=build.rs");
    let target = std::env::var("TARGET").unwrap_or_default();
    if target.starts_with("thumbv7em-") && target.ends_with("eabihf") {
        println!("cargo::rustc-cfg=faint_m4_asm");
    }
}
