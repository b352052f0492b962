//! AFL++ target: see `framewright_fuzz::ifc`.
fn main() {
    afl::fuzz!(|data: &[u8]| framewright_fuzz::ifc(data));
}
