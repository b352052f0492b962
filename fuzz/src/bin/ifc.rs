//! libFuzzer target: see `framewright_fuzz::ifc`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| framewright_fuzz::ifc(data));
