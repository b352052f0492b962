//! The scene: what the simulators build, from a model, a cell and the reasoned relations.

use super::WorldError;
use super::relations::{
    fed_with, framing_target_walls, framing_targets, piece_sizes, spawn_beyond_belt, spawns,
    world_pieces,
};
use crate::cell::{Cell, Conveyor, Floor, PlacedShape, ToolTable, TouchSensor};
use crate::frame::{Ask, Reasoned, RuleEngine, cell_facts, model_facts};
use crate::geom::ContactOptions;
use crate::ifc::Model;
use nalgebra::Isometry3;
use std::collections::BTreeMap;
use std::path::Path;

/// The robot as the scene places it.
#[derive(Debug, Clone)]
pub struct SceneRobot {
    /// framewright's robot name (e.g. `abb-irb4600-40-255`).
    pub name: String,
    pub description: Option<String>,
    /// `base_link` in the cell frame.
    pub base: Isometry3<f64>,
    /// The Webots proto of this robot and its R2023b URL, where one exists.
    pub webots_proto: Option<(&'static str, &'static str)>,
    /// Collision shapes of the base link (in its frame), for simulators without a robot model.
    pub base_shapes: Vec<PlacedShape>,
}

/// A conveyor by name (`conveyor 1`, `conveyor 2`).
#[derive(Debug, Clone)]
pub struct SceneConveyor {
    pub name: &'static str,
    pub conveyor: Conveyor,
}

/// A wall: its laid-flat frame in the robot frame and its pieces in spawn order (the plies
/// of a pre-assembled member after its lead, with no `ScenePiece` of their own).
#[derive(Debug, Clone)]
pub struct SceneWall {
    pub id: String,
    pub wall_to_robot: Isometry3<f64>,
    pub pieces: Vec<String>,
}

/// One lumber piece of the world.
#[derive(Debug, Clone)]
pub struct ScenePiece {
    /// Piece id (GlobalId, or GlobalId/k).
    pub id: String,
    pub name: String,
    pub ifc_type: String,
    pub wall: String,
    /// Position in the conveyor 1 queue (0 = first to be picked).
    pub slot: usize,
    /// Length, width, thickness (m): the box along the body axes x, y, z.
    pub size: [f64; 3],
    pub material: String,
    /// kg/m³
    pub density: f64,
    /// kg
    pub mass: f64,
    /// Body frame on conveyor 1, cell frame.
    pub spawn: Isometry3<f64>,
    /// How far the piece reaches beyond the upstream end of conveyor 1 (m), when it does.
    pub beyond_belt: Option<f64>,
    /// Body frame placed in the wall laid flat, robot frame.
    pub target_robot: Isometry3<f64>,
    /// The same in the cell frame.
    pub target_cell: Isometry3<f64>,
    /// Whether it lies on edge (width vertical) at its target; false for pieces that lie flat
    /// there, such as headers set on edge in the wall (`framing_flat`).
    pub on_edge: bool,
    /// The other plies of a pre-assembled member this piece leads (`fed_with`): they ride in
    /// it, its size and target being the whole member's.
    pub plies: Vec<ScenePly>,
}

/// A ply fed inside a pre-assembled member: not a body of its own.
#[derive(Debug, Clone)]
pub struct ScenePly {
    pub id: String,
    /// Length, width, thickness (m) of the ply alone.
    pub size: [f64; 3],
    /// Its own framing target (body frame), cell frame.
    pub target_cell: Isometry3<f64>,
}

/// Everything a simulator needs to build the cell and its lumber.
#[derive(Debug, Clone)]
pub struct Scene {
    /// The source model as named on the command line (file name).
    pub model: String,
    pub cell: String,
    /// The cell file (`robots/cells/<name>.toml` for built-ins).
    pub cell_source: String,
    pub robot: SceneRobot,
    pub floor: Floor,
    pub conveyors: Vec<SceneConveyor>,
    pub lumber_gap: f64,
    pub touch_sensor: TouchSensor,
    pub tool_table: ToolTable,
    /// Walls by id.
    pub walls: Vec<SceneWall>,
    /// Pieces in spawn order (slot 0 first).
    pub pieces: Vec<ScenePiece>,
    /// `frame_warning` messages as `subject: message`, sorted.
    pub warnings: Vec<String>,
}

/// The Webots proto (name, R2023b URL) of a framewright robot, where Webots ships one.
/// Webots has the ABB IRB 4600/40 (`projects/robots/abb/irb/protos/Irb4600-40.proto`); it has
/// no KUKA KR 150-2.
pub fn webots_proto(robot: &str) -> Option<(&'static str, &'static str)> {
    match robot {
        "abb-irb4600-40-255" => Some((
            "Irb4600-40",
            "https://raw.githubusercontent.com/cyberbotics/webots/R2023b/projects/robots/abb/irb/protos/Irb4600-40.proto",
        )),
        _ => None,
    }
}

impl Scene {
    /// Opens a model, reasons with the built-in (compiled) rules and builds its scene.
    pub fn from_model_file(path: &Path, cell: &Cell) -> Result<Scene, WorldError> {
        let model = Model::open(path)?;
        let mut facts = model_facts(&model, &ContactOptions::default());
        facts.extend(cell_facts(cell));
        let reasoned = Ask::new(&RuleEngine::Compiled).placed(facts, cell)?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        Scene::build(&name, &model, cell, &reasoned)
    }

