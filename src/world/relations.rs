//! Typed views of the reasoned relations of `rules/targets.dl` and `rules/world.dl`, read
//! through the rule base's typed rows (a replaced rule directory that declares them
//! differently gives an error naming the relation), each returned sorted.

use super::WorldError;
use crate::frame::Reasoned;
use crate::frame::rows::{
    self, FedWith, FramingTargetWall, PieceIndex, PieceSize, Row, SpawnBeyondBelt, WallOf,
};
use nalgebra::Isometry3;
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

/// `x` when it is finite; otherwise an error naming the relation, the row and the attribute.
fn finite(relation: &'static str, x: f64, row: &dyn std::fmt::Debug) -> Result<f64, WorldError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(WorldError::Relation {
            relation,
            message: format!("a number that is not finite in {row:?}"),
        })
    }
}

/// The wall of every piece (`wall_of`).
fn walls_of(r: &Reasoned) -> Result<BTreeMap<&'static str, &'static str>, WorldError> {
    Ok(r.rows::<WallOf>()?
        .into_iter()
        .map(|w| (w.p, w.w))
        .collect())
}

/// Every framing target by wall, each wall's targets sorted by piece id.
pub fn framing_targets(r: &Reasoned) -> Result<BTreeMap<String, Vec<FramingTarget>>, WorldError> {
    let wall_of = walls_of(r)?;
    let mut out: BTreeMap<String, Vec<FramingTarget>> = BTreeMap::new();
    for t in r.rows::<rows::FramingTarget>()? {
        let wall = wall_of
            .get(t.p)
            .ok_or_else(|| WorldError::Relation {
                relation: rows::FramingTarget::RELATION,
                message: format!("piece `{}` has a target but no wall (wall_of)", t.p),
            })?
            .to_string();
        out.entry(wall.clone()).or_default().push(FramingTarget {
            piece: t.p.to_string(),
            wall,
            pose: t.pose,
        });
    }
    for targets in out.values_mut() {
        targets.sort_by(|a, b| a.piece.cmp(&b.piece));
    }
    Ok(out)
}

/// The laid-flat frame of every wall in the robot frame (`framing_target_wall`).
pub fn framing_target_walls(r: &Reasoned) -> Result<BTreeMap<String, Isometry3<f64>>, WorldError> {
    Ok(r.rows::<FramingTargetWall>()?
        .into_iter()
        .map(|t| (t.w.to_string(), t.wall_to_robot))
        .collect())
}

/// The spawns wall by wall (walls in file order of their first piece), each
/// wall's queue in slot order; an error when two pieces of a wall share a slot
/// or a piece has two.
pub fn spawns(r: &Reasoned) -> Result<Vec<Spawn>, WorldError> {
    let wall_of = walls_of(r)?;
    let index: BTreeMap<&str, i64> = r
        .rows::<PieceIndex>()?
        .into_iter()
        .map(|t| (t.p, t.i))
        .collect();
    let wall_rank = |piece: &str| {
        wall_of
            .get(piece)
            .and_then(|w| index.get(w))
            .copied()
            .unwrap_or(i64::MAX)
    };
    const REL: &str = rows::Spawn::RELATION;
    let mut out = Vec::new();
    for t in r.rows::<rows::Spawn>()? {
        let slot = usize::try_from(t.slot).map_err(|_| WorldError::Relation {
            relation: REL,
            message: format!("piece `{}` spawns in slot {} (below 0)", t.p, t.slot),
        })?;
        out.push(Spawn {
            piece: t.p.to_string(),
            slot,
            pose: t.pose,
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
    r.rows::<rows::WorldPiece>()?
        .into_iter()
        .map(|t| {
            let mass = finite(rows::WorldPiece::RELATION, t.mass, &t)?;
            let size = t.size;
            Ok((
                t.p.to_string(),
                WorldPiece {
                    size: [size.x, size.y, size.z],
                    mass,
                },
            ))
        })
        .collect()
}

/// Pieces queued beyond the upstream end of conveyor 1, with their overhang (m).
pub fn spawn_beyond_belt(r: &Reasoned) -> Result<BTreeMap<String, f64>, WorldError> {
    r.rows::<SpawnBeyondBelt>()?
        .into_iter()
        .map(|t| {
            let overhang = finite(SpawnBeyondBelt::RELATION, t.overhang, &t)?;
            Ok((t.p.to_string(), overhang))
        })
        .collect()
}

/// Every piece riding inside another that is fed (`fed_with`: a pre-assembled member's plies,
/// a duplicated member's copy), as (piece, the piece fed), sorted.
pub fn fed_with(r: &Reasoned) -> Result<Vec<(String, String)>, WorldError> {
    let mut fed: Vec<(String, String)> = r
        .rows::<FedWith>()?
        .into_iter()
        .map(|t| (t.p.to_string(), t.lead.to_string()))
        .collect();
    fed.sort();
    Ok(fed)
}

/// Every piece's box size (length, width, thickness; m) by id (`piece_size`).
pub fn piece_sizes(r: &Reasoned) -> Result<BTreeMap<String, [f64; 3]>, WorldError> {
    const REL: &str = PieceSize::RELATION;
    r.rows::<PieceSize>()?
        .into_iter()
        .map(|t| {
            let size = [t.length, t.width, t.thickness];
            for x in size {
                finite(REL, x, &t)?;
            }
            Ok((t.p.to_string(), size))
        })
        .collect()
}
