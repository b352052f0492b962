//! Roles on a real framed wall written by another tool: buildingSMART's "wall elemented case"
//! (Constructivity, IFC4; `../shared/ifc-realworld/`, skipped when absent). One 144 x 120 in
//! (3.66 x 3.05 m) 2x4 wall with a 32 x 80 in door at u = 24 in and a 36 x 48 in window at
//! u = 84 in, its sill at 32 in. Every piece is labelled below by hand from its geometry (wall
//! frame, m): each opening is headed by a single flat 2x4 with no jack studs under it, the
//! head carried by the full-height king studs either side.

mod common;

use std::path::Path;
use std::process::Command;

const FILE: &str = "ifc-realworld/timber_constructivity_wall-elemented-case_IFC4.ifc";

/// "Track" (#130): the plates, headers and sill, one mapped item each.
const T: &str = "3E4igxyD1F5w4vj3LTAREz";
/// "Studs" (#133): every upright, one mapped item each.
const S: &str = "0y81T5OQ921PKefugNkz2z";

/// (piece, role): u and v ranges in the wall frame (m) and why.
const ROLES: [(&str, usize, &str); 32] = [
    (T, 0, "bottom_plate"),  // u 0-0.61, v 0-0.04: on the floor, up to the door
    (T, 1, "top_plate"),     // u 0-0.61, v 3.01-3.05
    (T, 2, "header"),        // u 0.61-1.42, v 2.03-2.07: spans the door, its underside the head
    (T, 3, "top_plate"),     // u 0.61-1.42, v 3.01-3.05
    (T, 4, "bottom_plate"),  // u 1.42-2.13, from the door's right edge
    (T, 5, "top_plate"),     // u 1.42-2.13
    (T, 6, "bottom_plate"),  // u 2.13-3.05, under the window
    (T, 7, "sill"),          // u 2.13-3.05, v 0.77-0.81: spans the window, its top the sill
    (T, 8, "header"),        // u 2.13-3.05, v 2.03-2.07: spans the window
    (T, 9, "top_plate"),     // u 2.13-3.05
    (T, 10, "bottom_plate"), // u 3.05-3.66, to the wall's end
    (T, 11, "top_plate"),    // u 3.05-3.66
    (S, 0, "stud"),          // u 0-0.04: full height, the wall's first stud
    (S, 1, "stud"),          // u 0.41-0.44: full height, clear of the door
    (S, 2, "king_stud"),     // u 0.57-0.61: full height, the door's left edge; T/2 butts it
    (S, 3, "cripple_stud"),  // u 0.61-0.65, v 2.07-3.01: on the door header
    (S, 4, "cripple_stud"),  // u 1.02-1.05: on the door header
    (S, 5, "cripple_stud"),  // u 1.38-1.42: on the door header
    (S, 6, "king_stud"),     // u 1.42-1.46: full height, the door's right edge
    (S, 7, "stud"),          // u 1.83-1.87: full height, between the openings
    (S, 8, "king_stud"),     // u 2.10-2.13: full height, the window's left edge
    (S, 9, "cripple_stud"),  // u 2.13-2.17, v 0.04-0.77: under the sill
    (S, 10, "cripple_stud"), // under the sill
    (S, 11, "cripple_stud"), // under the sill
    (S, 12, "cripple_stud"), // u 3.01-3.05: under the sill
    (S, 13, "cripple_stud"), // u 2.13-2.17, v 2.07-3.01: on the window header
    (S, 14, "cripple_stud"), // on the window header
    (S, 15, "cripple_stud"), // on the window header
    (S, 16, "cripple_stud"), // u 3.01-3.05: on the window header
    (S, 17, "king_stud"),    // u 3.05-3.09: full height, the window's right edge
    (S, 18, "stud"),         // u 3.45-3.49
    (S, 19, "stud"),         // u 3.62-3.66: the wall's last stud
];

