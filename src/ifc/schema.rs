//! Schema knowledge: which IFC release a file uses and where the attributes
//! that differ between releases sit.

/// The IFC releases framewright reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Schema {
    #[serde(rename = "IFC2X3")]
    Ifc2x3,
    #[serde(rename = "IFC4")]
    Ifc4,
    #[serde(rename = "IFC4X3")]
    Ifc4x3,
}

impl Schema {
    /// Recognises a FILE_SCHEMA identifier (`IFC2X3_TC1`, `IFC4X3_ADD2`, ...).
    pub fn from_identifier(name: &str) -> Option<Schema> {
        let upper = name.trim().to_ascii_uppercase();
        if upper.starts_with("IFC2X3") {
            Some(Schema::Ifc2x3)
        } else if upper.starts_with("IFC4X3") {
            Some(Schema::Ifc4x3)
        } else if upper == "IFC4"
            || upper.starts_with("IFC4_")
            || upper.starts_with("IFC4X1")
            || upper.starts_with("IFC4X2")
        {
            Some(Schema::Ifc4)
        } else {
            None
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Schema::Ifc2x3 => "IFC2X3",
            Schema::Ifc4 => "IFC4",
            Schema::Ifc4x3 => "IFC4X3",
        }
    }

    /// Index of `PredefinedType` in a product of this (upper-case) type, if any.
    pub fn predefined_type_index(self, type_name: &str) -> Option<usize> {
        match (self, type_name) {
            // IFC2X3 element assemblies have AssemblyPlace, PredefinedType.
            (_, "IFCELEMENTASSEMBLY") => Some(9),
            // In IFC2X3 members, beams, columns and plates carry no PredefinedType,
            // and the proxy's 9th attribute is CompositionType.
            (Schema::Ifc2x3, "IFCWALL" | "IFCWALLSTANDARDCASE") => None,
            (Schema::Ifc2x3, _) => None,
            (_, _) => Some(8),
        }
    }
}

/// Products that can hold lumber pieces.
pub const LUMBER_PRODUCTS: &[&str] = &[
    "IFCMEMBER",
    "IFCMEMBERSTANDARDCASE",
    "IFCCOLUMN",
    "IFCCOLUMNSTANDARDCASE",
    "IFCBEAM",
    "IFCBEAMSTANDARDCASE",
    "IFCPLATE",
    "IFCPLATESTANDARDCASE",
    "IFCBUILDINGELEMENTPROXY",
];

/// The schema's spelling of an upper-case type name, for output.
pub fn display_name(upper: &str) -> String {
    const NAMES: &[&str] = &[
        "IfcMember",
        "IfcMemberStandardCase",
        "IfcColumn",
        "IfcColumnStandardCase",
        "IfcBeam",
        "IfcBeamStandardCase",
        "IfcPlate",
        "IfcPlateStandardCase",
        "IfcBuildingElementProxy",
        "IfcWall",
        "IfcWallStandardCase",
        "IfcWallElementedCase",
        "IfcElementAssembly",
        "IfcCurtainWall",
        "IfcRoof",
        "IfcSlab",
        "IfcStair",
        "IfcRamp",
        "IfcBuildingStorey",
        "IfcBuilding",
        "IfcSite",
        "IfcProject",
        "IfcSpace",
        "IfcElementAssemblyType",
        "IfcWallType",
        "IfcMemberType",
        "IfcBuildingElementPart",
        "IfcCovering",
        "IfcOpeningElement",
        "IfcDoor",
        "IfcWindow",
        "IfcFooting",
        "IfcChimney",
        "IfcShadingDevice",
        "IfcRailing",
        "IfcFacility",
        "IfcFacilityPart",
    ];
    NAMES
        .iter()
        .find(|n| n.eq_ignore_ascii_case(upper))
        .map(|n| n.to_string())
        .unwrap_or_else(|| upper.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identifiers() {
        assert_eq!(Schema::from_identifier("IFC2X3_TC1"), Some(Schema::Ifc2x3));
        assert_eq!(Schema::from_identifier("IFC4"), Some(Schema::Ifc4));
        assert_eq!(Schema::from_identifier("IFC4X3_ADD2"), Some(Schema::Ifc4x3));
        assert_eq!(Schema::from_identifier("IFC9X9"), None);
        assert_eq!(Schema::from_identifier("IFC45"), None);
    }

    #[test]
    fn names() {
        assert_eq!(
            display_name("IFCCOLUMNSTANDARDCASE"),
            "IfcColumnStandardCase"
        );
        assert_eq!(display_name("IFCFOO"), "IFCFOO");
    }
}
