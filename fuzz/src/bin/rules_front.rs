//! AFL++ target: see `framewright_fuzz::rules_front`.
fn main() {
    afl::fuzz!(|data: &[u8]| framewright_fuzz::rules_front(data));
}
