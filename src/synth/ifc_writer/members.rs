//! A wall's framing products: one extruded product per piece, or two mapped-item products
//! per wall, placed relative to the storey or the wall's parent.
use super::ctx::{Ctx, snap, wall_local_dir};
use super::options::{PlacementBase, ProductKind, Schema, product_kind};
use super::truth_rows::{PlaceNames, truth_member};
use crate::step::text::{Real, Ref, RefList, string};
use crate::synth::layout::{Piece, Vec3, WallLayout};
use crate::synth::truth::TruthMember;

/// Where a wall's products are placed.
pub(super) struct WallPlacement<'a> {
    pub(super) wall: &'a WallLayout,
    /// World position of the storey's placement.
    pub(super) storey_origin: Vec3,
    pub(super) storey_lp: Ref,
    pub(super) parent_lp: Option<Ref>,
    pub(super) base: PlacementBase,
}

impl WallPlacement<'_> {
    /// A wall-aligned placement (x = u, y = -w, z = v) at world point `p`.
    fn at(&self, ctx: &mut Ctx, p: Vec3) -> Ref {
        let f = &self.wall.frame;
        match (self.base, self.parent_lp) {
            (PlacementBase::Parent, Some(parent)) => {
                let d = p - f.origin;
                let local = snap_point(Vec3::new(d.dot(&f.u), -d.dot(&f.w), d.dot(&f.v)));
                let a2p = ctx.placement3d(local, Vec3::z(), Vec3::x());
                ctx.local_placement(Some(parent), a2p)
            }
            _ => {
                let a2p = ctx.placement3d(snap_point(p - self.storey_origin), f.v, f.u);
                ctx.local_placement(Some(self.storey_lp), a2p)
            }
        }
    }
}

/// Round to 1e-12 m so -0 and float dust do not reach the file.
fn snap_point(v: Vec3) -> Vec3 {
    snap(v)
}

fn product_line(schema: Schema, kind: ProductKind, head: &str) -> String {
    if schema.has_element_predefined_type() {
        format!("{head},.{}.", kind.predefined)
    } else {
        head.to_string()
    }
}

/// One product per piece, each an extruded rectangle.
pub(super) fn write_piece_products(
    ctx: &mut Ctx,
    place: &WallPlacement,
    b: &PlaceNames,
    parent_gid: Option<String>,
    members: &mut Vec<TruthMember>,
) -> Vec<Ref> {
    let wall = place.wall;
    let mut out = Vec::with_capacity(wall.pieces.len());
    for (k, piece) in wall.pieces.iter().enumerate() {
        let vertical = piece.upright;
        let kind = product_kind(
            ctx.opts.products,
            vertical,
            matches!(
                piece.role,
                crate::synth::layout::Role::Header | crate::synth::layout::Role::Blocking
            ),
        );
        let lp = place.at(ctx, piece.start);
        // Vertical pieces extrude along the placement's z with default axes; the
        // profile's x is then whichever section side runs along u.
        let solid_pos;
        let (x_dim, y_dim);
        let along_u = wall_local_dir(wall, piece.width_dir)[0].abs() > 0.5;
        if vertical {
            solid_pos = ctx.identity;
            (x_dim, y_dim) = if along_u {
                (piece.width, piece.thickness)
            } else {
                (piece.thickness, piece.width)
            };
        } else {
            let axis = wall_local_dir(wall, piece.axis());
            let ref_dir = wall_local_dir(wall, piece.width_dir);
            solid_pos = ctx.placement3d(Vec3::zeros(), axis, ref_dir);
            (x_dim, y_dim) = (piece.width, piece.thickness);
        }
        let profile = ctx.profile(x_dim, y_dim);
        let z = ctx.dir(Vec3::z());
        let solid = ctx.w.add(
            "IFCEXTRUDEDAREASOLID",
            format_args!(
                "{profile},{solid_pos},{z},{}",
                Real(piece.length() * ctx.scale)
            ),
        );
        let rep = ctx.w.add(
            "IFCSHAPEREPRESENTATION",
            format_args!("{},'Body','SweptSolid',({solid})", ctx.body),
        );
        let shape = ctx
            .w
            .add("IFCPRODUCTDEFINITIONSHAPE", format_args!("$,$,({rep})"));
        let key = format!("piece:{}:{k}", wall.id);
        let gid = ctx.gid(&key);
        let name = piece_name(wall, piece, k);
        let tag = format!("{}-{:03}", wall.id, k + 1);
        let head = format!(
            "{},{},$,{},{lp},{shape},{}",
            ctx.owner_args(&key),
            string(&name),
            string(&format!("{} SPF", piece.nominal)),
            string(&tag)
        );
        out.push(
            ctx.w
                .add(kind.entity, product_line(ctx.opts.schema, kind, &head)),
        );
        members.push(truth_member(
            gid,
            name,
            kind,
            ctx.opts.schema,
            wall,
            b,
            parent_gid.clone(),
            piece,
        ));
    }
    out
}

