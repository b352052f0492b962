//! IFC model → input facts of the rule base (`rules/facts.dl`). Every tuple
//! keeps its origin: the IFC entity it was read from.

use crate::geom::{ContactOptions, OrientedBox, contacts_and_crossings};
use crate::ifc::Model;
use crate::logic::compiled::Relations;
use crate::logic::value::Sym;
use crate::logic::{Engine, LogicError, OBox, Origin, Value, Vec3};
use rustc_hash::FxHashMap;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Density used when the model names no material we know, kg/m³
/// (spruce-pine-fir, the study's lumber, at about 12 % moisture).
pub const DEFAULT_DENSITY: f64 = 450.0;

/// Relations about two pieces (the first two arguments): a tuple belongs to a part of the
/// model only when both of its pieces do.
pub const PAIR_RELATIONS: [&str; 2] = ["contact", "crossing"];

/// Densities of common framing species, kg/m³ (typical values at about 12 %
/// moisture); matched case-insensitively against the material name.
const SPECIES_DENSITY: &[(&str, f64)] = &[
    ("spruce-pine-fir", 450.0),
    ("spf", 450.0),
    ("southern pine", 550.0),
    ("southern yellow pine", 550.0),
    ("douglas fir", 530.0),
    ("douglas-fir", 530.0),
    ("hem-fir", 460.0),
    ("hem fir", 460.0),
    ("spruce", 450.0),
    ("fichte", 450.0),
    ("kiefer", 520.0),
    ("pine", 520.0),
    ("larch", 590.0),
    ("lvl", 600.0),
    ("glulam", 480.0),
];

/// The density for a material name and whether it was a default.
pub fn density_of(material: Option<&str>) -> (f64, bool) {
    let name = material.unwrap_or("").to_ascii_lowercase();
    SPECIES_DENSITY
        .iter()
        .find(|(key, _)| name.contains(key))
        .map_or((DEFAULT_DENSITY, true), |(_, d)| (*d, false))
}

/// Input tuples by relation, each with its origin.
#[derive(Debug, Default, Clone)]
pub struct Facts {
    pub tuples: BTreeMap<&'static str, Vec<(Vec<Value>, Origin)>>,
}

impl Facts {
    pub fn add(&mut self, relation: &'static str, tuple: Vec<Value>, origin: Origin) {
        self.tuples
            .entry(relation)
            .or_default()
            .push((tuple, origin));
    }

    /// The tuples without origins, sorted, as the compiled engine takes them.
    pub fn relations(&self) -> Relations {
        self.tuples
            .iter()
            .map(|(name, tuples)| {
                let mut v: Vec<Vec<Value>> = tuples.iter().map(|(t, _)| t.clone()).collect();
                v.sort_unstable();
                v.dedup();
                (name.to_string(), v)
            })
            .collect()
    }

    /// Splits the facts by spatial container (storey, building): a piece's
    /// tuples go to its container's part, contacts only when both pieces share
    /// it, and facts about no piece (the cell) to every part. Walls never span
    /// containers, so each part can be reasoned on its own.
    pub fn by_container(&self) -> Vec<Relations> {
        split_by_container(
            self.tuples
                .iter()
                .map(|(name, tuples)| (*name, tuples.iter().map(|(t, _)| t.clone()).collect()))
                .collect(),
        )
    }

    /// `by_container`, moving the tuples instead of copying them (only the facts about
    /// no piece are copied, once per part); their origins are dropped.
    pub fn into_by_container(self) -> Vec<Relations> {
        split_by_container(
            self.tuples
                .into_iter()
                .map(|(name, tuples)| (name, tuples.into_iter().map(|(t, _)| t).collect()))
                .collect(),
        )
    }

    /// Inserts every tuple into an interpreter (relations the program does not declare are skipped).
    pub fn insert_into(&self, engine: &mut Engine) -> Result<(), LogicError> {
        for (name, tuples) in &self.tuples {
            if !engine.program().relations.iter().any(|r| r.name == *name) {
                continue;
            }
            for (tuple, origin) in tuples {
                engine.insert(name, tuple.clone(), origin.clone())?;
            }
        }
        Ok(())
    }
}

