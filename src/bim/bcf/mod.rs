//! BCF (BIM Collaboration Format) export of a simulation: one topic per root cause per
//! wall, each pointing at the failing elements by IfcGuid with a camera on the wall.
//!
//! - `topics`: which topics (root causes; their consequences go into the description);
//! - `xml`: markup, viewpoint, version and extensions documents for BCF 2.1 and 3.0,
//!   written with quick-xml after buildingSMART's BCF-XML schemas;
//! - `archive`: the `.bcfzip` (stored entries, fixed dates: same inputs, same bytes).
//!
//! Snapshot: a topic's viewpoint carries a PNG of its wall's elevation drawing (pieces
//! coloured by verdict, nailing targets as dots; `report::png`), set by the caller.

mod archive;
mod topics;
mod xml;

pub use archive::{BcfError, write_bcfzip};
pub use topics::{Camera, IssueTopic, topics_of};

/// The BCF release written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum BcfVersion {
    #[value(name = "3.0")]
    V3_0,
    #[value(name = "2.1")]
    V2_1,
}

impl BcfVersion {
    pub fn id(self) -> &'static str {
        match self {
            BcfVersion::V3_0 => "3.0",
            BcfVersion::V2_1 => "2.1",
        }
    }
}

/// A viewpoint's snapshot image (PNG bytes).
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot(pub Vec<u8>);

/// What a BCF file is about: the model file and project, and the date its topics carry.
#[derive(Debug, Clone)]
pub struct BcfHeader {
    pub model_file: String,
    pub project_global_id: Option<String>,
    /// ISO 8601 date-time, written as each topic's creation date.
    pub date: String,
}
