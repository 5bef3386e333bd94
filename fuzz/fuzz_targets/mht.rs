#![no_main]
//! `mht`: see `faint_host::reliability::guided`.
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    faint_host::reliability::guided::fuzz(faint_host::reliability::guided::mht, data)
});
