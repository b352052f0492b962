//! A plan built from the reasoned relations: each wall with its frame, members, order and
//! targets, split into the panels the cell's limits allow (`panels`), and named after the
//! panels of the whole model when it is a panelized model's (`panelize`).

use super::panel::WallPanels;
use super::panels;
use super::plan::{NailingTarget, Plan, Wall};
use super::rows::{
    self, AssemblyRank, FrameWarning, FramingTarget, PieceMaterial, Precedence, Role, Row,
    RowError, WallFrame, WallGroup, WallOf, WallSize, rows_of,
};
use super::{FrameError, Reasoned};
use crate::geom::Point3;
use crate::ifc::Model;
use crate::logic::compiled::Relations;
use nalgebra::Isometry3;
use rustc_hash::FxHashMap;
use std::collections::BTreeMap;

/// `rows` bucketed by the wall of the piece `piece` names (rows of pieces in no wall dropped).
fn by_wall_of<'r, R>(
    rows: &'r [R],
    piece: impl Fn(&R) -> &'static str,
    wall_of_piece: &FxHashMap<&str, &'static str>,
) -> FxHashMap<&'static str, Vec<&'r R>> {
    let mut by: FxHashMap<&str, Vec<&R>> = FxHashMap::default();
    for t in rows {
        if let Some(w) = wall_of_piece.get(piece(t)) {
            by.entry(*w).or_default().push(t);
        }
    }
    by
}

