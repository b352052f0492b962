//! The sections of a cell TOML file as written, with their defaults.

use super::io::Io;
use super::layout::{Arrangement, BuiltUpHeaders, Motion, Orientation};
use super::panels::PanelLimits;
use serde::Deserialize;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct CellFile {
    pub(super) name: Option<String>,
    pub(super) description: Option<String>,
    pub(super) robot: RobotSection,
    pub(super) tool: ToolSection,
    #[serde(default)]
    pub(super) assembly: AssemblySection,
    pub(super) conveyor1: Conveyor1Section,
    pub(super) conveyor2: Conveyor2Section,
    #[serde(default)]
    pub(super) touch_sensor: SensorSection,
    pub(super) tool_table: TableSection,
    #[serde(default)]
    pub(super) floor: FloorSection,
    #[serde(default)]
    pub(super) motion: MotionSection,
    #[serde(default)]
    pub(super) panels: PanelLimits,
    pub(super) track: Option<TrackSection>,
    #[serde(default)]
    pub(super) io: Io,
}

/// `[track]`: the robot's base on a linear axis (see `track.rs`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TrackSection {
    /// Direction of travel in the cell frame, degrees about z from +x.
    pub(super) direction_deg: f64,
    /// Rail length, m; the carriage travels ±length/2 about `robot.base_position`.
    pub(super) length: f64,
    /// Programmed carriage speed, m/s.
    pub(super) speed: f64,
    /// Carriage acceleration, m/s².
    pub(super) accel: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RobotSection {
    pub(super) model: String,
    #[serde(default)]
    pub(super) base_position: [f64; 3],
    #[serde(default)]
    pub(super) base_yaw_deg: f64,
    /// How the robot is mounted: on the floor (default) or inverted (hanging under a gantry).
    #[serde(default)]
    pub(super) mounting: Mounting,
}

/// `[robot] mounting`: how `base_link` sits at `base_position`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub(super) enum Mounting {
    /// z up, as the URDF stands.
    #[default]
    Floor,
    /// Upside down (a half turn about the base's x axis): the arm hangs from a gantry or a
    /// ceiling. The base frame framewright works in stays z up.
    Inverted,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct ToolSection {
    pub(super) model: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct AssemblySection {
    pub(super) offset_x: OffsetSetting,
    /// For `offset_x = "auto"`: the offsets searched, m (default: clear of the robot's base
    /// out to its reach).
    pub(super) auto_range: Option<[f64; 2]>,
    pub(super) orientation: Orientation,
    pub(super) centre_y: f64,
    pub(super) surface_z: f64,
    pub(super) built_up_headers: BuiltUpHeaders,
}

impl Default for AssemblySection {
    fn default() -> Self {
        AssemblySection {
            offset_x: OffsetSetting::Metres(0.531),
            auto_range: None,
            orientation: Orientation::Parallel,
            centre_y: 0.0,
            surface_z: 0.0,
            built_up_headers: BuiltUpHeaders::Plies,
        }
    }
}

/// `offset_x` as written: a distance in m or a word (`"auto"`).
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub(super) enum OffsetSetting {
    Metres(f64),
    Word(String),
}

type MotionSection = Motion;

fn speed_1() -> f64 {
    0.05
}
fn speed_2() -> f64 {
    2.0
}
fn gap() -> f64 {
    0.150
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Conveyor1Section {
    pub(super) position: [f64; 3],
    pub(super) direction_deg: f64,
    pub(super) length: f64,
    pub(super) width: f64,
    #[serde(default = "speed_1")]
    pub(super) speed: f64,
    #[serde(default = "gap")]
    pub(super) lumber_gap: f64,
    #[serde(default = "end_to_end")]
    pub(super) arrangement: Arrangement,
}

fn end_to_end() -> Arrangement {
    Arrangement::EndToEnd
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct Conveyor2Section {
    pub(super) position: [f64; 3],
    pub(super) direction_deg: f64,
    pub(super) length: f64,
    pub(super) width: f64,
    #[serde(default = "speed_2")]
    pub(super) speed: f64,
    /// A slow-down: the belt runs at `creep_speed` while a piece reaches into its last
    /// `creep_length`.
    pub(super) creep_speed: Option<f64>,
    pub(super) creep_length: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct SensorSection {
    pub(super) size: [f64; 3],
    pub(super) pick_offset: f64,
    pub(super) pick_heights: Vec<f64>,
    pub(super) min_reach_margin: f64,
}

impl Default for SensorSection {
    fn default() -> Self {
        SensorSection {
            size: [0.05, 0.30, 0.20],
            pick_offset: 0.45,
            pick_heights: vec![0.089, 0.140],
            min_reach_margin: 0.10,
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct TableSection {
    pub(super) position: [f64; 3],
    pub(super) size: [f64; 3],
    pub(super) leg_height: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub(super) struct FloorSection {
    pub(super) size: [f64; 2],
    pub(super) z: f64,
}

impl Default for FloorSection {
    fn default() -> Self {
        FloorSection {
            size: [20.0, 20.0],
            z: 0.0,
        }
    }
}
