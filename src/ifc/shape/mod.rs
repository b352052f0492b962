//! Representations → lumber pieces. Each solid item of a product's Body
//! becomes one oriented box; mapped items are expanded (one product may hold
//! many pieces).

mod boolean;
mod brep;
mod operator;
mod profile;

use super::context::Ctx;
use super::error::{Issue, R};
use super::placement::{Iso, axis2_placement};
use crate::geom::{Affine, OrientedBox, Point3, fit_points};
use crate::step::Entity;

/// A solid in the coordinates of its representation item, in metres.
#[derive(Debug, Clone)]
pub(crate) enum SolidShape {
    /// Local bounds `min..max` placed by `map`; `length` is the local axis
    /// the lumber runs along (an extrusion's direction), when known.
    Box {
        map: Affine,
        min: Point3,
        max: Point3,
        length: Option<usize>,
    },
    /// Vertices of a Brep, tessellation or sheared extrusion.
    Points(Vec<Point3>),
}

/// One representation item with the transform that places it in the product.
#[derive(Debug, Clone)]
pub(crate) struct PlacedItem {
    pub item: u64,
    pub transform: Affine,
}

/// Mapped items nested deeper than this are treated as a cycle.
const MAX_MAP_DEPTH: usize = 16;
/// Boolean and CSG trees deeper than this are refused.
pub(crate) const MAX_TREE_DEPTH: usize = 64;

/// Representation types that describe a solid body.
const SOLID_TYPES: &[&str] = &[
    "SWEPTSOLID",
    "ADVANCEDSWEPTSOLID",
    "BREP",
    "ADVANCEDBREP",
    "CSG",
    "CLIPPING",
    "MAPPEDREPRESENTATION",
    "TESSELLATION",
    "SURFACEMODEL",
    "SOLIDMODEL",
    "BOUNDINGBOX",
];

/// The items of the product's body representation, mapped items expanded.
/// `Ok(None)` when the product has no representation at all.
pub(crate) fn body_items(ctx: &Ctx<'_>, product: &Entity<'_>) -> R<Option<Vec<PlacedItem>>> {
    let Some(shape) = ctx.follow(product, 6)? else {
        return Ok(None);
    };
    let mut body = None;
    let mut fallback = None;
    for rep_id in ctx.refs(&shape, 2)? {
        let rep = match ctx.get(rep_id, shape.id) {
            Ok(rep) => rep,
            Err(Issue::Missing { entity, missing }) => {
                ctx.warn(Some(entity), format!("#{entity} (line {}) lists representation #{missing}, which is not defined; it is ignored", ctx.line(entity)));
                continue;
            }
            Err(other) => return Err(other),
        };
        let identifier = ctx.text(&rep, 1).unwrap_or_default();
        let kind = ctx.text(&rep, 2).unwrap_or_default();
        if identifier.eq_ignore_ascii_case("BODY") && body.is_none() {
            body = Some(rep);
        } else if fallback.is_none() && SOLID_TYPES.iter().any(|t| t.eq_ignore_ascii_case(&kind)) {
            fallback = Some(rep);
        }
    }
    let Some(rep) = body.or(fallback) else {
        return Ok(Some(Vec::new()));
    };
    let mut out = Vec::new();
    let items = ctx.refs(&rep, 3)?;
    let many = items.len() > 1;
    for item in items {
        match expand(ctx, item, rep.id, Affine::identity(), 0, &mut out) {
            Ok(()) => {}
            // One bad item of several (an absurd mapping, say) costs that piece only.
            Err(issue @ (Issue::Invalid { .. } | Issue::Degenerate { .. })) if many => {
                ctx.warn(
                    Some(product.id),
                    format!(
                        "#{item}, a body item of #{} (line {}), skipped: {}",
                        product.id,
                        ctx.line(product.id),
                        issue.describe()
                    ),
                );
            }
            Err(issue) => return Err(issue),
        }
    }
    Ok(Some(out))
}

/// Expands mapped items: the mapped representation's items are placed by
/// `MappingTarget × MappingOrigin`, the composition IfcOpenShell uses.
fn expand(
    ctx: &Ctx<'_>,
    item: u64,
    from: u64,
    transform: Affine,
    depth: usize,
    out: &mut Vec<PlacedItem>,
) -> R<()> {
    let e = ctx.get(item, from)?;
    if e.type_name != "IFCMAPPEDITEM" {
        out.push(PlacedItem { item, transform });
        return Ok(());
    }
    if depth >= MAX_MAP_DEPTH {
        return Err(Issue::invalid(
            item,
            format!("mapped items nested more than {MAX_MAP_DEPTH} deep (a cycle?)"),
        ));
    }
    let source = ctx.follow_required(&e, 0, "MappingSource")?;
    ctx.expect_type(&source, &["IFCREPRESENTATIONMAP"])?;
    let origin = match ctx.follow(&source, 0)? {
        Some(p) => axis2_placement(ctx, &p)?.to_homogeneous(),
        None => Affine::identity(),
    };
    let target = match ctx.follow(&e, 1)? {
        Some(op) => operator::transformation(ctx, &op)?,
        None => Affine::identity(),
    };
    let mapped = ctx.follow_required(&source, 1, "MappedRepresentation")?;
    let placed = transform * target * origin;
    for child in ctx.refs(&mapped, 3)? {
        expand(ctx, child, mapped.id, placed, depth + 1, out)?;
    }
    Ok(())
}

