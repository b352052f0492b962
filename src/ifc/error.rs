//! Errors of the IFC layer (the file cannot be read as a whole) and
//! warnings (one product or value was skipped or repaired).

use crate::step::StepError;
use serde::Serialize;
use std::path::PathBuf;

/// A model that cannot be read. Displays as `FILE: line L: what; what to do`.
#[derive(Debug, thiserror::Error)]
#[error("{}: {kind}", path.display())]
pub struct IfcError {
    pub path: PathBuf,
    pub kind: IfcErrorKind,
}

#[derive(Debug, thiserror::Error)]
pub enum IfcErrorKind {
    #[error("{0}")]
    Step(#[from] StepError),
    #[error(
        "line {line}: FILE_SCHEMA names '{name}', which framewright does not read; supported schemas are IFC2X3, IFC4 and IFC4X3 (export the model in one of them)"
    )]
    UnsupportedSchema { name: String, line: usize },
    #[error(
        "line {line}: the DATA section holds no entity instances: there is nothing to read (was the export cut short?)"
    )]
    NoEntities { line: usize },
    #[error(
        "line {line}: placement cycle {}: IfcLocalPlacement.PlacementRelTo never reaches a root placement; make one of these placements absolute or relative to a placement outside the cycle",
        chain.iter().map(|id| format!("#{id}")).collect::<Vec<_>>().join(" -> ")
    )]
    PlacementCycle { chain: Vec<u64>, line: usize },
    #[error("line {line}: #{entity}: {message}")]
    Malformed {
        entity: u64,
        line: usize,
        message: String,
    },
}

/// Something the reader repaired or skipped; the model is still usable.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct Warning {
    /// The entity the warning is about (`#id`), when there is one.
    pub entity: Option<u64>,
    pub message: String,
}

/// Why a value could not be built, found while reading one product.
/// `Fatal` issues abort the whole read; the others skip the product or piece.
#[derive(Debug)]
pub(crate) enum Issue {
    /// `entity` refers to `missing`, which is not defined.
    Missing {
        entity: u64,
        missing: u64,
    },
    /// `entity` has an attribute of the wrong kind or type.
    Invalid {
        entity: u64,
        message: String,
    },
    /// Geometry that has no volume or cannot be a piece of lumber.
    Degenerate {
        entity: u64,
        message: String,
    },
    /// A construct the reader does not handle.
    Unsupported {
        entity: u64,
        message: String,
    },
    Fatal(IfcErrorKind),
}

impl Issue {
    pub(crate) fn invalid(entity: u64, message: impl Into<String>) -> Self {
        Issue::Invalid {
            entity,
            message: message.into(),
        }
    }

    pub(crate) fn degenerate(entity: u64, message: impl Into<String>) -> Self {
        Issue::Degenerate {
            entity,
            message: message.into(),
        }
    }

    pub(crate) fn unsupported(entity: u64, message: impl Into<String>) -> Self {
        Issue::Unsupported {
            entity,
            message: message.into(),
        }
    }

    /// A one-line description for a warning.
    pub(crate) fn describe(&self) -> String {
        match self {
            Issue::Missing { entity, missing } => {
                format!("#{entity} refers to #{missing}, which is not defined in the file")
            }
            Issue::Invalid { entity, message } => format!("#{entity}: {message}"),
            Issue::Degenerate { entity, message } => {
                format!("#{entity}: degenerate geometry: {message}")
            }
            Issue::Unsupported { entity, message } => {
                format!("#{entity}: not supported: {message}")
            }
            Issue::Fatal(kind) => kind.to_string(),
        }
    }
}

pub(crate) type R<T> = Result<T, Issue>;
