//! A model with its split walls cut into their panels: what the cell builds.
//!
//! `frame::panels` decides where each wall is split; this module makes those panels pieces
//! of a model, so every later stage (placement, targets, the scene, the executor, the cache,
//! the verdicts) works per panel without knowing about panels:
//! - a plate cut at a break becomes its segments (`PLATE~k`, the plate's box shortened to the
//!   segment's u range), in the plate's place in file order;
//! - an end stud a break adds (`STUD~endK`) is a copy of the stud it mirrors, moved along the
//!   wall to its u range, right after that stud in file order;
//! - every piece of a split wall gets a `panel_piece(piece, wall, panel)` fact: the rules
//!   (`rules/walls.dl`) never join pieces of two panels into one wall, so each panel is a
//!   wall of its own, framed in its own frame.
//!
//! Walls that fit are not touched; a model with no split wall needs no panelized model.

use super::Facts;
use super::panel::PanelOf;
use super::plan::{Plan, Wall};
use crate::geom::OrientedBox;
use crate::ifc::{Model, Piece};
use crate::logic::{Origin, Value};
use nalgebra::Vector3;
use std::collections::BTreeMap;

/// A model whose split walls are cut into panels.
pub struct Panelized {
    pub model: Model,
    /// The panel of every piece of a split wall (derived pieces included).
    pub panel_of: BTreeMap<String, PanelOf>,
    /// `panel_piece` facts for the rules.
    pub facts: Facts,
}

/// The panel each piece of `plan`'s walls belongs to (every wall, split or not; derived pieces
/// included): how a plan of the panelized model names its walls after the panels.
pub fn panels_by_piece(plan: &Plan) -> BTreeMap<String, PanelOf> {
    let mut out = BTreeMap::new();
    for wall in &plan.walls {
        let of = |panel_id: String, index: usize| PanelOf {
            wall_id: wall.id.clone(),
            wall_name: wall.name.clone(),
            wall_key: wall.key.clone(),
            panel_id,
            index,
        };
        if wall.panels.panels.len() <= 1 {
            let id = wall
                .panels
                .panels
                .first()
                .map_or_else(|| format!("{}-P1", wall.id), |p| p.id.clone());
            for m in &wall.members {
                out.insert(m.clone(), of(id.clone(), 0));
            }
            continue;
        }
        for panel in &wall.panels.panels {
            let ids = panel
                .member_ids
                .iter()
                .chain(panel.cut_pieces.iter().map(|c| &c.id))
                .chain(panel.added_pieces.iter().map(|a| &a.id));
            for id in ids {
                out.insert(id.clone(), of(panel.id.clone(), panel.index));
            }
        }
    }
    out
}

/// The model with `plan`'s split walls cut into panels; None when no wall is split.
pub fn panelize(model: &Model, plan: &Plan) -> Option<Panelized> {
    let split: Vec<&Wall> = plan
        .walls
        .iter()
        .filter(|w| w.panels.panels.len() > 1)
        .collect();
    if split.is_empty() {
        return None;
    }
    // What replaces a piece (its segments) and what follows it (added studs).
    let mut replaced: BTreeMap<&str, Vec<Piece>> = BTreeMap::new();
    let mut following: BTreeMap<&str, Vec<Piece>> = BTreeMap::new();
    let by_id: BTreeMap<&str, &Piece> = model.pieces().iter().map(|p| (p.id.as_str(), p)).collect();
    for wall in &split {
        for panel in &wall.panels.panels {
            for cut in &panel.cut_pieces {
                let Some(plate) = by_id.get(cut.of.as_str()) else {
                    continue;
                };
                let mut piece = derived(plate, &cut.id);
                piece.obox = segment_box(&plate.obox, wall, cut.u_start, cut.u_end);
                replaced.entry(plate.id.as_str()).or_default().push(piece);
            }
            for added in &panel.added_pieces {
                let Some(stud) = by_id.get(added.of.as_str()) else {
                    continue;
                };
                let mut piece = derived(stud, &added.id);
                piece.obox = moved_box(&stud.obox, wall, added.u_start, added.u_end);
                following.entry(stud.id.as_str()).or_default().push(piece);
            }
        }
    }
    let mut pieces = Vec::with_capacity(model.pieces().len() + following.len());
    for p in model.pieces() {
        match replaced.get_mut(p.id.as_str()) {
            Some(segments) => pieces.append(segments),
            None => pieces.push(p.clone()),
        }
        if let Some(more) = following.get_mut(p.id.as_str()) {
            pieces.append(more);
        }
    }
    let panel_of: BTreeMap<String, PanelOf> = panels_by_piece(plan)
        .into_iter()
        .filter(|(_, of)| split.iter().any(|w| w.key == of.wall_key))
        .collect();
    let entity: BTreeMap<&str, u64> = pieces.iter().map(|p| (p.id.as_str(), p.entity)).collect();
    let mut facts = Facts::default();
    for (piece, of) in &panel_of {
        let Some(&e) = entity.get(piece.as_str()) else {
            continue;
        };
        facts.add(
            "panel_piece",
            vec![
                Value::sym(piece),
                Value::sym(&of.wall_key),
                Value::sym(&of.panel_id),
            ],
            Origin::Entity(e),
        );
    }
    Some(Panelized {
        model: model.with_pieces(pieces),
        panel_of,
        facts,
    })
}

/// The box of a level plate cut to `u_start..u_end` of its wall (world frame): the plate's
/// length axis runs along the wall's u.
pub fn segment_box(plate: &OrientedBox, wall: &Wall, u_start: f64, u_end: f64) -> OrientedBox {
    let mut b = moved_box(plate, wall, u_start, u_end);
    b.half[0] = (u_end - u_start) / 2.0;
    b
}

/// A box moved along its wall's u so that its middle lies at the middle of `u_start..u_end`.
pub fn moved_box(b: &OrientedBox, wall: &Wall, u_start: f64, u_end: f64) -> OrientedBox {
    let origin = wall.frame.translation.vector;
    let along = wall.frame.rotation * Vector3::x();
    let mid = (b.centre.coords - origin).dot(&along);
    let mut moved = *b;
    moved.centre += along * ((u_start + u_end) / 2.0 - mid);
    moved
}

/// A piece derived from `from` (same product, material, container), named `id`.
fn derived(from: &Piece, id: &str) -> Piece {
    Piece {
        id: id.to_string(),
        ..from.clone()
    }
}
