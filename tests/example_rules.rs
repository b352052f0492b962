//! The shop rules of examples/rules/: each fires exactly where it should. The
//! expected findings are computed here from other sources (the `plan --json`
//! report, the cell's robot and tool, the executor's records), never by
//! running the rule again. Models: the bundled TM1–TM3, the door-and-window
//! wall fixture and, for heavy headers, a generated wall with a solid 2x6
//! header over a wide door.

use framewright::cell::Cell;
use framewright::frame::RuleEngine;
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::sim::SimOptions;
use framewright::user_rules::{Finding, UserRules};
use serde_json::Value as Json;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
}

fn rule(name: &str) -> PathBuf {
    root().join("examples/rules").join(name)
}

/// The bundled models and the fixture with openings.
fn models() -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = ["tm1", "tm2", "tm3"]
        .iter()
        .map(|m| root().join(format!("examples/models/{m}.ifc")))
        .collect();
    v.push(root().join("tests/fixtures/synth_wall_door_window_in.ifc"));
    v
}

/// A wall with a solid 2x6 header over a 2.4 m door (a 44 kg header).
fn heavy_header_wall(dir: &Path) -> PathBuf {
    let out = dir.join("heavy_header.ifc");
    let status = bin()
        .args([
            "synth",
            "wall",
            "--length",
            "4m",
            "--lumber",
            "2x6",
            "--door",
            "1,2.4,2.1",
            "--header",
            "solid",
            "-o",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    out
}

fn plan(model: &Path) -> Json {
    let out = bin().arg("plan").arg(model).arg("--json").output().unwrap();
    assert!(out.status.success());
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `check --json` with one rule file: its violations as (id, message).
fn check(model: &Path, rule_file: &Path) -> (Vec<(String, String)>, Option<i32>) {
    let out = bin()
        .arg("check")
        .arg(model)
        .arg("--rules")
        .arg(rule_file)
        .arg("--json")
        .output()
        .unwrap();
    let code = out.status.code();
    assert!(
        code == Some(0) || code == Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Json = serde_json::from_slice(&out.stdout).unwrap();
    let found = v["violations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["id"].as_str().unwrap().to_string(),
                f["message"].as_str().unwrap().to_string(),
            )
        })
        .collect();
    (found, code)
}

fn members(plan: &Json) -> &Vec<Json> {
    plan["members"].as_array().unwrap()
}

fn f(v: &Json) -> f64 {
    v.as_f64().unwrap()
}

fn ids(found: &[(String, String)]) -> BTreeSet<String> {
    found.iter().map(|(id, _)| id.clone()).collect()
}

#[test]
fn members_shorter_than_the_gripper_spacing() {
    let cell = Cell::load("study-abb").unwrap();
    let spacing = cell.tool.gripper.as_ref().unwrap().spacing;
    let mut fired_somewhere = false;
    for m in models() {
        let p = plan(&m);
        let expected: BTreeSet<String> = members(&p)
            .iter()
            .filter(|x| !x["wall_id"].is_null() && f(&x["length"]) < spacing)
            .map(|x| x["id"].as_str().unwrap().to_string())
            .collect();
        let (found, code) = check(&m, &rule("gripper_spacing.dl"));
        assert_eq!(ids(&found), expected, "{}", m.display());
        assert_eq!(found.len(), expected.len(), "one finding per member");
        assert_eq!(code, Some(if expected.is_empty() { 0 } else { 1 }));
        fired_somewhere |= !expected.is_empty();
    }
    // The fixture's short cripples and its 508 mm plate piece.
    assert!(fired_somewhere);
}

#[test]
fn pieces_heavier_than_the_payload_minus_the_tool() {
    let cell = Cell::load("study-abb").unwrap();
    let net = cell.robot.meta.payload.unwrap() - cell.tool.mass;
    assert!(
        (net - 26.5).abs() < 0.5,
        "ABB 40 kg - tool 13.5 kg, got {net}"
    );
    let dir = tempfile::tempdir().unwrap();
    let mut all = models();
    all.push(heavy_header_wall(dir.path()));
    let mut fired = 0;
    for m in all {
        let p = plan(&m);
        let expected: BTreeSet<String> = members(&p)
            .iter()
            .filter(|x| !x["wall_id"].is_null() && f(&x["mass"]) > net)
            .map(|x| x["id"].as_str().unwrap().to_string())
            .collect();
        let (found, _) = check(&m, &rule("payload.dl"));
        assert_eq!(ids(&found), expected, "{}", m.display());
        fired += expected.len();
    }
    assert_eq!(fired, 1, "only the solid header is too heavy");
}

#[test]
fn nails_closer_than_20_mm_to_a_plate_end() {
    let mut fired = 0;
    for m in models() {
        let p = plan(&m);
        let by_id = |id: &str| members(&p).iter().find(|x| x["id"] == id).unwrap();
        let mut expected = BTreeSet::new();
        for w in p["walls"].as_array().unwrap() {
            for n in w["nailing_targets"].as_array().unwrap() {
                // Distance along the plate's axis from the nail to the nearer plate end.
                let plate = by_id(n["plate"].as_str().unwrap());
                let a: Vec<f64> = plate["axis_start"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(f)
                    .collect();
                let b: Vec<f64> = plate["axis_end"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(f)
                    .collect();
                let x: Vec<f64> = n["world"].as_array().unwrap().iter().map(f).collect();
                let len = f(&plate["length"]);
                let along: f64 = (0..3).map(|i| (x[i] - a[i]) * (b[i] - a[i]) / len).sum();
                let d = along.min(len - along);
                if d < 0.020 {
                    expected.insert((
                        n["plate"].as_str().unwrap().to_string(),
                        n["member"].as_str().unwrap().to_string(),
                    ));
                }
            }
        }
        let (found, _) = check(&m, &rule("nail_end_distance.dl"));
        let found: BTreeSet<(String, String)> = found
            .iter()
            .map(|(plate, msg)| {
                let member = msg
                    .strip_prefix("the nails into ")
                    .and_then(|r| r.split(' ').next())
                    .unwrap()
                    .to_string();
                (plate.clone(), member)
            })
            .collect();
        assert_eq!(found, expected, "{}", m.display());
        fired += expected.len();
    }
    // The end studs of every wall sit 19 mm from the ends of its bottom and
    // top plates: 2 x 2 joints per wall, 1 + 1 + 4 walls, and 6 in the
    // fixture (its bottom plate is split at the door).
    assert_eq!(fired, 4 + 4 + 16 + 6);
}

#[test]
fn headers_that_need_two_robots() {
    let dir = tempfile::tempdir().unwrap();
    let mut all = models();
    all.push(heavy_header_wall(dir.path()));
    let mut fired = 0;
    for m in all {
        let p = plan(&m);
        let expected: BTreeSet<String> = members(&p)
            .iter()
            .filter(|x| x["role"] == "header" && f(&x["mass"]) > 25.0)
            .map(|x| x["id"].as_str().unwrap().to_string())
            .collect();
        let (found, _) = check(&m, &rule("two_robot_headers.dl"));
        assert_eq!(ids(&found), expected, "{}", m.display());
        fired += expected.len();
    }
    // The fixture's built-up headers (4 kg) do not fire; the solid one does.
    assert_eq!(fired, 1);
}

#[test]
fn walls_longer_than_the_assembly_table() {
    let mut fired = 0;
    for m in models() {
        let p = plan(&m);
        let long: Vec<&Json> = p["walls"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|w| f(&w["length"]) > 6.10)
            .collect();
        let (found, _) = check(&m, &rule("assembly_table.dl"));
        assert_eq!(found.len(), long.len(), "{}", m.display());
        // Each finding names a piece of one of the long walls, one per wall.
        for w in &long {
            let members: BTreeSet<&str> = w["member_ids"]
                .as_array()
                .unwrap()
                .iter()
                .map(|x| x.as_str().unwrap())
                .collect();
            let hits = found
                .iter()
                .filter(|(id, _)| members.contains(id.as_str()))
                .count();
            assert_eq!(hits, 1, "{}", w["name"]);
        }
        fired += long.len();
    }
    assert_eq!(fired, 2, "TM3's two 6.858 m walls");
}

#[test]
fn poses_reached_with_less_than_50_mm_to_spare() {
    // On the executor's facts: simulate TM3's wall W1 on the study cell with
    // the assembly area moved 69 mm farther from the robot (offset_x 0.600
    // instead of 0.531), which brings one stud's place pose within 50 mm of
    // the arm's reach, and compare with the executor's own IK records.
    let dir = tempfile::tempdir().unwrap();
    let study = std::fs::read_to_string(root().join("robots/cells/study-abb.toml")).unwrap();
    let moved: String = study
        .lines()
        .map(|l| {
            if l.starts_with("offset_x = ") {
                "offset_x = 0.600".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    assert_ne!(moved, study.trim_end());
    let cell_file = dir.path().join("farther.toml");
    std::fs::write(&cell_file, moved).unwrap();
    let model = Model::open(root().join("examples/models/tm3.ifc")).unwrap();
    let cell = Cell::load(cell_file.to_str().unwrap()).unwrap();
    let sim = simulate(
        &model,
        &cell,
        &SimOptions {
            walls: vec!["W1".into()],
            ..SimOptions::default()
        },
    )
    .unwrap();
    let expected: BTreeSet<(String, String)> = sim
        .records
        .iter()
        .flat_map(|r| &r.ik)
        .filter(|ik| matches!(ik.result, Ok(m) if m < 0.050))
        .map(|ik| (ik.piece.clone(), ik.op.to_string()))
        .collect();
    assert!(
        !expected.is_empty(),
        "the moved cell brings a pose within 50 mm"
    );
    let rules = UserRules::load(&[rule("reach_margin.dl")], &RuleEngine::Compiled).unwrap();
    let findings = rules.evaluate(&sim.reasoned.relations).unwrap();
    assert!(findings.violations.is_empty());
    let found: BTreeSet<(String, String)> = findings
        .warnings
        .iter()
        .map(|Finding { id, message, .. }| {
            (id.clone(), message.split(' ').next().unwrap().to_string())
        })
        .collect();
    assert_eq!(found, expected);
    // The same rule finds nothing without a simulation (no sim_* facts).
    let (none, code) = check(
        &root().join("examples/models/tm3.ifc"),
        &rule("reach_margin.dl"),
    );
    assert!(none.is_empty());
    assert_eq!(code, Some(0));
}
