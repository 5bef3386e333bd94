#![no_main]
//! `pso-phd-kmeans`: see `faint_host::reliability::guided`.
libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    faint_host::reliability::guided::fuzz(faint_host::reliability::guided::pso_phd_kmeans, data)
});
