//! Compiled engine: `build.rs` turns every `rules/*.dl` (the built-in rule
//! base) and `tests/logic/*.dl` into an `ascent!` program with a wrapper
//! `run(&edb) -> relations` on `Value` tuples. `PROGRAMS` lists them by path.

pub mod rt;

use crate::logic::value::Value;
use std::collections::BTreeMap;

/// Input or output relations by name, tuples sorted.
pub type Relations = BTreeMap<String, Vec<Vec<Value>>>;
/// A generated program's entry point.
pub type RunFn = fn(&Relations) -> Result<Relations, String>;

include!(concat!(env!("OUT_DIR"), "/logic_compiled.rs"));

/// The compiled program generated from `path` (relative to the crate root, e.g. `tests/logic/tc.dl`).
pub fn program(path: &str) -> Option<RunFn> {
    PROGRAMS.iter().find(|(p, _)| *p == path).map(|(_, f)| *f)
}
