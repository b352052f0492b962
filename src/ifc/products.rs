//! Products → pieces: every IfcMember, IfcColumn, IfcBeam, IfcPlate and
//! IfcBuildingElementProxy (and StandardCase variants) becomes one piece per
//! solid body item, with its parent, container and material.

use super::context::Ctx;
use super::error::{IfcErrorKind, Issue, R, Warning};
use super::limits::{MAX_DISTANCE_FROM_ORIGIN_M, MAX_PIECE_LENGTH_M};
use super::placement::{Iso, Placements};
use super::relations::{Relations, material_name};
use super::schema::{LUMBER_PRODUCTS, display_name};
use super::shape::{self, item_shape, world_box};
use super::units::{LengthUnit, length_unit};
use crate::geom::{OrientedBox, Point3};
use crate::step::{Entity, Record};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// One lumber piece: a solid body item of a product, as a world-frame box.
#[derive(Debug, Clone)]
pub struct Piece {
    /// `GLOBALID` for a one-piece product, `GLOBALID/k` otherwise.
    pub id: String,
    /// The product's entity id (`#id`).
    pub entity: u64,
    /// The representation item the piece comes from.
    pub item: u64,
    pub global_id: String,
    /// Index of the piece within a many-piece product.
    pub piece: Option<usize>,
    pub name: Option<String>,
    /// e.g. `IfcColumn`.
    pub ifc_type: String,
    pub predefined_type: Option<String>,
    pub object_type: Option<String>,
    /// Immediate aggregation parent (an IfcWall, IfcElementAssembly, ...).
    pub parent: Option<u64>,
    /// Spatial container (own, or the nearest aggregating ancestor's).
    pub container: Option<u64>,
    pub material: Option<String>,
    /// World frame, metres; axes longest first.
    pub obox: OrientedBox,
}

impl Piece {
    /// End points of the cross-section centre line: the lower end first for
    /// members steeper than 45°, otherwise the end with smaller x (then y).
    pub fn axis(&self) -> (Point3, Point3) {
        let (a, b) = self.obox.axis_ends();
        let d = b - a;
        let swap = if d.z.abs() > d.xy().norm() {
            d.z < 0.0
        } else if d.x.abs() > 1e-9 {
            d.x < 0.0
        } else {
            d.y < 0.0
        };
        if swap { (b, a) } else { (a, b) }
    }
}

/// A parent or container of pieces (wall, element assembly, storey, ...).
#[derive(Debug, Clone)]
pub struct Group {
    pub entity: u64,
    pub global_id: String,
    pub ifc_type: String,
    pub name: Option<String>,
    pub predefined_type: Option<String>,
    /// Aggregation parent of the group itself.
    pub parent: Option<u64>,
    pub container: Option<u64>,
}

pub(crate) struct Read {
    pub unit: LengthUnit,
    pub pieces: Vec<Piece>,
    pub groups: BTreeMap<u64, Group>,
    pub warnings: Vec<Warning>,
}

/// Products read by one parallel run.
const PRODUCTS_PER_RUN: usize = 512;

/// The pieces and warnings of one run of products.
type Run = (Vec<Piece>, Vec<Warning>);

pub(crate) fn read(mut ctx: Ctx<'_>) -> Result<Read, IfcErrorKind> {
    let unit = match length_unit(&ctx) {
        Ok(unit) => unit,
        Err(Issue::Fatal(kind)) => return Err(kind),
        Err(issue) => {
            ctx.warn(
                None,
                format!(
                    "the length unit cannot be read ({}); lengths are read as metres",
                    issue.describe()
                ),
            );
            LengthUnit::metre()
        }
    };
    ctx.scale = unit.metres_per_unit;
    let relations = Relations::read(&ctx).map_err(fatal)?;
    let mut records: Vec<&Record> = LUMBER_PRODUCTS
        .iter()
        .flat_map(|t| ctx.file.of_type(t))
        .collect();
    records.sort_by_key(|r| r.start);

    // Products are read in parallel runs, each with its own placement cache and warnings;
    // the runs are joined in file order, and the first fatal issue in file order stops the
    // read, as one pass would. Runs have a fixed size, not one that follows the machine's
    // threads: where a run's cache starts matters to a placement chain longer than
    // MAX_CHAIN, and the answer must not depend on the machine.
    let runs: Vec<Result<Run, IfcErrorKind>> = records
        .par_chunks(PRODUCTS_PER_RUN)
        .map(|run| {
            let ctx = Ctx::new(ctx.file, ctx.schema, ctx.scale);
            let mut placements = Placements::default();
            let mut pieces = Vec::new();
            for record in run {
                let product = ctx.file.decode(record).map_err(IfcErrorKind::Step)?;
                match product_pieces(&ctx, &relations, &mut placements, &product) {
                    Ok(found) => pieces.extend(found),
                    Err(Issue::Fatal(kind)) => return Err(kind),
                    Err(issue) => ctx.warn(
                        Some(product.id),
                        format!("{} skipped: {}", describe(&ctx, &product), issue.describe()),
                    ),
                }
            }
            Ok((pieces, ctx.take_warnings()))
        })
        .collect();
    let mut pieces = Vec::new();
    let mut warnings = Vec::new();
    for run in runs {
        let (found, warned) = run?;
        pieces.extend(found);
        warnings.extend(warned);
    }
    let groups = groups_of(&ctx, &relations, &pieces).map_err(fatal)?;
    warnings.extend(ctx.take_warnings());
    warnings.sort();
    warnings.dedup();
    Ok(Read {
        unit,
        pieces,
        groups,
        warnings,
    })
}

