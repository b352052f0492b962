//! Errors of the STEP layer. Every error carries a byte offset; the reader
//! turns it into `line:column` so that messages point into the file.

use super::limits::{ENV_MAX_BYTES, ENV_MAX_DEPTH, ENV_MAX_INSTANCES, ENV_MAX_STRING_BYTES};
use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub enum StepErrorKind {
    /// The file does not start with `ISO-10303-21;`.
    NotStep,
    /// No `HEADER;` section before `DATA;`.
    MissingHeader,
    /// A required header entity (FILE_SCHEMA, ...) is missing.
    MissingHeaderEntity(&'static str),
    /// No `DATA;` section.
    MissingData,
    /// The file ends inside an entity instance or section.
    Truncated { inside: String },
    /// A token that does not fit the grammar.
    Syntax(String),
    /// The same `#id` is defined twice.
    DuplicateId {
        id: u64,
        first_line: usize,
        first_type: String,
        second_type: String,
    },
    /// The file is larger than the configured limit.
    TooLarge { bytes: u64, limit: u64 },
    /// Lists nested deeper than the reader allows (protects the stack).
    TooDeep { limit: usize },
    /// The file could not be read.
    Io(String),
    /// More entity instances than the configured limit.
    TooManyInstances { limit: usize },
    /// A string literal longer than the configured limit.
    StringTooLong { limit: usize },
    /// A limit variable in the environment is not a whole number.
    BadLimit {
        variable: &'static str,
        value: String,
    },
}

/// A STEP error at a position in the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub struct StepError {
    pub kind: StepErrorKind,
    /// 1-based line, 0 when the error is not tied to a position.
    pub line: usize,
    /// 1-based column in bytes.
    pub column: usize,
    /// The entity the error is in, when known.
    pub entity: Option<u64>,
}

impl StepError {
    pub fn new(kind: StepErrorKind) -> Self {
        StepError {
            kind,
            line: 0,
            column: 0,
            entity: None,
        }
    }
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line > 0 {
            write!(f, "line {}:{}: ", self.line, self.column)?;
        }
        if let Some(id) = self.entity {
            write!(f, "#{id}: ")?;
        }
        match &self.kind {
            StepErrorKind::NotStep => write!(
                f,
                "not an ISO 10303-21 file: it must start with `ISO-10303-21;` (is this an IFC-SPF file? ifcXML and ifcZIP are not supported)"
            ),
            StepErrorKind::MissingHeader => write!(
                f,
                "no HEADER section: an IFC file needs `HEADER; ... ENDSEC;` with FILE_SCHEMA before DATA"
            ),
            StepErrorKind::MissingHeaderEntity(name) => {
                write!(
                    f,
                    "the HEADER section has no {name}; add it (e.g. FILE_SCHEMA(('IFC4'));)"
                )
            }
            StepErrorKind::MissingData => {
                write!(f, "no DATA section: the file holds no entity instances")
            }
            StepErrorKind::Truncated { inside } => write!(
                f,
                "unexpected end of file inside {inside}; the file looks truncated (no ENDSEC / END-ISO-10303-21)"
            ),
            StepErrorKind::Syntax(msg) => write!(f, "syntax error: {msg}"),
            StepErrorKind::DuplicateId {
                id,
                first_line,
                first_type,
                second_type,
            } => write!(
                f,
                "#{id} is defined twice: first as {first_type} on line {first_line}, again as {second_type}; entity ids must be unique"
            ),
            StepErrorKind::TooLarge { bytes, limit } => write!(
                f,
                "the file is {bytes} bytes, over the limit of {limit} bytes; raise the limit (`inspect --max-size MB`, or {ENV_MAX_BYTES}=BYTES for every command) if the file is genuine"
            ),
            StepErrorKind::TooDeep { limit } => {
                write!(
                    f,
                    "lists are nested deeper than {limit} levels; the file is malformed (if it is genuine, raise the limit with {ENV_MAX_DEPTH}=N)"
                )
            }
            StepErrorKind::Io(msg) => write!(f, "cannot read the file: {msg}"),
            StepErrorKind::TooManyInstances { limit } => write!(
                f,
                "the file holds more than {limit} entity instances, the limit; raise it with {ENV_MAX_INSTANCES}=N if the file is genuine"
            ),
            StepErrorKind::StringTooLong { limit } => write!(
                f,
                "a string is longer than {limit} bytes, the limit; raise it with {ENV_MAX_STRING_BYTES}=BYTES if the file is genuine"
            ),
            StepErrorKind::BadLimit { variable, value } => write!(
                f,
                "{variable}={value:?} is not a whole number; set it to a limit such as 1000000, or unset it"
            ),
        }
    }
}
