//! Cell layouts (`robots/cells/*.toml`): robot and base pose, tool, assembly area, the two
//! conveyors, the touch sensor at the end of conveyor 2, the tool table and the floor.
//! Positions are in the cell frame (z up, floor at z = 0 unless moved).

use super::builtin;
use super::error::CellError;
use super::ik::IkFailure;
use super::io::Io;
use super::load::looks_like_path;
use super::panels::{PanelLimits, PanelMode};
use super::robot::Robot;
use super::toml_file;
use super::tool::Tool;
use super::track::Track;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use serde::Deserialize;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CellFile {
    name: Option<String>,
    description: Option<String>,
    robot: RobotSection,
    tool: ToolSection,
    #[serde(default)]
    assembly: AssemblySection,
    conveyor1: Conveyor1Section,
    conveyor2: Conveyor2Section,
    #[serde(default)]
    touch_sensor: SensorSection,
    tool_table: TableSection,
    #[serde(default)]
    floor: FloorSection,
    #[serde(default)]
    motion: MotionSection,
    #[serde(default)]
    panels: PanelLimits,
    track: Option<TrackSection>,
    #[serde(default)]
    io: Io,
}

/// `[track]`: the robot's base on a linear axis (see `track.rs`).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct TrackSection {
    /// Direction of travel in the cell frame, degrees about z from +x.
    direction_deg: f64,
    /// Rail length, m; the carriage travels ±length/2 about `robot.base_position`.
    length: f64,
    /// Programmed carriage speed, m/s.
    speed: f64,
    /// Carriage acceleration, m/s².
    accel: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RobotSection {
    model: String,
    #[serde(default)]
    base_position: [f64; 3],
    #[serde(default)]
    base_yaw_deg: f64,
    /// How the robot is mounted: on the floor (default) or inverted (hanging under a gantry).
    #[serde(default)]
    mounting: Mounting,
}

