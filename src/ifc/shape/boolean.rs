//! Boolean results. Clipping by half-spaces (how timber tools cut member
//! ends) is applied to the first operand's box where it is cheap and exact;
//! other booleans keep the first operand, which bounds the result.

use super::super::context::Ctx;
use super::super::error::{Issue, R};
use super::super::placement::axis2_placement;
use super::{SolidShape, box_corners, item_shape};
use crate::geom::{Affine, Point3, Vector3, fit_points};
use crate::step::Entity;

pub(crate) fn boolean_result(ctx: &Ctx<'_>, e: &Entity<'_>, depth: usize) -> R<SolidShape> {
    let operator = e.get(0).as_enum().unwrap_or("");
    let first = item_shape(ctx, &ctx.follow_required(e, 1, "FirstOperand")?, depth + 1)?;
    let second = ctx.follow_required(e, 2, "SecondOperand")?;
    match (operator, second.type_name) {
        ("DIFFERENCE", "IFCHALFSPACESOLID" | "IFCBOXEDHALFSPACE") => {
            let plane = half_space_plane(ctx, &second)?;
            clip(&first, &plane, e.id)
        }
        ("DIFFERENCE", "IFCPOLYGONALBOUNDEDHALFSPACE") => {
            let plane = half_space_plane(ctx, &second)?;
            if inside_boundary(ctx, &second, &first)? {
                clip(&first, &plane, e.id)
            } else {
                Ok(first)
            }
        }
        ("UNION", _) => {
            let other = item_shape(ctx, &second, depth + 1)?;
            let mut points = vertices(&first);
            points.extend(vertices(&other));
            Ok(SolidShape::Points(points))
        }
        // A difference with a solid, or an intersection, lies inside the first operand.
        _ => Ok(first),
    }
}

/// A plane `normal · (p - point) = 0` with the side that is removed.
struct Plane {
    point: Point3,
    normal: Vector3,
    /// True when the removed half-space lies on the negative side of `normal`.
    removes_below: bool,
}

fn half_space_plane(ctx: &Ctx<'_>, half: &Entity<'_>) -> R<Plane> {
    let surface = ctx.follow_required(half, 0, "BaseSurface")?;
    ctx.expect_type(&surface, &["IFCPLANE"])?;
    let position = axis2_placement(ctx, &ctx.follow_required(&surface, 0, "Position")?)?;
    // AgreementFlag TRUE: the normal points away from the half-space's material,
    // so the material (what a DIFFERENCE removes) lies below the plane.
    let agreement = half.get(1).as_enum().unwrap_or("T");
    Ok(Plane {
        point: Point3::from(position.translation.vector),
        normal: position.rotation * Vector3::z(),
        removes_below: agreement == "T",
    })
}

/// Whether every vertex of the solid lies inside the prism of a polygonal boundary.
fn inside_boundary(ctx: &Ctx<'_>, half: &Entity<'_>, solid: &SolidShape) -> R<bool> {
    let position = axis2_placement(ctx, &ctx.follow_required(half, 2, "Position")?)?;
    let boundary = ctx.follow_required(half, 3, "PolygonalBoundary")?;
    let polygon: Vec<Point3> = match boundary.type_name {
        "IFCPOLYLINE" => ctx
            .refs(&boundary, 0)?
            .into_iter()
            .map(|id| ctx.point(&ctx.get(id, boundary.id)?))
            .collect::<R<_>>()?,
        "IFCINDEXEDPOLYCURVE" => {
            super::profile::coordinate_list(ctx, &ctx.follow_required(&boundary, 0, "Points")?)?
        }
        _ => return Ok(false),
    };
    let inverse = position.inverse();
    Ok(vertices(solid).iter().all(|p| {
        let local = inverse * p;
        point_in_polygon(local.x, local.y, &polygon)
    }))
}

