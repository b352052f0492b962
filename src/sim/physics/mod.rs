//! The rapier world of one wall's run: floor, conveyors (belts that carry lumber by friction),
//! the touch sensor and its end stop, the tool table, the robot's links and tool as
//! position-driven bodies, and the lumber as dynamic bodies with their sizes and densities.
//!
//! - `world`: the world's bodies, handles and groups, the f32/f64 conversions, stepping;
//! - `build`: the world of a cell; `belts`: the moving belt surfaces;
//! - `lumber`: pieces in, out, riding, held and nailed; `robot`: joints, jaws, nailer;
//! - `probe`: clearances and contacts, asked without stepping.

mod belts;
mod build;
mod lumber;
mod probe;
mod robot;
mod world;

pub use probe::Watch;
pub use world::{FINGER, GRAVITY, Physics, to_iso, to_pose};

#[cfg(test)]
mod tests;
