//! Loading a cell: a cell TOML file's sections, each checked in turn (robot and tool,
//! assembly, conveyors, touch sensor, tool table, floor, motion, io, track, panels, payload),
//! and the `Cell` they build, its pick point checked for reach.

use super::builtin;
use super::error::{CellError, InvalidValue};
use super::ik::IkFailure;
use super::layout::{
    Assembly, Cell, Conveyor, Creep, Floor, Motion, OffsetX, Pick, ToolTable, TouchSensor,
    carry_length,
};
use super::layout_file::{
    AssemblySection, CellFile, Conveyor1Section, Conveyor2Section, Mounting, OffsetSetting,
    RobotSection, SensorSection, TableSection, TrackSection,
};
use super::load::looks_like_path;
use super::panels::PanelMode;
use super::robot::Robot;
use super::toml_file;
use super::tool::Tool;
use super::track::Track;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use std::path::Path;

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

    /// A cell from TOML text; `path` names it in messages and anchors relative model paths.
    pub fn from_toml(path: &Path, text: &str) -> Result<Cell, CellError> {
        Cell::parse(path, text, false)
    }

    /// The sections are checked in a fixed order: a file with several faults always reports
    /// the same one first.
    fn parse(path: &Path, text: &str, builtin: bool) -> Result<Cell, CellError> {
        let f: CellFile = toml_file::parse(path, text)?;
        let file = Source { path, text };
        let (robot, tool) = load_models(&file, &f, builtin)?;
        check_robot(&file, &f.robot)?;
        let assembly = parse_assembly(&file, &f.assembly, &robot)?;
        let c1 = &f.conveyor1;
        check_conveyor1(&file, c1)?;
        let c2 = &f.conveyor2;
        let creep = parse_conveyor2(&file, c2)?;
        let s = &f.touch_sensor;
        check_sensor(&file, s, c2.length)?;
        let t = &f.tool_table;
        check_table(&file, t)?;
        file.size("floor", "size", &f.floor.size, 1000.0)?;
        check_motion(&f.motion).map_err(|(key, m)| file.bad("motion", key, m))?;
        f.io.check().map_err(|(key, m)| file.bad("io", key, m))?;
        if let Some(tr) = &f.track {
            check_track(&file, tr)?;
        }
        file.coord("floor", "z", &[f.floor.z])?;
        let carry = carry_length(c2.length, c1.length, c1.width, c1.arrangement);
        f.panels
            .check(carry)
            .map_err(|(key, m)| file.bad("panels", key, m))?;
        check_payload(&file, &robot, &tool)?;

        let (conveyor1, conveyor2) = build_conveyors(c1, c2, creep);
        let (touch_sensor, pick) = build_sensor_and_pick(&conveyor2, s);
        let robot_base = build_robot_base(&f.robot);
        let track = f.track.as_ref().map(|tr| build_track(tr, robot_base));
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
            assembly,
            conveyor1,
            conveyor2,
            lumber_gap: c1.lumber_gap,
            arrangement: c1.arrangement,
            motion: f.motion,
            touch_sensor,
            pick,
            tool_table: build_tool_table(t),
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
            .map_err(|m| file.bad("touch_sensor", "pick_offset", m.0))?;
        Ok(cell)
    }

    /// The pick point must be reachable, with the grip TCP, for every checked lumber height,
    /// with at least `min_reach_margin` of reach to spare.
    fn check_pick(&mut self, heights: &[f64]) -> Result<(), InvalidValue> {
        let tcp = *self
            .tool
            .tcp("grip")
            .ok_or_else(|| InvalidValue("the tool has no `grip` TCP to pick with".into()))?;
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
                return Err(InvalidValue(match fail {
                    IkFailure::OutOfReach {
                        distance, reach, ..
                    } => format!(
                        "{at} is out of reach: wrist centre {distance:.3} m from the shoulder, reach {reach:.3} m; move the conveyor or the robot"
                    ),
                    other => format!("{at} is not reachable: {other}"),
                }));
            }
            if let Some(margin) = self.robot.reach_margin(&pose, &tcp) {
                if margin < self.pick.min_reach_margin {
                    return Err(InvalidValue(format!(
                        "{at} is reachable with only {margin:.3} m to spare; at least {:.3} m (touch_sensor.min_reach_margin) is required",
                        self.pick.min_reach_margin
                    )));
                }
                margins.push((h, margin));
            }
        }
        self.pick.margins = margins;
        Ok(())
    }
}

