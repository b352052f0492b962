//! The shipped cells and tool load and are consistent; bad cell files are refused with
//! file:line, the key and what is expected.

use framewright::cell::{Cell, CellError, Orientation, Tool};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/cells")
        .join(name)
}

#[test]
fn study_cells_load_with_the_study_numbers() {
    for (name, robot) in [
        ("study-abb", "abb-irb4600-40-255"),
        ("study-kuka", "kuka-kr150-2"),
    ] {
        let cell = Cell::load(name).unwrap();
        assert_eq!(cell.name, name);
        assert_eq!(cell.robot.name, robot);
        // Each wall placed where the arm reaches most of it, searched from clear of the base.
        let framewright::cell::OffsetX::Auto { min, max } = cell.assembly.offset_x else {
            panic!("{name}: offset_x is {}", cell.assembly.offset_x)
        };
        assert!(min > 0.3 && min < 1.0 && max > 2.0, "{name}: {min}..{max}");
        assert_eq!(cell.assembly.orientation, Orientation::Parallel);
        assert_eq!(cell.assembly.centre_y, 0.0);
        assert_eq!(cell.conveyor1.speed, 0.05);
        assert_eq!(cell.conveyor2.speed, 2.0);
        assert_eq!(cell.lumber_gap, 0.150);
        // The sensor sits at the downstream end of conveyor 2; the pick point is on that belt.
        let end = cell.conveyor2.downstream_end();
        assert!((cell.touch_sensor.face - end).norm() < 1e-12);
        assert!((cell.pick.point - end).norm() - cell.pick.offset < 1e-12);
        // Conveyor 1 feeds conveyor 2 from the side: it runs across conveyor 2 and ends at
        // conveyor 2's near edge.
        assert_eq!(cell.arrangement, framewright::cell::Arrangement::SideBySide);
        assert!(
            cell.conveyor1
                .direction()
                .dot(&cell.conveyor2.direction())
                .abs()
                < 1e-9
        );
        let to_centre_line = (cell.conveyor2.pose.translation.vector
            - cell.conveyor1.downstream_end().coords)
            .dot(&cell.conveyor1.direction());
        assert!((to_centre_line - cell.conveyor2.width / 2.0).abs() < 1e-9);
        // Picks of 2x4 and 2x6 on edge are reachable with the required margin.
        assert_eq!(cell.pick.margins.len(), 2);
        for &(h, margin) in &cell.pick.margins {
            assert!(
                margin >= cell.pick.min_reach_margin,
                "{name}: {h} m lumber: margin {margin}"
            );
            let pose = cell.to_robot(&cell.pick_pose(h));
            let sols = cell
                .robot
                .ik(&pose, cell.tool.tcp("grip").unwrap(), &cell.robot.home())
                .unwrap();
            let got = cell.robot.fk_tip(&sols[0]) * cell.tool.tcp("grip").unwrap();
            assert!((got.translation.vector - pose.translation.vector).norm() < 1e-6);
        }
        // The tool is lighter than the payload.
        assert!(cell.tool.mass < cell.robot.meta.payload.unwrap());
    }
}

#[test]
fn cell_loads_from_a_path_too() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/cells/study-kuka.toml");
    let cell = Cell::load(path.to_str().unwrap()).unwrap();
    assert_eq!(cell.robot.name, "kuka-kr150-2");
}

#[test]
fn study_tool_has_grip_and_nail_frames_and_takes_2x6() {
    let tool = Tool::study();
    assert!(tool.tcp("grip").is_some() && tool.tcp("nail").is_some());
    assert!((tool.mass - 13.5).abs() < 1e-9, "{}", tool.mass);
    let nailer: f64 = tool
        .parts
        .iter()
        .filter(|p| p.name.starts_with("nailer"))
        .map(|p| p.mass)
        .sum();
    assert!((nailer - 4.0).abs() < 1e-9);
    let g = tool.gripper.as_ref().unwrap();
    assert_eq!(g.count, 2);
    let g = g.jaws().expect("the study's grippers have jaws");
    assert!(g.takes(0.038, 0.140), "2x6");
    assert!(g.takes(0.038, 0.089), "2x4");
    assert!(!g.takes(0.089, 0.184), "4x8 is too wide");
    // The nail direction (TCP z) is tool0 +x: nailing does not push the jaws into the work.
    let nail_z = tool.tcp("nail").unwrap().rotation * nalgebra::Vector3::z();
    assert!((nail_z - nalgebra::Vector3::x()).norm() < 1e-12);
}