    /// The scene of a model whose facts (model + cell) were reasoned into `r`.
    pub fn build(
        model_name: &str,
        model: &Model,
        cell: &Cell,
        r: &Reasoned,
    ) -> Result<Scene, WorldError> {
        let targets: BTreeMap<String, (String, Isometry3<f64>)> = framing_targets(r)?
            .into_values()
            .flatten()
            .map(|t| (t.piece, (t.wall, t.pose)))
            .collect();
        let sizes = world_pieces(r)?;
        let beyond = spawn_beyond_belt(r)?;
        let materials: BTreeMap<&str, (&str, f64)> = r
            .get("piece_material")
            .iter()
            .filter_map(|t| Some((t[0].as_symbol()?, (t[1].as_symbol()?, t[2].as_float()?))))
            .collect();
        let flat: std::collections::BTreeSet<&str> = r
            .get("framing_flat")
            .iter()
            .filter_map(|t| t.first()?.as_symbol())
            .collect();
        let products: BTreeMap<&str, _> =
            model.pieces().iter().map(|p| (p.id.as_str(), p)).collect();
        let piece_sizes = piece_sizes(r)?;
        let mut plies: BTreeMap<String, Vec<ScenePly>> = BTreeMap::new();
        for (ply, lead) in fed_with(r)? {
            let incomplete = |missing| WorldError::Incomplete {
                piece: ply.clone(),
                missing,
            };
            let (_, target) = targets
                .get(&ply)
                .ok_or_else(|| incomplete("framing target (framing_target)"))?;
            let size = *piece_sizes
                .get(&ply)
                .ok_or_else(|| incomplete("size (piece_size)"))?;
            let target_cell = cell.robot_base * target;
            plies.entry(lead).or_default().push(ScenePly {
                id: ply,
                size,
                target_cell,
            });
        }

        let mut pieces = Vec::new();
        for s in spawns(r)? {
            let incomplete = |missing| WorldError::Incomplete {
                piece: s.piece.clone(),
                missing,
            };
            let (wall, target) = targets
                .get(&s.piece)
                .cloned()
                .ok_or_else(|| incomplete("framing target (framing_target)"))?;
            let size = sizes
                .get(&s.piece)
                .ok_or_else(|| incomplete("size and mass (world_piece)"))?;
            let &(material, density) = materials
                .get(s.piece.as_str())
                .ok_or_else(|| incomplete("material (piece_material)"))?;
            let product = products.get(s.piece.as_str());
            pieces.push(ScenePiece {
                name: product.and_then(|p| p.name.clone()).unwrap_or_default(),
                ifc_type: product.map(|p| p.ifc_type.clone()).unwrap_or_default(),
                wall,
                slot: s.slot,
                size: size.size,
                material: material.to_string(),
                density,
                mass: size.mass,
                spawn: s.pose,
                beyond_belt: beyond.get(&s.piece).copied(),
                target_robot: target,
                target_cell: cell.robot_base * target,
                on_edge: !flat.contains(s.piece.as_str()),
                plies: plies.remove(&s.piece).unwrap_or_default(),
                id: s.piece,
            });
        }

        let walls = framing_target_walls(r)?
            .into_iter()
            .map(|(id, wall_to_robot)| SceneWall {
                // A pre-assembled member's plies follow its lead: elements, not bodies.
                pieces: pieces
                    .iter()
                    .filter(|p| p.wall == id)
                    .flat_map(|p| {
                        std::iter::once(p.id.clone()).chain(p.plies.iter().map(|q| q.id.clone()))
                    })
                    .collect(),
                id,
                wall_to_robot,
            })
            .collect();
        let mut warnings: Vec<String> = r
            .get("frame_warning")
            .iter()
            .chain(r.get("world_warning"))
            .filter_map(|t| Some(format!("{}: {}", t[0].as_symbol()?, t[1].as_symbol()?)))
            .collect();
        warnings.sort();
        warnings.dedup();

        let base_shapes = cell
            .robot
            .links
            .first()
            .map(|l| l.collisions.clone())
            .unwrap_or_default();
        Ok(Scene {
            model: model_name.to_string(),
            cell: cell.name.clone(),
            cell_source: cell.source.display().to_string(),
            robot: SceneRobot {
                name: cell.robot.name.clone(),
                description: cell.robot.meta.description.clone(),
                base: cell.robot_base,
                webots_proto: webots_proto(&cell.robot.name),
                base_shapes,
            },
            floor: cell.floor,
            conveyors: vec![
                SceneConveyor {
                    name: "conveyor 1",
                    conveyor: cell.conveyor1,
                },
                SceneConveyor {
                    name: "conveyor 2",
                    conveyor: cell.conveyor2,
                },
            ],
            lumber_gap: cell.lumber_gap,
            touch_sensor: cell.touch_sensor,
            tool_table: cell.tool_table,
            walls,
            pieces,
            warnings,
        })
    }
}