/// The cell file being read: it names the file in messages and finds the line of a key.
struct Source<'a> {
    path: &'a Path,
    text: &'a str,
}

impl Source<'_> {
    /// An error at `section.key`, with its line in the file.
    fn bad(&self, section: &str, key: &str, msg: String) -> CellError {
        toml_file::value_error(self.path, self.text, section, key, msg)
    }

    // Numbers: finite, positive where they are sizes, within a plausible factory hall.
    fn coord(&self, section: &str, key: &str, v: &[f64]) -> Result<(), CellError> {
        match v.iter().find(|x| !(x.is_finite() && x.abs() <= 1000.0)) {
            Some(x) => Err(self.bad(
                section,
                key,
                format!("expected coordinates in m within ±1000, got {x}"),
            )),
            None => Ok(()),
        }
    }

    fn size(&self, section: &str, key: &str, v: &[f64], max: f64) -> Result<(), CellError> {
        match v
            .iter()
            .find(|x| !(x.is_finite() && **x > 0.0 && **x <= max))
        {
            Some(x) => Err(self.bad(
                section,
                key,
                format!("expected a size in m above 0 and at most {max}, got {x}"),
            )),
            None => Ok(()),
        }
    }

    fn speed(&self, section: &str, v: f64) -> Result<(), CellError> {
        if v.is_finite() && v > 0.0 && v <= 10.0 {
            Ok(())
        } else {
            Err(self.bad(
                section,
                "speed",
                format!("expected a belt speed in m/s above 0 and at most 10, got {v}"),
            ))
        }
    }

    fn finite_angle(&self, section: &str, key: &str, v: f64) -> Result<(), CellError> {
        if v.is_finite() {
            Ok(())
        } else {
            Err(self.bad(
                section,
                key,
                format!("expected an angle in degrees, got {v}"),
            ))
        }
    }
}

/// `[robot] model` and `[tool] model`: the robot, mounted as `[robot] mounting` says, and the
/// tool.
fn load_models(file: &Source, f: &CellFile, builtin: bool) -> Result<(Robot, Tool), CellError> {
    // Models: built-in names, or paths relative to this file.
    let resolve = |model: &str| -> String {
        if builtin || !looks_like_path(model) || Path::new(model).is_absolute() {
            model.to_string()
        } else {
            file.path
                .parent()
                .unwrap_or(Path::new(""))
                .join(model)
                .to_string_lossy()
                .into_owned()
        }
    };
    let mut robot = Robot::load(&resolve(&f.robot.model))
        .map_err(|e| file.bad("robot", "model", e.to_string()))?;
    if f.robot.mounting == Mounting::Inverted {
        robot.set_mount(Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI),
        ));
    }
    let tool = Tool::load(&resolve(&f.tool.model))
        .map_err(|e| file.bad("tool", "model", e.to_string()))?;
    Ok((robot, tool))
}

/// `[robot]`: where the base stands.
fn check_robot(file: &Source, r: &RobotSection) -> Result<(), CellError> {
    file.coord("robot", "base_position", &r.base_position)?;
    file.finite_angle("robot", "base_yaw_deg", r.base_yaw_deg)?;
    Ok(())
}