fn load_error(file: &str) -> String {
    let err = Cell::load(fixture(file).to_str().unwrap()).unwrap_err();
    assert!(
        matches!(err, CellError::Toml { .. } | CellError::Value { .. }),
        "{err:?}"
    );
    err.to_string()
}

#[test]
fn unknown_key_names_file_line_and_key() {
    let msg = load_error("unknown_key.toml");
    assert!(
        msg.contains("unknown_key.toml:34:1: key `conveyor1.speeed`"),
        "{msg}"
    );
    assert!(
        msg.contains("speeed") && msg.contains("expected one of"),
        "{msg}"
    );
}

#[test]
fn wrong_type_names_file_line_and_expected_type() {
    let msg = load_error("wrong_type.toml");
    assert!(
        msg.contains("wrong_type.toml:41:9: key `conveyor2.width`"),
        "{msg}"
    );
    assert!(msg.contains("expected f64"), "{msg}");
}

#[test]
fn unreachable_pick_point_is_refused() {
    let msg = load_error("unreachable_pick.toml");
    assert!(msg.contains("unreachable_pick.toml:"), "{msg}");
    assert!(
        msg.contains("touch_sensor.pick_offset") && msg.contains("out of reach"),
        "{msg}"
    );
    assert!(msg.contains("reach 2.377"), "{msg}");
}

#[test]
fn tool_heavier_than_payload_is_refused() {
    let msg = load_error("heavy_tool_cell.toml");
    assert!(
        msg.contains("heavy_tool_cell.toml:15: key `tool.model`"),
        "{msg}"
    );
    assert!(
        msg.contains("50.5 kg") && msg.contains("payload of 40.0 kg"),
        "{msg}"
    );
}

#[test]
fn negative_speed_is_refused() {
    let msg = load_error("negative_speed.toml");
    assert!(
        msg.contains("negative_speed.toml:42: key `conveyor2.speed`"),
        "{msg}"
    );
}

#[test]
fn unknown_robot_is_refused_at_its_line() {
    let msg = load_error("unknown_robot.toml");
    assert!(
        msg.contains("unknown_robot.toml:10: key `robot.model`"),
        "{msg}"
    );
    assert!(msg.contains("abb-irb4600-40-255"), "{msg}");
}

#[test]
fn unknown_cell_name_lists_the_built_ins() {
    let msg = Cell::load("study-fanuc").unwrap_err().to_string();
    assert!(
        msg.contains("study-abb") && msg.contains("study-kuka"),
        "{msg}"
    );
}

#[test]
fn study_layout_reproduces_the_unreachable_top_plate() {
    // An 8 ft (2.44 m) wall laid flat from assembly.offset_x: the middle of a stud is within
    // reach, the top plate (2x4 on edge, grip TCP pointing down on its top face) is not — as in
    // the study.
    for name in ["study-abb", "study-kuka"] {
        let cell = Cell::load(name).unwrap();
        let grip = *cell.tool.tcp("grip").unwrap();
        let down = |x: f64| {
            nalgebra::Isometry3::from_parts(
                nalgebra::Translation3::new(x, 0.0, 0.089),
                nalgebra::UnitQuaternion::from_euler_angles(std::f64::consts::PI, 0.0, 0.0),
            )
        };
        // The study's placement of TM3 (Tables 6-9): bottom plate's outer face at x = 0.531 m.
        let middle = 0.531 + 1.22;
        let top = 0.531 + 2.44 - 0.019;
        assert!(
            cell.robot
                .ik(&cell.to_robot(&down(middle)), &grip, &cell.robot.home())
                .is_ok(),
            "{name}"
        );
        match cell
            .robot
            .ik(&cell.to_robot(&down(top)), &grip, &cell.robot.home())
        {
            Err(framewright::cell::IkFailure::OutOfReach {
                distance, reach, ..
            }) => assert!(distance > reach),
            other => panic!("{name}: top plate at x = {top}: {other:?}"),
        }
    }
}

