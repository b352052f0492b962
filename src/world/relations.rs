//! Typed views of the reasoned relations of `rules/targets.dl` and `rules/world.dl`. Each
//! accessor checks the tuple shapes (a replaced rule directory may declare them differently)
//! and returns its rows sorted.

use super::WorldError;
use crate::frame::Reasoned;
use crate::logic::Value;
use nalgebra::{Isometry3, Vector3};
use std::collections::BTreeMap;

/// A piece's framing target: its body frame (centre of mass, x along the length, y along the
/// width) in the robot's base frame once its wall is laid flat on the assembly area.
#[derive(Debug, Clone, PartialEq)]
pub struct FramingTarget {
    pub piece: String,
    pub wall: String,
    pub pose: Isometry3<f64>,
}

/// As JSON for `plan`: `{"piece", "wall_id", "pose": {"position", "matrix"}}` (robot frame,
/// numbers rounded like the world JSON).
impl serde::Serialize for FramingTarget {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut st = s.serialize_struct("FramingTarget", 3)?;
        st.serialize_field("piece", &self.piece)?;
        st.serialize_field("wall_id", &self.wall)?;
        st.serialize_field("pose", &super::json::pose(&self.pose))?;
        st.end()
    }
}

/// Where a piece appears on conveyor 1 (cell frame) and its place in the queue (0 = first).
#[derive(Debug, Clone, PartialEq)]
pub struct Spawn {
    pub piece: String,
    pub slot: usize,
    pub pose: Isometry3<f64>,
}

/// A spawned piece's box size (length, width, thickness; m) and mass (kg).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldPiece {
    pub size: [f64; 3],
    pub mass: f64,
}

fn bad(relation: &'static str, tuple: &[Value], what: &str) -> WorldError {
    WorldError::Relation {
        relation,
        message: format!("expected {what}, got {tuple:?}"),
    }
}

fn symbol(relation: &'static str, t: &[Value], k: usize, what: &str) -> Result<String, WorldError> {
    t.get(k)
        .and_then(Value::as_symbol)
        .map(str::to_string)
        .ok_or_else(|| bad(relation, t, what))
}

fn iso(
    relation: &'static str,
    t: &[Value],
    k: usize,
    what: &str,
) -> Result<Isometry3<f64>, WorldError> {
    match t.get(k) {
        Some(Value::Iso(i)) => Ok(i.0),
        _ => Err(bad(relation, t, what)),
    }
}

fn float(relation: &'static str, t: &[Value], k: usize, what: &str) -> Result<f64, WorldError> {
    t.get(k)
        .and_then(Value::as_float)
        .filter(|x| x.is_finite())
        .ok_or_else(|| bad(relation, t, what))
}

/// Every framing target by wall, each wall's targets sorted by piece id.
pub fn framing_targets(r: &Reasoned) -> Result<BTreeMap<String, Vec<FramingTarget>>, WorldError> {
    const REL: &str = "framing_target";
    const WHAT: &str = "(piece: symbol, pose: iso)";
    let wall_of: BTreeMap<&str, &str> = r
        .get("wall_of")
        .iter()
        .filter_map(|t| Some((t.first()?.as_symbol()?, t.get(1)?.as_symbol()?)))
        .collect();
    let mut out: BTreeMap<String, Vec<FramingTarget>> = BTreeMap::new();
    for t in r.get(REL) {
        let piece = symbol(REL, t, 0, WHAT)?;
        let pose = iso(REL, t, 1, WHAT)?;
        let wall = wall_of
            .get(piece.as_str())
            .ok_or_else(|| WorldError::Relation {
                relation: REL,
                message: format!("piece `{piece}` has a target but no wall (wall_of)"),
            })?
            .to_string();
        out.entry(wall.clone())
            .or_default()
            .push(FramingTarget { piece, wall, pose });
    }
    for targets in out.values_mut() {
        targets.sort_by(|a, b| a.piece.cmp(&b.piece));
    }
    Ok(out)
}

/// The laid-flat frame of every wall in the robot frame (`framing_target_wall`).
pub fn framing_target_walls(r: &Reasoned) -> Result<BTreeMap<String, Isometry3<f64>>, WorldError> {
    const REL: &str = "framing_target_wall";
    const WHAT: &str = "(w: symbol, wall_to_robot: iso)";
    r.get(REL)
        .iter()
        .map(|t| Ok((symbol(REL, t, 0, WHAT)?, iso(REL, t, 1, WHAT)?)))
        .collect()
}

