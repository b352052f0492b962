//! AFL++ target: see `framewright_fuzz::urdf`.
fn main() {
    afl::fuzz!(|data: &[u8]| framewright_fuzz::urdf(data));
}
