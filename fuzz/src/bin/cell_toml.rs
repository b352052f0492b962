//! AFL++ target: see `framewright_fuzz::cell_toml`.
fn main() {
    afl::fuzz!(|data: &[u8]| framewright_fuzz::cell_toml(data));
}