/// `[assembly]`: where walls are laid, with the offsets `auto` searches (by default clear of
/// the robot's base out to its reach).
fn parse_assembly(
    file: &Source,
    a: &AssemblySection,
    robot: &Robot,
) -> Result<Assembly, CellError> {
    let auto_range = match a.auto_range {
        Some(r) => {
            if !(r.iter().all(|x| x.is_finite() && (0.0..=100.0).contains(x)) && r[0] < r[1]) {
                return Err(file.bad(
                    "assembly",
                    "auto_range",
                    format!("expected [min, max] in m with 0 <= min < max <= 100, got {r:?}"),
                ));
            }
            r
        }
        None => [
            base_clearance(robot),
            robot
                .meta
                .reach
                .unwrap_or(3.0)
                .max(base_clearance(robot) + 0.1),
        ],
    };
    let offset_x = match &a.offset_x {
        OffsetSetting::Metres(x) => OffsetX::parse(&x.to_string(), auto_range),
        OffsetSetting::Word(w) => OffsetX::parse(w, auto_range),
    }
    .map_err(|m| file.bad("assembly", "offset_x", m.0))?;
    file.coord("assembly", "centre_y", &[a.centre_y])?;
    file.coord("assembly", "surface_z", &[a.surface_z])?;
    Ok(Assembly {
        offset_x,
        auto_range,
        orientation: a.orientation,
        centre_y: a.centre_y,
        surface_z: a.surface_z,
        built_up_headers: a.built_up_headers,
    })
}

/// `[conveyor1]`: the belt and the gap between pieces on it.
fn check_conveyor1(file: &Source, c1: &Conveyor1Section) -> Result<(), CellError> {
    file.coord("conveyor1", "position", &c1.position)?;
    file.finite_angle("conveyor1", "direction_deg", c1.direction_deg)?;
    file.size("conveyor1", "length", &[c1.length], 100.0)?;
    file.size("conveyor1", "width", &[c1.width], 100.0)?;
    file.speed("conveyor1", c1.speed)?;
    if !(c1.lumber_gap.is_finite() && (0.0..=10.0).contains(&c1.lumber_gap)) {
        return Err(file.bad(
            "conveyor1",
            "lumber_gap",
            format!("expected a gap in m from 0 to 10, got {}", c1.lumber_gap),
        ));
    }
    Ok(())
}

/// `[conveyor2]`: the belt, and its slow end section if it has one.
fn parse_conveyor2(file: &Source, c2: &Conveyor2Section) -> Result<Option<Creep>, CellError> {
    file.coord("conveyor2", "position", &c2.position)?;
    file.finite_angle("conveyor2", "direction_deg", c2.direction_deg)?;
    file.size("conveyor2", "length", &[c2.length], 100.0)?;
    file.size("conveyor2", "width", &[c2.width], 10.0)?;
    file.speed("conveyor2", c2.speed)?;
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
            return Err(file.bad(
                "conveyor2",
                "creep_speed",
                format!(
                    "creep_speed (m/s, above 0 and below the belt's speed {}) and creep_length (m, above 0 and at most the belt's length {}) go together: give both, or neither for a belt at one speed",
                    c2.speed, c2.length
                ),
            ));
        }
    };
    Ok(creep)
}

/// `[touch_sensor]`: its size, and where on conveyor 2 (`c2_length` long) the robot picks.
fn check_sensor(file: &Source, s: &SensorSection, c2_length: f64) -> Result<(), CellError> {
    file.size("touch_sensor", "size", &s.size, 5.0)?;
    if !(s.pick_offset.is_finite() && s.pick_offset >= 0.0 && s.pick_offset <= c2_length) {
        return Err(file.bad(
            "touch_sensor",
            "pick_offset",
            format!(
                "expected a distance in m from 0 to the length of conveyor 2 ({}), got {}",
                c2_length, s.pick_offset
            ),
        ));
    }
    file.size("touch_sensor", "pick_heights", &s.pick_heights, 2.0)?;
    if s.pick_heights.is_empty() {
        return Err(file.bad(
            "touch_sensor",
            "pick_heights",
            "expected at least one lumber height in m".into(),
        ));
    }
    if !(s.min_reach_margin.is_finite() && (0.0..=5.0).contains(&s.min_reach_margin)) {
        return Err(file.bad(
            "touch_sensor",
            "min_reach_margin",
            format!(
                "expected a margin in m from 0 to 5, got {}",
                s.min_reach_margin
            ),
        ));
    }
    Ok(())
}

