//! Robot cell → input facts of the rule base: `cell_value(key, float)` and
//! `cell_choice(key, symbol)` (`rules/facts.dl`). The rules for framing
//! targets and the simulation world read the cell only through these keys, so
//! a user rule file sees the same numbers.
//!
//! Keys (SI units: m, m/s, kg, rad; poses in the cell frame unless said):
//!
//! | key | kind | meaning |
//! |---|---|---|
//! | `robot_base_x`, `_y`, `_z` | value | robot `base_link` origin in the cell frame |
//! | `robot_base_yaw` | value | robot base rotation about z, rad |
//! | `robot_payload` | value | rated payload, kg (absent when the robot's metadata has none) |
//! | `assembly_offset` | choice | `fixed` (every wall at `assembly_offset_x`) or `auto` (each wall placed by `rules/targets.dl` from the reach facts of `frame::placement`) |
//! | `assembly_offset_x` | value | fixed: robot +x distance from the base to the wall's bottom edge (parallel) or start (perpendicular) |
//! | `assembly_offset_min`, `_max` | value | auto: the offsets searched |
//! | `assembly_centre_y` | value | robot-frame y the laid-flat wall is centred on |
//! | `assembly_surface_z` | value | robot-frame height of the surface the wall lies on |
//! | `assembly_orientation` | choice | `parallel` (wall length along robot y) or `perpendicular` (along robot x) |
//! | `conveyor1_x`, `_y`, `_z` | value | centre of conveyor 1's belt top |
//! | `conveyor1_yaw` | value | conveyor 1's travel direction about z, rad |
//! | `conveyor1_length`, `conveyor1_width` | value | belt size |
//! | `conveyor1_speed` | value | belt speed, m/s |
//! | `conveyor1_lumber_gap` | value | gap between consecutive pieces on the belt (0.150 in the study) |
//! | `conveyor1_arrangement` | choice | `end_to_end` (pieces in a line along the belt) or `side_by_side` (across it, fed sideways onto conveyor 2) |
//! | `conveyor2_x`, `_y`, `_z`, `_yaw`, `_length`, `_width`, `_speed` | value | the same for conveyor 2 |
//! | `tool_mass` | value | mass of the end effector, kg |
//! | `gripper_spacing`, `gripper_open_width`, `gripper_closed_width` | value | the tool's grippers (absent for a tool without; the widths only for jaws) |
//! | `carry_length` | value | the longest piece the conveyors carry (conveyor 2's length, conveyor 1's width side by side or length end to end) |
//! | `panel_max_length`, `panel_max_height`, `panel_max_mass`, `panel_min_length`, `panel_cap_lap` | value | `[panels]` of the cell file (m, kg) |
//! | `gripper_holds` | choice | `sides` (jaws on the piece's side faces) or `top` (pads on its top face); absent for a tool without grippers |
//! | `built_up_headers` | choice | `plies` (each ply fed on its own) or `preassembled` (a built-up header fed as one member, `rules/world.dl`) |
//! | `panels` | choice | `auto` (walls split into panels by `rules/panels.dl`) or `off` (`--panels off`: every wall one panel) |
//! | `cell_name`, `robot_name`, `tool_name` | choice | names, for messages |

use super::facts::Facts;
use crate::cell::{Arrangement, Cell, Conveyor, Hold, OffsetX, Orientation};
use crate::logic::{Origin, Value};

/// The facts of a cell (keys above), each tuple from the cell file.
pub fn cell_facts(cell: &Cell) -> Facts {
    let mut facts = Facts::default();
    let origin = Origin::File {
        file: cell.source.display().to_string(),
        line: 0,
    };
    let mut value = |key: &str, x: f64| {
        facts.add(
            "cell_value",
            vec![Value::sym(key), Value::float(x)],
            origin.clone(),
        );
    };
    let base = &cell.robot_base;
    value("robot_base_x", base.translation.x);
    value("robot_base_y", base.translation.y);
    value("robot_base_z", base.translation.z);
    value("robot_base_yaw", base.rotation.euler_angles().2);
    if let Some(payload) = cell.robot.meta.payload {
        value("robot_payload", payload);
    }
    let a = &cell.assembly;
    match a.offset_x {
        OffsetX::Fixed { x } => value("assembly_offset_x", x),
        OffsetX::Auto { min, max } => {
            value("assembly_offset_min", min);
            value("assembly_offset_max", max);
        }
    }
    value("assembly_centre_y", a.centre_y);
    value("assembly_surface_z", a.surface_z);
    conveyor_values(&mut value, "conveyor1", &cell.conveyor1);
    value("conveyor1_lumber_gap", cell.lumber_gap);
    conveyor_values(&mut value, "conveyor2", &cell.conveyor2);
    value("tool_mass", cell.tool.mass);
    if let Some(g) = &cell.tool.gripper {
        value("gripper_spacing", g.spacing);
        if let Some(j) = g.jaws() {
            value("gripper_open_width", j.open_width);
            value("gripper_closed_width", j.closed_width);
        }
    }
    value("carry_length", cell.carry_length());
    let p = &cell.panels;
    value("panel_max_length", p.max_length);
    value("panel_max_height", p.max_height);
    value("panel_max_mass", p.max_mass);
    value("panel_min_length", p.min_length);
    value("panel_cap_lap", p.cap_lap);

    let mut choice = |key: &str, s: &str| {
        facts.add(
            "cell_choice",
            vec![Value::sym(key), Value::sym(s)],
            origin.clone(),
        );
    };
    choice(
        "assembly_orientation",
        match a.orientation {
            Orientation::Parallel => "parallel",
            Orientation::Perpendicular => "perpendicular",
        },
    );
    choice(
        "assembly_offset",
        match a.offset_x {
            OffsetX::Fixed { .. } => "fixed",
            OffsetX::Auto { .. } => "auto",
        },
    );
    choice(
        "conveyor1_arrangement",
        match cell.arrangement {
            Arrangement::EndToEnd => "end_to_end",
            Arrangement::SideBySide => "side_by_side",
        },
    );
    if let Some(g) = &cell.tool.gripper {
        choice(
            "gripper_holds",
            match g.holds {
                Hold::Sides(_) => "sides",
                Hold::Top(_) => "top",
            },
        );
    }
    choice("built_up_headers", a.built_up_headers.as_str());
    choice("panels", cell.panel_mode.as_str());
    choice("cell_name", &cell.name);
    choice("robot_name", &cell.robot.name);
    choice("tool_name", &cell.tool.name);
    facts
}

fn conveyor_values(value: &mut impl FnMut(&str, f64), prefix: &str, c: &Conveyor) {
    let t = c.pose.translation.vector;
    value(&format!("{prefix}_x"), t.x);
    value(&format!("{prefix}_y"), t.y);
    value(&format!("{prefix}_z"), t.z);
    value(&format!("{prefix}_yaw"), c.pose.rotation.euler_angles().2);
    value(&format!("{prefix}_length"), c.length);
    value(&format!("{prefix}_width"), c.width);
    value(&format!("{prefix}_speed"), c.speed);
}

impl Facts {
    /// Adds every tuple of `other` (model facts + cell facts = one input set).
    pub fn extend(&mut self, other: Facts) {
        for (name, tuples) in other.tuples {
            self.tuples.entry(name).or_default().extend(tuples);
        }
    }
}