#[test]
fn pick_without_enough_margin_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/cells/study-abb.toml"),
    )
    .unwrap()
    .replace("min_reach_margin = 0.10", "min_reach_margin = 1.50");
    let file = dir.path().join("tight.toml");
    std::fs::write(&file, text).unwrap();
    let msg = Cell::load(file.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        msg.contains("key `touch_sensor.pick_offset`")
            && msg.contains("to spare; at least 1.500 m"),
        "{msg}"
    );
}

/// A nailer may lean a nail from 0 up to a toe nail's 30°; the study tool allows some lean.
#[test]
fn nail_lean_outside_0_to_30_degrees_is_refused() {
    let study = include_str!("../robots/tools/study-gripper-nailer.toml");
    assert!(Tool::study().max_nail_lean > 0.0);
    for bad in ["45.0", "-5.0", "nan"] {
        let text = study.replace("max_lean_deg = 20.0", &format!("max_lean_deg = {bad}"));
        assert_ne!(text, study, "the study tool says max_lean_deg = 20.0");
        let msg = Tool::parse(Path::new("lean.toml"), &text)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("lean.toml:")
                && msg.contains("nailer.max_lean_deg")
                && msg.contains("0 to 30"),
            "{bad}: {msg}"
        );
    }
    // Without a [nailer] table every nail is driven square.
    let start = study.find("[nailer]").unwrap();
    let end = study.find("slide = 0.10").unwrap() + "slide = 0.10".len();
    let square = format!("{}{}", &study[..start], &study[end..]);
    assert_eq!(
        Tool::parse(Path::new("square.toml"), &square)
            .unwrap()
            .max_nail_lean,
        0.0
    );
}

/// The line's tool holds the top face: no jaws, and the keys of each kind of gripper belong to
/// it alone.
#[test]
fn a_gripper_holding_the_top_face_has_pads_and_no_jaws() {
    use framewright::cell::Hold;
    let line = include_str!("../robots/tools/line-vacuum-nailer.toml");
    let tool = Tool::load("line-vacuum-nailer").unwrap();
    let g = tool.gripper.as_ref().unwrap();
    assert!(g.jaws().is_none());
    let Hold::Top(pads) = g.holds else {
        panic!("the line's tool holds the top face")
    };
    // The pads fit the 38 mm face of lumber on edge; the rating holds a 12 m 2x6 plate
    // (0.038 x 0.140 x 12 m at 500 kg/m3 = 31.9 kg).
    assert!(pads.pad_width < 0.038);
    assert!(pads.max_mass > 0.038 * 0.140 * 12.0 * 500.0);
    // No part of the tool reaches below the grip TCP (the top face of the held piece).
    let grip_z = tool.tcp("grip").unwrap().translation.z;
    for part in tool.parts.iter().filter(|p| p.name.starts_with("gripper")) {
        let framewright::cell::Shape::Box { half_extents } = part.shape.shape else {
            panic!("{} is a box", part.name)
        };
        let bottom = part.shape.origin.translation.z + half_extents[2];
        assert!(
            bottom <= grip_z + 1e-9,
            "{} reaches to z {bottom}",
            part.name
        );
    }

    let bad = |from: &str, to: &str| {
        let text = line.replace(from, to);
        assert_ne!(text, line, "{from}");
        Tool::parse(Path::new("pads.toml"), &text)
            .unwrap_err()
            .to_string()
    };
    let msg = bad("pad_width = 0.030", "pad_width = 0.030\nopen_width = 0.16");
    assert!(
        msg.contains("pads.toml:") && msg.contains("open_width") && msg.contains("top face"),
        "{msg}"
    );
    let msg = bad("pad_width = 0.030", "");
    assert!(
        msg.contains("pad_width") && msg.contains("missing"),
        "{msg}"
    );
    let msg = bad("holds = \"top\"", "holds = \"magnet\"");
    assert!(
        msg.contains("gripper.holds") && msg.contains("magnet"),
        "{msg}"
    );
    let msg = bad("max_mass = 50.0", "max_mass = -1.0");
    assert!(msg.contains("gripper.max_mass"), "{msg}");
    // The study's jaws without their stroke: named, with the kind that needs it.
    let study = include_str!("../robots/tools/study-gripper-nailer.toml");
    let text = study.replace("stroke = 0.065", "");
    let msg = Tool::parse(Path::new("jaws.toml"), &text)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("stroke") && msg.contains("sides"), "{msg}");
}

