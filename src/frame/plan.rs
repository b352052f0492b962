//! The typed result of frame reasoning for one model: walls with their frame,
//! members with roles, assembly order, precedence, nailing and framing targets.

use super::Reasoned;
use crate::geom::Point3;
use crate::ifc::Model;
use crate::logic::Value;
use nalgebra::{Isometry3, Vector3};
use std::collections::BTreeMap;

#[derive(Debug, Clone)]
pub struct Plan {
    pub walls: Vec<Wall>,
    /// Wall id of each piece that belongs to a wall, by piece id.
    pub wall_of: BTreeMap<String, String>,
    pub roles: BTreeMap<String, String>,
    /// Mass of each piece, kg.
    pub masses: BTreeMap<String, f64>,
    pub warnings: Vec<String>,
}

#[derive(Debug, Clone)]
pub struct Wall {
    /// `W1`, `W2`, … in file order of the walls' first pieces, or the GlobalId
    /// of the IFC group that is exactly this wall.
    pub id: String,
    pub name: String,
    /// The piece the rules name the wall after.
    pub key: String,
    pub group_global_id: Option<String>,
    pub members: Vec<String>,
    /// Wall coordinates (u along, v up, w inward) → world.
    pub frame: Isometry3<f64>,
    pub length: f64,
    pub height: f64,
    pub thickness: f64,
    pub assembly_order: Vec<String>,
    pub precedence: Vec<(String, String, String)>,
    pub nailing_targets: Vec<NailingTarget>,
    pub framing_targets: Vec<(String, Isometry3<f64>)>,
}

#[derive(Debug, Clone)]
pub struct NailingTarget {
    pub plate: String,
    pub member: String,
    pub kind: String,
    pub u: f64,
    pub v: f64,
    pub w: f64,
    pub world: Point3,
    pub direction: Vector3<f64>,
}

fn sym(v: &Value) -> String {
    v.as_symbol().unwrap_or_default().to_string()
}

fn float(v: &Value) -> f64 {
    v.as_float().unwrap_or(f64::NAN)
}

fn vec3(v: &Value) -> Vector3<f64> {
    match v {
        Value::Vec3(x) => x.0,
        _ => Vector3::from_element(f64::NAN),
    }
}

fn iso(v: &Value) -> Isometry3<f64> {
    match v {
        Value::Iso(x) => x.0,
        _ => Isometry3::identity(),
    }
}

