//! The spatial structure around the framing: buildings, storeys, the walls or assemblies
//! members are aggregated into, openings with their doors and windows, property sets, and
//! the relationships between them.
use super::ctx::Ctx;
use super::members::{WallPlacement, write_mapped_wall, write_piece_products};
use super::options::{Grouping, PlacementBase, ProductClasses, Schema};
use super::truth_rows::{PlaceNames, truth_wall};
use crate::step::text::{Real, Ref, RefList, string};
use crate::synth::error::SynthError;
use crate::synth::layout::{BuildingLayout, StoreyLayout, Vec3, WallLayout};
use crate::synth::truth::{TruthMember, TruthWall};

/// Building, storeys, walls and their relationships; returns the IfcBuilding.
pub(super) fn write_building(
    ctx: &mut Ctx,
    b: &BuildingLayout,
    site_lp: Ref,
    base: PlacementBase,
    material: Ref,
    members: &mut Vec<TruthMember>,
    walls: &mut Vec<TruthWall>,
) -> Result<Ref, SynthError> {
    let a2p = ctx.placement3d(b.origin, Vec3::z(), Vec3::x());
    let b_lp = ctx.local_placement(Some(site_lp), a2p);
    let args = format!(
        "{},{},$,$,{b_lp},$,$,.ELEMENT.,$,$,$",
        ctx.owner_args(&format!("building:{}", b.name)),
        string(&b.name)
    );
    let building = ctx.w.add("IFCBUILDING", args);
    let mut storeys = Vec::with_capacity(b.storeys.len());
    let mut framing = Vec::new();
    for (k, s) in b.storeys.iter().enumerate() {
        // The first storey keeps the keys one-storey buildings always had.
        let key = if k == 0 {
            b.name.clone()
        } else {
            format!("{}:{}", b.name, s.name)
        };
        storeys.push(write_storey(
            ctx,
            b,
            s,
            &key,
            b_lp,
            base,
            members,
            walls,
            &mut framing,
        ));
    }
    let rel = ctx.owner_args(&format!("rel:material:{}", b.name));
    ctx.w.add(
        "IFCRELASSOCIATESMATERIAL",
        format_args!("{rel},$,$,{},{material}", RefList(&framing)),
    );
    let rel = ctx.owner_args(&format!("rel:building:{}", b.name));
    ctx.w.add(
        "IFCRELAGGREGATES",
        format_args!("{rel},$,$,{building},{}", RefList(&storeys)),
    );
    Ok(building)
}

/// One storey with its walls; `framing` collects the framing products. Returns the storey.
#[allow(clippy::too_many_arguments)]
fn write_storey(
    ctx: &mut Ctx,
    b: &BuildingLayout,
    s: &StoreyLayout,
    key: &str,
    building_lp: Ref,
    base: PlacementBase,
    members: &mut Vec<TruthMember>,
    walls: &mut Vec<TruthWall>,
    framing: &mut Vec<Ref>,
) -> Ref {
    let opts = ctx.opts;
    let level = Vec3::new(0.0, 0.0, s.elevation);
    let a2p = ctx.placement3d(level, Vec3::z(), Vec3::x());
    let s_lp = ctx.local_placement(Some(building_lp), a2p);
    let args = format!(
        "{},{},$,$,{s_lp},$,$,.ELEMENT.,{}",
        ctx.owner_args(&format!("storey:{key}")),
        string(&s.name),
        Real(s.elevation * ctx.scale)
    );
    let storey = ctx.w.add("IFCBUILDINGSTOREY", args);
    let storey_origin = b.origin + level;
    let place_names = PlaceNames {
        building: &b.name,
        storey: &s.name,
    };
    let mut contained = Vec::new();
    for wall in &s.walls {
        let parent = write_parent(ctx, storey_origin, wall, s_lp);
        let (parent_ref, parent_lp, parent_gid) = match parent {
            Some((r, lp, gid)) => (Some(r), Some(lp), Some(gid)),
            None => (None, None, None),
        };
        let place = WallPlacement {
            wall,
            storey_origin,
            storey_lp: s_lp,
            parent_lp,
            base,
        };
        let products = if opts.mapped {
            write_mapped_wall(ctx, &place, &place_names, parent_gid.clone(), members)
        } else {
            write_piece_products(ctx, &place, &place_names, parent_gid.clone(), members)
        };
        if opts.property_sets {
            for (k, &product) in products.iter().enumerate() {
                write_property_set(ctx, wall, k, product);
            }
        }
        let first = members.len() - wall.pieces.len();
        walls.push(truth_wall(
            wall,
            &place_names,
            parent_gid,
            opts.grouping,
            &members[first..],
        ));
        match (parent_ref, parent_lp) {
            (Some(p), Some(lp)) => {
                let rel = ctx.owner_args(&format!("rel:wall:{}", wall.id));
                ctx.w.add(
                    "IFCRELAGGREGATES",
                    format_args!("{rel},$,$,{p},{}", RefList(&products)),
                );
                contained.push(p);
                if opts.openings {
                    contained.extend(write_openings(ctx, wall, p, lp));
                }
            }
            _ => contained.extend_from_slice(&products),
        }
        framing.extend(products);
    }
    let rel = ctx.owner_args(&format!("rel:contain:{key}"));
    ctx.w.add(
        "IFCRELCONTAINEDINSPATIALSTRUCTURE",
        format_args!("{rel},$,$,{},{storey}", RefList(&contained)),
    );
    storey
}

