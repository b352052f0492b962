//! Topics from a simulation: one per root cause per wall.
//!
//! A root cause is an element's own framing failure (beyond reach, a collision, a grip the
//! gripper cannot take, …: every framing reason of that element), or a nailing failure of
//! a joint that is not explained by a piece left unframed (a nail beyond reach, off target,
//! a collision while nailing). Nails left out because a piece was not framed are
//! consequences: they are named in the topic of that piece's framing failure.

use super::BcfHeader;
use crate::frame::plan::Wall;
use crate::ifc::Model;
use crate::ifc::guid::hash128;
use crate::logic::Value;
use crate::sim::Simulation;
use nalgebra::{Point3, Vector3};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;

const UUID_SEED: u64 = 0x6263_665f_746f_7063;

/// A camera looking at a wall, in the model's world coordinates (metres).
#[derive(Debug, Clone, PartialEq)]
pub struct Camera {
    pub position: [f64; 3],
    pub direction: [f64; 3],
    pub up: [f64; 3],
    /// Vertical field of view, degrees.
    pub field_of_view: f64,
    pub aspect_ratio: f64,
}

/// One BCF topic.
#[derive(Debug, Clone, PartialEq)]
pub struct IssueTopic {
    /// Stable: derived from the project, the wall and the cause.
    pub guid: String,
    pub viewpoint_guid: String,
    pub wall_id: String,
    pub title: String,
    pub description: String,
    /// Stage (framing | nailing) and component (robot, gripper, …).
    pub labels: Vec<String>,
    /// IfcGuids of the failing elements (shown selected and red).
    pub failing: Vec<String>,
    /// IfcGuids of every element of the wall (the rest of the model hidden).
    pub wall_elements: Vec<String>,
    pub camera: Camera,
    /// The viewpoint's image, when the caller rendered one.
    pub snapshot: Option<super::Snapshot>,
}

/// A UUID (RFC 9562 version 8: custom, here a hash of `key`), lower-case.
fn uuid(key: &str) -> String {
    let mut bits = hash128(UUID_SEED, key);
    bits &= !(0xF_u128 << 76);
    bits |= 0x8_u128 << 76;
    bits &= !(0x3_u128 << 62);
    bits |= 0x2_u128 << 62;
    let hex = format!("{bits:032x}");
    format!(
        "{}-{}-{}-{}-{}",
        &hex[..8],
        &hex[8..12],
        &hex[12..16],
        &hex[16..20],
        &hex[20..]
    )
}

fn sym(v: &Value) -> String {
    v.as_symbol().unwrap_or_default().to_string()
}

fn words(role: &str) -> String {
    role.replace('_', " ")
}

/// The head of a reason for a title: before its first `: `, or before its second when the
/// first part is only a word or two (`place pose: joint limit`).
fn head(message: &str) -> &str {
    let mut parts = message.splitn(3, ": ");
    let first = parts.next().unwrap_or(message);
    match parts.next() {
        Some(second) if first.split_whitespace().count() <= 2 => {
            message[..first.len() + 2 + second.len()].trim()
        }
        _ => first.trim(),
    }
}

/// A reason's head with its closing figure, e.g. `place pose beyond reach (466 mm too far)`.
fn headline(message: &str) -> String {
    let figure = message
        .ends_with(')')
        .then(|| message.rfind('(').map(|at| &message[at..]))
        .flatten();
    match figure {
        Some(f) if !head(message).ends_with(f) => format!("{} {f}", head(message)),
        _ => head(message).to_string(),
    }
}

/// `nail PL -> M #k …` → (PL, M).
fn joint_of(message: &str) -> Option<(&str, &str)> {
    let rest = message.strip_prefix("nail ")?;
    let (plate, rest) = rest.split_once(" -> ")?;
    let member = rest.split(' ').next()?;
    Some((plate, member))
}

/// The reason after its `nail PL -> M #k` prefix.
fn after_joint(message: &str) -> &str {
    if joint_of(message).is_none() {
        return message;
    }
    let Some(at) = message.find(" #") else {
        return message;
    };
    let rest = &message[at + 2..];
    let rest = rest.trim_start_matches(|c: char| c.is_ascii_digit());
    rest.trim_start_matches(':').trim()
}

