//! `annotate`: writes the plan (and optionally the simulation verdicts) back into the IFC
//! model the plan came from, for BIM tools to filter and schedule:
//!
//! - per element a property set `Framewright_Assembly` (role, wall, position in the
//!   assembly order, the pieces it must follow; with verdicts: framing and nailing
//!   status, the one-line reason, the reach margin);
//! - the assembly sequence as processes: an `IfcWorkSchedule` declared in the project, per
//!   wall a summary `IfcTask` with one nested `IfcTask` per piece in assembly order,
//!   `IfcRelSequence` (FINISH_START) for every precedence pair, `IfcRelAssignsToProcess`
//!   tying each piece's task to its element;
//! - each panel of a split wall as an `IfcElementAssembly` of its members, plate segments and
//!   added end studs as new `IfcMember`s (`bim::panels`); every piece of a split wall names
//!   its panel (`Panel`);
//! - the nails as `IfcMechanicalFastener` (NAIL) at the nailing targets, with a body,
//!   contained where the plate is and connected to the plate and the member they join
//!   (`IfcRelConnectsWithRealizingElements`).
//!
//! Every input entity is kept byte for byte; the new ones are appended after the last
//! one with fresh ids, and FILE_NAME's preprocessor field names the tool. GlobalIds are
//! derived from the elements' GlobalIds, so the same inputs give the same bytes.

use super::entities::{PSET_NAME, guid_for, label, property, swept_body, typed};
use super::error::AnnotateError;
use super::step_edit::{Appender, file_name_span, insertion_point, splice};
use super::verdicts::ElementVerdict;
use crate::frame::plan::{Plan, Wall};
use crate::ifc::{Model, Piece, Schema};
use crate::step::StepFile;
use crate::step::text::{Real, RealList, Ref, RefList, string};
use nalgebra::Vector3;
use std::collections::BTreeMap;

/// Size of the nails written as fasteners, metres.
#[derive(Debug, Clone, Copy)]
pub struct NailSize {
    pub length: f64,
    pub diameter: f64,
}

impl Default for NailSize {
    /// A common framing nail: 3.3 mm by 90 mm.
    fn default() -> Self {
        NailSize {
            length: 0.090,
            diameter: 0.0033,
        }
    }
}

#[derive(Debug, Clone, Default)]
pub struct AnnotateOptions {
    /// Date of the work schedule (ISO 8601); default: the header's time stamp.
    pub date: Option<String>,
    pub nail: NailSize,
    /// Verdicts by piece id (from a simulation).
    pub verdicts: Option<BTreeMap<String, ElementVerdict>>,
}

/// The annotated file and what was added.
#[derive(Debug, Clone)]
pub struct Annotated {
    pub bytes: Vec<u8>,
    pub property_sets: usize,
    pub tasks: usize,
    pub sequences: usize,
    pub fasteners: usize,
    /// Panels written as `IfcElementAssembly`, and the members added to them.
    pub panels: super::panels::PanelsWritten,
    pub first_new_id: u64,
}

fn opt_text(text: &str) -> String {
    if text.is_empty() {
        "$".into()
    } else {
        string(text)
    }
}

/// Text of attribute `i` of entity `id`, if it is a string.
fn text_attr(file: &StepFile, id: u64, i: usize) -> Option<String> {
    let entity = file.entity(id)?.ok()?;
    entity.get(i).text().map(|(t, _)| t.into_owned())
}

/// Is `text` (its first 19 characters) an ISO 8601 date-time `YYYY-MM-DDThh:mm:ss`?
pub fn iso_date_time(text: &str) -> Option<&str> {
    let head = text.get(..19)?;
    let ok = head.bytes().enumerate().all(|(i, c)| match i {
        4 | 7 => c == b'-',
        10 => c == b'T',
        13 | 16 => c == b':',
        _ => c.is_ascii_digit(),
    });
    ok.then_some(head)
}