fn fatal(issue: Issue) -> IfcErrorKind {
    match issue {
        Issue::Fatal(kind) => kind,
        other => {
            let entity = match &other {
                Issue::Missing { entity, .. }
                | Issue::Invalid { entity, .. }
                | Issue::Degenerate { entity, .. }
                | Issue::Unsupported { entity, .. } => *entity,
                Issue::Fatal(_) => 0,
            };
            IfcErrorKind::Malformed {
                entity,
                line: 0,
                message: other.describe(),
            }
        }
    }
}

/// `IfcColumn #47 'Stud' (2uOC…, line 54)` for messages.
fn describe(ctx: &Ctx<'_>, e: &Entity<'_>) -> String {
    let name = ctx
        .text(e, 2)
        .map(|n| format!(" '{n}'"))
        .unwrap_or_default();
    let gid = ctx.text(e, 0).unwrap_or_default();
    format!(
        "{} #{}{} ({}, line {})",
        display_name(e.type_name),
        e.id,
        name,
        gid,
        ctx.line(e.id)
    )
}

fn product_pieces(
    ctx: &Ctx<'_>,
    rel: &Relations,
    placements: &mut Placements,
    e: &Entity<'_>,
) -> R<Vec<Piece>> {
    let global_id = ctx.text(e, 0).filter(|g| !g.is_empty()).unwrap_or_else(|| {
        ctx.warn(
            Some(e.id),
            format!("#{} has no GlobalId; '#{}' is used as its id", e.id, e.id),
        );
        format!("#{}", e.id)
    });
    let items = match shape::body_items(ctx, e)? {
        None => return Err(no_representation(ctx, rel, e)),
        Some(items) if items.is_empty() => {
            return Err(Issue::invalid(
                e.id,
                "no Body representation with solid geometry",
            ));
        }
        Some(items) => items,
    };
    let placement = match e.get(5).as_ref_id() {
        Some(id) => placements.world(ctx, id, e.id)?,
        None => {
            ctx.warn(
                Some(e.id),
                format!(
                    "{} has no ObjectPlacement; its geometry is taken as world coordinates",
                    describe(ctx, e)
                ),
            );
            Iso::identity()
        }
    };
    let predefined_type = ctx
        .schema
        .predefined_type_index(e.type_name)
        .and_then(|i| e.get(i).as_enum())
        .map(str::to_string);
    let material = rel
        .material
        .get(&e.id)
        .or_else(|| rel.type_object.get(&e.id).and_then(|t| rel.material.get(t)))
        .map(|&m| material_name(ctx, m, e.id, 0))
        .transpose()
        .unwrap_or(None)
        .flatten();
    let ancestors = rel.ancestors(e.id);
    let container = std::iter::once(e.id)
        .chain(ancestors.iter().copied())
        .find_map(|id| rel.container.get(&id).copied());
    let many = items.len() > 1;
    let mut pieces = Vec::with_capacity(items.len());
    for (k, placed) in items.iter().enumerate() {
        let built = ctx.get(placed.item, e.id).and_then(|item| {
            let solid = item_shape(ctx, &item, 0)?;
            world_box(&solid, &placement, &placed.transform, placed.item)
                .and_then(|b| within_limits(b, placed.item))
        });
        let obox = match built {
            Ok(b) => b,
            Err(Issue::Fatal(kind)) => return Err(Issue::Fatal(kind)),
            Err(issue) if !many => return Err(issue),
            Err(issue) => {
                ctx.warn(
                    Some(e.id),
                    format!(
                        "piece {k} of {} skipped: {}",
                        describe(ctx, e),
                        issue.describe()
                    ),
                );
                continue;
            }
        };
        pieces.push(Piece {
            id: if many {
                format!("{global_id}/{k}")
            } else {
                global_id.clone()
            },
            entity: e.id,
            item: placed.item,
            global_id: global_id.clone(),
            piece: many.then_some(k),
            name: ctx.text(e, 2),
            ifc_type: display_name(e.type_name),
            predefined_type: predefined_type.clone(),
            object_type: ctx.text(e, 4),
            parent: ancestors.first().copied(),
            container,
            material: material.clone(),
            obox,
        });
    }
    Ok(pieces)
}

