#![no_main]
//! `dp-second`: see `faint_host::reliability::guided`.
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    faint_host::reliability::guided::fuzz(faint_host::reliability::guided::dp_second, data)
});
