//! framewright: IFC light wood-frame walls to a checked, simulated robotic assembly.
//!
//! Stages (each takes the previous stage's value and returns its own):
//! `step` (ISO 10303-21 bytes) → `ifc` (units, placements, lumber pieces) →
//! `logic` (rule language) → `cell` (robots, tools, layouts, kinematics).
//! See `docs/ARCHITECTURE.md` for the codemap.

pub mod atomic;
pub mod bim;
pub mod cache;
pub mod cell;
pub mod diff;
pub mod explain;
pub mod frame;
pub mod geom;
pub mod ifc;
pub mod logic;
pub mod pipeline;
pub mod program;
pub mod report;
pub mod sim;
pub mod step;
pub mod synth;
pub mod user_rules;
pub mod world;
