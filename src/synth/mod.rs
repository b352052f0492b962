//! The project's own wood-frame model generator and IFC writer.
//!
//! `layout` holds framing as plain data (world-space lumber pieces, metres);
//! `wall`, `building` and `models` produce layouts; `ifc_writer` turns a layout
//! into ISO 10303-21 text plus a `truth` sidecar that records what was written,
//! so tests can check the reader and the rules on models nobody hand-tuned.

pub mod building;
pub mod error;
pub mod ifc_writer;
pub mod layout;
pub mod models;
pub mod targets;
pub mod truth;
pub mod units;
pub mod wall;

pub use error::SynthError;
pub use ifc_writer::{
    Grouping, PlacementBase, ProductClasses, Schema, WriteOptions, WrittenModel, write_ifc,
};
pub use layout::{Layout, Piece, Role, WallLayout};
pub use units::{LengthUnit, Lumber};