fn piece_name(wall: &WallLayout, piece: &Piece, k: usize) -> String {
    format!(
        "{} {} {}-{:03}",
        piece.nominal,
        piece.role.as_str().replace('_', " "),
        wall.id,
        k + 1
    )
}

/// Two products per wall (vertical pieces, horizontal pieces), every piece an
/// IfcMappedItem of a unit-length section scaled along its axis.
pub(super) fn write_mapped_wall(
    ctx: &mut Ctx,
    place: &WallPlacement,
    b: &PlaceNames,
    parent_gid: Option<String>,
    members: &mut Vec<TruthMember>,
) -> Vec<Ref> {
    let wall = place.wall;
    let mut out = Vec::new();
    // Truth rows must follow the wall's piece order; collect per piece index first.
    let mut rows: Vec<Option<TruthMember>> = vec![None; wall.pieces.len()];
    for (group, vertical) in [("studs", true), ("plates", false)] {
        let indices: Vec<usize> = (0..wall.pieces.len())
            .filter(|&k| wall.pieces[k].upright == vertical)
            .collect();
        if indices.is_empty() {
            continue;
        }
        let kind = product_kind(ctx.opts.products, vertical, false);
        let mut items = Vec::with_capacity(indices.len());
        for &k in &indices {
            let piece = &wall.pieces[k];
            let map = ctx.unit_map(piece.width, piece.thickness);
            let a1 = wall_local_dir(wall, piece.width_dir);
            let a3 = wall_local_dir(wall, piece.axis());
            let a2 = snap(a3.cross(&a1));
            let (d1, d2, d3) = (ctx.dir(a1), ctx.dir(a2), ctx.dir(a3));
            let f = &wall.frame;
            let d = piece.start - f.origin;
            let local = snap_point(Vec3::new(d.dot(&f.u), -d.dot(&f.w), d.dot(&f.v)));
            let o = ctx.point(local);
            let op = ctx.w.add(
                "IFCCARTESIANTRANSFORMATIONOPERATOR3DNONUNIFORM",
                format_args!(
                    "{d1},{d2},{o},1.,{d3},1.,{}",
                    Real(piece.length() * ctx.scale)
                ),
            );
            items.push(ctx.w.add("IFCMAPPEDITEM", format_args!("{map},{op}")));
        }
        let rep = ctx.w.add(
            "IFCSHAPEREPRESENTATION",
            format_args!(
                "{},'Body','MappedRepresentation',{}",
                ctx.body,
                RefList(&items)
            ),
        );
        let shape = ctx
            .w
            .add("IFCPRODUCTDEFINITIONSHAPE", format_args!("$,$,({rep})"));
        let lp = place.at(ctx, wall.frame.origin);
        let key = format!("group:{}:{group}", wall.id);
        let gid = ctx.gid(&key);
        let name = format!("{} {}", wall.id, if vertical { "Studs" } else { "Plates" });
        let nominal = &wall.pieces[indices[0]].nominal;
        let head = format!(
            "{},{},$,{},{lp},{shape},{}",
            ctx.owner_args(&key),
            string(&name),
            string(&format!("{nominal} SPF")),
            string(&format!("{}-{group}", wall.id))
        );
        out.push(
            ctx.w
                .add(kind.entity, product_line(ctx.opts.schema, kind, &head)),
        );
        for (item, &k) in indices.iter().enumerate() {
            // DESIGN §3: a one-piece product's piece id is its GlobalId.
            let piece_id = if indices.len() == 1 {
                gid.clone()
            } else {
                format!("{gid}/{item}")
            };
            rows[k] = Some(truth_member(
                piece_id,
                name.clone(),
                kind,
                ctx.opts.schema,
                wall,
                b,
                parent_gid.clone(),
                &wall.pieces[k],
            ));
        }
    }
    members.extend(rows.into_iter().flatten());
    out
}
