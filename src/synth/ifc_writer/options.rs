//! The writer's options and what they mean for the written products: schema, product
//! classes, grouping, placement base, and the IFC class each framing piece becomes.
use crate::synth::error::SynthError;
use crate::synth::truth::Truth;
use crate::synth::units::LengthUnit;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Schema {
    Ifc2x3,
    Ifc4,
    Ifc4x3,
}

impl Schema {
    /// The FILE_SCHEMA identifier.
    pub fn header_name(self) -> &'static str {
        match self {
            Schema::Ifc2x3 => "IFC2X3",
            Schema::Ifc4 => "IFC4",
            Schema::Ifc4x3 => "IFC4X3_ADD2",
        }
    }

    pub fn parse(text: &str) -> Result<Schema, SynthError> {
        match text.to_ascii_uppercase().as_str() {
            "IFC2X3" => Ok(Schema::Ifc2x3),
            "IFC4" => Ok(Schema::Ifc4),
            "IFC4X3" | "IFC4X3_ADD2" => Ok(Schema::Ifc4x3),
            _ => Err(SynthError::Parse {
                what: "schema",
                value: text.into(),
                hint: "use IFC4, IFC2X3 or IFC4X3".into(),
            }),
        }
    }

    /// IFC2X3 has no PredefinedType on IfcMember/IfcColumn/IfcBeam/IfcWall.
    pub(super) fn has_element_predefined_type(self) -> bool {
        self != Schema::Ifc2x3
    }
}

/// Which IFC classes framing pieces become.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ProductClasses {
    /// IfcMember typed STUD (vertical), PLATE (plates, sills), MEMBER (headers).
    Member,
    /// IfcColumn studs and IfcBeam plates, headers and sills (what Revit writes).
    ColumnBeam,
}

/// What, if anything, the members of one wall are aggregated into.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Grouping {
    None,
    /// IfcWall (ELEMENTEDWALL in IFC4+) via IfcRelAggregates.
    Wall,
    /// IfcElementAssembly via IfcRelAggregates.
    Assembly,
}

/// What member placements are relative to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlacementBase {
    Storey,
    /// The wall or assembly the member is aggregated into (needs grouping).
    Parent,
}

#[derive(Debug, Clone, PartialEq)]
pub struct WriteOptions {
    pub schema: Schema,
    pub unit: LengthUnit,
    pub products: ProductClasses,
    pub grouping: Grouping,
    /// One product per wall and direction holding every piece as an IfcMappedItem.
    pub mapped: bool,
    /// `None`: relative to the parent when grouped, else to the storey.
    pub placement: Option<PlacementBase>,
    pub seed: u64,
    /// A property set (`Pset_MemberCommon`, …) for every framing product.
    pub property_sets: bool,
    /// For grouped walls: an IfcOpeningElement and an IfcDoor or IfcWindow per rough opening.
    pub openings: bool,
    /// The file name written into FILE_NAME and the truth file (no directories).
    pub file_name: String,
}

impl Default for WriteOptions {
    fn default() -> Self {
        WriteOptions {
            schema: Schema::Ifc4,
            unit: LengthUnit::Metre,
            products: ProductClasses::Member,
            grouping: Grouping::None,
            mapped: false,
            placement: None,
            seed: 20_240_101,
            property_sets: false,
            openings: false,
            file_name: "model.ifc".into(),
        }
    }
}

impl WriteOptions {
    pub(super) fn placement_base(&self) -> Result<PlacementBase, SynthError> {
        match (self.placement, self.grouping) {
            (Some(PlacementBase::Parent), Grouping::None) => Err(SynthError::Options {
                what: "placement relative to the parent needs a parent".into(),
                hint: "add --grouping wall or --grouping assembly, or use --placement storey"
                    .into(),
            }),
            (Some(p), _) => Ok(p),
            (None, Grouping::None) => Ok(PlacementBase::Storey),
            (None, _) => Ok(PlacementBase::Parent),
        }
    }
}

/// The written file and what it holds.
#[derive(Debug, Clone)]
pub struct WrittenModel {
    pub ifc: String,
    pub truth: Truth,
}

/// A product class with its IFC4 predefined type.
#[derive(Clone, Copy)]
pub(super) struct ProductKind {
    pub(super) entity: &'static str,
    pub(super) ifc_type: &'static str,
    pub(super) predefined: &'static str,
}

/// `is_member`: a lying piece that is not a plate (a header or blocking).
pub(super) fn product_kind(
    products: ProductClasses,
    piece_vertical: bool,
    is_member: bool,
) -> ProductKind {
    match (products, piece_vertical) {
        (ProductClasses::Member, true) => ProductKind {
            entity: "IFCMEMBER",
            ifc_type: "IfcMember",
            predefined: "STUD",
        },
        (ProductClasses::Member, false) if is_member => ProductKind {
            entity: "IFCMEMBER",
            ifc_type: "IfcMember",
            predefined: "MEMBER",
        },
        (ProductClasses::Member, false) => ProductKind {
            entity: "IFCMEMBER",
            ifc_type: "IfcMember",
            predefined: "PLATE",
        },
        (ProductClasses::ColumnBeam, true) => ProductKind {
            entity: "IFCCOLUMN",
            ifc_type: "IfcColumn",
            predefined: "COLUMN",
        },
        (ProductClasses::ColumnBeam, false) => ProductKind {
            entity: "IFCBEAM",
            ifc_type: "IfcBeam",
            predefined: "BEAM",
        },
    }
}