impl Plan {
    /// The relations `from_reasoned` reads (`frame::reason_selected` returns only these).
    pub const RELATIONS: &'static [&'static str] = &[
        "wall",
        "wall_of",
        "role",
        "piece_material",
        "wall_group",
        "wall_frame",
        "wall_size",
        "assembly_rank",
        "precedence",
        "nailing_target",
        "framing_target",
        "frame_warning",
        "lumber",
        "across",
        "coplanar",
    ];

    /// Collects the plan from the rule base's relations (missing relations give empty parts).
    pub fn from_reasoned(model: &Model, r: &Reasoned) -> Plan {
        let index: BTreeMap<&str, usize> = model
            .pieces()
            .iter()
            .enumerate()
            .map(|(i, p)| (p.id.as_str(), i))
            .collect();
        let wall_of: BTreeMap<String, String> = r
            .get("wall_of")
            .iter()
            .map(|t| (sym(&t[0]), sym(&t[1])))
            .collect();
        let roles: BTreeMap<String, String> = r
            .get("role")
            .iter()
            .map(|t| (sym(&t[0]), sym(&t[1])))
            .collect();
        let masses: BTreeMap<String, f64> = r
            .get("piece_material")
            .iter()
            .filter_map(|t| {
                let p = model.pieces().get(*index.get(sym(&t[0]).as_str())?)?;
                Some((p.id.clone(), p.obox.volume() * float(&t[2])))
            })
            .collect();
        let groups: BTreeMap<String, (String, String)> = r
            .get("wall_group")
            .iter()
            .map(|t| (sym(&t[0]), (sym(&t[1]), sym(&t[3]))))
            .collect();
        let frames: BTreeMap<String, Isometry3<f64>> = r
            .get("wall_frame")
            .iter()
            .map(|t| (sym(&t[0]), iso(&t[1])))
            .collect();
        let sizes: BTreeMap<String, [f64; 3]> = r
            .get("wall_size")
            .iter()
            .map(|t| (sym(&t[0]), [float(&t[1]), float(&t[2]), float(&t[3])]))
            .collect();
        let ranks: BTreeMap<String, i64> = r
            .get("assembly_rank")
            .iter()
            .map(|t| (sym(&t[0]), t[1].as_number().unwrap_or(i64::MAX)))
            .collect();

        // Walls in file order of their key piece.
        let mut keys: Vec<String> = r.get("wall").iter().map(|t| sym(&t[0])).collect();
        keys.sort_by_key(|k| index.get(k.as_str()).copied().unwrap_or(usize::MAX));
        let mut members: BTreeMap<&str, Vec<String>> = BTreeMap::new();
        for (p, w) in &wall_of {
            members.entry(w.as_str()).or_default().push(p.clone());
        }
        // Precedence, nailing and framing targets bucketed by wall in one pass.
        let mut precedence_by: BTreeMap<&str, Vec<(String, String, String)>> = BTreeMap::new();
        for t in r.get("precedence") {
            let (before, after) = (sym(&t[0]), sym(&t[1]));
            if let (Some(w), Some(w2)) = (wall_of.get(&before), wall_of.get(&after))
                && w == w2
            {
                precedence_by
                    .entry(w.as_str())
                    .or_default()
                    .push((before, after, sym(&t[2])));
            }
        }
        let mut nails_by: BTreeMap<&str, Vec<NailingTarget>> = BTreeMap::new();
        for t in r.get("nailing_target") {
            if let Some(w) = wall_of.get(&sym(&t[0])) {
                nails_by.entry(w.as_str()).or_default().push(NailingTarget {
                    plate: sym(&t[0]),
                    member: sym(&t[1]),
                    kind: sym(&t[2]),
                    u: float(&t[3]),
                    v: float(&t[4]),
                    w: float(&t[5]),
                    world: Point3::from(vec3(&t[6])),
                    direction: vec3(&t[7]),
                });
            }
        }
        let mut framing_by: BTreeMap<&str, Vec<(String, Isometry3<f64>)>> = BTreeMap::new();
        for t in r.get("framing_target") {
            if let Some(w) = wall_of.get(&sym(&t[0])) {
                framing_by
                    .entry(w.as_str())
                    .or_default()
                    .push((sym(&t[0]), iso(&t[1])));
            }
        }
        let mut walls = Vec::new();
        for (n, key) in keys.iter().enumerate() {
            let mut list = members.get(key.as_str()).cloned().unwrap_or_default();
            list.sort_by_key(|p| index.get(p.as_str()).copied().unwrap_or(usize::MAX));
            let mut order = list.clone();
            order.sort_by_key(|p| {
                (
                    ranks.get(p).copied().unwrap_or(i64::MAX),
                    index.get(p.as_str()).copied(),
                )
            });
            let mut precedence = precedence_by.remove(key.as_str()).unwrap_or_default();
            precedence.sort();
            let mut nailing_targets = nails_by.remove(key.as_str()).unwrap_or_default();
            nailing_targets.sort_by(|a, b| {
                (a.u, a.v, a.w)
                    .partial_cmp(&(b.u, b.v, b.w))
                    .unwrap_or(std::cmp::Ordering::Equal)
            });
            let position: BTreeMap<&str, usize> = order
                .iter()
                .enumerate()
                .map(|(i, p)| (p.as_str(), i))
                .collect();
            let mut framing_targets = framing_by.remove(key.as_str()).unwrap_or_default();
            framing_targets.sort_by_key(|(p, _)| position.get(p.as_str()).copied());
            let group = groups.get(key);
            let size = sizes.get(key).copied().unwrap_or([f64::NAN; 3]);
            walls.push(Wall {
                id: group.map_or_else(|| format!("W{}", n + 1), |(g, _)| g.clone()),
                name: group.map_or_else(|| format!("Wall {}", n + 1), |(_, name)| name.clone()),
                key: key.clone(),
                group_global_id: group.map(|(g, _)| g.clone()),
                members: list,
                frame: frames.get(key).copied().unwrap_or_else(Isometry3::identity),
                length: size[0],
                height: size[1],
                thickness: size[2],
                assembly_order: order,
                precedence,
                nailing_targets,
                framing_targets,
            });
        }
        let wall_ids: BTreeMap<&str, &str> = walls
            .iter()
            .map(|w| (w.key.as_str(), w.id.as_str()))
            .collect();
        let wall_of = wall_of
            .iter()
            .map(|(p, w)| {
                (
                    p.clone(),
                    wall_ids.get(w.as_str()).unwrap_or(&w.as_str()).to_string(),
                )
            })
            .collect();
        let mut warnings: Vec<String> = r
            .get("frame_warning")
            .iter()
            .map(|t| {
                let subject = sym(&t[0]);
                let subject = wall_ids
                    .get(subject.as_str())
                    .map_or(subject.clone(), |w| w.to_string());
                format!("{subject}: {}", sym(&t[1]))
            })
            .collect();
        if walls.is_empty() {
            warnings.push(no_walls_reason(model, r));
        }
        Plan {
            walls,
            wall_of,
            roles,
            masses,
            warnings,
        }
    }
}

/// Why a model gave no wall frames, in the user's terms.
fn no_walls_reason(model: &Model, r: &Reasoned) -> String {
    let pieces = model.pieces().len();
    if pieces == 0 {
        return "no wall frames: the model holds no members, columns, beams, plates or proxies with solid geometry".into();
    }
    let lumber = r.get("lumber").len();
    let upright = r.get("across").len();
    let coplanar = r.get("coplanar").len() / 2;
    format!(
        "no wall frames: of {pieces} pieces, {lumber} have lumber sections, {upright} stand plumb or lie level in a wall plane, and {coplanar} pairs touch in one plane; a wall needs at least three lumber pieces (plates and studs) touching in one vertical plane"
    )
}
