//! Cell layouts (`robots/cells/*.toml`): robot and base pose, tool, assembly area, the two
//! conveyors, the touch sensor at the end of conveyor 2, the tool table and the floor.
//! Positions are in the cell frame (z up, floor at z = 0 unless moved).
//!
//! Loading a cell from its TOML file is in `layout_parse.rs`.

use super::error::InvalidValue;
use super::io::Io;
use super::panels::{PanelLimits, PanelMode};
use super::robot::Robot;
use super::tool::Tool;
use super::track::Track;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;
use std::path::PathBuf;

/// Where each wall lies along the robot's x axis.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
#[serde(tag = "mode", rename_all = "snake_case")]
pub enum OffsetX {
    /// Every wall at this distance (m) from the base.
    Fixed { x: f64 },
    /// Each wall where the arm reaches the most of its pieces, then nearest the base; the
    /// offsets searched run from `min` to `max` (m). Chosen by `rules/targets.dl`.
    Auto { min: f64, max: f64 },
}

impl OffsetX {
    /// Parses a command-line or file value: metres or `auto` (searched over `range`).
    pub fn parse(text: &str, range: [f64; 2]) -> Result<OffsetX, InvalidValue> {
        if text.trim() == "auto" {
            return Ok(OffsetX::Auto {
                min: range[0],
                max: range[1],
            });
        }
        // Negative: the wall's bottom edge (or start) lies behind the base, as under a robot
        // hanging over the middle of the table.
        match text.trim().parse::<f64>() {
            Ok(x) if x.is_finite() && (-100.0..=100.0).contains(&x) => Ok(OffsetX::Fixed { x }),
            _ => Err(InvalidValue(format!(
                "expected a distance in m from -100 to 100 or \"auto\", got {text:?}"
            ))),
        }
    }
}

impl std::fmt::Display for OffsetX {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            OffsetX::Fixed { x } => write!(f, "{x:.3} m"),
            OffsetX::Auto { min, max } => write!(f, "auto ({min:.3}..{max:.3} m)"),
        }
    }
}

/// How lumber lies on conveyor 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Arrangement {
    /// In a line along the belt, `lumber_gap` between one piece's end and the next's.
    EndToEnd,
    /// Side by side across the belt (long axis across the travel), `lumber_gap` between
    /// neighbours; conveyor 1 delivers each piece to conveyor 2's upstream end, where it
    /// turns onto conveyor 2 long axis first.
    SideBySide,
}

/// How fast the robot program runs and how long it dwells: industrial controllers run a
/// program at a programmed speed, not at the joints' limits.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Motion {
    /// Fraction of the joints' speed and acceleration limits for free moves while framing.
    pub transfer_speed: f64,
    /// TCP speed of straight descents and lifts at pick and place, m/s.
    pub approach_speed: f64,
    /// Fraction of the joints' limits for free moves between nails.
    pub nailing_speed: f64,
    /// TCP speed of the straight approach to a nail and back, m/s.
    pub nail_approach_speed: f64,
    /// TCP acceleration of straight moves, m/s².
    pub line_accel: f64,
    /// Closing the grippers, s.
    pub grip_dwell: f64,
    /// Opening the grippers, s.
    pub release_dwell: f64,
    /// Firing one nail, s.
    pub fire_dwell: f64,
    /// How close a robot program's free moves pass their intermediate points (m): the zone
    /// of a joint move followed by another move. Default 0.005, the clearance the executor
    /// keeps along free moves: at the TCP a rounded corner stays within the clearance checked.
    pub free_zone: f64,
}

impl Default for Motion {
    fn default() -> Self {
        Motion {
            transfer_speed: 1.0,
            approach_speed: 0.25,
            nailing_speed: 1.0,
            nail_approach_speed: 0.25,
            line_accel: 1.0,
            grip_dwell: 0.5,
            release_dwell: 0.3,
            fire_dwell: 0.2,
            free_zone: 0.005,
        }
    }
}

