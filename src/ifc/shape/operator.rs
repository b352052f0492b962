//! IfcCartesianTransformationOperator (2D/3D, uniform and non-uniform) as an
//! affine map, following the schema's base-axis rules.

use super::super::context::Ctx;
use super::super::error::{Issue, R};
use super::super::limits::MAX_OPERATOR_SCALE;
use super::super::placement::frame;
use crate::geom::{Affine, Point3, Vector3};
use crate::step::Entity;
use nalgebra::Matrix3;

/// The operator as a 4×4 affine map (translation in metres, scales unitless).
pub(crate) fn transformation(ctx: &Ctx<'_>, e: &Entity<'_>) -> R<Affine> {
    let three_d = match e.type_name {
        "IFCCARTESIANTRANSFORMATIONOPERATOR3D"
        | "IFCCARTESIANTRANSFORMATIONOPERATOR3DNONUNIFORM" => true,
        "IFCCARTESIANTRANSFORMATIONOPERATOR2D"
        | "IFCCARTESIANTRANSFORMATIONOPERATOR2DNONUNIFORM" => false,
        other => {
            return Err(Issue::unsupported(
                e.id,
                format!("{other} as a mapping target"),
            ));
        }
    };
    let axis1 = ctx.direction_attr(e, 0)?;
    let axis2 = ctx.direction_attr(e, 1)?;
    let origin = match ctx.follow(e, 2)? {
        Some(p) => ctx.point(&p)?,
        None => Point3::origin(),
    };
    let scale = optional_number(ctx, e, 3)?.unwrap_or(1.0);
    let (axis3, scale2, scale3) = match e.type_name {
        "IFCCARTESIANTRANSFORMATIONOPERATOR3D" => (ctx.direction_attr(e, 4)?, scale, scale),
        "IFCCARTESIANTRANSFORMATIONOPERATOR3DNONUNIFORM" => (
            ctx.direction_attr(e, 4)?,
            optional_number(ctx, e, 5)?.unwrap_or(scale),
            optional_number(ctx, e, 6)?.unwrap_or(scale),
        ),
        "IFCCARTESIANTRANSFORMATIONOPERATOR2DNONUNIFORM" => {
            (None, optional_number(ctx, e, 4)?.unwrap_or(scale), 1.0)
        }
        _ => (None, scale, 1.0),
    };
    for s in [scale, scale2, scale3] {
        if !crate::geom::above(s, 0.0) {
            return Err(Issue::degenerate(
                e.id,
                format!("scale factor {s} is not positive"),
            ));
        }
        if s > MAX_OPERATOR_SCALE {
            return Err(Issue::degenerate(
                e.id,
                format!(
                    "scale factor {s:e} is absurd (above {MAX_OPERATOR_SCALE}); the file is probably corrupt"
                ),
            ));
        }
    }
    let basis = base_axes(three_d, axis1, axis2, axis3);
    let scaled = Matrix3::from_columns(&[
        basis.column(0) * scale,
        basis.column(1) * scale2,
        basis.column(2) * scale3,
    ]);
    let mut m = Affine::identity();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(&scaled);
    m.fixed_view_mut::<3, 1>(0, 3).copy_from(&origin.coords);
    Ok(m)
}

fn optional_number(ctx: &Ctx<'_>, e: &Entity<'_>, i: usize) -> R<Option<f64>> {
    if e.get(i).is_null() {
        Ok(None)
    } else {
        ctx.number(e, i, "a scale factor").map(Some)
    }
}

/// Orthonormal axes from the operator's (optional) axes: z from Axis3, x from
/// Axis1 projected, y completing the frame (the IfcBaseAxis rule).
fn base_axes(
    three_d: bool,
    axis1: Option<Vector3>,
    axis2: Option<Vector3>,
    axis3: Option<Vector3>,
) -> Matrix3<f64> {
    if !three_d {
        let x = axis1
            .map(|a| Vector3::new(a.x, a.y, 0.0))
            .filter(|a| a.norm() > 1e-9);
        return frame(None, x);
    }
    let z = axis3;
    // Without Axis3 the schema derives z from Axis1 × Axis2 when both are given.
    let z = z.or_else(|| match (axis1, axis2) {
        (Some(a), Some(b)) if a.cross(&b).norm() > 1e-9 => Some(a.cross(&b).normalize()),
        _ => None,
    });
    frame(z, axis1)
}