/// The context new bodies belong to: the `Body` sub-context, else the 3D model context.
fn body_context(file: &StepFile) -> Option<u64> {
    let sub = file
        .of_type("IFCGEOMETRICREPRESENTATIONSUBCONTEXT")
        .find(|r| text_attr(file, r.id, 0).is_some_and(|t| t.eq_ignore_ascii_case("Body")));
    sub.or_else(|| {
        file.of_type("IFCGEOMETRICREPRESENTATIONCONTEXT")
            .find(|r| text_attr(file, r.id, 1).is_some_and(|t| t.eq_ignore_ascii_case("Model")))
    })
    .map(|r| r.id)
}

/// The pieces of each product, in file order of their first piece.
fn products(model: &Model) -> Vec<(u64, Vec<&Piece>)> {
    let mut order: Vec<(u64, Vec<&Piece>)> = Vec::new();
    let mut at: BTreeMap<u64, usize> = BTreeMap::new();
    for p in model.pieces() {
        match at.get(&p.entity) {
            Some(&i) => order[i].1.push(p),
            None => {
                at.insert(p.entity, order.len());
                order.push((p.entity, vec![p]));
            }
        }
    }
    order
}

/// Everything the writer needs to know about the plan, by piece id.
struct PlanIndex<'a> {
    wall: BTreeMap<&'a str, &'a Wall>,
    /// The panel of each piece of a split wall; a cut plate lists its segments' panels.
    panel: BTreeMap<&'a str, String>,
    position: BTreeMap<&'a str, usize>,
    follows: BTreeMap<&'a str, Vec<&'a str>>,
}