impl Plan {
    /// The relations `from_reasoned` reads (`Ask::only` returns only these).
    pub const RELATIONS: &'static [&'static str] = super::rule_reads::PLAN;

    /// Collects the plan from the rule base's relations (missing relations give empty parts);
    /// an error when a tuple does not match its relation's declaration.
    pub fn from_reasoned(model: &Model, r: &Reasoned) -> Result<Plan, FrameError> {
        // The relations alone (the interpreter `r` may hold is not shared between threads).
        Plan::from_relations(model, &r.relations)
    }

    /// `from_reasoned` on the relations alone (others than `RELATIONS` are not read).
    pub fn from_relations(model: &Model, relations: &Relations) -> Result<Plan, FrameError> {
        use rayon::prelude::*;
        // Lookups borrow the relations' symbols; only what the plan keeps is copied.
        let index = model.piece_positions();
        let file_order = |p: &str| index.get(p).copied().unwrap_or(usize::MAX);
        let wall_pairs = rows_of::<WallOf>(relations)?;
        let wall_of_piece: FxHashMap<&str, &'static str> =
            wall_pairs.iter().map(|t| (t.p, t.w)).collect();
        // The per-piece maps and the walls are built side by side.
        let piece_maps = || -> Result<_, RowError> {
            let roles: BTreeMap<String, String> = rows_of::<Role>(relations)?
                .into_iter()
                .map(|t| (t.p.to_string(), t.r.to_string()))
                .collect();
            let masses: BTreeMap<String, f64> = rows_of::<PieceMaterial>(relations)?
                .into_iter()
                .filter_map(|t| {
                    let p = model.pieces().get(*index.get(t.p)?)?;
                    Some((p.id.clone(), p.obox.volume() * t.density))
                })
                .collect();
            Ok((roles, masses))
        };
        let build_walls = || -> Result<Vec<Wall>, RowError> {
            let groups: FxHashMap<&str, (&str, &str)> = rows_of::<WallGroup>(relations)?
                .into_iter()
                .map(|t| (t.w, (t.g, t.g_name)))
                .collect();
            let frames: FxHashMap<&str, Isometry3<f64>> = rows_of::<WallFrame>(relations)?
                .into_iter()
                .map(|t| (t.w, t.f))
                .collect();
            let sizes: FxHashMap<&str, [f64; 3]> = rows_of::<WallSize>(relations)?
                .into_iter()
                .map(|t| (t.w, [t.length, t.height, t.thickness]))
                .collect();
            let ranks: FxHashMap<&str, i64> = rows_of::<AssemblyRank>(relations)?
                .into_iter()
                .map(|t| (t.p, t.k))
                .collect();

            // Walls in file order of their key piece.
            let mut keys: Vec<&str> = rows_of::<rows::Wall>(relations)?
                .into_iter()
                .map(|t| t.w)
                .collect();
            keys.sort_by_key(|k| file_order(k));
            // Members, precedence, nailing and framing targets bucketed by wall in one pass each.
            // Each member with its place in the file, looked up once (not in every comparison).
            let mut members: FxHashMap<&str, Vec<(usize, &str)>> = FxHashMap::default();
            for (p, w) in &wall_of_piece {
                members.entry(w).or_default().push((file_order(p), p));
            }
            let precedences = rows_of::<Precedence>(relations)?;
            let mut precedence_by: FxHashMap<&str, Vec<&Precedence>> = FxHashMap::default();
            for t in &precedences {
                if let (Some(w), Some(w2)) =
                    (wall_of_piece.get(t.before), wall_of_piece.get(t.after))
                    && w == w2
                {
                    precedence_by.entry(w).or_default().push(t);
                }
            }
            let nails = rows_of::<rows::NailingTarget>(relations)?;
            let nails_by = by_wall_of(&nails, |t| t.plate, &wall_of_piece);
            let framings = rows_of::<FramingTarget>(relations)?;
            let framing_by = by_wall_of(&framings, |t| t.p, &wall_of_piece);
            let walls: Vec<Wall> = keys
                .par_iter()
                .enumerate()
                .map(|(n, &key)| {
                    // Sort keys are distinct for distinct pieces: unstable sorts give the
                    // stable order.
                    let mut placed = members.get(key).cloned().unwrap_or_default();
                    placed.sort_unstable();
                    let list: Vec<&str> = placed.iter().map(|(_, p)| *p).collect();
                    let mut ranked: Vec<(i64, usize, &str)> = placed
                        .iter()
                        .map(|&(at, p)| (ranks.get(p).copied().unwrap_or(i64::MAX), at, p))
                        .collect();
                    ranked.sort_unstable();
                    let order: Vec<&str> = ranked.iter().map(|(_, _, p)| *p).collect();
                    let mut precedence: Vec<(String, String, String)> = precedence_by
                        .get(key)
                        .into_iter()
                        .flatten()
                        .map(|t| {
                            (
                                t.before.to_string(),
                                t.after.to_string(),
                                t.reason.to_string(),
                            )
                        })
                        .collect();
                    precedence.sort();
                    let mut nailing_targets: Vec<NailingTarget> = nails_by
                        .get(key)
                        .into_iter()
                        .flatten()
                        .map(|t| NailingTarget {
                            plate: t.plate.to_string(),
                            member: t.member.to_string(),
                            kind: t.kind.to_string(),
                            u: t.u,
                            v: t.v,
                            w: t.w,
                            world: Point3::from(t.world),
                            direction: t.direction,
                        })
                        .collect();
                    nailing_targets.sort_by(|a, b| {
                        (a.u, a.v, a.w)
                            .partial_cmp(&(b.u, b.v, b.w))
                            .unwrap_or(std::cmp::Ordering::Equal)
                    });
                    let position: FxHashMap<&str, usize> =
                        order.iter().enumerate().map(|(i, p)| (*p, i)).collect();
                    let mut framing: Vec<(&str, Isometry3<f64>)> = framing_by
                        .get(key)
                        .into_iter()
                        .flatten()
                        .map(|t| (t.p, t.pose))
                        .collect();
                    framing.sort_by_key(|(p, _)| position.get(p).copied());
                    let group = groups.get(key);
                    let size = sizes.get(key).copied().unwrap_or([f64::NAN; 3]);
                    let strings = |v: Vec<&str>| v.into_iter().map(str::to_string).collect();
                    Wall {
                        id: group.map_or_else(|| format!("W{}", n + 1), |(g, _)| g.to_string()),
                        name: group.map_or_else(
                            || format!("Wall {}", n + 1),
                            |(_, name)| name.to_string(),
                        ),
                        key: key.to_string(),
                        group_global_id: group.map(|(g, _)| g.to_string()),
                        members: strings(list),
                        frame: frames.get(key).copied().unwrap_or_else(Isometry3::identity),
                        length: size[0],
                        height: size[1],
                        thickness: size[2],
                        assembly_order: strings(order),
                        precedence,
                        nailing_targets,
                        framing_targets: framing
                            .into_iter()
                            .map(|(p, pose)| (p.to_string(), pose))
                            .collect(),
                        panels: WallPanels::default(),
                        panel: None,
                    }
                })
                .collect();
            Ok(walls)
        };
        let (maps, walls) = rayon::join(piece_maps, build_walls);
        let ((roles, masses), mut walls) = (maps?, walls?);
        let panel_limits = panels::limits_from(relations);
        if let Some(limits) = &panel_limits {
            panels::split_walls(&mut walls, relations, &roles, &masses, limits);
        }
        let wall_ids: FxHashMap<&str, &str> = walls
            .iter()
            .map(|w| (w.key.as_str(), w.id.as_str()))
            .collect();
        // From the relation's rows, which come sorted by piece: the map is built without sorting.
        let wall_of = wall_pairs
            .iter()
            .map(|t| {
                (
                    t.p.to_string(),
                    wall_ids.get(t.w).unwrap_or(&t.w).to_string(),
                )
            })
            .collect();
        let mut warnings: Vec<String> = rows_of::<FrameWarning>(relations)?
            .into_iter()
            .map(|t| {
                let subject = wall_ids.get(t.subject).copied().unwrap_or(t.subject);
                format!("{subject}: {}", t.message)
            })
            .collect();
        warnings.extend(panel_warnings(&walls));
        if walls.is_empty() {
            warnings.push(no_walls_reason(model, relations));
        }
        Ok(Plan {
            walls,
            wall_of,
            roles,
            masses,
            warnings,
            panel_limits,
        })
    }
}