/// `Facts::by_container` on tuples without origins.
fn split_by_container(tuples: BTreeMap<&'static str, Vec<Vec<Value>>>) -> Vec<Relations> {
    // Keyed by shared symbols (not borrowed names), so the tuples can be moved below.
    let mut part_names: FxHashMap<Sym, usize> = FxHashMap::default();
    let mut part_of_piece: FxHashMap<Sym, usize> = FxHashMap::default();
    for t in tuples.get("piece_container").into_iter().flatten() {
        if let (Value::Symbol(p), Value::Symbol(c)) = (&t[0], &t[1]) {
            let next = part_names.len();
            part_of_piece.insert(*p, *part_names.entry(*c).or_insert(next));
        }
    }
    let n = part_names.len().max(1);
    let part_of = |v: Option<&Value>| {
        v.and_then(Value::as_sym)
            .and_then(|p| part_of_piece.get(&p).copied())
    };
    let mut parts: Vec<Relations> = vec![Relations::new(); n];
    for (name, relation) in tuples {
        let mut buckets: Vec<Vec<Vec<Value>>> = vec![Vec::new(); n];
        for tuple in relation {
            match part_of(tuple.first()) {
                Some(k) if PAIR_RELATIONS.contains(&name) => {
                    if part_of(tuple.get(1)) == Some(k) {
                        buckets[k].push(tuple);
                    }
                }
                Some(k) => buckets[k].push(tuple),
                None => buckets.iter_mut().for_each(|b| b.push(tuple.clone())),
            }
        }
        for (part, bucket) in parts.iter_mut().zip(buckets) {
            part.insert(name.to_string(), bucket);
        }
    }
    parts
}

fn sym(s: &str) -> Value {
    Value::sym(s)
}

fn vec3(v: &nalgebra::Vector3<f64>) -> Value {
    Value::Vec3(Vec3(*v))
}

/// The box as the rule language sees it: pose axes x, y, z = length, width, thickness.
pub fn obox_value(b: &OrientedBox) -> Value {
    let m = nalgebra::Matrix3::from_columns(&b.axes);
    let rotation = nalgebra::UnitQuaternion::from_rotation_matrix(
        &nalgebra::Rotation3::from_matrix_unchecked(m),
    );
    let pose =
        nalgebra::Isometry3::from_parts(nalgebra::Translation3::from(b.centre.coords), rotation);
    Value::Box(Arc::new(OBox {
        pose,
        half: nalgebra::Vector3::from(b.half),
    }))
}

/// The facts of a model: pieces, their boxes, groups, containers, materials and contacts.
/// Built in parallel runs of pieces and of contacts, joined in order: the same tuples in the
/// same order as one pass.
pub fn model_facts(model: &Model, contact_options: &ContactOptions) -> Facts {
    use rayon::prelude::*;
    let pieces = model.pieces();
    let ids: Vec<Value> = pieces.par_iter().map(|p| sym(&p.id)).collect();
    // A fixed run size, so the runs never follow the machine's threads.
    const PER_RUN: usize = 1024;
    let piece_runs: Vec<Facts> = pieces
        .par_chunks(PER_RUN)
        .zip(ids.par_chunks(PER_RUN))
        .enumerate()
        .map(|(run, (pieces_of_run, ids_of_run))| {
            let first = run * PER_RUN;
            let mut facts = Facts::default();
            for (k, (p, id)) in pieces_of_run.iter().zip(ids_of_run).enumerate() {
                add_piece_facts(&mut facts, model, first + k, p, id);
            }
            facts
        })
        .collect();
    let boxes: Vec<OrientedBox> = pieces.iter().map(|p| p.obox).collect();
    let (found, crossings) = contacts_and_crossings(&boxes, contact_options);
    let contact_runs: Vec<Facts> = found
        .par_chunks(PER_RUN)
        .map(|run| {
            let mut facts = Facts::default();
            for c in run {
                add_contact_facts(&mut facts, model, &ids, c);
            }
            facts
        })
        .collect();
    // Only crossings of an inclined piece (a let-in brace) are facts: the rules read no others,
    // and a stray overlap elsewhere would otherwise add a relation to every part of the model.
    let inclined = |k: usize| {
        let z = boxes[k].axes[0].z.abs();
        z > 0.1 - 1e-6 && z < 0.9 + 1e-6
    };
    let mut crossing_facts = Facts::default();
    for c in crossings.iter().filter(|c| inclined(c.a) || inclined(c.b)) {
        for (a, b) in [(c.a, c.b), (c.b, c.a)] {
            crossing_facts.add(
                "crossing",
                vec![ids[a].clone(), ids[b].clone(), Value::float(c.depth)],
                Origin::Entity(pieces[a].entity),
            );
        }
    }
    let mut facts = Facts::default();
    for run in piece_runs
        .into_iter()
        .chain(contact_runs)
        .chain([crossing_facts])
    {
        for (relation, tuples) in run.tuples {
            facts.tuples.entry(relation).or_default().extend(tuples);
        }
    }
    facts
}