fn point_in_polygon(x: f64, y: f64, polygon: &[Point3]) -> bool {
    let mut inside = false;
    let n = polygon.len();
    for i in 0..n {
        let (a, b) = (polygon[i], polygon[(i + n - 1) % n]);
        if (a.y > y) != (b.y > y) && x < (b.x - a.x) * (y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
    }
    inside
}

fn vertices(shape: &SolidShape) -> Vec<Point3> {
    match shape {
        SolidShape::Box { map, min, max, .. } => box_corners(map, min, max),
        SolidShape::Points(p) => p.clone(),
    }
}

/// Removes the part of the solid in the plane's removed half-space and
/// returns the bounds of what is left, in the solid's own frame.
fn clip(shape: &SolidShape, plane: &Plane, boolean: u64) -> R<SolidShape> {
    let (map, min, max, length) = match shape {
        SolidShape::Box {
            map,
            min,
            max,
            length,
        } => (*map, *min, *max, *length),
        SolidShape::Points(points) => {
            let fitted = fit_points(points)
                .ok_or_else(|| Issue::degenerate(boolean, "the first operand is flat"))?;
            let mut map = Affine::identity();
            for i in 0..3 {
                map.fixed_view_mut::<3, 1>(0, i).copy_from(&fitted.axes[i]);
            }
            map.fixed_view_mut::<3, 1>(0, 3)
                .copy_from(&fitted.centre.coords);
            let h = fitted.half;
            (
                map,
                Point3::new(-h[0], -h[1], -h[2]),
                Point3::new(h[0], h[1], h[2]),
                Some(0),
            )
        }
    };
    let corners = box_corners(&map, &min, &max);
    let sign = if plane.removes_below { 1.0 } else { -1.0 };
    let kept_side = |p: &Point3| sign * plane.normal.dot(&(p - plane.point));
    let mut kept: Vec<Point3> = Vec::new();
    let tolerance = 1e-9;
    for (i, a) in corners.iter().enumerate() {
        let da = kept_side(a);
        if da >= -tolerance {
            kept.push(*a);
        }
        // Box edges join corners whose indices differ in one bit.
        for bit in [1, 2, 4] {
            let j = i ^ bit;
            if j > i {
                let b = &corners[j];
                let db = kept_side(b);
                if (da > tolerance && db < -tolerance) || (da < -tolerance && db > tolerance) {
                    kept.push(a + (b - a) * (da / (da - db)));
                }
            }
        }
    }
    if kept.len() < 4 {
        return Err(Issue::degenerate(
            boolean,
            "clipping removes the whole solid",
        ));
    }
    let Some(inverse) = map.try_inverse() else {
        return Err(Issue::degenerate(
            boolean,
            "the first operand has no volume",
        ));
    };
    let mut lo = Point3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut hi = Point3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
    for p in &kept {
        let local = inverse.transform_point(p);
        for k in 0..3 {
            lo[k] = lo[k].min(local[k]);
            hi[k] = hi[k].max(local[k]);
        }
    }
    Ok(SolidShape::Box {
        map,
        min: lo,
        max: hi,
        length,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn clipping_shortens_a_box() {
        let shape = SolidShape::Box {
            map: Affine::identity(),
            min: Point3::origin(),
            max: Point3::new(2.0, 0.1, 0.05),
            length: Some(0),
        };
        // Remove x > 1.5: normal +x, material above the plane (AgreementFlag false).
        let plane = Plane {
            point: Point3::new(1.5, 0.0, 0.0),
            normal: Vector3::x(),
            removes_below: false,
        };
        match clip(&shape, &plane, 1).unwrap() {
            SolidShape::Box { max, min, .. } => {
                assert!((max.x - 1.5).abs() < 1e-12 && min.x == 0.0);
            }
            other => panic!("{other:?}"),
        }
        let everything = Plane {
            point: Point3::new(5.0, 0.0, 0.0),
            normal: Vector3::x(),
            removes_below: true,
        };
        assert!(clip(&shape, &everything, 1).is_err());
    }

    #[test]
    fn polygon_test() {
        let square = [
            Point3::new(0., 0., 0.),
            Point3::new(1., 0., 0.),
            Point3::new(1., 1., 0.),
            Point3::new(0., 1., 0.),
        ];
        assert!(point_in_polygon(0.5, 0.5, &square));
        assert!(!point_in_polygon(1.5, 0.5, &square));
    }
}