/// The spawns wall by wall (walls in file order of their first piece), each
/// wall's queue in slot order; an error when two pieces of a wall share a slot
/// or a piece has two.
pub fn spawns(r: &Reasoned) -> Result<Vec<Spawn>, WorldError> {
    let wall_of: BTreeMap<&str, &str> = r
        .get("wall_of")
        .iter()
        .filter_map(|t| Some((t.first()?.as_symbol()?, t.get(1)?.as_symbol()?)))
        .collect();
    let index: BTreeMap<&str, i64> = r
        .get("piece_index")
        .iter()
        .filter_map(|t| Some((t.first()?.as_symbol()?, t.get(1)?.as_number()?)))
        .collect();
    let wall_rank = |piece: &str| {
        wall_of
            .get(piece)
            .and_then(|w| index.get(w))
            .copied()
            .unwrap_or(i64::MAX)
    };
    const REL: &str = "spawn";
    const WHAT: &str = "(p: symbol, slot: number >= 0, pose: iso)";
    let mut out = Vec::new();
    for t in r.get(REL) {
        let slot = t
            .get(1)
            .and_then(Value::as_number)
            .and_then(|n| usize::try_from(n).ok())
            .ok_or_else(|| bad(REL, t, WHAT))?;
        out.push(Spawn {
            piece: symbol(REL, t, 0, WHAT)?,
            slot,
            pose: iso(REL, t, 2, WHAT)?,
        });
    }
    out.sort_by(|a, b| {
        (wall_rank(&a.piece), a.slot, &a.piece).cmp(&(wall_rank(&b.piece), b.slot, &b.piece))
    });
    for pair in out.windows(2) {
        if pair[0].slot == pair[1].slot && wall_rank(&pair[0].piece) == wall_rank(&pair[1].piece) {
            return Err(WorldError::SlotTaken {
                slot: pair[0].slot as i64,
                first: pair[0].piece.clone(),
                second: pair[1].piece.clone(),
            });
        }
    }
    let mut seen = BTreeMap::new();
    for s in &out {
        if let Some(first) = seen.insert(s.piece.as_str(), s.slot) {
            return Err(WorldError::Relation {
                relation: REL,
                message: format!(
                    "piece `{}` spawns twice (slots {first} and {}): its wall or rank is not unique",
                    s.piece, s.slot
                ),
            });
        }
    }
    Ok(out)
}

/// Size and mass of every spawned piece (`world_piece`).
pub fn world_pieces(r: &Reasoned) -> Result<BTreeMap<String, WorldPiece>, WorldError> {
    const REL: &str = "world_piece";
    const WHAT: &str = "(p: symbol, size: vec3, mass: float)";
    r.get(REL)
        .iter()
        .map(|t| {
            let size: Vector3<f64> = match t.get(1) {
                Some(Value::Vec3(v)) => v.0,
                _ => return Err(bad(REL, t, WHAT)),
            };
            Ok((
                symbol(REL, t, 0, WHAT)?,
                WorldPiece {
                    size: [size.x, size.y, size.z],
                    mass: float(REL, t, 2, WHAT)?,
                },
            ))
        })
        .collect()
}

/// Pieces queued beyond the upstream end of conveyor 1, with their overhang (m).
pub fn spawn_beyond_belt(r: &Reasoned) -> Result<BTreeMap<String, f64>, WorldError> {
    const REL: &str = "spawn_beyond_belt";
    const WHAT: &str = "(p: symbol, overhang: float)";
    r.get(REL)
        .iter()
        .map(|t| Ok((symbol(REL, t, 0, WHAT)?, float(REL, t, 1, WHAT)?)))
        .collect()
}

/// Every piece riding inside another that is fed (`fed_with`: a pre-assembled member's plies,
/// a duplicated member's copy), as (piece, the piece fed), sorted.
pub fn fed_with(r: &Reasoned) -> Result<Vec<(String, String)>, WorldError> {
    const REL: &str = "fed_with";
    const WHAT: &str = "(p: symbol, lead: symbol)";
    let mut rows: Vec<(String, String)> = r
        .get(REL)
        .iter()
        .map(|t| Ok((symbol(REL, t, 0, WHAT)?, symbol(REL, t, 1, WHAT)?)))
        .collect::<Result<_, WorldError>>()?;
    rows.sort();
    Ok(rows)
}

/// Every piece's box size (length, width, thickness; m) by id (`piece_size`).
pub fn piece_sizes(r: &Reasoned) -> Result<BTreeMap<String, [f64; 3]>, WorldError> {
    const REL: &str = "piece_size";
    const WHAT: &str = "(p: symbol, length: float, width: float, thickness: float)";
    r.get(REL)
        .iter()
        .map(|t| {
            let f = |k| float(REL, t, k, WHAT);
            Ok((symbol(REL, t, 0, WHAT)?, [f(1)?, f(2)?, f(3)?]))
        })
        .collect()
}
