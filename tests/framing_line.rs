//! The shipped production line (`--cell framing-line`): an ABB IRB 4600 hanging inverted from a
//! gantry over the framing table. Its kinematics are checked against the floor-mounted robot's
//! own chain turned over by hand; its runs against the models' ground truth.

use framewright::cell::Cell;
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/models")
        .join(name)
}

fn simulate_json(model: &Path, cell: &str) -> Value {
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["simulate", model.to_str().unwrap(), "--cell", cell])
        .args(["--json", "--no-cache"])
        .output()
        .expect("framewright runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON")
}

/// A point and rotation turned over by a half turn about x, written out: (x, y, z) → (x, -y, -z).
fn turned_over(pose: &Isometry3<f64>) -> Isometry3<f64> {
    let t = pose.translation.vector;
    let flip = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
    Isometry3::from_parts(Translation3::new(t.x, -t.y, -t.z), flip * pose.rotation)
}

#[test]
fn the_hanging_robot_is_the_floor_robot_turned_over() {
    let line = Cell::load("framing-line").unwrap();
    let floor = Cell::load("study-abb").unwrap();
    assert_eq!(line.robot.name, floor.robot.name);
    for q in [
        [0.0, 0.0, 0.0, 0.0, 0.5, 0.0],
        [0.4, -0.3, 0.6, 1.0, -0.8, 2.0],
        [-1.2, 0.5, -0.4, -2.0, 1.1, -0.7],
    ] {
        let got = line.robot.fk_tip(&q);
        let want = turned_over(&floor.robot.fk_tip(&q));
        assert!((got.translation.vector - want.translation.vector).norm() < 1e-12);
        assert!(got.rotation.angle_to(&want.rotation) < 1e-12);
    }
}

#[test]
fn the_hanging_robot_reaches_down_to_the_table_in_the_upright_base_frame() {
    let cell = Cell::load("framing-line").unwrap();
    let grip = *cell.tool.tcp("grip").unwrap();
    let table = cell.surface_height();
    assert!((table - 0.80).abs() < 1e-9, "the table top at 0.80 m");
    // Grip straight down on a 2x4 lying on edge on the table, 1.2 m to the side of the base.
    let down = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI);
    let point = Point3::new(1.2, 0.3, table + 0.089);
    let pose_cell = Isometry3::from_parts(Translation3::from(point.coords), down);
    let pose = cell.robot_base.inverse() * pose_cell;
    let solutions = cell.robot.ik(&pose, &grip, &cell.robot.home()).unwrap();
    assert!(!solutions.is_empty());
    for q in &solutions {
        let tcp = cell.robot_base * cell.robot.fk_tip(q) * grip;
        assert!((tcp.translation.vector - point.coords).norm() < 1e-6);
        assert!(tcp.rotation.angle_to(&down) < 1e-6);
        // The same joints on the floor robot put its TCP at the point turned over.
        let floor = Cell::load("study-abb").unwrap();
        let unmounted = floor.robot.fk_tip(q) * grip;
        let back = turned_over(&unmounted);
        assert!((back.translation.vector - pose.translation.vector).norm() < 1e-6);
    }
    // The reach check sees the arm from the shoulder that hangs below the base.
    let margin = cell.robot.reach_margin(&pose, &grip).unwrap();
    assert!(margin > 0.0 && margin < 2.4, "margin {margin}");
}

/// TM3 has cap plates: laid beside its top plate on the table, a cap covers the entry points of
/// the nails through the top plate into the studs, and it is set face to face against that
/// plate. The line drives those nails before the cap goes on, and its grippers hold the cap by
/// its top face.
#[test]
fn the_line_frames_and_nails_every_piece_of_the_study_models() {
    for model in ["tm1", "tm2", "tm3"] {
        let truth: Value = serde_json::from_str(
            &std::fs::read_to_string(example(&format!("{model}.truth.json"))).unwrap(),
        )
        .unwrap();
        let sim = simulate_json(&example(&format!("{model}.ifc")), "framing-line");
        let elements = sim["elements"].as_array().unwrap();
        assert_eq!(
            elements.len() as u64,
            truth["counts"]["members"].as_u64().unwrap(),
            "{model}: every member of the model"
        );
        for e in elements {
            assert_eq!(e["framing"]["status"], "framed", "{model}: {e}");
            // Every plate and stud is nailed; a cap plate has no nails in the plan.
            let nailing = &e["nailing"]["status"];
            if e["role"] == "cap_plate" {
                assert_eq!(nailing, "none", "{model}: {e}");
            } else {
                assert_eq!(nailing, "nailed", "{model}: {e}");
            }
        }
        // A square frame: two nails through a plate into each end of each stud.
        let studs = truth["counts"]["by_role"]["stud"].as_u64().unwrap();
        let v = &sim["nailing_validation"];
        assert_eq!(v["planned"].as_u64().unwrap(), studs * 2 * 2, "{model}");
        assert_eq!(v["checked"], v["planned"], "{model}: every nail driven");
        assert_eq!(v["all_inside_members"], true);
        let targets = v["targets"].as_array().unwrap();
        assert!(targets.iter().all(|t| t["status"] == "fired"));
        assert_eq!(sim["contacts"].as_array().unwrap().len(), 0, "{model}");
    }
}

#[test]
fn a_cell_with_an_unknown_mounting_is_refused_with_its_key() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/cells/framing-line.toml"),
    )
    .unwrap()
    .replace("mounting = \"inverted\"", "mounting = \"sideways\"");
    let path = dir.path().join("bad.toml");
    std::fs::write(&path, text).unwrap();
    let err = Cell::load(path.to_str().unwrap()).unwrap_err().to_string();
    assert!(
        err.contains("mounting") || err.contains("sideways"),
        "{err}"
    );
    assert!(err.contains("bad.toml"), "{err}");
}
