//! Vertices of Breps, surface models and tessellations; the piece is the
//! oriented box of these vertices.

use super::super::context::Ctx;
use super::super::error::{Issue, R};
use super::SolidShape;
use super::profile::coordinate_list;
use crate::step::Entity;
use std::collections::BTreeMap;

pub(crate) fn vertices(ctx: &Ctx<'_>, e: &Entity<'_>) -> R<SolidShape> {
    let points = match e.type_name {
        "IFCTRIANGULATEDFACESET" | "IFCPOLYGONALFACESET" => {
            coordinate_list(ctx, &ctx.follow_required(e, 0, "Coordinates")?)?
        }
        _ => {
            let mut point_ids = BTreeMap::new();
            collect_shell_points(ctx, e, &mut point_ids)?;
            point_ids
                .into_iter()
                .map(|(id, from)| ctx.point(&ctx.get(id, from)?))
                .collect::<R<Vec<_>>>()?
        }
    };
    if points.len() < 4 {
        return Err(Issue::degenerate(
            e.id,
            format!("{} has fewer than 4 vertices", e.type_name),
        ));
    }
    Ok(SolidShape::Points(points))
}

/// Walks shells → faces → bounds → poly loops, gathering point ids (each once,
/// with the loop that refers to it).
fn collect_shell_points(ctx: &Ctx<'_>, e: &Entity<'_>, out: &mut BTreeMap<u64, u64>) -> R<()> {
    let shells: Vec<u64> = match e.type_name {
        "IFCFACETEDBREP" | "IFCFACETEDBREPWITHVOIDS" => ctx.refs(e, 0)?,
        "IFCSHELLBASEDSURFACEMODEL" | "IFCFACEBASEDSURFACEMODEL" => ctx.refs(e, 0)?,
        "IFCCLOSEDSHELL" | "IFCOPENSHELL" | "IFCCONNECTEDFACESET" => vec![e.id],
        other => return Err(Issue::unsupported(e.id, format!("{other} as a Brep"))),
    };
    for shell_id in shells {
        let shell = ctx.get(shell_id, e.id)?;
        for face_id in ctx.refs(&shell, 0)? {
            let face = ctx.get(face_id, shell.id)?;
            for bound_id in ctx.refs(&face, 0)? {
                let bound = ctx.get(bound_id, face.id)?;
                let Some(lp) = ctx.follow(&bound, 0)? else {
                    continue;
                };
                if lp.type_name != "IFCPOLYLOOP" {
                    return Err(Issue::unsupported(
                        lp.id,
                        format!(
                            "{} as a face bound (only IfcPolyLoop is read)",
                            lp.type_name
                        ),
                    ));
                }
                for point in ctx.refs(&lp, 0)? {
                    out.entry(point).or_insert(lp.id);
                }
            }
        }
    }
    Ok(())
}
