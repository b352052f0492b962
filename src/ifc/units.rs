//! The project's length unit: SI units with prefixes and conversion-based
//! units (FOOT, INCH, ...). Everything inside framewright is in metres.

use super::context::Ctx;
use super::error::R;
use crate::step::{Entity, Param};
use serde::Serialize;

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LengthUnit {
    /// e.g. `METRE`, `MILLIMETRE`, `FOOT`, `INCH`.
    pub name: String,
    pub metres_per_unit: f64,
}

impl LengthUnit {
    pub fn metre() -> Self {
        LengthUnit {
            name: "METRE".into(),
            metres_per_unit: 1.0,
        }
    }
}

fn prefix_factor(prefix: &str) -> Option<f64> {
    Some(match prefix {
        "EXA" => 1e18,
        "PETA" => 1e15,
        "TERA" => 1e12,
        "GIGA" => 1e9,
        "MEGA" => 1e6,
        "KILO" => 1e3,
        "HECTO" => 1e2,
        "DECA" => 1e1,
        "DECI" => 1e-1,
        "CENTI" => 1e-2,
        "MILLI" => 1e-3,
        "MICRO" => 1e-6,
        "NANO" => 1e-9,
        "PICO" => 1e-12,
        "FEMTO" => 1e-15,
        "ATTO" => 1e-18,
        _ => return None,
    })
}

/// Well-known conversion units, used when a file gives a name but no usable factor.
fn known_conversion(name: &str) -> Option<f64> {
    match name.to_ascii_uppercase().as_str() {
        "INCH" | "IN" => Some(0.0254),
        "FOOT" | "FT" => Some(0.3048),
        "YARD" => Some(0.9144),
        "MILE" => Some(1609.344),
        _ => None,
    }
}

/// Finds the length unit of the first IfcProject; metres (with a warning)
/// when the file does not say.
pub(crate) fn length_unit(ctx: &Ctx<'_>) -> R<LengthUnit> {
    let mut projects = ctx.file.of_type("IFCPROJECT");
    let Some(project) = projects.next() else {
        ctx.warn(
            None,
            "the file has no IfcProject, so no unit assignment: lengths are read as metres",
        );
        return Ok(LengthUnit::metre());
    };
    if projects.next().is_some() {
        ctx.warn(
            Some(project.id),
            "the file has more than one IfcProject; the units of the first are used",
        );
    }
    let project = ctx
        .file
        .decode(project)
        .map_err(|e| super::error::Issue::Fatal(e.into()))?;
    let Some(assignment) = ctx.follow(&project, 8)? else {
        ctx.warn(
            Some(project.id),
            format!(
                "IfcProject #{} has no UnitsInContext: lengths are read as metres",
                project.id
            ),
        );
        return Ok(LengthUnit::metre());
    };
    for unit_id in ctx.refs(&assignment, 0)? {
        let unit = ctx.get(unit_id, assignment.id)?;
        if unit.get(1).as_enum() == Some("LENGTHUNIT")
            && let Some(found) = unit_value(ctx, &unit, 0)?
        {
            return Ok(found);
        }
    }
    ctx.warn(
        Some(assignment.id),
        format!(
            "IfcUnitAssignment #{} has no length unit: lengths are read as metres",
            assignment.id
        ),
    );
    Ok(LengthUnit::metre())
}

/// Metres per unit of an IfcSIUnit or conversion-based unit (recursion bounded).
fn unit_value(ctx: &Ctx<'_>, unit: &Entity<'_>, depth: usize) -> R<Option<LengthUnit>> {
    if depth > 8 {
        return Ok(None);
    }
    match unit.type_name {
        "IFCSIUNIT" => {
            let prefix = unit.get(2).as_enum();
            let name = unit.get(3).as_enum().unwrap_or("");
            let factor = match prefix {
                None => 1.0,
                Some(p) => match prefix_factor(p) {
                    Some(f) => f,
                    None => {
                        ctx.warn(
                            Some(unit.id),
                            format!("#{}: unknown SI prefix .{p}. ignored", unit.id),
                        );
                        1.0
                    }
                },
            };
            if name != "METRE" {
                ctx.warn(
                    Some(unit.id),
                    format!(
                        "#{}: length unit .{name}. is not METRE; read as metres",
                        unit.id
                    ),
                );
            }
            Ok(Some(LengthUnit {
                name: format!("{}{}", prefix.unwrap_or(""), name),
                metres_per_unit: factor,
            }))
        }
        "IFCCONVERSIONBASEDUNIT" | "IFCCONVERSIONBASEDUNITWITHOFFSET" => {
            let name = ctx.text(unit, 2).unwrap_or_default();
            let from_measure = match ctx.follow(unit, 3)? {
                Some(measure) => measure_value(ctx, &measure, depth)?,
                None => None,
            };
            let factor = match (from_measure, known_conversion(&name)) {
                (Some(f), Some(known)) if (f - known).abs() > known * 1e-6 => {
                    ctx.warn(Some(unit.id), format!("#{}: unit '{name}' converts with {f} m, not the usual {known} m; the file's factor is used", unit.id));
                    f
                }
                (Some(f), _) => f,
                (None, Some(known)) => {
                    ctx.warn(
                        Some(unit.id),
                        format!(
                            "#{}: unit '{name}' has no usable conversion factor; {known} m is used",
                            unit.id
                        ),
                    );
                    known
                }
                (None, None) => {
                    ctx.warn(Some(unit.id), format!("#{}: unit '{name}' has no usable conversion factor; lengths are read as metres", unit.id));
                    1.0
                }
            };
            Ok(Some(LengthUnit {
                name: name.to_ascii_uppercase(),
                metres_per_unit: factor,
            }))
        }
        _ => Ok(None),
    }
}

/// Value × unit of an IfcMeasureWithUnit, in metres.
fn measure_value(ctx: &Ctx<'_>, measure: &Entity<'_>, depth: usize) -> R<Option<f64>> {
    let value = match measure.get(0) {
        p @ (Param::Typed(..) | Param::Real(_) | Param::Int(_)) => p.as_f64(),
        _ => None,
    };
    let Some(value) = value.filter(|v| v.is_finite() && *v > 0.0) else {
        return Ok(None);
    };
    let base = match ctx.follow(measure, 1)? {
        Some(u) => unit_value(ctx, &u, depth + 1)?.map(|u| u.metres_per_unit),
        None => Some(1.0),
    };
    Ok(base.map(|b| value * b))
}
