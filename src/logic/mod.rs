//! The rule language: a subset of Soufflé's Datalog with geometric extensions
//! (see docs/RULES-LANGUAGE.md), and its engines.
//!
//! - `front`: lexer, parser, checker and ascent code generator (std only, also
//!   compiled into `build.rs`).
//! - `interp`: the semi-naive interpreter with provenance (`Engine`).
//! - `compiled`: ascent programs generated from `rules/*.dl` and `tests/logic/*.dl`.
//! - `functors`: the Rust functors `@name(...)`; `ops`: typed operations both engines share;
//!   `std_regex`: `match` patterns read as Soufflé's C++ std::regex reads them.

pub mod compiled;
pub mod error;
pub mod front;
pub mod functors;
pub mod interp;
pub mod io;
pub mod ops;
pub mod provenance;
pub mod std_regex;
pub mod tokens;
pub mod value;

pub use error::LogicError;
pub use front::ast::BaseTy;
pub use front::{Diagnostic, Diagnostics, Program};
pub use interp::{Engine, Limits, Options, Origin, RunStats};
pub use provenance::{Explanation, WhyNot};
pub use value::{F64, Iso, OBox, Value, Vec3};

use std::path::Path;

impl Program {
    /// Parse and check rule files (and their `.include`s) as one program.
    pub fn parse_files<P: AsRef<Path>>(paths: &[P]) -> Result<Program, Diagnostics> {
        let paths: Vec<_> = paths.iter().map(|p| p.as_ref().to_path_buf()).collect();
        front::load_files(&paths, &functors::signatures())
    }

    /// Like `parse_files`, with every `.include` confined to `include_root`
    /// instead of each file's own folder.
    pub fn parse_files_within<P: AsRef<Path>>(
        paths: &[P],
        include_root: Option<&Path>,
    ) -> Result<Program, Diagnostics> {
        let paths: Vec<_> = paths.iter().map(|p| p.as_ref().to_path_buf()).collect();
        front::load_files_within(&paths, include_root, &functors::signatures())
    }

    /// The built-in rule base (`rules/*.dl`, embedded at build time) as one
    /// checked program; its compiled form is `compiled::program("rules")`.
    pub fn builtin() -> Result<Program, Diagnostics> {
        front::load_sources(compiled::BUILTIN_SOURCES, &functors::signatures())
    }

    /// Parse and check program text; `name` is used in error messages.
    pub fn parse_str(name: &str, text: &str) -> Result<Program, Diagnostics> {
        front::load_str(name, text, &functors::signatures())
    }
}
