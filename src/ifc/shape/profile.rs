//! Profiles and extrusions: IfcExtrudedAreaSolid of rectangle, parameterised
//! and arbitrary closed profiles.

use super::super::context::Ctx;
use super::super::error::{Issue, R};
use super::super::placement::axis2_placement;
use super::SolidShape;
use crate::geom::{Affine, Point3, Vector3};
use crate::step::{Entity, Param};

/// A profile in its own plane (z = 0 of the extrusion's position).
enum Profile {
    /// A rectangle `x × y` centred on the origin of `map`.
    Rect { map: Affine, x: f64, y: f64 },
    /// The vertices of a closed curve.
    Polygon(Vec<Point3>),
}

pub(crate) fn extrusion(ctx: &Ctx<'_>, e: &Entity<'_>) -> R<SolidShape> {
    let area = ctx.follow_required(e, 0, "SweptArea")?;
    let profile = profile(ctx, &area, 0)?;
    let position = match ctx.follow(e, 1)? {
        Some(p) => axis2_placement(ctx, &p)?.to_homogeneous(),
        None => Affine::identity(),
    };
    let Some(direction) = ctx.direction_attr(e, 2)? else {
        return Err(Issue::degenerate(
            e.id,
            "ExtrudedDirection is missing or zero",
        ));
    };
    let depth = ctx.length(e, 3, "Depth")?;
    if !crate::geom::above(depth, 0.0) {
        return Err(Issue::degenerate(
            e.id,
            format!("extrusion Depth is {depth} (must be > 0)"),
        ));
    }
    if direction.z.abs() < 1e-9 {
        return Err(Issue::degenerate(
            e.id,
            "ExtrudedDirection lies in the profile plane",
        ));
    }
    let sweep = direction * depth;
    match profile {
        Profile::Rect { map, x, y } if direction.x.abs() < 1e-12 && direction.y.abs() < 1e-12 => {
            let (z0, z1) = if sweep.z > 0.0 {
                (0.0, sweep.z)
            } else {
                (sweep.z, 0.0)
            };
            Ok(SolidShape::Box {
                map: position * map,
                min: Point3::new(-x / 2.0, -y / 2.0, z0),
                max: Point3::new(x / 2.0, y / 2.0, z1),
                length: Some(2),
            })
        }
        Profile::Rect { map, x, y } => {
            let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(sx, sy)| map.transform_point(&Point3::new(sx * x / 2.0, sy * y / 2.0, 0.0)));
            Ok(SolidShape::Points(swept(&position, &corners, &sweep)))
        }
        Profile::Polygon(points) => Ok(SolidShape::Points(swept(&position, &points, &sweep))),
    }
}

fn swept(position: &Affine, base: &[Point3], sweep: &Vector3) -> Vec<Point3> {
    base.iter()
        .flat_map(|p| [*p, p + sweep])
        .map(|p| position.transform_point(&p))
        .collect()
}

