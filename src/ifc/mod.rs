//! IFC knowledge on top of the STEP reader: schema, units, placements and
//! representations → lumber pieces (oriented boxes in metres, world frame).
//!
//! ```no_run
//! let model = framewright::ifc::Model::open("examples/models/tm1.ifc")?;
//! for piece in model.pieces() {
//!     println!("{} {:.3} m", piece.id, piece.obox.length());
//! }
//! # Ok::<(), framewright::ifc::IfcError>(())
//! ```

mod context;
mod error;
pub mod guid;
pub mod limits;
mod placement;
mod products;
mod relations;
mod schema;
mod shape;
mod units;

pub use error::{IfcError, IfcErrorKind, Warning};
pub use products::{Group, Piece};
pub use schema::{LUMBER_PRODUCTS, Schema, display_name};
pub use units::LengthUnit;

use crate::step::{Header, ReadOptions, StepFile};
use context::Ctx;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A read IFC model: header facts, the length unit, every lumber piece and
/// the groups (walls, assemblies, storeys) they belong to.
#[derive(Debug)]
pub struct Model {
    pub path: PathBuf,
    pub schema: Schema,
    /// The FILE_SCHEMA identifier as written (e.g. `IFC4X3_ADD2`).
    pub schema_identifier: String,
    pub length_unit: LengthUnit,
    pub pieces: Vec<Piece>,
    /// Parents and containers of pieces, by entity id.
    pub groups: BTreeMap<u64, Group>,
    /// Sorted; repaired values and skipped products.
    pub warnings: Vec<Warning>,
    /// Shared by a model and the models derived from it (`with_pieces`).
    file: std::sync::Arc<StepFile>,
}

impl Model {
    /// Reads a model with the reader's default limits (`open_with` takes others).
    pub fn open(path: impl AsRef<Path>) -> Result<Model, IfcError> {
        Self::open_with(path, &ReadOptions::default())
    }

    pub fn open_with(path: impl AsRef<Path>, options: &ReadOptions) -> Result<Model, IfcError> {
        let path = path.as_ref().to_path_buf();
        match StepFile::open(&path, options) {
            Ok(file) => Self::from_step(path, file),
            Err(e) => Err(IfcError {
                path,
                kind: e.into(),
            }),
        }
    }

    /// Reads a model from bytes; `name` stands for the path in messages.
    pub fn from_bytes(
        name: impl Into<PathBuf>,
        bytes: Vec<u8>,
        options: &ReadOptions,
    ) -> Result<Model, IfcError> {
        let path = name.into();
        match StepFile::from_bytes(bytes, options) {
            Ok(file) => Self::from_step(path, file),
            Err(e) => Err(IfcError {
                path,
                kind: e.into(),
            }),
        }
    }

    fn from_step(path: PathBuf, file: StepFile) -> Result<Model, IfcError> {
        let fail = |kind| IfcError {
            path: path.clone(),
            kind,
        };
        let identifier = file.header.schemas.first().cloned().unwrap_or_default();
        let Some(schema) = Schema::from_identifier(&identifier) else {
            let line = line_of(&file, b"FILE_SCHEMA");
            return Err(fail(IfcErrorKind::UnsupportedSchema {
                name: identifier,
                line,
            }));
        };
        if file.is_empty() {
            return Err(fail(IfcErrorKind::NoEntities {
                line: line_of(&file, b"DATA"),
            }));
        }
        let read = products::read(Ctx::new(&file, schema, 1.0)).map_err(fail)?;
        Ok(Model {
            path,
            schema,
            schema_identifier: identifier,
            length_unit: read.unit,
            pieces: read.pieces,
            groups: read.groups,
            warnings: read.warnings,
            file: std::sync::Arc::new(file),
        })
    }

    pub fn pieces(&self) -> &[Piece] {
        &self.pieces
    }

    /// The same model (file, groups, warnings) holding `pieces` instead of its own: a model
    /// derived from this one, such as its walls cut into panels.
    pub fn with_pieces(&self, pieces: Vec<Piece>) -> Model {
        Model {
            path: self.path.clone(),
            schema: self.schema,
            schema_identifier: self.schema_identifier.clone(),
            length_unit: self.length_unit.clone(),
            pieces,
            groups: self.groups.clone(),
            warnings: self.warnings.clone(),
            file: self.file.clone(),
        }
    }

    /// Each piece's index in `pieces()`, by piece id.
    pub fn piece_positions(&self) -> rustc_hash::FxHashMap<&str, usize> {
        self.pieces
            .iter()
            .enumerate()
            .map(|(i, p)| (p.id.as_str(), i))
            .collect()
    }

    pub fn header(&self) -> &Header {
        &self.file.header
    }

    /// The underlying STEP file, for stages that need more than pieces.
    pub fn step(&self) -> &StepFile {
        &self.file
    }

    pub fn entity_count(&self) -> usize {
        self.file.len()
    }
}

fn line_of(file: &StepFile, needle: &[u8]) -> usize {
    memchr::memmem::find(file.bytes(), needle).map_or(0, |at| file.line_col(at).0)
}
