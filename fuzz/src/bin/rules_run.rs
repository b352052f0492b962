//! libFuzzer target: see `framewright_fuzz::rules_run`.
#![no_main]
libfuzzer_sys::fuzz_target!(|data: &[u8]| framewright_fuzz::rules_run(data));
