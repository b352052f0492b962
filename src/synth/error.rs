//! Typed errors for layouts and writer options.
use thiserror::Error;

#[derive(Debug, Error, PartialEq)]
pub enum SynthError {
    /// A wall parameter is outside what a light wood-frame wall can be.
    #[error("wall {wall}: {what} (hint: {hint})")]
    Wall {
        wall: String,
        what: String,
        hint: String,
    },
    /// An opening does not fit its wall or collides with another opening.
    #[error("wall {wall}, opening {index} ({kind}): {what} (hint: {hint})")]
    Opening {
        wall: String,
        index: usize,
        kind: &'static str,
        what: String,
        hint: String,
    },
    /// Building or grid parameters are out of range.
    #[error("building: {what} (hint: {hint})")]
    Building { what: String, hint: String },
    /// Writer options that cannot be combined.
    #[error("writer options: {what} (hint: {hint})")]
    Options { what: String, hint: String },
    /// A value given on the command line could not be read.
    #[error("cannot read {what} '{value}': {hint}")]
    Parse {
        what: &'static str,
        value: String,
        hint: String,
    },
}
