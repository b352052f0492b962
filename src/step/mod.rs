//! ISO 10303-21 ("STEP physical file") reader, and the writer's text forms (`text`). Knows
//! nothing about IFC.
//!
//! One pass over the bytes indexes every entity instance as `#id → (type, byte
//! range)`; parameters are decoded on demand with nom ([`StepFile::entity`]).
//! Handles comments, `$`, `*`, enums, typed values, nested lists, string
//! escapes and CR-only line ends.

mod error;
mod header;
mod index;
mod limits;
mod params;
mod source;
mod strings;
pub mod text;

pub use error::{StepError, StepErrorKind};
pub use header::Header;
pub use index::{Record, StepFile, TypeId};
pub use limits::{
    ENV_MAX_BYTES, ENV_MAX_DEPTH, ENV_MAX_INSTANCES, ENV_MAX_STRING_BYTES, ReadOptions,
};
pub use params::{Entity, Param};
pub use source::Source;
pub use strings::decode_step_string;
