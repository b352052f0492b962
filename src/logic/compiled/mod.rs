//! Compiled engine: `build.rs` turns the built-in rule base (all `rules/*.dl`
//! as one program, listed as `"rules"`) into an `ascent!` program with a
//! wrapper `run(&edb) -> relations` on `Value` tuples; with the feature
//! `logic-test-programs` (the crate's own tests and benches) also every
//! `tests/logic/*.dl`, `benches/logic/*.dl` and Soufflé corpus program the
//! generator takes, listed by path.

pub mod rt;

pub use crate::logic::error::CompiledError;
use crate::logic::value::Value;
use std::collections::BTreeMap;

/// Input or output relations by name, tuples sorted.
pub type Relations = BTreeMap<String, Vec<Vec<Value>>>;
/// A generated program's entry point.
pub type RunFn = fn(&Relations) -> Result<Relations, CompiledError>;

include!(concat!(env!("OUT_DIR"), "/logic_compiled.rs"));

/// The compiled program for `"rules"` (the built-in rule base; absent while
/// `rules/` is empty) or a path such as `tests/logic/tc.dl`.
pub fn program(path: &str) -> Option<RunFn> {
    PROGRAMS.iter().find(|(p, _)| *p == path).map(|(_, f)| *f)
}
