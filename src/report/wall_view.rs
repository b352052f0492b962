//! What the drawings of one wall show, gathered once from the simulation and its report:
//! every piece with its verdict, its outline in the wall frame (u along, v up) and in the
//! cell's top view, every nailing target, the wall's operations and figures.

use super::causes::{RootCause, root_causes};
use super::simulate::{PanelRow, SimReport};
use super::verdict;
use crate::frame::panel::PanelOf;
use crate::frame::panel::WallPanels;
use crate::ifc::Model;
use crate::sim::Simulation;
use crate::sim::record::{NailOutcome, WallRecord};
use nalgebra::Point3;

pub struct PieceView {
    /// Piece id (GlobalId, or GlobalId/k).
    pub id: String,
    pub guid: String,
    /// The IFC name ("" when none).
    pub name: String,
    /// The product's `#entity`, when the model is at hand.
    pub entity: Option<u64>,
    pub role: String,
    pub class: &'static str,
    /// The first reason of its framing, else of its nailing ("" when none).
    pub reason: String,
    /// (u0, v0, u1, v1) in the wall frame, m.
    pub wall_rect: [f64; 4],
    /// Its outline at its framing target seen from above (cell x, y), m.
    pub plan_outline: Vec<[f64; 2]>,
}

pub struct NailView {
    pub u: f64,
    pub v: f64,
    pub driven: bool,
    /// `plate -> member #k` and what became of it.
    pub label: String,
}

pub struct WallView<'a> {
    /// The run's wall as the plan names it: `W1`, or `W1-P2` for a panel of a split wall.
    pub id: &'a str,
    /// Its verdict row: the panel the cell built.
    pub row: &'a PanelRow,
    pub record: &'a WallRecord,
    pub pieces: Vec<PieceView>,
    pub nails: Vec<NailView>,
    pub causes: Vec<RootCause>,
    /// Smallest reach margin of the wall's solved pick and place poses (m).
    pub min_margin: Option<f64>,
    /// The wall's panels (one when it fits the cell); for a panel of a split wall, the whole
    /// wall's.
    pub panels: &'a WallPanels,
    /// The whole wall this is a panel of, when it was split.
    pub panel: Option<&'a PanelOf>,
}

impl<'a> WallView<'a> {
    /// The view of the simulated wall `wall_id` (as the plan names it: a wall, or a panel of a
    /// split wall); `None` when the simulation has no such wall. `model` (the simulation's,
    /// `Simulation::model`) supplies `#entity` numbers when given.
    pub fn new(
        sim: &'a Simulation,
        report: &'a SimReport,
        model: Option<&Model>,
        wall_id: &str,
    ) -> Option<WallView<'a>> {
        let plan_wall = sim.plan.walls.iter().find(|w| w.id == wall_id)?;
        // The report's panel rows follow the records.
        let at = sim.records.iter().position(|r| r.wall == plan_wall.key)?;
        let (record, row) = (&sim.records[at], report.panels.get(at)?);
        let scene_wall = sim.scene.walls.iter().find(|w| w.id == plan_wall.key)?;
        let to_wall = scene_wall.wall_to_robot.inverse();
        let mut pieces = Vec::new();
        for id in &scene_wall.pieces {
            let Some(p) = sim.scene.pieces.iter().find(|p| &p.id == id) else {
                continue;
            };
            let element = report.elements.iter().find(|e| &e.id == id);
            let [l, w, t] = p.size.map(|v| v / 2.0);
            let corners: Vec<Point3<f64>> = [-1.0, 1.0]
                .into_iter()
                .flat_map(|a| {
                    [-1.0, 1.0].into_iter().flat_map(move |b| {
                        [-1.0, 1.0]
                            .into_iter()
                            .map(move |c| Point3::new(a * l, b * w, c * t))
                    })
                })
                .collect();
            let in_wall: Vec<Point3<f64>> = corners
                .iter()
                .map(|c| to_wall * (p.target_robot * c))
                .collect();
            let rect = [
                in_wall.iter().map(|c| c.x).fold(f64::INFINITY, f64::min),
                in_wall.iter().map(|c| c.y).fold(f64::INFINITY, f64::min),
                in_wall
                    .iter()
                    .map(|c| c.x)
                    .fold(f64::NEG_INFINITY, f64::max),
                in_wall
                    .iter()
                    .map(|c| c.y)
                    .fold(f64::NEG_INFINITY, f64::max),
            ];
            let top: Vec<[f64; 2]> = corners
                .iter()
                .map(|c| {
                    let q = p.target_cell * c;
                    [q.x, q.y]
                })
                .collect();
            let reason = element
                .and_then(|e| {
                    e.framing
                        .reasons
                        .first()
                        .or(e.nailing.reasons.first())
                        .map(|r| format!("{}: {}", r.component, r.message))
                })
                .unwrap_or_default();
            let entity =
                model.and_then(|m| m.pieces.iter().find(|mp| &mp.id == id).map(|mp| mp.entity));
            pieces.push(PieceView {
                id: id.clone(),
                guid: id.split('/').next().unwrap_or(id).to_string(),
                name: p.name.clone(),
                entity,
                role: element.map(|e| e.role.clone()).unwrap_or_default(),
                class: element.map_or("not-attempted", verdict::of),
                reason,
                wall_rect: rect,
                plan_outline: convex_hull(top),
            });
        }
        let nails = record
            .nails
            .iter()
            .map(|n| {
                let (driven, what) = match &n.outcome {
                    NailOutcome::Fired { position_error, .. } => (
                        true,
                        format!("driven, {:.2} mm off", position_error * 1000.0),
                    ),
                    NailOutcome::Skipped { message, .. } => {
                        (false, format!("not driven: {message}"))
                    }
                };
                NailView {
                    u: n.planned[0],
                    v: n.planned[1],
                    driven,
                    label: format!("nail {} -> {} #{}: {what}", n.plate, n.member, n.k),
                }
            })
            .collect();
        let min_margin = record
            .ik
            .iter()
            .filter_map(|r| r.result.as_ref().ok().copied())
            .reduce(f64::min);
        Some(WallView {
            id: &plan_wall.id,
            row,
            record,
            pieces,
            nails,
            causes: root_causes(report, wall_id),
            min_margin,
            panels: &plan_wall.panels,
            panel: plan_wall.panel.as_ref().filter(|p| p.index > 0),
        })
    }

    /// Pieces placed of those in the wall.
    pub fn placed(&self) -> (usize, usize) {
        (self.record.placements.len(), self.pieces.len())
    }

    /// Nails driven of those planned.
    pub fn driven(&self) -> (usize, usize) {
        (
            self.nails.iter().filter(|n| n.driven).count(),
            self.nails.len(),
        )
    }
}

/// The convex hull of points, counter-clockwise (monotone chain).
fn convex_hull(mut points: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    points.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    points.dedup_by(|a, b| (a[0] - b[0]).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-12);
    if points.len() < 3 {
        return points;
    }
    let cross = |o: &[f64; 2], a: &[f64; 2], b: &[f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(points.iter())
        } else {
            Box::new(points.iter().rev())
        };
        for p in iter {
            while hull.len() >= start + 2
                && cross(&hull[hull.len() - 2], &hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    hull
}
