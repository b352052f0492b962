//! `why` gives each failure's numbers of where: the pose a piece would have taken (cell and
//! wall frames), the two bodies that touched with their centres and the depth, and for a piece
//! that came to rest off its target what lay beneath it when released and how far below. The
//! expected numbers come from the model and the tool as written, worked out by hand.

mod common;

use serde_json::Value;
use std::path::{Path, PathBuf};

use common::framewright_ok as framewright;
use common::ifc_edit::tm3_stud_moved;

fn tm3() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc")
}

/// The framing cause `why --json` gives for the one element.
fn framing_cause(model: &Path, id: &str, extra: &[&str]) -> Value {
    let args = [&["why", model.to_str().unwrap(), id, "--json"][..], extra].concat();
    let json: Value = serde_json::from_str(&framewright(&args)).unwrap();
    json["elements"][0]["answer"]["causes"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["stage"] == "framing")
        .cloned()
        .unwrap_or_else(|| panic!("no framing cause: {json}"))
}

fn located<'c>(cause: &'c Value, kind: &str) -> Vec<&'c Value> {
    cause["located"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|l| l["kind"] == kind)
        .collect()
}

fn xyz(v: &Value) -> [f64; 3] {
    let a = v.as_array().unwrap();
    [0, 1, 2].map(|i| a[i].as_f64().unwrap())
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn a_place_pose_beyond_reach_is_where_the_model_puts_the_piece() {
    // Stud F-016: IfcLocalPlacement at (1.1684, 0.04445, 0.0381), extruded 2.352675 m up.
    // TM3's wall runs from x = 6.858 along -x (its placement #28: origin #25, axis #27 = (-1, 0, 0)); its frame: u from
    // that start, v up from z = 0, w across from the face at y = 0 (docs/RELATIONS.md). So the
    // stud's centre is at u = 6.858 - 1.1684, v = 0.0381 + 2.352675 / 2, w = 0.04445.
    let cause = framing_cause(&tm3(), "2nv91WmrtNJ_0CsN4f5WS5", &["--no-cache"]);
    assert!(
        cause["message"].as_str().unwrap().contains("beyond reach"),
        "{cause}"
    );
    let poses = located(&cause, "pose");
    assert_eq!(poses.len(), 1, "{cause}");
    assert_eq!(poses[0]["op"], "place");
    let wall = xyz(&poses[0]["wall"]);
    let modelled = [6.858 - 1.1684, 0.0381 + 2.352675 / 2.0, 0.04445];
    assert!(dist(wall, modelled) < 1e-4, "{wall:?} vs {modelled:?}");
    // Laid flat on the table, the wall's w is the cell's height: both frames agree on it.
    let cell = xyz(&poses[0]["cell"]);
    assert!((cell[2] - wall[2]).abs() < 1e-4, "{cell:?} / {wall:?}");
}

#[test]
fn a_piece_modelled_above_its_support_says_how_far_it_dropped_and_onto_what() {
    // Stud F-016 moved 20 mm across the wall (out of its plane): laid flat, its target lies
    // 20 mm above what it should rest on; the executor releases it 1 mm above its target, so
    // it is let go 21 mm above the surface and drops onto it. At offset_x 0.742 the arm
    // reaches it (TM3's own remedy for this stud).
    let dir = tempfile::tempdir().unwrap();
    let model = tm3_stud_moved(dir.path(), 0.020);
    let cause = framing_cause(
        &model,
        "2nv91WmrtNJ_0CsN4f5WS5",
        &["--offset-x", "0.742", "--no-cache"],
    );
    assert!(
        cause["message"]
            .as_str()
            .unwrap()
            .starts_with("came to rest "),
        "{cause}"
    );
    let releases = located(&cause, "release");
    assert_eq!(releases.len(), 1, "{cause}");
    let gap = releases[0]["gap"].as_f64().unwrap();
    assert!((gap - 0.021).abs() < 0.001, "released {gap} m above");
    assert!(!releases[0]["below"].as_str().unwrap().is_empty());
    // The remedy moves the piece back by what it is off: 20 mm back across the wall, which
    // runs along the model's x with its faces at y = 0 and y = 0.0889 (−y in the model), and
    // a new simulation with it moved frames it.
    let remedy = cause["remedies"]
        .as_array()
        .unwrap()
        .iter()
        .find(|r| r["change"] == "piece_position")
        .unwrap_or_else(|| panic!("no remedy: {cause}"));
    assert!(
        (remedy["value"].as_f64().unwrap() + 0.020).abs() < 0.001,
        "{remedy}"
    );
    let by = xyz(&remedy["piece_move"]["by"]);
    assert!(dist(by, [0.0, -0.020, 0.0]) < 0.001, "{remedy}");
    assert_eq!(remedy["piece_move"]["piece"], "2nv91WmrtNJ_0CsN4f5WS5");
    assert_eq!(remedy["checked"], true, "{remedy}");
    assert!(
        remedy["text"]
            .as_str()
            .unwrap()
            .ends_with("checked by simulating the wall again with the piece moved: framed"),
        "{remedy}"
    );
    // The text says it in the first lines.
    let text = framewright(&[
        "why",
        model.to_str().unwrap(),
        "2nv91WmrtNJ_0CsN4f5WS5",
        "--offset-x",
        "0.742",
    ]);
    let head: Vec<&str> = text.lines().take(8).collect();
    assert!(
        head.iter()
            .any(|l| l.contains("where: released 21.0 mm above")),
        "{text}"
    );
}

#[test]
fn where_survives_the_cache() {
    // A `why` answered from the cached simulation gives the same numbers of where.
    let dir = tempfile::tempdir().unwrap();
    let model = tm3_stud_moved(dir.path(), 0.020);
    let cache = dir.path().join("cache");
    let run = || {
        framewright(&[
            "why",
            model.to_str().unwrap(),
            "2nv91WmrtNJ_0CsN4f5WS5",
            "--offset-x",
            "0.742",
            "--cache-dir",
            cache.to_str().unwrap(),
        ])
    };
    let wheres = |text: &str| -> Vec<String> {
        text.lines()
            .filter(|l| l.trim_start().starts_with("where: "))
            .map(str::to_string)
            .collect()
    };
    let fresh = run();
    let cached = run();
    assert!(cached.contains("(from the cache)"), "{cached}");
    assert!(!wheres(&fresh).is_empty(), "{fresh}");
    assert_eq!(wheres(&fresh), wheres(&cached));
}

#[test]
fn a_collision_names_both_bodies_where_they_are_and_how_deep() {
    // The 3-storey model on the study's ABB cell: two cripples far out to the side of the
    // robot, whose place poses are ruled out because the arm's link_2 would meet a placed
    // plate, and the floor.
    let Some(model) = common::shared_path("ifc-testcases/g_scale_3storey.ifc") else {
        return;
    };
    for (id, other) in [
        ("04NmzTFAbBswOTSKeuD7NF", "piece "),
        ("33byu$rir8Qx9Gsa5Jzd8K", "floor"),
    ] {
        let cause = framing_cause(&model, id, &["--cell", "study-abb", "--no-cache"]);
        // A pose ruled out by a collision: where the piece would have been, and the touch.
        assert_eq!(located(&cause, "pose").len(), 1, "{cause}");
        let touch = located(&cause, "touch");
        assert_eq!(touch.len(), 1, "{cause}");
        let t = touch[0];
        assert!(t["depth"].as_f64().unwrap() > 0.0, "{t}");
        assert_eq!(t["body_a"], "link_2", "{t}");
        assert!(t["body_b"].as_str().unwrap().starts_with(other), "{t}");
        let message = cause["message"].as_str().unwrap();
        assert!(
            message.contains(t["body_a"].as_str().unwrap())
                && message.contains(t["body_b"].as_str().unwrap()),
            "{message} / {t}"
        );
    }
}