/// How the wall's length lies relative to the robot's y axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Orientation {
    /// Wall length along robot y, wall height along +x.
    Parallel,
    /// Wall length along robot +x, wall height along y.
    Perpendicular,
}

/// How a built-up header (plies stacked across the wall, spacers between) reaches the table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BuiltUpHeaders {
    /// Each ply is fed and placed on its own, as the model has it.
    #[default]
    Plies,
    /// Nailed up with its spacers upstream (a header station) and fed as one member.
    Preassembled,
}

impl BuiltUpHeaders {
    pub fn as_str(self) -> &'static str {
        match self {
            BuiltUpHeaders::Plies => "plies",
            BuiltUpHeaders::Preassembled => "preassembled",
        }
    }
}

/// Where the wall is laid flat for framing.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Assembly {
    /// Distance (m) from the robot base origin along +x to the wall's bottom edge
    /// (parallel) or to its start (perpendicular), or `auto` (per wall, by the rules).
    pub offset_x: OffsetX,
    /// The offsets `auto` searches, m.
    pub auto_range: [f64; 2],
    pub orientation: Orientation,
    /// The wall is centred on this y (m, robot frame).
    pub centre_y: f64,
    /// Height (m) of the surface the wall lies on.
    pub surface_z: f64,
    pub built_up_headers: BuiltUpHeaders,
}

/// A belt conveyor. `pose`: centre of the belt's top surface, x along the travel direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conveyor {
    pub pose: Isometry3<f64>,
    pub length: f64,
    pub width: f64,
    /// Belt speed, m/s.
    pub speed: f64,
    /// A slow-down before the end stop, where the belt has one.
    pub creep: Option<Creep>,
}

/// The whole belt runs at `speed` while a piece on it reaches into its last `length` before
/// the downstream end: lumber meets the end stop slowly (a short block arriving at full speed
/// tips over against it).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Creep {
    /// m/s
    pub speed: f64,
    /// m
    pub length: f64,
}

impl Conveyor {
    pub fn direction(&self) -> Vector3<f64> {
        self.pose.rotation * Vector3::x()
    }
    /// Centre of the downstream edge of the belt's top surface.
    pub fn downstream_end(&self) -> Point3<f64> {
        self.pose * Point3::new(self.length / 2.0, 0.0, 0.0)
    }
    pub fn upstream_end(&self) -> Point3<f64> {
        self.pose * Point3::new(-self.length / 2.0, 0.0, 0.0)
    }
    /// Whether a point lies over the belt's top surface (seen from above).
    pub fn covers(&self, point: &Point3<f64>) -> bool {
        let local = self.pose.inverse() * point;
        local.x.abs() <= self.length / 2.0 && local.y.abs() <= self.width / 2.0
    }
}

/// The touch sensor box at the downstream end of conveyor 2 (`pose`: its centre, x along the
/// belt); lumber stops when its leading end touches the sensor face.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TouchSensor {
    pub pose: Isometry3<f64>,
    pub size: [f64; 3],
    /// Centre of the face the lumber touches (at belt top height).
    pub face: Point3<f64>,
}

