//! libFuzzer target: see `framewright_fuzz::rules_front`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| framewright_fuzz::rules_front(data));