/// The facts of piece `index` of the model.
fn add_piece_facts(
    facts: &mut Facts,
    model: &Model,
    index: usize,
    p: &crate::ifc::Piece,
    id: &Value,
) {
    let origin = Origin::Entity(p.entity);
    facts.add(
        "piece",
        vec![
            id.clone(),
            Value::Number(p.entity as i64),
            sym(&p.ifc_type),
            text(&p.name),
        ],
        origin.clone(),
    );
    facts.add(
        "piece_box",
        vec![id.clone(), obox_value(&p.obox)],
        Origin::Entity(p.item),
    );
    facts.add(
        "piece_size",
        vec![
            id.clone(),
            Value::float(p.obox.length()),
            Value::float(p.obox.width()),
            Value::float(p.obox.thickness()),
        ],
        Origin::Entity(p.item),
    );
    facts.add(
        "piece_index",
        vec![id.clone(), Value::Number(index as i64)],
        origin.clone(),
    );
    facts.add(
        "piece_type",
        vec![id.clone(), text(&p.predefined_type), text(&p.object_type)],
        origin.clone(),
    );
    if let Some(group) = p.parent.and_then(|g| model.groups.get(&g)) {
        facts.add(
            "piece_group",
            vec![
                id.clone(),
                sym(&group.global_id),
                sym(&group.ifc_type),
                text(&group.name),
            ],
            Origin::Entity(group.entity),
        );
    }
    let container = p.container.and_then(|c| model.groups.get(&c));
    facts.add(
        "piece_container",
        vec![
            id.clone(),
            sym(container.map_or("", |c| c.global_id.as_str())),
        ],
        container.map_or(origin.clone(), |c| Origin::Entity(c.entity)),
    );
    let (density, _) = density_of(p.material.as_deref());
    facts.add(
        "piece_material",
        vec![id.clone(), text(&p.material), Value::float(density)],
        origin,
    );
}

/// The two `contact` facts of a touching pair, one from each side.
fn add_contact_facts(facts: &mut Facts, model: &Model, ids: &[Value], c: &crate::geom::Contact) {
    let (a, b) = (&model.pieces()[c.a], &model.pieces()[c.b]);
    let kind = sym(c.kind.name());
    let (face_a, face_b) = (sym(c.face_a.name()), sym(c.face_b.name()));
    facts.add(
        "contact",
        vec![
            ids[c.a].clone(),
            ids[c.b].clone(),
            kind.clone(),
            face_a.clone(),
            face_b.clone(),
            Value::float(c.gap),
            vec3(&c.normal),
            vec3(&c.centre.coords),
        ],
        Origin::Entity(a.entity),
    );
    facts.add(
        "contact",
        vec![
            ids[c.b].clone(),
            ids[c.a].clone(),
            kind,
            face_b,
            face_a,
            Value::float(c.gap),
            vec3(&-c.normal),
            vec3(&c.centre.coords),
        ],
        Origin::Entity(b.entity),
    );
}

/// An optional text as a symbol, "" when absent.
fn text(text: &Option<String>) -> Value {
    sym(text.as_deref().unwrap_or(""))
}