/// A box that is finite, at most `MAX_PIECE_LENGTH_M` long and within
/// `MAX_DISTANCE_FROM_ORIGIN_M` of the origin; anything else is corrupt geometry.
fn within_limits(b: OrientedBox, item: u64) -> R<OrientedBox> {
    let finite = b.centre.iter().all(|c| c.is_finite())
        && b.half.iter().all(|h| h.is_finite())
        && b.axes.iter().flat_map(|a| a.iter()).all(|c| c.is_finite());
    if !finite {
        return Err(Issue::degenerate(
            item,
            "the piece's size or position is not a finite number",
        ));
    }
    let length = 2.0 * b.half[0];
    if length > MAX_PIECE_LENGTH_M {
        return Err(Issue::degenerate(
            item,
            format!(
                "the piece is {length:.3e} m long, more than the {MAX_PIECE_LENGTH_M} m any lumber can be"
            ),
        ));
    }
    let distance = b.centre.coords.norm();
    if distance > MAX_DISTANCE_FROM_ORIGIN_M {
        return Err(Issue::degenerate(
            item,
            format!(
                "the piece lies {distance:.3e} m from the origin, beyond {MAX_DISTANCE_FROM_ORIGIN_M} m"
            ),
        ));
    }
    Ok(b)
}

/// Explains a product without geometry; type templates are named as such.
fn no_representation(ctx: &Ctx<'_>, rel: &Relations, e: &Entity<'_>) -> Issue {
    let template = rel.ancestors(e.id).into_iter().find(|&a| {
        ctx.file.record(a).is_some_and(|r| {
            let t = ctx.file.type_name(r.type_id);
            t.ends_with("TYPE") || t.ends_with("STYLE")
        })
    });
    let message = match template {
        Some(t) => format!(
            "has no representation; it is part of the type object #{t} (a template, not an occurrence in the building)"
        ),
        None => "has no representation (Representation is $), so it cannot be placed".to_string(),
    };
    Issue::invalid(e.id, message)
}

/// Every parent and container of the pieces, with their own ancestors.
fn groups_of(ctx: &Ctx<'_>, rel: &Relations, pieces: &[Piece]) -> R<BTreeMap<u64, Group>> {
    let mut pending: Vec<u64> = pieces
        .iter()
        .flat_map(|p| p.parent.into_iter().chain(p.container))
        .collect();
    let mut groups = BTreeMap::new();
    while let Some(id) = pending.pop() {
        if groups.contains_key(&id) {
            continue;
        }
        let e = match ctx.file.entity(id) {
            Some(Ok(e)) => e,
            Some(Err(step)) => return Err(Issue::Fatal(step.into())),
            None => {
                ctx.warn(
                    Some(id),
                    format!("#{id} is named as a parent or container but is not defined"),
                );
                continue;
            }
        };
        let parent = rel.parent.get(&id).copied();
        let container = rel.container.get(&id).copied();
        pending.extend(parent.into_iter().chain(container));
        let predefined_type = ctx
            .schema
            .predefined_type_index(e.type_name)
            .and_then(|i| e.get(i).as_enum())
            .map(str::to_string);
        groups.insert(
            id,
            Group {
                entity: id,
                global_id: ctx.text(&e, 0).unwrap_or_default(),
                ifc_type: display_name(e.type_name),
                name: ctx.text(&e, 2),
                predefined_type,
                parent,
                container,
            },
        );
    }
    Ok(groups)
}