/// A camera in front of the wall's outer face, far enough back to see all of it.
fn wall_camera(wall: &Wall) -> Camera {
    let (fov, aspect) = (60.0_f64, 4.0 / 3.0);
    let f = &wall.frame;
    let centre = f * Point3::new(wall.length / 2.0, wall.height / 2.0, wall.thickness / 2.0);
    let (w, v) = (f * Vector3::z(), f * Vector3::y());
    let half = (fov.to_radians() / 2.0).tan();
    let distance =
        (wall.height / 2.0 / half).max(wall.length / 2.0 / (half * aspect)) * 1.15 + wall.thickness;
    let position = centre - w * distance;
    let r = |x: f64| (x * 1e6).round() / 1e6 + 0.0;
    Camera {
        position: [r(position.x), r(position.y), r(position.z)],
        direction: [r(w.x), r(w.y), r(w.z)],
        up: [r(v.x), r(v.y), r(v.z)],
        field_of_view: fov,
        aspect_ratio: aspect,
    }
}

/// The topics of a simulation, wall by wall in plan order, causes in a fixed order; `model` is
/// the one the simulation ran on (`Simulation::model`: cut plates name their plate's GlobalId).
pub fn topics_of(model: &Model, sim: &Simulation, header: &BcfHeader) -> Vec<IssueTopic> {
    let pieces: BTreeMap<&str, &crate::ifc::Piece> =
        model.pieces().iter().map(|p| (p.id.as_str(), p)).collect();
    let gid = |p: &str| pieces.get(p).map(|p| p.global_id.clone());
    let label = |p: &str| {
        let role = sim.plan.roles.get(p).map_or("element", String::as_str);
        let name = pieces.get(p).and_then(|p| p.name.clone());
        match name {
            Some(n) => format!("{} {n}", words(role)),
            None => format!("{} {p}", words(role)),
        }
    };
    // (piece, stage) → [(component, message)], sorted.
    let mut reasons: BTreeMap<(String, String), BTreeSet<(String, String)>> = BTreeMap::new();
    for t in sim.reasoned.get("element_reason") {
        reasons
            .entry((sym(&t[0]), sym(&t[1])))
            .or_default()
            .insert((sym(&t[2]), sym(&t[3])));
    }
    let project = header
        .project_global_id
        .clone()
        .unwrap_or_else(|| header.model_file.clone());
    let simulated: BTreeSet<&str> = sim.records.iter().map(|r| r.wall.as_str()).collect();
    let mut topics = Vec::new();
    for wall in sim
        .plan
        .walls
        .iter()
        .filter(|w| simulated.contains(w.key.as_str()))
    {
        let wall_elements: Vec<String> = {
            let mut seen = BTreeSet::new();
            wall.assembly_order
                .iter()
                .filter_map(|p| gid(p))
                .filter(|g| seen.insert(g.clone()))
                .collect()
        };
        let camera = wall_camera(wall);
        let mut make = |cause: String,
                        title: String,
                        description: String,
                        labels: Vec<String>,
                        failing: Vec<String>| {
            let key = format!("{project}/{}/{cause}", wall.id);
            topics.push(IssueTopic {
                guid: uuid(&format!("topic/{key}")),
                viewpoint_guid: uuid(&format!("viewpoint/{key}")),
                wall_id: wall.id.clone(),
                title,
                description,
                labels,
                failing,
                wall_elements: wall_elements.clone(),
                camera: camera.clone(),
                snapshot: None,
            });
        };
        // Framing: one topic per element that failed on its own account.
        for p in &wall.assembly_order {
            let Some(own) = reasons.get(&(p.clone(), "framing".into())) else {
                continue;
            };
            let Some((component, first)) = own.iter().next() else {
                continue;
            };
            let mut description = format!(
                "{} ({}) in {} was not framed.\nReasons:\n",
                label(p),
                gid(p).unwrap_or_default(),
                wall.name
            );
            for (c, m) in own {
                let _ = writeln!(description, "- {c}: {m}");
            }
            // Consequences: nails left out because this piece was not framed.
            let mut left_out = BTreeSet::new();
            for ((q, stage), list) in &reasons {
                if stage != "nailing" {
                    continue;
                }
                for (c, m) in list {
                    if c == "Framing"
                        && let Some((pl, mb)) = joint_of(m)
                        && (pl == p || mb == p)
                        && m.contains(&format!("{p} was not placed"))
                    {
                        left_out.insert((m.clone(), q.clone()));
                    }
                }
            }
            let nails: BTreeSet<&str> = left_out.iter().map(|(m, _)| m.as_str()).collect();
            if !nails.is_empty() {
                let others: BTreeSet<String> = left_out
                    .iter()
                    .filter(|(_, q)| q != p)
                    .map(|(_, q)| label(q))
                    .collect();
                let _ = writeln!(
                    description,
                    "Consequences: {} nail(s) not driven{}.",
                    nails.len(),
                    if others.is_empty() {
                        String::new()
                    } else {
                        format!(
                            "; left unfastened: {}",
                            others.into_iter().collect::<Vec<_>>().join(", ")
                        )
                    }
                );
            }
            let labels = vec!["framing".to_string(), component.to_lowercase()];
            make(
                format!("framing/{p}"),
                format!("{}: {} {}", wall.name, label(p), headline(first)),
                description,
                labels,
                gid(p).into_iter().collect(),
            );
        }
        // Nailing: one topic per joint (or element) and component, consequences excluded.
        let mut joints: BTreeMap<(String, String, String), BTreeSet<String>> = BTreeMap::new();
        for p in &wall.assembly_order {
            for (c, m) in reasons
                .get(&(p.clone(), "nailing".into()))
                .into_iter()
                .flatten()
            {
                if c == "Framing" {
                    continue;
                }
                let (a, b) = joint_of(m).unwrap_or((p.as_str(), ""));
                joints
                    .entry((a.to_string(), b.to_string(), c.clone()))
                    .or_default()
                    .insert(m.clone());
            }
        }
        for ((plate, member, component), messages) in joints {
            let subject = if member.is_empty() {
                label(&plate)
            } else {
                format!("{} to {}", label(&plate), label(&member))
            };
            let mut description = format!("Nailing {subject} in {} failed.\nReasons:\n", wall.name);
            for m in &messages {
                let _ = writeln!(description, "- {component}: {m}");
            }
            let first = messages.iter().next().map_or("", |m| after_joint(m));
            let failing: Vec<String> = {
                let mut seen = BTreeSet::new();
                [plate.as_str(), member.as_str()]
                    .iter()
                    .filter_map(|p| gid(p))
                    .filter(|g| seen.insert(g.clone()))
                    .collect()
            };
            make(
                format!("nailing/{plate}/{member}/{component}"),
                format!(
                    "{}: nailing {subject}: {} nail(s) {}",
                    wall.name,
                    messages.len(),
                    headline(first)
                ),
                description,
                vec!["nailing".to_string(), component.to_lowercase()],
                failing,
            );
        }
    }
    topics
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uuids_are_version_8_and_stable() {
        let a = uuid("topic/x");
        assert_eq!(a, uuid("topic/x"));
        assert_ne!(a, uuid("topic/y"));
        assert_eq!(a.len(), 36);
        assert_eq!(&a[14..15], "8");
        assert!(matches!(&a[19..20], "8" | "9" | "a" | "b"));
        assert!(
            a.chars()
                .all(|c| c == '-' || c.is_ascii_hexdigit() && !c.is_ascii_uppercase())
        );
    }

    #[test]
    fn titles_take_the_reason_head_and_figure() {
        assert_eq!(
            headline("place pose: joint limit: joint_3 would be 1.43"),
            "place pose: joint limit"
        );
        assert_eq!(
            headline(
                "place pose beyond reach: the wrist centre would be 3.1 m from the shoulder (466 mm too far)"
            ),
            "place pose beyond reach (466 mm too far)"
        );
    }

    #[test]
    fn joints_parse() {
        assert_eq!(
            joint_of("nail A/0 -> B #1 beyond reach: …"),
            Some(("A/0", "B"))
        );
        assert_eq!(joint_of("tool touched x"), None);
    }
}
