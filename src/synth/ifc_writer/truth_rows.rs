//! The truth sidecar's rows for what was written: one per member, one per wall, and the
//! file-level summary.
use super::options::{Grouping, PlacementBase, ProductClasses, ProductKind, Schema, WriteOptions};
use crate::synth::layout::{Layout, Piece, WallLayout};
use crate::synth::targets::{self, Nail};
use crate::synth::truth::{
    self, BoxInfo, Counts, Truth, TruthMember, TruthNail, TruthOpening, TruthPrecedence, TruthWall,
    q, q3,
};
use std::collections::BTreeMap;

/// The building and storey names the truth file gives each wall and member.
pub(super) struct PlaceNames<'a> {
    pub(super) building: &'a str,
    pub(super) storey: &'a str,
}

#[allow(clippy::too_many_arguments)]
pub(super) fn truth_member(
    global_id: String,
    name: String,
    kind: ProductKind,
    schema: Schema,
    wall: &WallLayout,
    b: &PlaceNames,
    wall_global_id: Option<String>,
    piece: &Piece,
) -> TruthMember {
    let bx = piece.wall_box;
    TruthMember {
        global_id,
        name,
        ifc_type: kind.ifc_type,
        predefined_type: schema
            .has_element_predefined_type()
            .then_some(kind.predefined),
        wall_id: wall.id.clone(),
        wall_global_id,
        building: b.building.to_string(),
        storey: b.storey.to_string(),
        role: piece.role.as_str(),
        role_detail: piece.role_detail.clone(),
        nominal: piece.nominal.clone(),
        orientation: if piece.upright {
            "vertical"
        } else if piece.role == crate::synth::layout::Role::Brace {
            "inclined"
        } else {
            "horizontal"
        },
        axis_start: q3(&piece.start),
        axis_end: q3(&piece.end),
        width: q(piece.width),
        thickness: q(piece.thickness),
        section_w: q(bx.w[1] - bx.w[0]),
        length: q(piece.length()),
        volume: q(piece.volume()),
        wall_local_box: BoxInfo {
            u: [q(bx.u[0]), q(bx.u[1])],
            v: [q(bx.v[0]), q(bx.v[1])],
            w: [q(bx.w[0]), q(bx.w[1])],
        },
    }
}

pub(super) fn truth_wall(
    wall: &WallLayout,
    b: &PlaceNames,
    wall_global_id: Option<String>,
    grouping: Grouping,
    members: &[TruthMember],
) -> TruthWall {
    let mut role_counts = BTreeMap::new();
    for p in &wall.pieces {
        *role_counts.entry(p.role.as_str().to_string()).or_insert(0) += 1;
    }
    let m = wall.frame.matrix();
    let ids: Vec<String> = members.iter().map(|m| m.global_id.clone()).collect();
    let nail = |n: &Nail| TruthNail {
        pair: [ids[n.plate].clone(), ids[n.member].clone()],
        plate: ids[n.plate].clone(),
        member: ids[n.member].clone(),
        kind: n.kind,
        u: q(n.u),
        v: q(n.v),
        w: q(n.w),
        world: q3(&wall.frame.to_world(n.u, n.v, n.w)),
        direction_world: q3(&(wall.frame.v * n.v_direction)),
    };
    let (primary, secondary) = targets::nailing_targets(wall);
    TruthWall {
        wall_id: wall.id.clone(),
        wall_global_id,
        container_type: match grouping {
            Grouping::None => None,
            Grouping::Wall => Some("IfcWall"),
            Grouping::Assembly => Some("IfcElementAssembly"),
        },
        name: wall.name.clone(),
        building: b.building.to_string(),
        storey: b.storey.to_string(),
        length: q(wall.length),
        height: q(wall.height),
        thickness: q(wall.thickness),
        frame_matrix: m.map(|row| row.map(q)),
        member_global_ids: ids.clone(),
        assembly_order: ids.clone(),
        assembly_order_roles: wall.pieces.iter().map(|p| p.role.as_str()).collect(),
        precedence_constraints: targets::precedence(wall)
            .iter()
            .map(|p| TruthPrecedence {
                before: ids[p.before].clone(),
                after: ids[p.after].clone(),
                reason: p.reason.as_str(),
            })
            .collect(),
        nailing_targets: primary.iter().map(nail).collect(),
        secondary_nailing_targets: secondary.iter().map(nail).collect(),
        openings: wall
            .openings
            .iter()
            .map(|o| TruthOpening {
                kind: o.kind,
                rough_opening_u: o.rough_opening_u.map(q),
                rough_opening_v: o.rough_opening_v.map(q),
                header: o.header.clone(),
            })
            .collect(),
        role_counts,
    }
}

pub(super) fn build_truth(
    layout: &Layout,
    opts: &WriteOptions,
    base: PlacementBase,
    members: Vec<TruthMember>,
    walls: Vec<TruthWall>,
) -> Truth {
    let mut by_role = BTreeMap::new();
    let mut by_ifc_type = BTreeMap::new();
    for m in &members {
        *by_role.entry(m.role.to_string()).or_insert(0) += 1;
        *by_ifc_type.entry(m.ifc_type.to_string()).or_insert(0) += 1;
    }
    Truth {
        generator: "framewright synth",
        model: layout.name.clone(),
        file: opts.file_name.clone(),
        description: layout.description.clone(),
        schema: opts.schema.header_name(),
        length_unit: truth::UnitInfo {
            name: opts.unit.ifc_name(),
            metres_per_unit: opts.unit.metres_per_unit(),
            kind: opts.unit.ifc_kind(),
        },
        seed: opts.seed,
        options: truth::OptionsInfo {
            products: match opts.products {
                ProductClasses::Member => "member",
                ProductClasses::ColumnBeam => "column-beam",
            },
            grouping: match opts.grouping {
                Grouping::None => "none",
                Grouping::Wall => "wall",
                Grouping::Assembly => "assembly",
            },
            mapped: opts.mapped,
            placement: match base {
                PlacementBase::Storey => "storey",
                PlacementBase::Parent => "parent",
            },
        },
        conventions: truth::CONVENTIONS,
        counts: Counts {
            members: members.len(),
            walls: walls.len(),
            buildings: layout.buildings.len(),
            by_role,
            by_ifc_type,
        },
        members,
        walls,
    }
}
