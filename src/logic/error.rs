//! Errors of the rule engines (library side; the CLI maps them to exit 2).

use super::front::Diagnostics;
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum LogicError {
    /// Errors in rule files: each with file:line:col, caret line and hint.
    #[error("{0}")]
    Program(#[from] Diagnostics),
    #[error("cannot read {path}: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("cannot write {path}: {source}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    /// An `.input`/`.output` file name that would leave its folder (the
    /// message names the directive, file:line and the folder).
    #[error("{0}")]
    Confined(String),
    /// A malformed line in a facts file.
    #[error("{file}:{line}: {message}\n  = hint: {hint}")]
    Facts {
        file: String,
        line: usize,
        message: String,
        hint: String,
    },
    /// Division by zero, bad `to_number`, ...: names the rule and the variable values.
    #[error("runtime error in {rule}: {message}\n  rule: {rule_text}\n  with {bindings}")]
    Runtime {
        rule: String,
        rule_text: String,
        bindings: String,
        message: String,
    },
    /// The tuple or iteration limit stopped a run that kept creating values.
    #[error("evaluation stopped: {message}\n  = hint: {hint}")]
    Limit { message: String, hint: String },
    /// Misuse from Rust code or the command line (unknown relation, wrong arity, ...).
    #[error("{0}")]
    Usage(String),
}