/// `[robot] mounting`: how `base_link` sits at `base_position`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum Mounting {
    /// z up, as the URDF stands.
    #[default]
    Floor,
    /// Upside down (a half turn about the base's x axis): the arm hangs from a gantry or a
    /// ceiling. The base frame framewright works in stays z up.
    Inverted,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ToolSection {
    model: String,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct AssemblySection {
    offset_x: OffsetSetting,
    /// For `offset_x = "auto"`: the offsets searched, m (default: clear of the robot's base
    /// out to its reach).
    auto_range: Option<[f64; 2]>,
    orientation: Orientation,
    centre_y: f64,
    surface_z: f64,
    built_up_headers: BuiltUpHeaders,
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
enum OffsetSetting {
    Metres(f64),
    Word(String),
}

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
    pub fn parse(text: &str, range: [f64; 2]) -> Result<OffsetX, String> {
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
            _ => Err(format!(
                "expected a distance in m from -100 to 100 or \"auto\", got {text:?}"
            )),
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

type MotionSection = Motion;

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
struct Conveyor1Section {
    position: [f64; 3],
    direction_deg: f64,
    length: f64,
    width: f64,
    #[serde(default = "speed_1")]
    speed: f64,
    #[serde(default = "gap")]
    lumber_gap: f64,
    #[serde(default = "end_to_end")]
    arrangement: Arrangement,
}

fn end_to_end() -> Arrangement {
    Arrangement::EndToEnd
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Conveyor2Section {
    position: [f64; 3],
    direction_deg: f64,
    length: f64,
    width: f64,
    #[serde(default = "speed_2")]
    speed: f64,
    /// A slow end section: the belt's last `creep_length` runs at `creep_speed`.
    creep_speed: Option<f64>,
    creep_length: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct SensorSection {
    size: [f64; 3],
    pick_offset: f64,
    pick_heights: Vec<f64>,
    min_reach_margin: f64,
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
struct TableSection {
    position: [f64; 3],
    size: [f64; 3],
    leg_height: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct FloorSection {
    size: [f64; 2],
    z: f64,
}

impl Default for FloorSection {
    fn default() -> Self {
        FloorSection {
            size: [20.0, 20.0],
            z: 0.0,
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
    /// A slow end section before the end stop, where the belt has one.
    pub creep: Option<Creep>,
}

/// The last `length` of a belt before its downstream end runs at `speed`: lumber meets the end
/// stop slowly (a short block arriving at full speed tips over against it).
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
    /// A built-in cell (`study-abb`, `study-kuka`) or a cell TOML file.
    pub fn load(name_or_path: &str) -> Result<Cell, CellError> {
        if let Some(&(_, file, text)) = builtin::CELLS.iter().find(|c| c.0 == name_or_path) {
            return Cell::parse(Path::new(file), text, true);
        }
        if !looks_like_path(name_or_path) && !Path::new(name_or_path).exists() {
            return Err(CellError::UnknownName {
                what: "cell",
                name: name_or_path.to_string(),
                known: builtin::cell_names().join(", "),
            });
        }
        let path = Path::new(name_or_path);
        let text = std::fs::read_to_string(path).map_err(|source| CellError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        Cell::parse(path, &text, false)
    }

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
    pub fn set_offset_x(&mut self, text: &str) -> Result<(), String> {
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

    /// A cell from TOML text; `path` names it in messages and anchors relative model paths.
    pub fn from_toml(path: &Path, text: &str) -> Result<Cell, CellError> {
        Cell::parse(path, text, false)
    }

    fn parse(path: &Path, text: &str, builtin: bool) -> Result<Cell, CellError> {
        let f: CellFile = toml_file::parse(path, text)?;
        let bad = |section: &str, key: &str, msg: String| {
            toml_file::value_error(path, text, section, key, msg)
        };
        // Models: built-in names, or paths relative to this file.
        let resolve = |model: &str| -> String {
            if builtin || !looks_like_path(model) || Path::new(model).is_absolute() {
                model.to_string()
            } else {
                path.parent()
                    .unwrap_or(Path::new(""))
                    .join(model)
                    .to_string_lossy()
                    .into_owned()
            }
        };
        let mut robot = Robot::load(&resolve(&f.robot.model))
            .map_err(|e| bad("robot", "model", e.to_string()))?;
        if f.robot.mounting == Mounting::Inverted {
            robot.set_mount(Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
            ));
        }
        let tool =
            Tool::load(&resolve(&f.tool.model)).map_err(|e| bad("tool", "model", e.to_string()))?;

        // Numbers: finite, positive where they are sizes, within a plausible factory hall.
        let coord = |section: &str, key: &str, v: &[f64]| -> Result<(), CellError> {
            match v.iter().find(|x| !(x.is_finite() && x.abs() <= 1000.0)) {
                Some(x) => Err(bad(
                    section,
                    key,
                    format!("expected coordinates in m within ±1000, got {x}"),
                )),
                None => Ok(()),
            }
        };
        let size = |section: &str, key: &str, v: &[f64], max: f64| -> Result<(), CellError> {
            match v
                .iter()
                .find(|x| !(x.is_finite() && **x > 0.0 && **x <= max))
            {
                Some(x) => Err(bad(
                    section,
                    key,
                    format!("expected a size in m above 0 and at most {max}, got {x}"),
                )),
                None => Ok(()),
            }
        };
        let speed = |section: &str, v: f64| -> Result<(), CellError> {
            if v.is_finite() && v > 0.0 && v <= 10.0 {
                Ok(())
            } else {
                Err(bad(
                    section,
                    "speed",
                    format!("expected a belt speed in m/s above 0 and at most 10, got {v}"),
                ))
            }
        };
        let finite_angle = |section: &str, key: &str, v: f64| -> Result<(), CellError> {
            if v.is_finite() {
                Ok(())
            } else {
                Err(bad(
                    section,
                    key,
                    format!("expected an angle in degrees, got {v}"),
                ))
            }
        };
        coord("robot", "base_position", &f.robot.base_position)?;
        finite_angle("robot", "base_yaw_deg", f.robot.base_yaw_deg)?;
        let a = &f.assembly;
        let auto_range = match a.auto_range {
            Some(r) => {
                if !(r.iter().all(|x| x.is_finite() && (0.0..=100.0).contains(x)) && r[0] < r[1]) {
                    return Err(bad(
                        "assembly",
                        "auto_range",
                        format!("expected [min, max] in m with 0 <= min < max <= 100, got {r:?}"),
                    ));
                }
                r
            }
            None => [
                base_clearance(&robot),
                robot
                    .meta
                    .reach
                    .unwrap_or(3.0)
                    .max(base_clearance(&robot) + 0.1),
            ],
        };
        let offset_x = match &a.offset_x {
            OffsetSetting::Metres(x) => OffsetX::parse(&x.to_string(), auto_range),
            OffsetSetting::Word(w) => OffsetX::parse(w, auto_range),
        }
        .map_err(|m| bad("assembly", "offset_x", m))?;
        coord("assembly", "centre_y", &[a.centre_y])?;
        coord("assembly", "surface_z", &[a.surface_z])?;
        let c1 = &f.conveyor1;
        coord("conveyor1", "position", &c1.position)?;
        finite_angle("conveyor1", "direction_deg", c1.direction_deg)?;
        size("conveyor1", "length", &[c1.length], 100.0)?;
        size("conveyor1", "width", &[c1.width], 100.0)?;
        speed("conveyor1", c1.speed)?;
        if !(c1.lumber_gap.is_finite() && (0.0..=10.0).contains(&c1.lumber_gap)) {
            return Err(bad(
                "conveyor1",
                "lumber_gap",
                format!("expected a gap in m from 0 to 10, got {}", c1.lumber_gap),
            ));
        }
        let c2 = &f.conveyor2;
        coord("conveyor2", "position", &c2.position)?;
        finite_angle("conveyor2", "direction_deg", c2.direction_deg)?;
        size("conveyor2", "length", &[c2.length], 100.0)?;
        size("conveyor2", "width", &[c2.width], 10.0)?;
        speed("conveyor2", c2.speed)?;
        let creep = match (c2.creep_speed, c2.creep_length) {
            (None, None) => None,
            (Some(speed), Some(length))
                if speed.is_finite()
                    && speed > 0.0
                    && speed < c2.speed
                    && length.is_finite()
                    && length > 0.0
                    && length <= c2.length =>
            {
                Some(Creep { speed, length })
            }
            _ => {
                return Err(bad(
                    "conveyor2",
                    "creep_speed",
                    format!(
                        "creep_speed (m/s, above 0 and below the belt's speed {}) and creep_length (m, above 0 and at most the belt's length {}) go together: give both, or neither for a belt at one speed",
                        c2.speed, c2.length
                    ),
                ));
            }
        };
        let s = &f.touch_sensor;
        size("touch_sensor", "size", &s.size, 5.0)?;
        if !(s.pick_offset.is_finite() && s.pick_offset >= 0.0 && s.pick_offset <= c2.length) {
            return Err(bad(
                "touch_sensor",
                "pick_offset",
                format!(
                    "expected a distance in m from 0 to the length of conveyor 2 ({}), got {}",
                    c2.length, s.pick_offset
                ),
            ));
        }
        size("touch_sensor", "pick_heights", &s.pick_heights, 2.0)?;
        if s.pick_heights.is_empty() {
            return Err(bad(
                "touch_sensor",
                "pick_heights",
                "expected at least one lumber height in m".into(),
            ));
        }
        if !(s.min_reach_margin.is_finite() && (0.0..=5.0).contains(&s.min_reach_margin)) {
            return Err(bad(
                "touch_sensor",
                "min_reach_margin",
                format!(
                    "expected a margin in m from 0 to 5, got {}",
                    s.min_reach_margin
                ),
            ));
        }
        let t = &f.tool_table;
        coord("tool_table", "position", &t.position)?;
        size("tool_table", "size", &t.size, 10.0)?;
        size("tool_table", "leg_height", &[t.leg_height], 5.0)?;
        size("floor", "size", &f.floor.size, 1000.0)?;
        check_motion(&f.motion).map_err(|(key, m)| bad("motion", key, m))?;
        f.io.check().map_err(|(key, m)| bad("io", key, m))?;
        if let Some(tr) = &f.track {
            finite_angle("track", "direction_deg", tr.direction_deg)?;
            size("track", "length", &[tr.length], 100.0)?;
            let positive = |key: &str, v: f64, max: f64, what: &str| {
                if v.is_finite() && v > 0.0 && v <= max {
                    Ok(())
                } else {
                    Err(bad(
                        "track",
                        key,
                        format!("expected {what} above 0 and at most {max}, got {v}"),
                    ))
                }
            };
            positive("speed", tr.speed, 10.0, "a carriage speed in m/s")?;
            positive("accel", tr.accel, 20.0, "a carriage acceleration in m/s²")?;
        }
        coord("floor", "z", &[f.floor.z])?;
        let carry = carry_length(c2.length, c1.length, c1.width, c1.arrangement);
        f.panels
            .check(carry)
            .map_err(|(key, m)| bad("panels", key, m))?;

        // Payload: the tool alone must not exceed it (the lumber comes on top; the executor checks).
        if let Some(payload) = robot.meta.payload
            && tool.mass > payload
        {
            return Err(bad(
                "tool",
                "model",
                format!(
                    "the tool weighs {:.1} kg, more than the robot's payload of {payload:.1} kg",
                    tool.mass
                ),
            ));
        }

        let belt = |pos: [f64; 3], dir_deg: f64| {
            Isometry3::from_parts(
                Translation3::from(Vector3::from(pos)),
                UnitQuaternion::from_euler_angles(0.0, 0.0, dir_deg.to_radians()),
            )
        };
        let conveyor1 = Conveyor {
            pose: belt(c1.position, c1.direction_deg),
            length: c1.length,
            width: c1.width,
            speed: c1.speed,
            creep: None,
        };
        let conveyor2 = Conveyor {
            pose: belt(c2.position, c2.direction_deg),
            length: c2.length,
            width: c2.width,
            speed: c2.speed,
            creep,
        };
        let face = conveyor2.downstream_end();
        let dir = conveyor2.direction();
        let touch_sensor = TouchSensor {
            pose: Isometry3::from_parts(
                Translation3::from(
                    face.coords + dir * (s.size[0] / 2.0) + Vector3::z() * (s.size[2] / 2.0),
                ),
                conveyor2.pose.rotation,
            ),
            size: s.size,
            face,
        };
        let robot_base = Isometry3::from_parts(
            Translation3::from(Vector3::from(f.robot.base_position)),
            UnitQuaternion::from_euler_angles(0.0, 0.0, f.robot.base_yaw_deg.to_radians()),
        );
        let track = f.track.as_ref().map(|tr| {
            let a = tr.direction_deg.to_radians();
            Track {
                home: robot_base,
                direction: Vector3::new(a.cos(), a.sin(), 0.0),
                travel: [-tr.length / 2.0, tr.length / 2.0],
                speed: tr.speed,
                accel: tr.accel,
            }
        });
        let mut cell = Cell {
            name: f.name.unwrap_or_else(|| {
                path.file_stem()
                    .map_or("cell".into(), |s| s.to_string_lossy().into_owned())
            }),
            description: f.description,
            source: path.to_path_buf(),
            robot,
            robot_base,
            tool,
            assembly: Assembly {
                offset_x,
                auto_range,
                orientation: a.orientation,
                centre_y: a.centre_y,
                surface_z: a.surface_z,
                built_up_headers: a.built_up_headers,
            },
            conveyor1,
            conveyor2,
            lumber_gap: c1.lumber_gap,
            arrangement: c1.arrangement,
            motion: f.motion,
            touch_sensor,
            pick: Pick {
                point: face - dir * s.pick_offset,
                offset: s.pick_offset,
                margins: vec![],
                min_reach_margin: s.min_reach_margin,
            },
            tool_table: ToolTable {
                top_centre: Point3::new(
                    t.position[0],
                    t.position[1],
                    t.position[2] + t.leg_height + t.size[2],
                ),
                size: t.size,
                leg_height: t.leg_height,
            },
            floor: Floor {
                size: f.floor.size,
                z: f.floor.z,
            },
            track,
            panels: f.panels,
            io: f.io,
            panel_mode: PanelMode::default(),
        };
        cell.check_pick(&s.pick_heights)
            .map_err(|m| bad("touch_sensor", "pick_offset", m))?;
        Ok(cell)
    }

    /// The pick point must be reachable, with the grip TCP, for every checked lumber height,
    /// with at least `min_reach_margin` of reach to spare.
    fn check_pick(&mut self, heights: &[f64]) -> Result<(), String> {
        let tcp = *self
            .tool
            .tcp("grip")
            .ok_or("the tool has no `grip` TCP to pick with")?;
        let home = self.robot.home();
        // On a track the carriage picks from abeam of the pick point.
        let (base, carriage) = match &self.track {
            Some(t) => {
                let s = t.abeam(&self.pick.point);
                (t.base_at(s), format!(", carriage at {s:.3} m"))
            }
            None => (self.robot_base, String::new()),
        };
        let mut margins = vec![];
        for &h in heights {
            let pose = base.inverse() * self.pick_pose(h);
            let p = pose.translation.vector;
            let at = format!(
                "pick point ({:.3}, {:.3}, {:.3}) m in the robot frame (lumber height {h} m{carriage})",
                p.x, p.y, p.z
            );
            if let Err(fail) = self.robot.ik(&pose, &tcp, &home) {
                return Err(match fail {
                    IkFailure::OutOfReach {
                        distance, reach, ..
                    } => format!(
                        "{at} is out of reach: wrist centre {distance:.3} m from the shoulder, reach {reach:.3} m; move the conveyor or the robot"
                    ),
                    other => format!("{at} is not reachable: {other}"),
                });
            }
            if let Some(margin) = self.robot.reach_margin(&pose, &tcp) {
                if margin < self.pick.min_reach_margin {
                    return Err(format!(
                        "{at} is reachable with only {margin:.3} m to spare; at least {:.3} m (touch_sensor.min_reach_margin) is required",
                        self.pick.min_reach_margin
                    ));
                }
                margins.push((h, margin));
            }
        }
        self.pick.margins = margins;
        Ok(())
    }
}

/// How far from the base axis (m) a wall must start to stay clear of the base and the
/// turntable above it: the widest of their collision shapes, turned about the base axis, plus
/// 5 cm.
fn base_clearance(robot: &Robot) -> f64 {
    let q = robot.home();
    let poses = robot.fk_all(&q);
    // The base and the links carried by the first joint only (they turn about the base axis):
    // links with at most one moving joint between them and the root.
    let radius = robot
        .links
        .iter()
        .enumerate()
        .filter(|(i, _)| robot.moving_joints_above(*i) <= 1)
        .flat_map(|(i, link)| link.collisions.iter().map(move |c| (i, c)))
        .map(|(i, c)| {
            let centre = (poses[i] * c.origin).translation.vector;
            centre.xy().norm() + bounding_radius(&c.shape)
        })
        .fold(0.0, f64::max);
    radius + 0.05
}

/// The radius of a ball around the shape's origin that holds it.
fn bounding_radius(shape: &super::shapes::Shape) -> f64 {
    use super::shapes::Shape;
    match *shape {
        Shape::Box { half_extents: h } => (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt(),
        Shape::Cylinder { radius, length } => (radius * radius + length * length / 4.0).sqrt(),
        Shape::Capsule { radius, length } => radius + length / 2.0,
        Shape::Sphere { radius } => radius,
    }
}

/// The longest piece the conveyors carry, m: no longer than conveyor 2, nor than conveyor 1's
/// deck is wide (side by side) or its belt long (end to end).
fn carry_length(c2_length: f64, c1_length: f64, c1_width: f64, arrangement: Arrangement) -> f64 {
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

/// Motion settings: speed fractions in (0, 1], TCP speeds and accelerations positive and at
/// most 10, dwells from 0 to 60 s. Err: the key and what is wrong.
fn check_motion(m: &Motion) -> Result<(), (&'static str, String)> {
    for (key, v) in [
        ("transfer_speed", m.transfer_speed),
        ("nailing_speed", m.nailing_speed),
    ] {
        if !(v.is_finite() && v > 0.0 && v <= 1.0) {
            return Err((
                key,
                format!("expected a fraction of the joint limits in (0, 1], got {v}"),
            ));
        }
    }
    for (key, v) in [
        ("approach_speed", m.approach_speed),
        ("nail_approach_speed", m.nail_approach_speed),
        ("line_accel", m.line_accel),
    ] {
        if !(v.is_finite() && v > 0.0 && v <= 10.0) {
            return Err((
                key,
                format!("expected a value above 0 and at most 10, got {v}"),
            ));
        }
    }
    for (key, v) in [
        ("grip_dwell", m.grip_dwell),
        ("release_dwell", m.release_dwell),
        ("fire_dwell", m.fire_dwell),
    ] {
        if !(v.is_finite() && (0.0..=60.0).contains(&v)) {
            return Err((key, format!("expected a time in s from 0 to 60, got {v}")));
        }
    }
    if !(m.free_zone.is_finite() && (0.0..=0.2).contains(&m.free_zone)) {
        return Err((
            "free_zone",
            format!(
                "expected a distance in m from 0 to 0.2, got {}",
                m.free_zone
            ),
        ));
    }
    Ok(())
}
