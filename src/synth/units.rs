//! Inch-based lumber facts (the only place inches appear) and file length units.
use crate::synth::SynthError;

/// Metres per inch, exact by definition.
pub const INCH: f64 = 0.0254;
/// Metres per foot, exact by definition.
pub const FOOT: f64 = 0.3048;

/// Convert inches to metres.
pub fn inches(x: f64) -> f64 {
    x * INCH
}

/// Convert feet to metres.
pub fn feet(x: f64) -> f64 {
    x * FOOT
}

/// A dressed lumber size: nominal name and actual cross-section in metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lumber {
    pub nominal: &'static str,
    /// Smaller cross-section dimension (1.5 in for all 2x sizes).
    pub thickness: f64,
    /// Larger cross-section dimension.
    pub width: f64,
}

impl Lumber {
    pub const L2X4: Lumber = Lumber {
        nominal: "2x4",
        thickness: 1.5 * INCH,
        width: 3.5 * INCH,
    };
    pub const L2X6: Lumber = Lumber {
        nominal: "2x6",
        thickness: 1.5 * INCH,
        width: 5.5 * INCH,
    };
    pub const L2X8: Lumber = Lumber {
        nominal: "2x8",
        thickness: 1.5 * INCH,
        width: 7.25 * INCH,
    };
    pub const L2X10: Lumber = Lumber {
        nominal: "2x10",
        thickness: 1.5 * INCH,
        width: 9.25 * INCH,
    };
    pub const L2X12: Lumber = Lumber {
        nominal: "2x12",
        thickness: 1.5 * INCH,
        width: 11.25 * INCH,
    };

    /// Wall lumber by nominal name (the sizes a wall can be framed with).
    pub fn parse_wall(name: &str) -> Result<Lumber, SynthError> {
        match name {
            "2x4" => Ok(Lumber::L2X4),
            "2x6" => Ok(Lumber::L2X6),
            _ => Err(SynthError::Parse {
                what: "lumber size",
                value: name.to_string(),
                hint: "use 2x4 or 2x6".into(),
            }),
        }
    }
}

/// The length unit a file is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum LengthUnit {
    Metre,
    Millimetre,
    Foot,
    Inch,
}

impl LengthUnit {
    pub fn metres_per_unit(self) -> f64 {
        match self {
            LengthUnit::Metre => 1.0,
            LengthUnit::Millimetre => 0.001,
            LengthUnit::Foot => FOOT,
            LengthUnit::Inch => INCH,
        }
    }

    /// Name as recorded in truth files (IFC unit name).
    pub fn ifc_name(self) -> &'static str {
        match self {
            LengthUnit::Metre => "METRE",
            LengthUnit::Millimetre => "MILLIMETRE",
            LengthUnit::Foot => "FOOT",
            LengthUnit::Inch => "INCH",
        }
    }

    /// How the unit is declared in IFC.
    pub fn ifc_kind(self) -> &'static str {
        match self {
            LengthUnit::Metre | LengthUnit::Millimetre => "IfcSIUnit",
            LengthUnit::Foot | LengthUnit::Inch => "IfcConversionBasedUnit",
        }
    }

    /// Command-line spelling: m, mm, ft, in.
    pub fn parse(text: &str) -> Result<LengthUnit, SynthError> {
        match text {
            "m" => Ok(LengthUnit::Metre),
            "mm" => Ok(LengthUnit::Millimetre),
            "ft" => Ok(LengthUnit::Foot),
            "in" => Ok(LengthUnit::Inch),
            _ => Err(SynthError::Parse {
                what: "length unit",
                value: text.to_string(),
                hint: "use m, mm, ft or in".into(),
            }),
        }
    }
}

/// Read a length such as `3.6576`, `3.6576m`, `3657.6mm`, `12ft`, `144in` as metres
/// (plain numbers are metres).
pub fn parse_length(text: &str) -> Result<f64, SynthError> {
    let t = text.trim();
    let (number, factor) = if let Some(n) = t.strip_suffix("mm") {
        (n, 0.001)
    } else if let Some(n) = t.strip_suffix("ft") {
        (n, FOOT)
    } else if let Some(n) = t.strip_suffix("in") {
        (n, INCH)
    } else if let Some(n) = t.strip_suffix('m') {
        (n, 1.0)
    } else {
        (t, 1.0)
    };
    match number.trim().parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v * factor),
        _ => Err(SynthError::Parse {
            what: "length",
            value: text.to_string(),
            hint: "write a number with an optional unit: 3.2, 3.2m, 3200mm, 10.5ft, 126in".into(),
        }),
    }
}
