//! Errors of the cell stage: robot, tool and cell files. Each names the file and, where the
//! input has lines, the line and column, the key and what was expected.

use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum CellError {
    #[error("{path}: cannot read: {source}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A TOML file that does not parse or does not match the schema.
    #[error("{path}:{line}:{column}: {message}")]
    Toml {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    /// A value that parses but is not acceptable (absurd size, unreachable pick point...).
    #[error("{path}:{line}: key `{key}`: {message}")]
    Value {
        path: PathBuf,
        line: usize,
        key: String,
        message: String,
    },
    #[error("{path}: URDF: {message}")]
    Urdf { path: PathBuf, message: String },
    #[error("unknown {what} `{name}`: give a file path or one of the built-in names: {known}")]
    UnknownName {
        what: &'static str,
        name: String,
        known: String,
    },
}

/// A setting given as text (a command-line option, a cell key) that is not acceptable, or a
/// pick point the robot cannot reach: what is wrong; the caller names where it came from.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct InvalidValue(pub String);

impl CellError {
    pub(crate) fn urdf(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        CellError::Urdf {
            path: path.into(),
            message: message.into(),
        }
    }
}