/// The solid of one (non-mapped) representation item, in item coordinates.
pub(crate) fn item_shape(ctx: &Ctx<'_>, e: &Entity<'_>, depth: usize) -> R<SolidShape> {
    if depth > MAX_TREE_DEPTH {
        return Err(Issue::invalid(
            e.id,
            format!("boolean/CSG tree deeper than {MAX_TREE_DEPTH}"),
        ));
    }
    match e.type_name {
        "IFCEXTRUDEDAREASOLID" | "IFCEXTRUDEDAREASOLIDTAPERED" => profile::extrusion(ctx, e),
        "IFCBOOLEANCLIPPINGRESULT" | "IFCBOOLEANRESULT" => boolean::boolean_result(ctx, e, depth),
        "IFCFACETEDBREP"
        | "IFCFACETEDBREPWITHVOIDS"
        | "IFCSHELLBASEDSURFACEMODEL"
        | "IFCFACEBASEDSURFACEMODEL"
        | "IFCTRIANGULATEDFACESET"
        | "IFCPOLYGONALFACESET"
        | "IFCCLOSEDSHELL"
        | "IFCOPENSHELL" => brep::vertices(ctx, e),
        "IFCBOUNDINGBOX" => {
            let corner = ctx.point(&ctx.follow_required(e, 0, "Corner")?)?;
            let (dx, dy, dz) = (
                ctx.length(e, 1, "XDim")?,
                ctx.length(e, 2, "YDim")?,
                ctx.length(e, 3, "ZDim")?,
            );
            Ok(SolidShape::Box {
                map: Affine::identity(),
                min: corner,
                max: corner + nalgebra::Vector3::new(dx, dy, dz),
                length: None,
            })
        }
        "IFCBLOCK" => {
            let map = match ctx.follow(e, 0)? {
                Some(p) => axis2_placement(ctx, &p)?.to_homogeneous(),
                None => Affine::identity(),
            };
            let (x, y, z) = (
                ctx.length(e, 1, "XLength")?,
                ctx.length(e, 2, "YLength")?,
                ctx.length(e, 3, "ZLength")?,
            );
            Ok(SolidShape::Box {
                map,
                min: Point3::origin(),
                max: Point3::new(x, y, z),
                length: None,
            })
        }
        "IFCCSGSOLID" => item_shape(
            ctx,
            &ctx.follow_required(e, 0, "TreeRootExpression")?,
            depth + 1,
        ),
        other => Err(Issue::unsupported(e.id, format!("{other} as a solid"))),
    }
}

/// World box of a shape placed by `placement × transform`.
pub(crate) fn world_box(
    shape: &SolidShape,
    placement: &Iso,
    transform: &Affine,
    item: u64,
) -> R<OrientedBox> {
    let to_world = placement.to_homogeneous() * transform;
    let fitted = match shape {
        SolidShape::Box {
            map,
            min,
            max,
            length,
        } => {
            let full = to_world * map;
            let extent = max - min;
            if extent.iter().any(|e| !crate::geom::above(*e, 1e-9)) {
                return Err(Issue::degenerate(
                    item,
                    format!(
                        "a box dimension is zero ({:.6} x {:.6} x {:.6} m)",
                        extent.x, extent.y, extent.z
                    ),
                ));
            }
            OrientedBox::from_affine_bounds(&full, min, max, *length)
                .or_else(|| fit_points(&box_corners(&full, min, max)))
        }
        SolidShape::Points(points) => {
            let world: Vec<Point3> = points.iter().map(|p| to_world.transform_point(p)).collect();
            fit_points(&world)
        }
    };
    fitted.ok_or_else(|| Issue::degenerate(item, "the solid is flat or empty"))
}

pub(crate) fn box_corners(map: &Affine, min: &Point3, max: &Point3) -> Vec<Point3> {
    (0..8)
        .map(|k| {
            let p = Point3::new(
                if k & 1 == 0 { min.x } else { max.x },
                if k & 2 == 0 { min.y } else { max.y },
                if k & 4 == 0 { min.z } else { max.z },
            );
            map.transform_point(&p)
        })
        .collect()
}
