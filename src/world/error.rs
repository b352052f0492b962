//! Errors of building a scene.

use crate::cell::CellError;
use crate::frame::FrameError;
use crate::ifc::IfcError;

#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    #[error(transparent)]
    Ifc(#[from] IfcError),
    #[error(transparent)]
    Cell(#[from] CellError),
    #[error(transparent)]
    Frame(#[from] FrameError),
    #[error(transparent)]
    Row(#[from] crate::frame::rows::RowError),
    /// A relation holds a tuple of the wrong shape (possible with a replaced rule directory).
    #[error("relation `{relation}`: {message}")]
    Relation {
        relation: &'static str,
        message: String,
    },
    /// Two pieces share a spawn slot: the assembly order gave them the same rank.
    #[error(
        "pieces `{first}` and `{second}` both spawn in slot {slot}: the assembly order (assembly_rank) must rank a wall's pieces 0, 1, 2, … without ties"
    )]
    SlotTaken {
        slot: i64,
        first: String,
        second: String,
    },
    /// A spawned piece without a framing target, size or mass.
    #[error("piece `{piece}` spawns on conveyor 1 but has no {missing}")]
    Incomplete {
        piece: String,
        missing: &'static str,
    },
}
