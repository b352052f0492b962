//! Front end of the rule language: lexer, parser, checker and the ascent
//! code generator. Self-contained (std only) so `build.rs` can include it
//! with `#[path = "src/logic/front/mod.rs"] mod front;`.

// Nested `if`s keep the checker readable next to its error messages.
#![allow(clippy::collapsible_if)]

pub mod ast;
pub mod check;
pub mod codegen;
pub mod confine;
pub mod diag;
pub mod lex;
pub mod parse;

pub use check::{FunctorSig, Program, Stratum};
pub use diag::{Diagnostic, Diagnostics, Source};

use std::path::{Path, PathBuf};

/// Parse and check the given files (and what they `.include`) as one program.
pub fn load_files(paths: &[PathBuf], functors: &[FunctorSig]) -> Result<Program, Diagnostics> {
    load_files_within(paths, None, functors)
}

/// Like `load_files`, with `.include`s confined to `include_root` instead of
/// each top-level file's own folder (`--rules-dir`).
pub fn load_files_within(
    paths: &[PathBuf],
    include_root: Option<&Path>,
    functors: &[FunctorSig],
) -> Result<Program, Diagnostics> {
    let mut loader = check::Loader::new(functors);
    loader.set_include_root(include_root);
    for p in paths {
        loader.load_file(p, None)?;
    }
    loader.finish()
}

/// Parse and check program text; `.include` paths resolve against the current directory.
pub fn load_str(name: &str, text: &str, functors: &[FunctorSig]) -> Result<Program, Diagnostics> {
    let mut loader = check::Loader::new(functors);
    loader.load_text(name, text, Path::new("."))?;
    loader.finish()
}

/// Parse and check several in-memory sources as one program (the embedded
/// built-in rules); `.include` paths resolve against each source's directory.
pub fn load_sources(
    sources: &[(&str, &str)],
    functors: &[FunctorSig],
) -> Result<Program, Diagnostics> {
    let mut loader = check::Loader::new(functors);
    for (name, text) in sources {
        let dir = Path::new(name)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        loader.load_text(name, text, &dir)?;
    }
    loader.finish()
}