fn profile(ctx: &Ctx<'_>, e: &Entity<'_>, depth: usize) -> R<Profile> {
    let position = || -> R<Affine> {
        Ok(match ctx.follow(e, 2)? {
            Some(p) => axis2_placement(ctx, &p)?.to_homogeneous(),
            None => Affine::identity(),
        })
    };
    // (x, y) attribute indices of the bounding rectangle of parameterised profiles.
    let dims = match e.type_name {
        "IFCRECTANGLEPROFILEDEF"
        | "IFCROUNDEDRECTANGLEPROFILEDEF"
        | "IFCRECTANGLEHOLLOWPROFILEDEF"
        | "IFCISHAPEPROFILEDEF"
        | "IFCASYMMETRICISHAPEPROFILEDEF" => Some((3, 4)),
        "IFCLSHAPEPROFILEDEF"
        | "IFCUSHAPEPROFILEDEF"
        | "IFCTSHAPEPROFILEDEF"
        | "IFCCSHAPEPROFILEDEF"
        | "IFCZSHAPEPROFILEDEF" => Some((4, 3)),
        _ => None,
    };
    if let Some((xi, yi)) = dims {
        let x = ctx.length(e, xi, "profile width")?;
        let y = ctx.length(e, yi, "profile depth")?;
        if !(crate::geom::above(x, 0.0) && crate::geom::above(y, 0.0)) {
            return Err(Issue::degenerate(
                e.id,
                format!("profile dimensions {x} x {y} m are not positive"),
            ));
        }
        return Ok(Profile::Rect {
            map: position()?,
            x,
            y,
        });
    }
    match e.type_name {
        "IFCCIRCLEPROFILEDEF" | "IFCCIRCLEHOLLOWPROFILEDEF" => {
            let r = ctx.length(e, 3, "Radius")?;
            if !crate::geom::above(r, 0.0) {
                return Err(Issue::degenerate(e.id, "circle radius is not positive"));
            }
            Ok(Profile::Rect {
                map: position()?,
                x: 2.0 * r,
                y: 2.0 * r,
            })
        }
        "IFCARBITRARYCLOSEDPROFILEDEF" | "IFCARBITRARYPROFILEDEFWITHVOIDS" => {
            let curve = ctx.follow_required(e, 2, "OuterCurve")?;
            let points = curve_points(ctx, &curve)?;
            if points.len() < 3 {
                return Err(Issue::degenerate(
                    e.id,
                    "the outer curve has fewer than 3 points",
                ));
            }
            Ok(Profile::Polygon(points))
        }
        "IFCDERIVEDPROFILEDEF" if depth < 8 => {
            let parent = profile(ctx, &ctx.follow_required(e, 2, "ParentProfile")?, depth + 1)?;
            let op = super::operator::transformation(ctx, &ctx.follow_required(e, 3, "Operator")?)?;
            Ok(match parent {
                Profile::Rect { map, x, y } => Profile::Rect {
                    map: op * map,
                    x,
                    y,
                },
                Profile::Polygon(points) => {
                    Profile::Polygon(points.iter().map(|p| op.transform_point(p)).collect())
                }
            })
        }
        other => Err(Issue::unsupported(e.id, format!("profile {other}"))),
    }
}

/// Vertices of a polyline or indexed poly curve (arcs are approximated by their points).
fn curve_points(ctx: &Ctx<'_>, curve: &Entity<'_>) -> R<Vec<Point3>> {
    match curve.type_name {
        "IFCPOLYLINE" => ctx
            .refs(curve, 0)?
            .into_iter()
            .map(|id| ctx.point(&ctx.get(id, curve.id)?))
            .collect(),
        "IFCINDEXEDPOLYCURVE" => {
            let list = ctx.follow_required(curve, 0, "Points")?;
            coordinate_list(ctx, &list)
        }
        other => Err(Issue::unsupported(
            curve.id,
            format!("profile curve {other}"),
        )),
    }
}

/// Points of an IfcCartesianPointList2D/3D, in metres.
pub(crate) fn coordinate_list(ctx: &Ctx<'_>, list: &Entity<'_>) -> R<Vec<Point3>> {
    ctx.expect_type(
        list,
        &["IFCCARTESIANPOINTLIST2D", "IFCCARTESIANPOINTLIST3D"],
    )?;
    let rows = list
        .get(0)
        .as_list()
        .ok_or_else(|| Issue::invalid(list.id, "CoordList is not a list"))?;
    rows.iter()
        .map(|row| {
            let coords: Vec<f64> = match row {
                Param::List(c) => c.iter().filter_map(Param::as_f64).collect(),
                _ => Vec::new(),
            };
            if coords.len() < 2 || coords.len() > 3 || coords.iter().any(|c| !c.is_finite()) {
                return Err(Issue::invalid(
                    list.id,
                    "a coordinate row is not 2 or 3 numbers",
                ));
            }
            let z = coords.get(2).copied().unwrap_or(0.0);
            Ok(Point3::new(coords[0], coords[1], z) * ctx.scale)
        })
        .collect()
}
