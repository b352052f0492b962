//! libFuzzer target: see `framewright_fuzz::cell_toml`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| framewright_fuzz::cell_toml(data));
