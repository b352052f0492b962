//! `annotate`'s panels: each panel of a split wall as an `IfcElementAssembly` (a wall
//! element built in the factory, `AssemblyPlace` FACTORY, ObjectType `PANEL`) holding its
//! members, so the BIM model learns how its walls are built.
//!
//! - The plate segments and added end studs of a panel are new `IfcMember`s (PLATE / STUD)
//!   with a swept-solid body (the piece's box) and a property set naming the piece they come
//!   from; the modelled plate stays as it was (every input entity is kept).
//! - The assembly aggregates its new members and the modelled members that no other element
//!   aggregates (`IfcRelAggregates`); a modelled member that already belongs to an element
//!   (an `IfcWall`, an `IfcElementAssembly` of the model) can have only one whole, so it is
//!   assigned to the panel instead (`IfcRelAssignsToProduct`).
//! - The assembly is contained where its wall's first piece is, and so is each site piece (the
//!   stretch of a lapped cap plate across a joint: a new `IfcMember` in no panel, `Panel` =
//!   `site`).

use super::entities::{PSET_NAME, guid_for, label, property, swept_body, typed};
use super::step_edit::Appender;
use super::verdicts::ElementVerdict;
use crate::frame::panelize::{moved_box, segment_box};
use crate::frame::plan::Plan;
use crate::geom::OrientedBox;
use crate::ifc::Piece;
use crate::step::text::{Real, RealList, Ref, RefList, string};
use std::collections::{BTreeMap, BTreeSet};

/// What `write_panels` added.
#[derive(Debug, Clone, Copy, Default)]
pub struct PanelsWritten {
    pub assemblies: usize,
    pub members: usize,
}

/// One new member of a panel: a plate segment or an added end stud.
struct NewMember<'a> {
    id: &'a str,
    of: &'a Piece,
    role: &'a str,
    obox: OrientedBox,
    /// `PLATE` or `STUD`.
    kind: &'static str,
    /// What it is, before the GlobalId of the piece it comes from.
    what: String,
}

/// Writes the panels of `plan`'s split walls; `context` is the model's body context (no
/// bodies without one), `unit` metres per model length unit.
pub(super) fn write_panels(
    w: &mut Appender,
    plan: &Plan,
    pieces: &BTreeMap<&str, &Piece>,
    context: Option<u64>,
    unit: f64,
    verdicts: Option<&BTreeMap<String, ElementVerdict>>,
) -> PanelsWritten {
    let mut written = PanelsWritten::default();
    for wall in plan.walls.iter().filter(|w| w.panels.panels.len() > 1) {
        let wall_key = wall.group_global_id.as_deref().unwrap_or(&wall.key);
        // The products each panel holds whole (a product with pieces in two panels is in none).
        let mut panels_of_product: BTreeMap<u64, BTreeSet<usize>> = BTreeMap::new();
        for (k, panel) in wall.panels.panels.iter().enumerate() {
            for m in &panel.member_ids {
                if let Some(p) = pieces.get(m.as_str()) {
                    panels_of_product.entry(p.entity).or_default().insert(k);
                }
            }
        }
        let container = wall
            .members
            .iter()
            .find_map(|m| pieces.get(m.as_str()).and_then(|p| p.container));
        let mut assemblies = Vec::new();
        for panel in &wall.panels.panels {
            let mut new_members: Vec<NewMember> = Vec::new();
            for cut in &panel.cut_pieces {
                if let Some(of) = pieces.get(cut.of.as_str()) {
                    new_members.push(NewMember {
                        id: &cut.id,
                        of,
                        role: plan.roles.get(&cut.of).map_or("", String::as_str),
                        obox: segment_box(&of.obox, wall, cut.u_start, cut.u_end),
                        kind: "PLATE",
                        what: "segment of plate".into(),
                    });
                }
            }
            for added in &panel.added_pieces {
                if let Some(of) = pieces.get(added.of.as_str()) {
                    new_members.push(NewMember {
                        id: &added.id,
                        of,
                        role: &added.role,
                        obox: moved_box(&of.obox, wall, added.u_start, added.u_end),
                        kind: "STUD",
                        what: "end stud added beside".into(),
                    });
                }
            }
            let panel_key = format!("{wall_key}/{}", panel.index);
            let origin = wall.frame * nalgebra::Point3::new(panel.u_start, 0.0, 0.0);
            let along = wall.frame.rotation * nalgebra::Vector3::x();
            let placement = placement_at(
                w,
                [origin.x / unit, origin.y / unit, origin.z / unit],
                [0.0, 0.0, 1.0],
                [along.x, along.y, along.z],
            );
            let assembly = w.add(
                "IFCELEMENTASSEMBLY",
                format!(
                    "{},$,{},{},{},{placement},$,{},.FACTORY.,.USERDEFINED.",
                    guid_for("panel", &panel_key),
                    label(&panel.id),
                    string(&format!(
                        "Panel {} of {} of {}: u {:.3} to {:.3} m along the wall, {:.3} m long, {:.3} m high, {:.1} kg",
                        panel.index,
                        wall.panels.panels.len(),
                        wall.name,
                        panel.u_start,
                        panel.u_end,
                        panel.length(),
                        panel.height,
                        panel.mass
                    )),
                    string("PANEL"),
                    label(&panel.id),
                ),
            );
            assemblies.push(assembly);
            written.assemblies += 1;
            let mut parts = Vec::new();
            let mut assigned = Vec::new();
            let mut seen = BTreeSet::new();
            for m in &panel.member_ids {
                let Some(p) = pieces.get(m.as_str()) else {
                    continue;
                };
                let whole = panels_of_product
                    .get(&p.entity)
                    .is_some_and(|s| s.len() == 1);
                if !whole || !seen.insert(p.entity) {
                    continue;
                }
                if p.parent.is_some() {
                    assigned.push(format!("#{}", p.entity));
                } else {
                    parts.push(format!("#{}", p.entity));
                }
            }
            for m in &new_members {
                let member = write_member(w, m, &panel.id, &wall.id, context, unit, verdicts);
                parts.push(member.to_string());
                written.members += 1;
            }
            if !parts.is_empty() {
                w.add(
                    "IFCRELAGGREGATES",
                    format!(
                        "{},$,{},$,{assembly},({})",
                        guid_for("panel-aggregates", &panel_key),
                        string("Panel members"),
                        parts.join(",")
                    ),
                );
            }
            if !assigned.is_empty() {
                w.add(
                    "IFCRELASSIGNSTOPRODUCT",
                    format!(
                        "{},$,{},{},({}),$,{assembly}",
                        guid_for("panel-assigns", &panel_key),
                        string("Panel members"),
                        string("Members of this panel that belong to a modelled element too"),
                        assigned.join(",")
                    ),
                );
            }
        }
        let mut contained = assemblies;
        for site in &wall.panels.site_pieces {
            let Some(of) = pieces.get(site.of.as_str()) else {
                continue;
            };
            let m = NewMember {
                id: &site.id,
                of,
                role: plan.roles.get(&site.of).map_or("", String::as_str),
                obox: segment_box(&of.obox, wall, site.u_start, site.u_end),
                kind: "PLATE",
                what: format!(
                    "lap across the joint of {}, fixed on site, from plate",
                    site.laps.join(" and ")
                ),
            };
            contained.push(write_member(
                w, &m, "site", &wall.id, context, unit, verdicts,
            ));
            written.members += 1;
        }
        if let Some(c) = container {
            w.add(
                "IFCRELCONTAINEDINSPATIALSTRUCTURE",
                format!(
                    "{},$,{},$,{},#{c}",
                    guid_for("panel-contained", wall_key),
                    string("Panels"),
                    RefList(&contained)
                ),
            );
        }
    }
    written
}