/// A slow-down of conveyor 2 needs both its speed (below the belt's) and its length (within
/// the belt); the line and the study's cells have one, a belt without the keys runs at one
/// speed.
#[test]
fn a_creep_section_needs_its_speed_and_length_within_the_belt() {
    let line = Cell::load("framing-line").unwrap();
    let creep = line
        .conveyor2
        .creep
        .expect("the line's pick belt has a slow end");
    assert!(creep.speed < line.conveyor2.speed && creep.length <= line.conveyor2.length);
    assert!(Cell::load("study-abb").unwrap().conveyor2.creep.is_some());
    let text = include_str!("../robots/cells/framing-line.toml");
    let one_speed: String = text
        .lines()
        .filter(|l| !l.starts_with("creep_"))
        .map(|l| format!("{l}\n"))
        .collect();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("one-speed.toml");
    std::fs::write(&path, one_speed).unwrap();
    assert!(
        Cell::load(path.to_str().unwrap())
            .unwrap()
            .conveyor2
            .creep
            .is_none()
    );
    for (from, to) in [
        ("creep_length = 0.6\n", ""),
        ("creep_speed = 0.3", "creep_speed = 2.5"),
        ("creep_length = 0.6", "creep_length = 13.0"),
        ("creep_speed = 0.3", "creep_speed = -0.3"),
    ] {
        let bad = text.replace(from, to);
        assert_ne!(bad, text, "{from}");
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("creep.toml");
        std::fs::write(&path, bad).unwrap();
        let msg = Cell::load(path.to_str().unwrap()).unwrap_err().to_string();
        assert!(
            msg.contains("creep.toml:") && msg.contains("conveyor2.creep_speed"),
            "{to}: {msg}"
        );
    }
}

/// The nailer rides back on a slide while the tool frames (the line's tool and the study's).
#[test]
fn a_nailer_slide_is_within_half_a_metre() {
    let line = include_str!("../robots/tools/line-vacuum-nailer.toml");
    assert!(Tool::load("line-vacuum-nailer").unwrap().nailer_slide > 0.0);
    for bad in ["-0.1", "0.6", "nan"] {
        let text = line.replace("slide = 0.10", &format!("slide = {bad}"));
        assert_ne!(text, line);
        let msg = Tool::parse(Path::new("slide.toml"), &text)
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("slide.toml:") && msg.contains("nailer.slide"),
            "{bad}: {msg}"
        );
    }
}

/// The line's built-up headers arrive pre-assembled; the study's cells feed each ply; any
/// other word is refused at its line with the two it takes.
#[test]
fn built_up_headers_are_plies_or_preassembled() {
    use framewright::cell::BuiltUpHeaders;
    let line = Cell::load("framing-line").unwrap();
    assert_eq!(line.assembly.built_up_headers, BuiltUpHeaders::Preassembled);
    for study in ["study-abb", "study-abb-track", "study-kuka"] {
        let cell = Cell::load(study).unwrap();
        assert_eq!(cell.assembly.built_up_headers, BuiltUpHeaders::Plies);
    }
    let text = include_str!("../robots/cells/framing-line.toml");
    let bad = text.replace(
        "built_up_headers = \"preassembled\"",
        "built_up_headers = \"glued\"",
    );
    assert_ne!(bad, text);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("headers.toml");
    std::fs::write(&path, bad).unwrap();
    let msg = Cell::load(path.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        msg.contains("headers.toml:")
            && msg.contains("assembly.built_up_headers")
            && msg.contains("preassembled"),
        "{msg}"
    );
}
