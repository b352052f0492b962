//! Back into BIM tools: what framewright inferred, written where authoring and
//! coordination tools read it.
//!
//! - `annotate`: the input IFC with property sets, the assembly sequence as
//!   processes (IfcWorkSchedule, IfcTask, IfcRelSequence) and the nails as
//!   IfcMechanicalFastener appended; the input's entities are kept byte for byte.
//! - `panels`: each panel of a split wall as an IfcElementAssembly of its members (plate
//!   segments and added end studs as new IfcMembers), written by `annotate`.
//! - `bcf`: BCF 2.1 / 3.0 topics (one per root cause per wall) from a simulation.
//! - `step_edit`: the byte-level edit of a STEP file (header record, appended entities).

pub mod annotate;
pub mod bcf;
mod entities;
mod error;
mod panels;
pub mod step_edit;
mod verdicts;

pub use annotate::{AnnotateOptions, Annotated, NailSize, annotate, iso_date_time};
pub use bcf::{BcfHeader, BcfVersion};
pub use entities::PSET_NAME;
pub use error::AnnotateError;
pub use verdicts::{ElementVerdict, element_verdicts};