fn plan_json(path: &Path, extra: &[&str]) -> serde_json::Value {
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("plan")
        .arg(path)
        .args(["--json", "--no-cache"])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn every_piece_of_the_constructivity_wall_has_its_role() {
    let Some(path) = common::shared_path(FILE) else {
        return;
    };
    let plan = plan_json(&path, &[]);
    let members = plan["members"].as_array().unwrap();
    assert_eq!(members.len(), 32);
    let role_of = |id: &str| {
        members
            .iter()
            .find(|m| m["id"] == id)
            .unwrap_or_else(|| panic!("no piece {id}"))["role"]
            .as_str()
            .unwrap_or("none")
            .to_string()
    };
    let wrong: Vec<String> = ROLES
        .iter()
        .map(|(product, k, role)| (format!("{product}/{k}"), *role))
        .filter(|(id, role)| role_of(id) != *role)
        .map(|(id, role)| format!("{id}: {role}, plan says {}", role_of(&id)))
        .collect();
    assert!(
        wrong.is_empty(),
        "{} of 32 wrong:\n{}",
        wrong.len(),
        wrong.join("\n")
    );
    // Nothing is left unsure: no piece is "other", none carries a role warning.
    let warnings = plan["warnings"].as_array().unwrap();
    assert!(
        warnings
            .iter()
            .all(|w| !w.as_str().unwrap().contains("role")),
        "{warnings:?}"
    );
}

#[test]
fn each_header_is_assembled_before_the_cripples_on_it() {
    let Some(path) = common::shared_path(FILE) else {
        return;
    };
    let plan = plan_json(&path, &[]);
    let wall = &plan["walls"][0];
    let order: Vec<&str> = wall["assembly_order"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    let at = |id: &str| {
        order
            .iter()
            .position(|o| *o == id)
            .unwrap_or_else(|| panic!("{id} is not in the assembly order"))
    };
    for (header, cripples) in [(2, &[3, 4, 5][..]), (8, &[13, 14, 15, 16][..])] {
        let h = at(&format!("{T}/{header}"));
        for c in cripples {
            assert!(
                h < at(&format!("{S}/{c}")),
                "header {T}/{header} after cripple {S}/{c}"
            );
        }
    }
}

#[test]
fn plan_truth_prints_each_role_s_precision_and_recall() {
    let Some(path) = common::shared_path(FILE) else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.json");
    // One piece mislabelled on purpose: the figures must show it.
    let members: Vec<serde_json::Value> = ROLES
        .iter()
        .map(|(product, k, role)| {
            let role = if *product == S && *k == 7 {
                "king_stud"
            } else {
                role
            };
            serde_json::json!({"id": format!("{product}/{k}"), "role": role})
        })
        .collect();
    std::fs::write(
        &truth,
        serde_json::json!({ "members": members }).to_string(),
    )
    .unwrap();
    let plan = plan_json(&path, &["--truth", truth.to_str().unwrap()]);
    let check = &plan["role_check"];
    assert_eq!(check["labelled"], 32);
    assert_eq!(check["correct"], 31);
    let row = |role: &str| {
        check["roles"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["role"] == role)
            .unwrap()
            .clone()
    };
    // 4 king studs labelled 5: the plan finds the 4, so precision 1 and recall 4/5.
    let king = row("king_stud");
    assert_eq!(
        (king["truth"].as_u64(), king["found"].as_u64()),
        (Some(5), Some(4))
    );
    assert_eq!(king["precision"], 1.0);
    assert_eq!(king["recall"], 0.8);
    // 5 studs found, 4 labelled: precision 4/5, recall 1.
    let stud = row("stud");
    assert_eq!(stud["precision"], 0.8);
    assert_eq!(stud["recall"], 1.0);
    assert_eq!(check["mismatches"][0]["id"], format!("{S}/7"));
    // The text form says the same.
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("plan")
        .arg(&path)
        .args(["--no-cache", "--truth"])
        .arg(&truth)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("31 of 32 labelled pieces right"), "{text}");
    assert!(
        text.contains(&format!("{S}/7: labelled king_stud, plan says stud")),
        "{text}"
    );
}

#[test]
fn a_bad_truth_file_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let truth = dir.path().join("truth.json");
    std::fs::write(&truth, r#"{"members": [{"role": "stud"}]}"#).unwrap();
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc");
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("plan")
        .arg(&model)
        .args(["--no-cache", "--truth"])
        .arg(&truth)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("truth.json") && err.contains("member 0 has neither `id` nor `global_id`"),
        "{err}"
    );
}