impl<'a> PlanIndex<'a> {
    fn new(plan: &'a Plan) -> PlanIndex<'a> {
        let mut index = PlanIndex {
            wall: BTreeMap::new(),
            panel: BTreeMap::new(),
            position: BTreeMap::new(),
            follows: BTreeMap::new(),
        };
        for wall in plan.walls.iter().filter(|w| w.panels.panels.len() > 1) {
            for panel in &wall.panels.panels {
                for m in &panel.member_ids {
                    index.panel.insert(m, panel.id.clone());
                }
                for cut in &panel.cut_pieces {
                    let entry = index
                        .panel
                        .entry(&cut.of)
                        .or_insert_with(|| "cut into".into());
                    entry.push_str(&format!(" {} ({})", cut.id, panel.id));
                }
            }
            for site in &wall.panels.site_pieces {
                let entry = index
                    .panel
                    .entry(&site.of)
                    .or_insert_with(|| "cut into".into());
                entry.push_str(&format!(" {} (site)", site.id));
            }
        }
        for wall in &plan.walls {
            for (i, p) in wall.assembly_order.iter().enumerate() {
                index.wall.insert(p, wall);
                index.position.insert(p, i + 1);
            }
            for (before, after, _) in &wall.precedence {
                index
                    .follows
                    .entry(after.as_str())
                    .or_default()
                    .push(before.as_str());
            }
        }
        index
    }
}

/// Writes the annotated model. Refuses IFC2X3 (its processes and fasteners differ).
pub fn annotate(
    model: &Model,
    plan: &Plan,
    options: &AnnotateOptions,
) -> Result<Annotated, AnnotateError> {
    let path = model.path.clone();
    if model.schema == Schema::Ifc2x3 {
        return Err(AnnotateError::UnsupportedSchema {
            path,
            schema: model.schema_identifier.clone(),
        });
    }
    let nail = options.nail;
    if !(nail.length > 0.0 && nail.length < 1.0 && nail.diameter > 0.0 && nail.diameter < 0.05) {
        return Err(AnnotateError::BadNail(format!(
            "{} mm long, {} mm thick; give a length in (0, 1000) mm and a diameter in (0, 50) mm",
            nail.length * 1000.0,
            nail.diameter * 1000.0
        )));
    }
    let file = model.step();
    let bytes = file.bytes();
    let first_record = file.records().iter().map(|r| r.start).min();
    let (Some(first_record), Some((insert_at, eol))) = (first_record, insertion_point(file)) else {
        return Err(AnnotateError::Empty { path });
    };
    let name_span = file_name_span(bytes, first_record)
        .ok_or_else(|| AnnotateError::NoFileName { path: path.clone() })?;
    let already = file
        .of_type("IFCPROPERTYSET")
        .any(|r| text_attr(file, r.id, 2).as_deref() == Some(PSET_NAME));
    if already {
        return Err(AnnotateError::AlreadyAnnotated { path });
    }
    let date = match &options.date {
        Some(d) => iso_date_time(d)
            .ok_or_else(|| AnnotateError::BadDate(d.clone()))?
            .to_string(),
        None => iso_date_time(&model.header().time_stamp)
            .ok_or_else(|| AnnotateError::NoDate {
                path: path.clone(),
                found: model.header().time_stamp.clone(),
            })?
            .to_string(),
    };
    let project = file
        .of_type("IFCPROJECT")
        .next()
        .map(|r| r.id)
        .ok_or_else(|| AnnotateError::NoProject { path: path.clone() })?;
    let project_gid = text_attr(file, project, 0).unwrap_or_default();
    let max_id = file.records().iter().map(|r| r.id).max().unwrap_or(0);
    let mid_line = insert_at > 0 && !matches!(bytes[insert_at - 1], b'\n' | b'\r');
    let mut w = Appender::new(max_id, eol, mid_line);
    let index = PlanIndex::new(plan);
    let unit = model.length_unit.metres_per_unit;
    let pieces: BTreeMap<&str, &Piece> =
        model.pieces().iter().map(|p| (p.id.as_str(), p)).collect();

    // The work schedule, declared in the project (none when there is nothing to schedule).
    let schedule = (!plan.walls.is_empty()).then(|| {
        let schedule = w.add(
        "IFCWORKSCHEDULE",
        format!(
            "{},$,{},{},$,{},{},$,{},$,$,{},$,.PLANNED.",
            guid_for("schedule", &project_gid),
            string("Framewright assembly sequence"),
            string("Robotic framing order of every wall: one task per piece, FINISH_START for every precedence"),
            string("framewright-assembly"),
            string(&date),
            string("Robotic wall framing"),
            string(&date),
        ),
    );
        w.add(
            "IFCRELDECLARES",
            format!(
                "{},$,$,$,#{project},({schedule})",
                guid_for("declares", &project_gid)
            ),
        );
        schedule
    });

    // Per wall: a summary task, one task per piece, sequences and assignments.
    let mut wall_tasks = Vec::new();
    let (mut tasks, mut sequences) = (0, 0);
    for wall in &plan.walls {
        let wall_key = wall
            .group_global_id
            .clone()
            .unwrap_or_else(|| wall.key.clone());
        let wall_task = w.add(
            "IFCTASK",
            format!(
                "{},$,{},$,$,{},$,$,$,.F.,$,$,.CONSTRUCTION.",
                guid_for("wall-task", &wall_key),
                label(&format!("Frame {}", wall.name)),
                label(&wall.id),
            ),
        );
        wall_tasks.push(wall_task);
        tasks += 1;
        let mut task_of: BTreeMap<&str, Ref> = BTreeMap::new();
        let mut element_tasks = Vec::new();
        for id in &wall.assembly_order {
            let Some(piece) = pieces.get(id.as_str()) else {
                continue;
            };
            let role = plan.roles.get(id).map_or("unclassified", String::as_str);
            let name = piece.name.as_deref().unwrap_or(id);
            let task = w.add(
                "IFCTASK",
                format!(
                    "{},$,{},{},$,{},$,$,$,.F.,$,$,.CONSTRUCTION.",
                    guid_for("task", id),
                    label(&format!("Place {role} {name}")),
                    string(&wall.name),
                    label(id),
                ),
            );
            tasks += 1;
            w.add(
                "IFCRELASSIGNSTOPROCESS",
                format!(
                    "{},$,$,$,(#{}),$,{task},$",
                    guid_for("assign", id),
                    piece.entity
                ),
            );
            task_of.insert(id, task);
            element_tasks.push(task);
        }
        if !element_tasks.is_empty() {
            w.add(
                "IFCRELNESTS",
                format!(
                    "{},$,$,$,{wall_task},{}",
                    guid_for("nests", &wall_key),
                    RefList(&element_tasks)
                ),
            );
        }
        for (before, after, reason) in &wall.precedence {
            let (Some(a), Some(b)) = (task_of.get(before.as_str()), task_of.get(after.as_str()))
            else {
                continue;
            };
            w.add(
                "IFCRELSEQUENCE",
                format!(
                    "{},$,$,{},{a},{b},$,.FINISH_START.,$",
                    guid_for("sequence", &format!("{before}>{after}")),
                    opt_text(reason),
                ),
            );
            sequences += 1;
        }
    }
    if let (Some(schedule), false) = (schedule, wall_tasks.is_empty()) {
        w.add(
            "IFCRELASSIGNSTOCONTROL",
            format!(
                "{},$,$,$,{},$,{schedule}",
                guid_for("control", &project_gid),
                RefList(&wall_tasks)
            ),
        );
    }

    // Property sets, one per product that holds pieces.
    let mut property_sets = 0;
    for (entity, parts) in products(model) {
        let gid = &parts[0].global_id;
        let props = element_properties(&mut w, &parts, plan, &index, options, unit);
        let pset = w.add(
            "IFCPROPERTYSET",
            format!(
                "{},$,{},{},{}",
                guid_for("pset", gid),
                string(PSET_NAME),
                string("What framewright inferred about this element (and, after a simulation, its verdicts)"),
                RefList(&props)
            ),
        );
        w.add(
            "IFCRELDEFINESBYPROPERTIES",
            format!("{},$,$,$,(#{entity}),{pset}", guid_for("defines", gid)),
        );
        property_sets += 1;
    }

    let fasteners = write_nails(&mut w, file, plan, &pieces, nail, unit);
    let panels = super::panels::write_panels(
        &mut w,
        plan,
        &pieces,
        body_context(file),
        unit,
        options.verdicts.as_ref(),
    );

    // The header names the tool that wrote this file; every other byte stays.
    let header = model.header();
    let earlier = if header.preprocessor_version.is_empty() {
        String::new()
    } else {
        format!("; written earlier by {}", header.preprocessor_version)
    };
    let list = |items: &[String]| {
        let items: Vec<String> = items.iter().map(|s| string(s)).collect();
        format!("({})", items.join(","))
    };
    let file_name = format!(
        "FILE_NAME({},{},{},{},{},{},{});",
        string(&header.file_name),
        string(&header.time_stamp),
        list(&header.authors),
        list(&header.organizations),
        label(&format!(
            "framewright {} annotate{earlier}",
            env!("CARGO_PKG_VERSION")
        )),
        string(&header.originating_system),
        string(&header.authorization),
    );
    Ok(Annotated {
        bytes: splice(bytes, name_span, &file_name, insert_at, &w.into_text()),
        property_sets,
        tasks,
        sequences,
        fasteners,
        panels,
        first_new_id: max_id + 1,
    })
}

/// The properties of one product (values per piece for a many-piece product).
fn element_properties(
    w: &mut Appender,
    parts: &[&Piece],
    plan: &Plan,
    index: &PlanIndex<'_>,
    options: &AnnotateOptions,
    unit: f64,
) -> Vec<Ref> {
    let per_piece = |f: &dyn Fn(&Piece) -> String| -> Vec<String> {
        parts.iter().map(|p| f(p)).collect::<Vec<_>>()
    };
    let mut props = Vec::new();
    if parts.len() > 1 {
        props.push(property(
            w,
            "Pieces",
            &per_piece(&|p| typed("IFCIDENTIFIER", &p.id)),
        ));
    }
    props.push(property(
        w,
        "Role",
        &per_piece(&|p| typed("IFCLABEL", plan.roles.get(&p.id).map_or("", String::as_str))),
    ));
    let wall_of = |p: &Piece| index.wall.get(p.id.as_str()).copied();
    props.push(property(
        w,
        "WallId",
        &per_piece(&|p| typed("IFCIDENTIFIER", wall_of(p).map_or("", |w| w.id.as_str()))),
    ));
    props.push(property(
        w,
        "Wall",
        &per_piece(&|p| typed("IFCLABEL", wall_of(p).map_or("", |w| w.name.as_str()))),
    ));
    if parts
        .iter()
        .any(|p| index.panel.contains_key(p.id.as_str()))
    {
        props.push(property(
            w,
            "Panel",
            &per_piece(&|p| {
                typed(
                    "IFCLABEL",
                    index.panel.get(p.id.as_str()).map_or("", String::as_str),
                )
            }),
        ));
    }
    props.push(property(
        w,
        "AssemblyPosition",
        &per_piece(&|p| {
            format!(
                "IFCINTEGER({})",
                index.position.get(p.id.as_str()).copied().unwrap_or(0)
            )
        }),
    ));
    // The pieces any of this element's pieces must follow, in order of first mention.
    let mut follows: Vec<&str> = Vec::new();
    for p in parts {
        for f in index.follows.get(p.id.as_str()).into_iter().flatten() {
            if !follows.contains(f) {
                follows.push(f);
            }
        }
    }
    if !follows.is_empty() {
        let values: Vec<String> = follows.iter().map(|f| typed("IFCIDENTIFIER", f)).collect();
        props.push(w.add(
            "IFCPROPERTYLISTVALUE",
            format!("{},$,({}),$", string("MustFollow"), values.join(",")),
        ));
    }
    if let Some(verdicts) = &options.verdicts {
        let verdict = |p: &Piece| verdicts.get(&p.id);
        if parts.iter().any(|p| verdict(p).is_some()) {
            let field = |f: fn(&ElementVerdict) -> &str| {
                move |p: &Piece| verdict(p).map_or("", f).to_string()
            };
            let framing = field(|v| &v.framing);
            let nailing = field(|v| &v.nailing);
            let reason = field(|v| &v.reason);
            props.push(property(
                w,
                "FramingVerdict",
                &per_piece(&|p| typed("IFCLABEL", &framing(p))),
            ));
            props.push(property(
                w,
                "NailingVerdict",
                &per_piece(&|p| typed("IFCLABEL", &nailing(p))),
            ));
            props.push(property(
                w,
                "Reason",
                &per_piece(&|p| typed("IFCTEXT", &reason(p))),
            ));
            let margins: Option<Vec<String>> = parts
                .iter()
                .map(|p| {
                    verdict(p)
                        .and_then(|v| v.reach_margin)
                        .map(|m| format!("IFCLENGTHMEASURE({})", Real(m / unit)))
                })
                .collect();
            if let Some(margins) = margins {
                props.push(property(w, "ReachMargin", &margins));
            }
        }
    }
    props
}

/// A unit vector at right angles to `d`.
fn perpendicular(d: &Vector3<f64>) -> Vector3<f64> {
    let helper = if d.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let p = helper - d * d.dot(&helper);
    p.normalize()
}

/// The nails: one fastener per nailing target, placed at the target along the nail line,
/// with a shared cylinder body; contained where the plate is; connected to plate and member.
fn write_nails(
    w: &mut Appender,
    file: &StepFile,
    plan: &Plan,
    pieces: &BTreeMap<&str, &Piece>,
    nail: NailSize,
    unit: f64,
) -> usize {
    let any_nail = plan.walls.iter().any(|w| {
        w.nailing_targets.iter().any(|t| {
            pieces.contains_key(t.plate.as_str()) && pieces.contains_key(t.member.as_str())
        })
    });
    if !any_nail {
        // A body shared by no fastener would break IfcProductDefinitionShape's inverse rule.
        return 0;
    }
    let shape = body_context(file).map(|context| {
        let profile = w.add(
            "IFCCIRCLEPROFILEDEF",
            format!(
                ".AREA.,{},$,{}",
                string("nail"),
                Real(nail.diameter / 2.0 / unit)
            ),
        );
        swept_body(w, context, profile, nail.length / unit)
    });
    let mut count = 0;
    // (plate product, member product) → nails; container → nails.
    let mut joints: BTreeMap<(u64, u64), (Vec<Ref>, String)> = BTreeMap::new();
    let mut contained: BTreeMap<u64, Vec<Ref>> = BTreeMap::new();
    for wall in &plan.walls {
        let mut k_of: BTreeMap<(&str, &str), usize> = BTreeMap::new();
        for t in &wall.nailing_targets {
            let (Some(plate), Some(member)) =
                (pieces.get(t.plate.as_str()), pieces.get(t.member.as_str()))
            else {
                continue;
            };
            let k = k_of.entry((&t.plate, &t.member)).or_insert(0);
            let key = format!("{}>{}#{k}", t.plate, t.member);
            *k += 1;
            let d = t.direction.normalize();
            if !(d.iter().all(|x| x.is_finite()) && t.world.iter().all(|x| x.is_finite())) {
                continue;
            }
            let origin = [t.world.x / unit, t.world.y / unit, t.world.z / unit];
            let point = w.add("IFCCARTESIANPOINT", RealList(&origin));
            let axis = w.add("IFCDIRECTION", RealList(&[d.x, d.y, d.z]));
            let r = perpendicular(&d);
            let refdir = w.add("IFCDIRECTION", RealList(&[r.x, r.y, r.z]));
            let frame = w.add("IFCAXIS2PLACEMENT3D", format!("{point},{axis},{refdir}"));
            let placement = w.add("IFCLOCALPLACEMENT", format!("$,{frame}"));
            let fastener = w.add(
                "IFCMECHANICALFASTENER",
                format!(
                    "{},$,{},{},$,{placement},{},{},{},{},.NAIL.",
                    guid_for("nail", &key),
                    string("Nail"),
                    string(&format!(
                        "{} nail through plate {} into {}",
                        t.kind, t.plate, t.member
                    )),
                    shape.map_or("$".to_string(), |s| s.to_string()),
                    label(&key),
                    Real(nail.diameter / unit),
                    Real(nail.length / unit),
                ),
            );
            count += 1;
            if let Some(c) = plate.container {
                contained.entry(c).or_default().push(fastener);
            }
            if plate.entity != member.entity {
                joints
                    .entry((plate.entity, member.entity))
                    .or_insert_with(|| {
                        (
                            Vec::new(),
                            format!("{}>{}", plate.global_id, member.global_id),
                        )
                    })
                    .0
                    .push(fastener);
            }
        }
    }
    for ((plate, member), (nails, key)) in &joints {
        w.add(
            "IFCRELCONNECTSWITHREALIZINGELEMENTS",
            format!(
                "{},$,{},$,$,#{plate},#{member},{},{}",
                guid_for("joint", key),
                string("Nailed joint"),
                RefList(nails),
                string("NAILED")
            ),
        );
    }
    for (container, nails) in &contained {
        let gid = text_attr(file, *container, 0).unwrap_or_else(|| container.to_string());
        w.add(
            "IFCRELCONTAINEDINSPATIALSTRUCTURE",
            format!(
                "{},$,{},$,{},#{container}",
                guid_for("contains", &gid),
                string("Nails"),
                RefList(nails)
            ),
        );
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn date_time_check() {
        assert_eq!(
            iso_date_time("2024-01-01T00:00:00"),
            Some("2024-01-01T00:00:00")
        );
        assert_eq!(
            iso_date_time("2015-03-13T19:19:38+01:00"),
            Some("2015-03-13T19:19:38")
        );
        assert_eq!(iso_date_time("13.03.2015 19:19"), None);
        assert_eq!(iso_date_time(""), None);
    }

    #[test]
    fn perpendicular_is_unit_and_orthogonal() {
        for d in [Vector3::x(), Vector3::z(), Vector3::new(0.6, 0.8, 0.0)] {
            let p = perpendicular(&d);
            assert!((p.norm() - 1.0).abs() < 1e-12);
            assert!(p.dot(&d).abs() < 1e-12);
        }
    }
}
