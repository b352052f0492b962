//! The scene as JSON (`framewright world --format json`). Same scene, same bytes: fields in a
//! fixed order, walls by id, pieces in spawn order, numbers rounded to 1e-12 m (which also
//! turns -0 into 0).
//!
//! A pose is `{"position": [x, y, z], "matrix": 4×4 row-major}` (columns: the body's x, y, z
//! axes and its origin).

use super::Scene;
use nalgebra::{Isometry3, Point3};
use serde::Serialize;

/// Rounds away floating-point noise (1e-12) and the sign of zero.
fn tidy(x: f64) -> f64 {
    let r = (x * 1e12).round() / 1e12;
    if r == 0.0 { 0.0 } else { r }
}

fn tidy3(v: [f64; 3]) -> [f64; 3] {
    v.map(tidy)
}

#[derive(Serialize)]
pub(crate) struct Pose {
    position: [f64; 3],
    matrix: [[f64; 4]; 4],
}

pub(crate) fn pose(p: &Isometry3<f64>) -> Pose {
    let t = p.translation.vector;
    Pose {
        position: tidy3([t.x, t.y, t.z]),
        matrix: crate::cell::matrix_rows(p).map(|r| r.map(tidy)),
    }
}

fn point(p: &Point3<f64>) -> [f64; 3] {
    tidy3([p.x, p.y, p.z])
}

#[derive(Serialize)]
struct Doc<'a> {
    schema: &'static str,
    model: &'a str,
    cell: &'a str,
    cell_source: &'a str,
    length_unit: &'static str,
    robot: Robot<'a>,
    floor: FloorJson,
    conveyors: Vec<ConveyorJson<'a>>,
    lumber_gap: f64,
    touch_sensor: SensorJson,
    tool_table: TableJson,
    walls: Vec<WallJson<'a>>,
    pieces: Vec<PieceJson<'a>>,
    warnings: &'a [String],
}

#[derive(Serialize)]
struct Robot<'a> {
    name: &'a str,
    description: Option<&'a str>,
    webots_proto: Option<&'static str>,
    base: Pose,
}

#[derive(Serialize)]
struct FloorJson {
    size: [f64; 2],
    z: f64,
}

#[derive(Serialize)]
struct ConveyorJson<'a> {
    name: &'a str,
    /// Centre of the belt top, x along travel.
    pose: Pose,
    direction: [f64; 3],
    length: f64,
    width: f64,
    speed: f64,
    upstream_end: [f64; 3],
    downstream_end: [f64; 3],
}

#[derive(Serialize)]
struct SensorJson {
    pose: Pose,
    size: [f64; 3],
    face: [f64; 3],
}

#[derive(Serialize)]
struct TableJson {
    top_centre: [f64; 3],
    size: [f64; 3],
    leg_height: f64,
}

#[derive(Serialize)]
struct WallJson<'a> {
    wall_id: &'a str,
    /// The wall frame (u along, v up, w inward) laid flat, robot frame.
    wall_to_robot: Pose,
    pieces: &'a [String],
}

#[derive(Serialize)]
struct TargetJson {
    robot: Pose,
    cell: Pose,
}

#[derive(Serialize)]
struct PieceJson<'a> {
    id: &'a str,
    name: &'a str,
    ifc_type: &'a str,
    wall_id: &'a str,
    slot: usize,
    size: [f64; 3],
    material: &'a str,
    density: f64,
    mass: f64,
    spawn: Pose,
    beyond_belt: Option<f64>,
    on_edge: bool,
    framing_target: TargetJson,
    /// The other plies of the pre-assembled member it is fed as (its size and target are the
    /// member's); omitted for a piece fed alone.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    plies: Vec<&'a str>,
}

/// The scene as pretty-printed JSON with a final newline.
pub fn to_json(scene: &Scene) -> String {
    let doc = Doc {
        schema: "framewright.world/1",
        model: &scene.model,
        cell: &scene.cell,
        cell_source: &scene.cell_source,
        length_unit: "m",
        robot: Robot {
            name: &scene.robot.name,
            description: scene.robot.description.as_deref(),
            webots_proto: scene.robot.webots_proto.map(|(name, _)| name),
            base: pose(&scene.robot.base),
        },
        floor: FloorJson {
            size: scene.floor.size.map(tidy),
            z: tidy(scene.floor.z),
        },
        conveyors: scene
            .conveyors
            .iter()
            .map(|c| {
                let d = c.conveyor.direction();
                ConveyorJson {
                    name: c.name,
                    pose: pose(&c.conveyor.pose),
                    direction: tidy3([d.x, d.y, d.z]),
                    length: tidy(c.conveyor.length),
                    width: tidy(c.conveyor.width),
                    speed: tidy(c.conveyor.speed),
                    upstream_end: point(&c.conveyor.upstream_end()),
                    downstream_end: point(&c.conveyor.downstream_end()),
                }
            })
            .collect(),
        lumber_gap: tidy(scene.lumber_gap),
        touch_sensor: SensorJson {
            pose: pose(&scene.touch_sensor.pose),
            size: tidy3(scene.touch_sensor.size),
            face: point(&scene.touch_sensor.face),
        },
        tool_table: TableJson {
            top_centre: point(&scene.tool_table.top_centre),
            size: tidy3(scene.tool_table.size),
            leg_height: tidy(scene.tool_table.leg_height),
        },
        walls: scene
            .walls
            .iter()
            .map(|w| WallJson {
                wall_id: &w.id,
                wall_to_robot: pose(&w.wall_to_robot),
                pieces: &w.pieces,
            })
            .collect(),
        pieces: scene
            .pieces
            .iter()
            .map(|p| PieceJson {
                id: &p.id,
                name: &p.name,
                ifc_type: &p.ifc_type,
                wall_id: &p.wall,
                slot: p.slot,
                size: tidy3(p.size),
                material: &p.material,
                density: tidy(p.density),
                mass: tidy(p.mass),
                spawn: pose(&p.spawn),
                beyond_belt: p.beyond_belt.map(tidy),
                on_edge: p.on_edge,
                framing_target: TargetJson {
                    robot: pose(&p.target_robot),
                    cell: pose(&p.target_cell),
                },
                plies: p.plies.iter().map(|q| q.id.as_str()).collect(),
            })
            .collect(),
        warnings: &scene.warnings,
    };
    let mut text = serde_json::to_string_pretty(&doc).expect("the scene serialises: plain data");
    text.push('\n');
    text
}