/// `[tool_table]`: where it stands and its size.
fn check_table(file: &Source, t: &TableSection) -> Result<(), CellError> {
    file.coord("tool_table", "position", &t.position)?;
    file.size("tool_table", "size", &t.size, 10.0)?;
    file.size("tool_table", "leg_height", &[t.leg_height], 5.0)?;
    Ok(())
}

/// `[track]`: its direction, length, speed and acceleration.
fn check_track(file: &Source, tr: &TrackSection) -> Result<(), CellError> {
    file.finite_angle("track", "direction_deg", tr.direction_deg)?;
    file.size("track", "length", &[tr.length], 100.0)?;
    let positive = |key: &str, v: f64, max: f64, what: &str| {
        if v.is_finite() && v > 0.0 && v <= max {
            Ok(())
        } else {
            Err(file.bad(
                "track",
                key,
                format!("expected {what} above 0 and at most {max}, got {v}"),
            ))
        }
    };
    positive("speed", tr.speed, 10.0, "a carriage speed in m/s")?;
    positive("accel", tr.accel, 20.0, "a carriage acceleration in m/s²")?;
    Ok(())
}

/// Payload: the tool alone must not exceed it (the lumber comes on top; the executor checks).
fn check_payload(file: &Source, robot: &Robot, tool: &Tool) -> Result<(), CellError> {
    if let Some(payload) = robot.meta.payload
        && tool.mass > payload
    {
        return Err(file.bad(
            "tool",
            "model",
            format!(
                "the tool weighs {:.1} kg, more than the robot's payload of {payload:.1} kg",
                tool.mass
            ),
        ));
    }
    Ok(())
}

/// Both belts, placed in the cell; conveyor 2 with its slow end section.
fn build_conveyors(
    c1: &Conveyor1Section,
    c2: &Conveyor2Section,
    creep: Option<Creep>,
) -> (Conveyor, Conveyor) {
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
    (conveyor1, conveyor2)
}

/// The touch sensor at conveyor 2's downstream end, and the pick point `pick_offset` back
/// from its face.
fn build_sensor_and_pick(conveyor2: &Conveyor, s: &SensorSection) -> (TouchSensor, Pick) {
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
    let pick = Pick {
        point: face - dir * s.pick_offset,
        offset: s.pick_offset,
        margins: vec![],
        min_reach_margin: s.min_reach_margin,
    };
    (touch_sensor, pick)
}

/// The robot's base frame in the cell frame.
fn build_robot_base(r: &RobotSection) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(Vector3::from(r.base_position)),
        UnitQuaternion::from_euler_angles(0.0, 0.0, r.base_yaw_deg.to_radians()),
    )
}

/// The track, its carriage at `home` (the robot's base).
fn build_track(tr: &TrackSection, home: Isometry3<f64>) -> Track {
    let a = tr.direction_deg.to_radians();
    Track {
        home,
        direction: Vector3::new(a.cos(), a.sin(), 0.0),
        travel: [-tr.length / 2.0, tr.length / 2.0],
        speed: tr.speed,
        accel: tr.accel,
    }
}

/// The tool table, by the centre of its top's upper face.
fn build_tool_table(t: &TableSection) -> ToolTable {
    ToolTable {
        top_centre: Point3::new(
            t.position[0],
            t.position[1],
            t.position[2] + t.leg_height + t.size[2],
        ),
        size: t.size,
        leg_height: t.leg_height,
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