/// Where the robot picks lumber: `pick_offset` back from the sensor face, on the belt centre line.
#[derive(Debug, Clone, PartialEq)]
pub struct Pick {
    /// Grip point at belt-top height (add the lumber height for the grip TCP), cell frame.
    pub point: Point3<f64>,
    pub offset: f64,
    /// Lumber heights on the belt checked for reach (m), with the reach margin found (m).
    pub margins: Vec<(f64, f64)>,
    pub min_reach_margin: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ToolTable {
    /// Centre of the table top's upper face.
    pub top_centre: Point3<f64>,
    /// Length (x), width (y), top thickness (z).
    pub size: [f64; 3],
    pub leg_height: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Floor {
    pub size: [f64; 2],
    pub z: f64,
}

/// A loaded and checked cell.
#[derive(Debug, Clone)]
pub struct Cell {
    pub name: String,
    pub description: Option<String>,
    /// The file it came from (`robots/cells/<name>.toml` for built-ins).
    pub source: PathBuf,
    pub robot: Robot,
    /// The robot's base frame in the cell frame: at `base_position`, turned by the yaw, z up.
    /// `base_link` itself lies at `robot_base` times the robot's mount (turned over when inverted).
    pub robot_base: Isometry3<f64>,
    pub tool: Tool,
    pub assembly: Assembly,
    pub conveyor1: Conveyor,
    pub conveyor2: Conveyor,
    /// Gap between lumber pieces on conveyor 1, m.
    pub lumber_gap: f64,
    /// How lumber lies on conveyor 1.
    pub arrangement: Arrangement,
    /// Programmed speeds and dwells.
    pub motion: Motion,
    pub touch_sensor: TouchSensor,
    pub pick: Pick,
    pub tool_table: ToolTable,
    pub floor: Floor,
    /// The linear track the base rides on, if the cell has one; `robot_base` is then the
    /// base at the carriage's current position.
    pub track: Option<Track>,
    /// `[panels]`: the limits walls are split to.
    pub panels: PanelLimits,
    /// `[io]`: the signals a robot program drives and waits on.
    pub io: Io,
    /// Whether walls are split (`--panels`; not a file key).
    pub panel_mode: PanelMode,
}

impl Cell {
    /// The grip TCP pose (cell frame) for picking lumber of `height` on conveyor 2: TCP z down,
    /// TCP y along the belt (the lumber's long axis).
    pub fn pick_pose(&self, height: f64) -> Isometry3<f64> {
        let y = self.conveyor2.direction();
        let z = -Vector3::z();
        let x = y.cross(&z);
        let rot = nalgebra::Rotation3::from_basis_unchecked(&[x, y, z]);
        Isometry3::from_parts(
            Translation3::from(self.pick.point.coords + Vector3::new(0.0, 0.0, height)),
            UnitQuaternion::from_rotation_matrix(&rot),
        )
    }

    /// The height (cell z) of the surface walls are laid on: `surface_z` is measured from the
    /// robot's base frame, which a gantry or a pedestal raises off the floor.
    pub fn surface_height(&self) -> f64 {
        self.robot_base.translation.z + self.assembly.surface_z
    }

    /// Overrides the cell's `offset_x` (a distance in m, or `auto`), as the command line does.
    pub fn set_offset_x(&mut self, text: &str) -> Result<(), InvalidValue> {
        self.assembly.offset_x = OffsetX::parse(text, self.assembly.auto_range)?;
        Ok(())
    }

    /// The carriage's position on its track (0 without a track).
    pub fn carriage(&self) -> f64 {
        self.track
            .as_ref()
            .map_or(0.0, |t| t.position_of(&self.robot_base))
    }

    /// Moves the base to carriage position `s` (nothing without a track).
    pub fn set_carriage(&mut self, s: f64) {
        if let Some(t) = &self.track {
            self.robot_base = t.base_at(t.clamp(s));
        }
    }

    /// A cell-frame pose in the robot's base_link frame.
    pub fn to_robot(&self, pose: &Isometry3<f64>) -> Isometry3<f64> {
        self.robot_base.inverse() * pose
    }
}

/// The longest piece the conveyors carry, m: no longer than conveyor 2, nor than conveyor 1's
/// deck is wide (side by side) or its belt long (end to end).
pub(super) fn carry_length(
    c2_length: f64,
    c1_length: f64,
    c1_width: f64,
    arrangement: Arrangement,
) -> f64 {
    c2_length.min(match arrangement {
        Arrangement::SideBySide => c1_width,
        Arrangement::EndToEnd => c1_length,
    })
}

impl Cell {
    /// The longest piece this cell's conveyors carry, m.
    pub fn carry_length(&self) -> f64 {
        carry_length(
            self.conveyor2.length,
            self.conveyor1.length,
            self.conveyor1.width,
            self.arrangement,
        )
    }
}
