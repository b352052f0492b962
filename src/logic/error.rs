//! Errors of the rule engines (library side; the CLI maps them to exit 2).

use super::front::Diagnostics;
use super::front::ast::BaseTy;
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

/// A runtime error of an operation in a rule (division by zero, bad `to_number`, ...): what
/// went wrong; the engine that ran the rule names it (`LogicError::Runtime`, `CompiledError`).
#[derive(Debug, Clone, Default, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct EvalError(pub String);

impl EvalError {
    pub fn new(message: impl Into<String>) -> Self {
        EvalError(message.into())
    }
}

/// The first runtime error of a compiled rule program (`logic::compiled`), in the rule it
/// happened in; the run's results are discarded.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("runtime error in {rule}: {message}")]
pub struct CompiledError {
    pub rule: String,
    pub message: EvalError,
}

/// A field of a `.facts` file (or a queried tuple) that is not a value of its type
/// (`Value::parse`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ParseValueError {
    #[error("`{0}` is not a number")]
    Number(String),
    #[error("`{0}` is not an unsigned number")]
    Unsigned(String),
    #[error("`{0}` is not a float")]
    Float(String),
    /// A vector, pose or box not written `[...]`.
    #[error("expected `[...]` with {n} numbers for a {ty}, found `{text}`")]
    Brackets { n: usize, ty: BaseTy, text: String },
    /// A vector, pose or box with the wrong count of numbers, or one that is not a number.
    #[error("expected {n} comma-separated numbers for a {ty}, found `{text}`")]
    Numbers { n: usize, ty: BaseTy, text: String },
}
