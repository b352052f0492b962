//! The robot cell: robots from URDF (links, joints, collision primitives, FK), closed-form and
//! numeric IK with failure reasons as data, tools with TCP frames, and cell layouts from TOML.
//!
//! Frames: every robot pose is in its `base_link` (z up); cell positions are in the cell frame
//! (floor at z = 0). SI units throughout (m, kg, s, rad); TOML files say `_deg` where they use
//! degrees.

mod builtin;
mod dls;
mod error;
mod ik;
pub mod io;
mod layout;
mod layout_file;
mod layout_parse;
mod load;
mod meta;
mod opw;
mod panels;
mod robot;
mod shapes;
pub mod tcp_poses;
mod toml_file;
mod tool;
pub mod track;
mod urdf_depth;

pub use builtin::{cell_names, robot_names, tool_names};
pub use error::{CellError, InvalidValue};
pub use ik::{IkFailure, IkOptions};
pub use layout::{
    Arrangement, Assembly, BuiltUpHeaders, Cell, Conveyor, Creep, Floor, Motion, OffsetX,
    Orientation, Pick, ToolTable, TouchSensor,
};
pub use meta::{OpwParams, RobotMeta};
pub use panels::{PanelLimits, PanelMode};
pub use robot::{Inertial, Joint, JointKind, Link, Robot};
pub use shapes::{PlacedShape, Shape, isometry_from_xyz_rpy};
pub use tool::{Gripper, Hold, Jaws, OneGripper, Tool, ToolPart, TopPads};
pub use track::Track;

use nalgebra::Isometry3;

/// A pose as a 4×4 row-major matrix (rows of the homogeneous transform).
pub fn matrix_rows(pose: &Isometry3<f64>) -> [[f64; 4]; 4] {
    let m = pose.to_homogeneous();
    std::array::from_fn(|r| std::array::from_fn(|c| m[(r, c)]))
}

pub(crate) fn serialize_isometry<S: serde::Serializer>(
    pose: &Isometry3<f64>,
    s: S,
) -> Result<S::Ok, S::Error> {
    use serde::Serialize;
    matrix_rows(pose).serialize(s)
}