/// A property set of the product's common set (`Pset_MemberCommon`, …) for the k-th
/// product of a wall: its reference tag, load bearing, exterior.
fn write_property_set(ctx: &mut Ctx, wall: &WallLayout, k: usize, product: Ref) {
    let pset_name = match ctx.opts.products {
        ProductClasses::Member => "Pset_MemberCommon",
        ProductClasses::ColumnBeam if wall.pieces.get(k).is_some_and(|p| p.upright) => {
            "Pset_ColumnCommon"
        }
        ProductClasses::ColumnBeam => "Pset_BeamCommon",
    };
    let tag = if ctx.opts.mapped {
        format!("{}-{}", wall.id, ["studs", "plates"][k.min(1)])
    } else {
        format!("{}-{:03}", wall.id, k + 1)
    };
    let reference = ctx.w.add(
        "IFCPROPERTYSINGLEVALUE",
        format_args!("'Reference',$,IFCIDENTIFIER({}),$", string(&tag)),
    );
    let load = ctx.w.add(
        "IFCPROPERTYSINGLEVALUE",
        "'LoadBearing',$,IFCBOOLEAN(.T.),$",
    );
    let external = ctx
        .w
        .add("IFCPROPERTYSINGLEVALUE", "'IsExternal',$,IFCBOOLEAN(.T.),$");
    let key = format!("pset:{}:{k}", wall.id);
    let pset = ctx.w.add(
        "IFCPROPERTYSET",
        format_args!(
            "{},{},$,({reference},{load},{external})",
            ctx.owner_args(&key),
            string(pset_name)
        ),
    );
    let rel = ctx.owner_args(&format!("rel:{key}"));
    ctx.w.add(
        "IFCRELDEFINESBYPROPERTIES",
        format_args!("{rel},$,$,({product}),{pset}"),
    );
}

/// Depth of a door leaf or window unit across the wall, metres.
const FILLING_DEPTH: f64 = 0.05;

