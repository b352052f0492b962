//! AFL++ target: see `framewright_fuzz::rules_run`.
fn main() {
    afl::fuzz!(|data: &[u8]| framewright_fuzz::rules_run(data));
}
