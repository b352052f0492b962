//! The shipped production line (`--cell framing-line`): an ABB IRB 4600 hanging inverted from a
//! gantry over the framing table. Its kinematics are checked against the floor-mounted robot's
//! own chain turned over by hand; its runs against the models' ground truth.

mod common;

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
    simulate_json_with(model, cell, &[])
}

fn simulate_json_with(model: &Path, cell: &str, args: &[&str]) -> Value {
    let mut all = vec!["simulate", model.to_str().unwrap(), "--cell", cell];
    all.extend(["--json", "--no-cache"]);
    all.extend(args);
    serde_json::from_slice(&framewright(&all)).expect("JSON")
}

/// `framewright ARGS…`, which must succeed: its standard output.
fn framewright(args: &[&str]) -> Vec<u8> {
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .expect("framewright runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    out.stdout
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

/// The world (`framewright world --format json`) of a model on a cell.
fn world_json(model: &Path, cell: &str) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("world.json");
    framewright(&[
        "world",
        model.to_str().unwrap(),
        "--cell",
        cell,
        "--format",
        "json",
        "--output",
        path.to_str().unwrap(),
    ]);
    serde_json::from_str(&std::fs::read_to_string(&path).unwrap()).unwrap()
}

/// Column `axis` of a pose's 4x4 matrix: where the piece's length (0), width (1) or thickness
/// (2) axis points.
fn axis(pose: &Value, axis: usize) -> Vector3<f64> {
    let m = &pose["matrix"];
    Vector3::from_fn(|row, _| m[row][axis].as_f64().unwrap())
}

/// The model's built-up headers: two plies of 2x10 on edge in the wall, 1/2 inch apart (the
/// spacer between them is not modelled). (outer ply, inner ply, thickness across the wall
/// from the outer ply's outer face to the inner ply's inner face, the gap between them.)
fn built_up_headers(truth: &Value) -> Vec<(String, String, f64, f64)> {
    let headers: Vec<&Value> = truth["members"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|m| m["role"] == "header")
        .collect();
    let mut out: Vec<(String, String, f64, f64)> = headers
        .iter()
        .filter(|h| h["role_detail"].as_str().unwrap().contains("inner"))
        .map(|inner| {
            let outer = headers
                .iter()
                .find(|h| {
                    h["axis_start"][0] == inner["axis_start"][0]
                        && h["global_id"] != inner["global_id"]
                })
                .unwrap();
            let t = inner["thickness"].as_f64().unwrap();
            let apart = (inner["axis_start"][1].as_f64().unwrap()
                - outer["axis_start"][1].as_f64().unwrap())
            .abs();
            let id = |m: &Value| m["global_id"].as_str().unwrap().to_string();
            (id(outer), id(inner), apart + t, apart - t)
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn door_window_wall() -> (PathBuf, Value) {
    let model =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/synth_wall_door_window_in.ifc");
    let truth: Value =
        serde_json::from_str(&std::fs::read_to_string(model.with_extension("truth.json")).unwrap())
            .unwrap();
    (model, truth)
}

/// A gripper holding the top face cannot turn a piece over between pick and place: a piece
/// that lies flat on the table at its target (a header on edge in the wall, whose width runs
/// up the wall and so lies level when the wall is laid down) is fed flat to it, thickness up;
/// the study's jaws take every piece on edge, width up.
#[test]
fn a_piece_flat_at_its_target_is_fed_flat_to_grippers_holding_the_top_face() {
    let (model, truth) = door_window_wall();
    let line = world_json(&model, "framing-line");
    let study = world_json(&model, "study-abb");
    // Lumber spawns on conveyor 1.
    let belt_top = Cell::load("framing-line")
        .unwrap()
        .conveyor1
        .pose
        .translation
        .z;
    let mut flat = vec![];
    for p in line["pieces"].as_array().unwrap() {
        let q = study["pieces"]
            .as_array()
            .unwrap()
            .iter()
            .find(|q| q["id"] == p["id"])
            .unwrap();
        // Flat at its target: its width axis lies (nearly) level on the table.
        let lies_flat = axis(&p["framing_target"]["cell"], 1).z.abs() < 0.9;
        let up = if lies_flat { 2 } else { 1 };
        assert!(
            axis(&p["spawn"], up).z.abs() > 0.999,
            "{}: fed with axis {up} up on the line",
            p["id"]
        );
        assert!(
            axis(&q["spawn"], 1).z.abs() > 0.999,
            "{}: on edge for the jaws",
            q["id"]
        );
        if lies_flat {
            flat.push(p["id"].as_str().unwrap().to_string());
            // Lying on the belt: its centre half its thickness above the belt top.
            let t = p["size"][2].as_f64().unwrap();
            let z = p["spawn"]["position"][2].as_f64().unwrap();
            assert!(
                (z - (belt_top + t / 2.0)).abs() < 1e-6,
                "{}: z {z}",
                p["id"]
            );
        }
    }
    // The headers are the flat pieces; on the line each arrives pre-assembled, fed as its
    // outer ply.
    let headers = built_up_headers(&truth);
    let outer: Vec<String> = headers.iter().map(|h| h.0.clone()).collect();
    flat.sort();
    assert_eq!(flat, outer, "the headers lie flat on the table");
}

/// The line's built-up headers arrive nailed up (`built_up_headers = "preassembled"`): one
/// member as thick as its plies and the spacer the model leaves out, set at once, so every
/// ply is framed. Fed ply by ply, an inner ply's target lies the missing spacer's thickness
/// above the outer ply, and released there it drops onto it by exactly that much.
#[test]
fn a_built_up_header_is_set_preassembled_and_fed_ply_by_ply_its_inner_ply_drops_by_the_spacer() {
    let (model, truth) = door_window_wall();
    let headers = built_up_headers(&truth);
    assert_eq!(headers.len(), 2);
    let line = world_json(&model, "framing-line");
    let pieces = line["pieces"].as_array().unwrap();
    for (outer, inner, thickness, _) in &headers {
        assert!(
            pieces.iter().all(|p| p["id"] != inner.as_str()),
            "{inner} fed alone"
        );
        let lead = pieces.iter().find(|p| p["id"] == outer.as_str()).unwrap();
        let t = lead["size"][2].as_f64().unwrap();
        assert!(
            (t - thickness).abs() < 1e-6,
            "{outer}: {t} m thick, plies {thickness} m"
        );
    }
    let sim = simulate_json(&model, "framing-line");
    let elements = sim["elements"].as_array().unwrap();
    assert_eq!(
        elements.len() as u64,
        truth["counts"]["members"].as_u64().unwrap()
    );
    for e in elements {
        assert_eq!(e["framing"]["status"], "framed", "{e}");
    }

    // The same line, each ply on its own.
    let dir = tempfile::tempdir().unwrap();
    let cell = dir.path().join("plies.toml");
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/cells/framing-line.toml"),
    )
    .unwrap();
    assert!(text.contains("built_up_headers = \"preassembled\""));
    std::fs::write(
        &cell,
        text.replace(
            "built_up_headers = \"preassembled\"",
            "built_up_headers = \"plies\"",
        ),
    )
    .unwrap();
    let sim = simulate_json(&model, cell.to_str().unwrap());
    for e in sim["elements"].as_array().unwrap() {
        let Some((_, _, _, gap)) = headers.iter().find(|h| h.1 == e["id"].as_str().unwrap()) else {
            assert_eq!(e["framing"]["status"], "framed", "{e}");
            continue;
        };
        let reason = e["framing"]["reasons"][0]["message"].as_str().unwrap();
        let mm: f64 = reason
            .strip_prefix("came to rest ")
            .and_then(|r| r.split(' ').next())
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{reason}"));
        assert!(
            (mm - gap * 1000.0).abs() < 0.5,
            "{reason}: the gap is {gap} m"
        );
    }
}

/// The line's pick belt ends in a slow section: a 60 mm block pushed onto it beside the sensor
/// meets the end stop at the creep speed and stays on edge. Without the slow section the same
/// blocks tip over against the stop.
#[test]
fn short_blocks_meet_the_end_stop_slowly_and_stay_on_edge() {
    let Some(model) = common::shared_path("ifc-testcases/g_scale_3storey.ifc") else {
        return;
    };
    // A wall of the 3-storey model with three 60 mm cripples (under its window sills).
    let wall = "0ZxqTpovzA$h0MfOGE1WTG";
    let sim = simulate_json_with(&model, "framing-line", &["--wall", wall]);
    let elements = sim["elements"].as_array().unwrap();
    assert!(!elements.is_empty());
    for e in elements {
        assert_eq!(e["framing"]["status"], "framed", "{e}");
    }
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/cells/framing-line.toml"),
    )
    .unwrap();
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("creep_"))
        .map(|l| format!("{l}\n"))
        .collect();
    assert_ne!(without, text, "the line's cell file has a slow section");
    let dir = tempfile::tempdir().unwrap();
    let cell = dir.path().join("no-creep.toml");
    std::fs::write(&cell, without).unwrap();
    let sim = simulate_json_with(&model, cell.to_str().unwrap(), &["--wall", wall]);
    let toppled: Vec<&Value> = sim["elements"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["framing"]["reasons"].to_string().contains("toppled"))
        .collect();
    assert_eq!(toppled.len(), 3, "{toppled:?}");
}

/// A model that holds members twice (the AutoTimber generator wrote one of its walls twice
/// over): each copy is named in a warning and built once, as its original, so it shares its
/// original's verdict and is never fed on its own. The copies are found here from the plan's
/// members (same wall, axis and section to the millimetre), apart from the rules.
#[test]
fn a_member_the_model_holds_twice_is_named_and_built_once() {
    let Some(model) = common::shared_path(
        "ifc-realworld/timber_autotimber-xbim-generated_outer-walls-5-framed_IFC4_feet.ifc",
    ) else {
        return;
    };
    let model = model.to_str().unwrap();
    let plan: Value = serde_json::from_slice(&framewright(&[
        "plan",
        model,
        "--cell",
        "framing-line",
        "--json",
    ]))
    .unwrap();
    let mm = |v: &Value| -> Vec<i64> {
        v.as_array()
            .unwrap()
            .iter()
            .map(|x| (x.as_f64().unwrap() * 1000.0).round() as i64)
            .collect()
    };
    let mut twins: std::collections::BTreeMap<(String, Vec<i64>), Vec<String>> = Default::default();
    for m in plan["members"].as_array().unwrap() {
        let mut ends = [mm(&m["axis_start"]), mm(&m["axis_end"])];
        ends.sort();
        let mut key = ends.concat();
        key.push((m["width"].as_f64().unwrap() * 1000.0).round() as i64);
        key.push((m["thickness"].as_f64().unwrap() * 1000.0).round() as i64);
        twins
            .entry((m["wall_id"].as_str().unwrap().to_string(), key))
            .or_default()
            .push(m["id"].as_str().unwrap().to_string());
    }
    let mut copies: Vec<(String, String)> = vec![];
    for ids in twins.values_mut().filter(|ids| ids.len() > 1) {
        ids.sort();
        copies.extend(ids[1..].iter().map(|c| (c.clone(), ids[0].clone())));
    }
    copies.sort();
    assert!(copies.len() >= 100, "{} copies", copies.len());
    let mut named: Vec<(String, String)> = plan["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|w| {
            // "SUBJECT: piece COPY duplicates ORIGINAL (…)"; the subject of a wall's key
            // piece reads as the wall.
            let (_, rest) = w.as_str()?.split_once(": piece ")?;
            let (copy, rest) = rest.split_once(" duplicates ")?;
            Some((copy.to_string(), rest.split(' ').next()?.to_string()))
        })
        .collect();
    named.sort();
    assert_eq!(named, copies);

    let wall = common::wall_holding(&plan, &copies[0].0)["wall_id"]
        .as_str()
        .unwrap()
        .to_string();
    let sim = simulate_json_with(Path::new(model), "framing-line", &["--wall", &wall]);
    let elements = sim["elements"].as_array().unwrap();
    let status = |id: &str| {
        elements
            .iter()
            .find(|e| e["id"] == id)
            .map(|e| e["framing"]["status"].clone())
            .unwrap_or_else(|| panic!("{id} has no verdict"))
    };
    let mut framed = 0;
    for (copy, original) in copies
        .iter()
        .filter(|(c, _)| common::wall_holding(&plan, c)["wall_id"] == wall.as_str())
    {
        // A plate cut at the panel breaks is elements `ID~k`: each segment as its original's.
        let segments: Vec<&str> = elements
            .iter()
            .filter_map(|e| e["id"].as_str())
            .filter(|id| {
                *id == copy
                    || id
                        .strip_prefix(copy.as_str())
                        .is_some_and(|r| r.starts_with('~'))
            })
            .collect();
        assert!(!segments.is_empty(), "{copy} has no verdict");
        for segment in segments {
            let twin = segment.replacen(copy.as_str(), original, 1);
            assert_eq!(status(segment), status(&twin), "{segment} as {twin}");
            framed += usize::from(status(segment) == "framed");
        }
    }
    assert!(framed > 0);
    let world = world_json(Path::new(model), "framing-line");
    let fed: Vec<&str> = world["pieces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["id"].as_str().unwrap())
        .collect();
    assert!(copies.iter().all(|(c, _)| !fed.contains(&c.as_str())));
}