/// For each rough opening of a grouped wall: an IfcOpeningElement voiding the wall and the
/// IfcDoor or IfcWindow filling it, both boxes in the wall's placement. Returns the fillings
/// (contained in the storey).
fn write_openings(ctx: &mut Ctx, wall: &WallLayout, wall_ref: Ref, wall_lp: Ref) -> Vec<Ref> {
    let mut fillings = Vec::with_capacity(wall.openings.len());
    for (k, o) in wall.openings.iter().enumerate() {
        let (u, v) = (o.rough_opening_u, o.rough_opening_v);
        let (width, height) = (u[1] - u[0], v[1] - v[0]);
        // Wall placement axes: x = u, y = -w (the outer face at y = 0, inside at -thickness), z = v.
        let corner = Vec3::new(u[0], -wall.thickness, v[0]);
        let key = format!("opening:{}:{k}", wall.id);
        let body = ctx.box_body(Vec3::new(width, wall.thickness, height));
        let a2p = ctx.placement3d(corner, Vec3::z(), Vec3::x());
        let lp = ctx.local_placement(Some(wall_lp), a2p);
        let opening = ctx.w.add(
            "IFCOPENINGELEMENT",
            format_args!(
                "{},'Rough opening',$,$,{lp},{body},$,.OPENING.",
                ctx.owner_args(&key)
            ),
        );
        let rel = ctx.owner_args(&format!("rel:void:{key}"));
        ctx.w.add(
            "IFCRELVOIDSELEMENT",
            format_args!("{rel},$,$,{wall_ref},{opening}"),
        );
        let inset = Vec3::new(0.0, (wall.thickness - FILLING_DEPTH) / 2.0, 0.0);
        let a2p = ctx.placement3d(inset, Vec3::z(), Vec3::x());
        let f_lp = ctx.local_placement(Some(lp), a2p);
        let f_body = ctx.box_body(Vec3::new(width, FILLING_DEPTH, height));
        let f_key = format!("filling:{}:{k}", wall.id);
        let head = format!(
            "{},{},$,$,{f_lp},{f_body},$",
            ctx.owner_args(&f_key),
            string(o.kind)
        );
        let size = format!("{},{}", Real(height * ctx.scale), Real(width * ctx.scale));
        let filling = match (o.kind, ctx.opts.schema) {
            ("door", Schema::Ifc2x3) => ctx.w.add("IFCDOOR", format_args!("{head},{size}")),
            ("door", _) => ctx.w.add(
                "IFCDOOR",
                format_args!("{head},{size},.DOOR.,.SINGLE_SWING_LEFT.,$"),
            ),
            (_, Schema::Ifc2x3) => ctx.w.add("IFCWINDOW", format_args!("{head},{size}")),
            _ => ctx.w.add(
                "IFCWINDOW",
                format_args!("{head},{size},.WINDOW.,.SINGLE_PANEL.,$"),
            ),
        };
        let rel = ctx.owner_args(&format!("rel:fill:{key}"));
        ctx.w.add(
            "IFCRELFILLSELEMENT",
            format_args!("{rel},$,$,{opening},{filling}"),
        );
        fillings.push(filling);
    }
    fillings
}

/// The IfcWall or IfcElementAssembly a wall's members are aggregated into, if any:
/// (entity, its local placement, GlobalId).
fn write_parent(
    ctx: &mut Ctx,
    storey_origin: Vec3,
    wall: &WallLayout,
    storey_lp: Ref,
) -> Option<(Ref, Ref, String)> {
    let schema = ctx.opts.schema;
    let entity = match ctx.opts.grouping {
        Grouping::None => return None,
        Grouping::Wall => "IFCWALL",
        Grouping::Assembly => "IFCELEMENTASSEMBLY",
    };
    let a2p = ctx.placement3d(
        wall.frame.origin - storey_origin,
        wall.frame.v,
        wall.frame.u,
    );
    let lp = ctx.local_placement(Some(storey_lp), a2p);
    let key = format!("wall:{}", wall.id);
    let gid = ctx.gid(&key);
    let head = format!(
        "{},{},$,'Wood frame wall',{lp},$,{}",
        ctx.owner_args(&key),
        string(&wall.name),
        string(&wall.id)
    );
    let r = match (ctx.opts.grouping, schema.has_element_predefined_type()) {
        (Grouping::Wall, true) => ctx.w.add(entity, format_args!("{head},.ELEMENTEDWALL.")),
        (Grouping::Wall, false) => ctx.w.add(entity, head),
        // IfcElementAssembly has AssemblyPlace and PredefinedType in every schema.
        _ => ctx
            .w
            .add(entity, format_args!("{head},.FACTORY.,.USERDEFINED.")),
    };
    Some((r, lp, gid))
}