impl Plan {
    /// What the panel split could not do, by wall or panel: limits dropped, breaks not made,
    /// panels over a limit.
    pub fn panel_warnings(&self) -> Vec<String> {
        panel_warnings(&self.walls)
    }

    /// Names the walls of a plan of a panelized model after the panels of the whole model's
    /// plan `whole`: a panel of a split wall becomes `W1-P2` (name "Wall 1, panel 2") and holds
    /// its whole wall's split (`panels`, all of them); a wall that fits takes its whole wall's
    /// id and name back; warnings follow.
    pub fn name_after_panels(&mut self, whole: &Plan) {
        let panel_of = super::panelize::panels_by_piece(whole);
        let splits: BTreeMap<&str, &WallPanels> = whole
            .walls
            .iter()
            .map(|w| (w.key.as_str(), &w.panels))
            .collect();
        let mut renamed: BTreeMap<String, String> = BTreeMap::new();
        for wall in &mut self.walls {
            let Some(of) = panel_of.get(&wall.key) else {
                continue;
            };
            let (id, name) = (of.unit_id().to_string(), of.unit_name());
            renamed.insert(std::mem::replace(&mut wall.id, id), wall.id.clone());
            wall.name = name;
            match splits.get(of.wall_key.as_str()) {
                Some(split) if of.index > 0 => wall.panels = (*split).clone(),
                _ => {
                    if let Some(panel) = wall.panels.panels.first_mut() {
                        panel.id.clone_from(&of.panel_id);
                    }
                }
            }
            wall.panel = Some(of.clone());
        }
        for id in self.wall_of.values_mut() {
            if let Some(new) = renamed.get(id.as_str()) {
                id.clone_from(new);
            }
        }
        for warning in &mut self.warnings {
            if let Some((subject, rest)) = warning.split_once(": ")
                && let Some(new) = renamed.get(subject)
            {
                *warning = format!("{new}: {rest}");
            }
        }
    }
}

/// What the panel split of `walls` could not do: limits dropped, breaks not made, panels over
/// a limit.
fn panel_warnings(walls: &[Wall]) -> Vec<String> {
    let mut warnings = vec![];
    for wall in walls {
        let split = &wall.panels;
        warnings.extend(split.notes.iter().map(|n| format!("{}: {n}", wall.id)));
        for panel in &split.panels {
            if !panel.exceeds.is_empty() {
                warnings.push(format!(
                    "{}: the panel exceeds the cell's panel limits: {}",
                    panel.id,
                    panel.exceeds.join(", ")
                ));
            }
        }
    }
    warnings
}

/// Why a model gave no wall frames, in the user's terms.
fn no_walls_reason(model: &Model, relations: &Relations) -> String {
    let count = |relation: &str| relations.get(relation).map_or(0, Vec::len);
    let pieces = model.pieces().len();
    if pieces == 0 {
        return "no wall frames: the model holds no members, columns, beams, plates or proxies with solid geometry".into();
    }
    let lumber = count(rows::Lumber::RELATION);
    let upright = count(rows::Across::RELATION);
    let coplanar = count(rows::Coplanar::RELATION) / 2;
    format!(
        "no wall frames: of {pieces} pieces, {lumber} have lumber sections, {upright} stand plumb or lie level in a wall plane, and {coplanar} pairs touch in one plane; a wall needs at least three lumber pieces (plates and studs) touching in one vertical plane"
    )
}
