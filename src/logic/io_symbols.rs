//! Soufflé's fact and output files hold symbols unquoted, one tuple a line: a symbol that holds
//! the delimiter or a line break (or is the only, empty field of a line) cannot be written so
//! that `.input` reads it back the same. Writing it anyway would split or drop the tuple
//! silently, so the writer refuses and says which tuple.

use super::value::Value;

/// The first symbol of `tuples` that the file format cannot carry, with the reason.
pub fn unwritable_symbol<'t>(
    tuples: &'t [Vec<Value>],
    delimiter: &str,
) -> Option<(&'t str, &'static str)> {
    for t in tuples {
        for v in t {
            let Some(s) = v.as_symbol() else { continue };
            if s.contains('\n') || s.contains('\r') {
                return Some((s, "holds a line break"));
            }
            if !delimiter.is_empty() && s.contains(delimiter) {
                return Some((s, "holds the delimiter"));
            }
            if t.len() == 1 && s.is_empty() {
                return Some((s, "is empty, the only field of its line"));
            }
        }
    }
    None
}
