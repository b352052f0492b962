//! Framing targets (`rules/targets.dl`): where each piece lies in the robot frame once its wall
//! is laid flat on the assembly area. Expected poses are computed here from the truth sidecar
//! of the example models (independent of the rules), and the laid-flat wall frame is compared
//! with `cell::Assembly::wall_to_cell`.

use framewright::cell::{Cell, Orientation};
use framewright::frame::{Ask, RuleEngine, cell_facts, model_facts};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::logic::Value;
use nalgebra::{Isometry3, Vector3};
use std::collections::BTreeMap;
use std::path::Path;

/// The shipped cell as the study laid its TM3 (bottom plate 0.531 m from the base) with
/// lumber end to end on conveyor 1: the fixed layout these tests were written against.
fn pinned(mut cell: Cell) -> Cell {
    cell.set_offset_x("0.531").unwrap();
    cell.arrangement = framewright::cell::Arrangement::EndToEnd;
    cell
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn iso(v: &Value) -> Isometry3<f64> {
    match v {
        Value::Iso(i) => i.0,
        other => panic!("expected an iso, got {other:?}"),
    }
}

fn sym(v: &Value) -> String {
    v.as_symbol().expect("a symbol").to_string()
}

/// (piece → target pose, wall → laid-flat frame) for a model on a cell.
fn targets(
    model: &str,
    cell: &Cell,
    engine: RuleEngine,
) -> (
    BTreeMap<String, Isometry3<f64>>,
    BTreeMap<String, Isometry3<f64>>,
) {
    let model = Model::open(root().join("examples/models").join(model)).unwrap();
    let mut facts = model_facts(&model, &ContactOptions::default());
    facts.extend(cell_facts(cell));
    let r = Ask::new(&engine).over(&facts).unwrap();
    let pieces = r
        .get("framing_target")
        .iter()
        .map(|t| (sym(&t[0]), iso(&t[1])))
        .collect();
    let walls = r
        .get("framing_target_wall")
        .iter()
        .map(|t| (sym(&t[0]), iso(&t[1])))
        .collect();
    (pieces, walls)
}

fn truth(model: &str) -> serde_json::Value {
    let text = std::fs::read_to_string(
        root()
            .join("examples/models")
            .join(model.replace(".ifc", ".truth.json")),
    )
    .unwrap();
    serde_json::from_str(&text).unwrap()
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap()
}

fn close(a: &Vector3<f64>, b: &Vector3<f64>, tol: f64) -> bool {
    (a - b).norm() < tol
}

/// Every member's expected target centre and axes from the truth's wall-local boxes, for a
/// parallel assembly area: wall (u, v, w) → robot (offset_x + v, centre_y + L/2 − u, surface_z + w).
#[test]
fn tm1_targets_on_the_abb_cell() {
    let cell = pinned(Cell::load("study-abb").unwrap());
    assert_eq!(cell.assembly.orientation, Orientation::Parallel);
    let (pieces, _) = targets("tm1.ifc", &cell, RuleEngine::Compiled);
    let t = truth("tm1.ifc");
    let wall = &t["walls"][0];
    let length = f(&wall["length"]);
    let members = t["members"].as_array().unwrap();
    assert_eq!(pieces.len(), members.len(), "one target per member");
    for m in members {
        let id = m["global_id"].as_str().unwrap();
        let b = &m["wall_local_box"];
        let mid = |k: &str| (f(&b[k][0]) + f(&b[k][1])) / 2.0;
        let (u, v, w) = (mid("u"), mid("v"), mid("w"));
        let expected = Vector3::new(0.531 + v, 0.0 + length / 2.0 - u, 0.0 + w);
        let pose = pieces[id];
        assert!(
            close(&pose.translation.vector, &expected, 1e-6),
            "{id}: target {:?}, expected {expected:?}",
            pose.translation.vector
        );
        // On edge: the width axis (body y) points up; the length axis (body x) lies level.
        let y = pose.rotation * Vector3::y();
        let x = pose.rotation * Vector3::x();
        assert!(close(&y, &Vector3::z(), 1e-9), "{id}: width axis {y:?}");
        let along = if m["orientation"] == "vertical" {
            // A stud runs up the wall: along robot +x.
            Vector3::x()
        } else {
            // A plate runs along the wall: along robot -y.
            -Vector3::y()
        };
        assert!(close(&x, &along, 1e-9), "{id}: length axis {x:?}");
        // The piece lies on the floor: its lowest point at surface_z (the wall's outer face).
        let lowest = pose.translation.z - f(&m["width"]) / 2.0;
        assert!(lowest > -1e-6, "{id}: below the floor ({lowest})");
    }
}

/// The laid-flat wall frame from the rules equals the cell contract computed here (robot at
/// the cell origin in both shipped cells, a fixed offset), for both orientations: parallel,
/// v (height) along +x from offset_x and u along -y centred on centre_y; perpendicular, u along
/// +x from offset_x and v along +y, the height centred on centre_y.
#[test]
fn wall_frames_agree_with_the_cell_module() {
    for cell_name in ["study-abb", "study-kuka"] {
        for orientation in [Orientation::Parallel, Orientation::Perpendicular] {
            let mut cell = pinned(Cell::load(cell_name).unwrap());
            cell.set_offset_x("0.531").unwrap();
            cell.assembly.orientation = orientation;
            let (pieces, walls) = targets("tm3.ifc", &cell, RuleEngine::Compiled);
            assert_eq!(walls.len(), 4, "{cell_name}: tm3 has four walls");
            assert!(pieces.len() >= 60, "{cell_name}: {} targets", pieces.len());
            let model = Model::open(root().join("examples/models/tm3.ifc")).unwrap();
            let facts = model_facts(&model, &ContactOptions::default());
            let r = Ask::new(&RuleEngine::Compiled).over(&facts).unwrap();
            for t in r.get("wall_size") {
                let w = sym(&t[0]);
                let (l, h) = (t[1].as_float().unwrap(), t[2].as_float().unwrap());
                let a = &cell.assembly;
                let (origin, u, v) = match orientation {
                    Orientation::Parallel => (
                        Vector3::new(0.531, a.centre_y + l / 2.0, a.surface_z),
                        -Vector3::y(),
                        Vector3::x(),
                    ),
                    Orientation::Perpendicular => (
                        Vector3::new(0.531, a.centre_y - h / 2.0, a.surface_z),
                        Vector3::x(),
                        Vector3::y(),
                    ),
                };
                let rotation = nalgebra::Rotation3::from_basis_unchecked(&[u, v, u.cross(&v)]);
                let expected = cell.to_robot(&nalgebra::Isometry3::from_parts(
                    nalgebra::Translation3::from(origin),
                    nalgebra::UnitQuaternion::from_rotation_matrix(&rotation),
                ));
                let got = walls[&w];
                assert!(
                    close(&got.translation.vector, &expected.translation.vector, 1e-9)
                        && got.rotation.angle_to(&expected.rotation) < 1e-9,
                    "{cell_name} {orientation:?} {w}: rules {got}, cell module {expected}"
                );
            }
        }
    }
}

/// Perpendicular: wall u along robot +x from offset_x, v along +y centred on centre_y.
#[test]
fn perpendicular_targets_run_along_x() {
    let mut cell = pinned(Cell::load("study-abb").unwrap());
    cell.set_offset_x("0.531").unwrap();
    cell.assembly.orientation = Orientation::Perpendicular;
    let (pieces, _) = targets("tm1.ifc", &cell, RuleEngine::Compiled);
    let t = truth("tm1.ifc");
    let height = f(&t["walls"][0]["height"]);
    for m in t["members"].as_array().unwrap() {
        let id = m["global_id"].as_str().unwrap();
        let b = &m["wall_local_box"];
        let mid = |k: &str| (f(&b[k][0]) + f(&b[k][1])) / 2.0;
        let expected = Vector3::new(0.531 + mid("u"), mid("v") - height / 2.0, mid("w"));
        assert!(
            close(&pieces[id].translation.vector, &expected, 1e-6),
            "{id}: {:?} vs {expected:?}",
            pieces[id].translation.vector
        );
    }
}

/// The interpreter and the compiled rules give the same targets.
#[test]
fn engines_agree_on_targets() {
    let cell = pinned(Cell::load("study-kuka").unwrap());
    let (a, wa) = targets("tm3.ifc", &cell, RuleEngine::Compiled);
    let (b, wb) = targets("tm3.ifc", &cell, RuleEngine::Interpreted);
    assert_eq!(a, b);
    assert_eq!(wa, wb);
}

/// The cell facts carry the keys the rules read, with the cell's numbers.
#[test]
fn cell_facts_hold_the_documented_keys() {
    let cell = pinned(Cell::load("study-abb").unwrap());
    let rel = cell_facts(&cell).relations();
    let values: BTreeMap<String, f64> = rel["cell_value"]
        .iter()
        .map(|t| (sym(&t[0]), t[1].as_float().unwrap()))
        .collect();
    let choices: BTreeMap<String, String> = rel["cell_choice"]
        .iter()
        .map(|t| (sym(&t[0]), sym(&t[1])))
        .collect();
    for (key, expected) in [
        ("assembly_offset_x", 0.531),
        ("assembly_centre_y", 0.0),
        ("assembly_surface_z", 0.0),
        ("conveyor1_x", -5.45),
        ("conveyor1_y", 3.45),
        ("conveyor1_z", 0.80),
        ("conveyor1_length", 8.0),
        ("conveyor1_width", 7.5),
        ("conveyor1_speed", 0.05),
        ("conveyor1_lumber_gap", 0.150),
        ("conveyor2_speed", 2.0),
        ("robot_base_x", 0.0),
        ("robot_base_yaw", 0.0),
        ("robot_payload", 40.0),
    ] {
        assert!(
            (values[key] - expected).abs() < 1e-12,
            "{key}: {}",
            values[key]
        );
    }
    // The infeed deck runs towards +x, across conveyor 2.
    assert!(values["conveyor1_yaw"].abs() < 1e-12);
    assert_eq!(choices["assembly_orientation"], "parallel");
    assert_eq!(choices["cell_name"], "study-abb");
}

/// A moved and turned robot base: targets stay in the robot frame (the assembly keys are
/// robot-frame numbers), and the scene's cell-frame targets follow the base.
#[test]
fn targets_are_in_the_robot_frame_for_a_moved_base() {
    let mut cell = pinned(Cell::load("study-abb").unwrap());
    let (before, _) = targets("tm1.ifc", &cell, RuleEngine::Compiled);
    cell.robot_base = Isometry3::new(Vector3::new(1.0, -2.0, 0.0), Vector3::z() * 0.7);
    let (after, _) = targets("tm1.ifc", &cell, RuleEngine::Compiled);
    for (id, pose) in &before {
        assert!(
            close(
                &pose.translation.vector,
                &after[id].translation.vector,
                1e-9
            ),
            "{id}"
        );
    }
    let target = serde_json::to_value(framewright::world::FramingTarget {
        piece: "p".into(),
        wall: "w".into(),
        pose: after.values().next().copied().unwrap(),
    })
    .unwrap();
    assert_eq!(target["pose"]["matrix"].as_array().unwrap().len(), 4);
    assert_eq!(target["wall_id"], "w");
}
