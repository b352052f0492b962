//! The simulation world: a typed [`Scene`] (the cell's parts and every lumber piece with its
//! spawn pose on conveyor 1, size, mass, density and framing target) built from the reasoned
//! relations of `rules/targets.dl` and `rules/world.dl`, and its exporters (`json`, Webots
//! `wbt`).
//!
//! Frames: spawn poses and the cell's parts are in the cell frame (z up, floor at z = 0);
//! framing targets in the robot's base frame, and in the cell frame beside. A piece's pose is
//! its body frame: origin at the centre of mass, x along the length, y along the width,
//! z = x × y along the thickness; its box size is (length, width, thickness).

mod error;
pub mod json;
mod relations;
mod scene;
pub mod wbt;

pub use error::WorldError;
pub use relations::{
    FramingTarget, Spawn, WorldPiece, framing_target_walls, framing_targets, spawn_beyond_belt,
    spawns, world_pieces,
};
pub use scene::{Scene, SceneConveyor, ScenePiece, ScenePly, SceneRobot, SceneWall, webots_proto};