/// An absolute placement: origin, z axis and x direction in model units.
fn placement_at(w: &mut Appender, origin: [f64; 3], z: [f64; 3], x: [f64; 3]) -> Ref {
    let point = w.add("IFCCARTESIANPOINT", RealList(&origin));
    let axis = w.add("IFCDIRECTION", RealList(&z));
    let refdir = w.add("IFCDIRECTION", RealList(&x));
    let frame = w.add("IFCAXIS2PLACEMENT3D", format!("{point},{axis},{refdir}"));
    w.add("IFCLOCALPLACEMENT", format!("$,{frame}"))
}

/// A plate segment or added stud as an `IfcMember` with its body and property set.
fn write_member(
    w: &mut Appender,
    m: &NewMember,
    panel: &str,
    wall: &str,
    context: Option<u64>,
    unit: f64,
    verdicts: Option<&BTreeMap<String, ElementVerdict>>,
) -> Ref {
    let b = &m.obox;
    // Extruded along the length from one end; the profile's x along the width.
    let start = b.centre - b.axes[0] * b.half[0];
    let [l, y] = [b.axes[0], b.axes[1]];
    let placement = placement_at(
        w,
        [start.x / unit, start.y / unit, start.z / unit],
        [l.x, l.y, l.z],
        [y.x, y.y, y.z],
    );
    let shape = context.map(|context| {
        let profile = w.add(
            "IFCRECTANGLEPROFILEDEF",
            format!(
                ".AREA.,{},$,{},{}",
                string("section"),
                Real(2.0 * b.half[1] / unit),
                Real(2.0 * b.half[2] / unit)
            ),
        );
        // The profile centred on the placement's axis: the solid sits at the box.
        swept_body(w, context, profile, 2.0 * b.half[0] / unit)
    });
    let member = w.add(
        "IFCMEMBER",
        format!(
            "{},$,{},{},$,{placement},{},{},.{}.",
            guid_for("panel-member", m.id),
            label(m.of.name.as_deref().unwrap_or(m.id)),
            string(&format!("{panel}: {} {}", m.what, m.of.global_id)),
            shape.map_or("$".to_string(), |s| s.to_string()),
            label(m.id),
            m.kind,
        ),
    );
    let mut props = vec![
        property(w, "Role", &[typed("IFCLABEL", m.role)]),
        property(w, "WallId", &[typed("IFCIDENTIFIER", wall)]),
        property(w, "Panel", &[typed("IFCIDENTIFIER", panel)]),
        property(w, "DerivedFrom", &[typed("IFCIDENTIFIER", &m.of.id)]),
    ];
    if let Some(v) = verdicts.and_then(|v| v.get(m.id)) {
        props.push(property(
            w,
            "FramingStatus",
            &[typed("IFCLABEL", &v.framing)],
        ));
        props.push(property(
            w,
            "NailingStatus",
            &[typed("IFCLABEL", &v.nailing)],
        ));
        if !v.reason.is_empty() {
            props.push(property(w, "Reason", &[typed("IFCTEXT", &v.reason)]));
        }
    }
    let pset = w.add(
        "IFCPROPERTYSET",
        format!(
            "{},$,{},{},{}",
            guid_for("pset", m.id),
            string(PSET_NAME),
            string("A piece framewright added to build the wall as panels"),
            RefList(&props)
        ),
    );
    w.add(
        "IFCRELDEFINESBYPROPERTIES",
        format!("{},$,$,$,({member}),{pset}", guid_for("defines", m.id)),
    );
    member
}
