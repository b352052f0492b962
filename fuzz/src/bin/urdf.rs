//! libFuzzer target: see `framewright_fuzz::urdf`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| framewright_fuzz::urdf(data));
