//! Panels in the simulation: a wall longer than the cell carries is simulated panel by panel
//! (cut plates and added studs are pieces with their own verdicts), and an edit re-simulates
//! only the panel it touched.

mod common;

use common::ifc_edit::{long_wall, move_point, stud_points};
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::process::{Command, Output};

fn framewright(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .expect("framewright runs")
}

fn json_of(args: &[&str]) -> Value {
    let out = framewright(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn strs(v: &Value) -> Vec<&str> {
    v.as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap())
        .collect()
}

/// The plan's panels of its one wall: panel id → the pieces it is built from.
fn plan_panels(plan: &Value) -> BTreeMap<String, BTreeSet<String>> {
    let walls = plan["walls"].as_array().unwrap();
    assert_eq!(walls.len(), 1);
    walls[0]["panels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let mut pieces: BTreeSet<String> = strs(&p["member_ids"])
                .into_iter()
                .map(str::to_string)
                .collect();
            for kind in ["cut_pieces", "added_pieces"] {
                for piece in p[kind].as_array().unwrap() {
                    pieces.insert(piece["id"].as_str().unwrap().to_string());
                }
            }
            (p["panel_id"].as_str().unwrap().to_string(), pieces)
        })
        .collect()
}

fn simulate(model: &Path, cache: &Path, extra: &[&str]) -> Value {
    let m = model.to_str().unwrap();
    let c = cache.to_str().unwrap();
    json_of(&[&["simulate", m, "--json", "--cache", c][..], extra].concat())
}

fn cache_counts(report: &Value) -> (u64, u64) {
    let c = &report["sim"]["cache"];
    (
        c["computed"].as_u64().unwrap(),
        c["cached"].as_u64().unwrap(),
    )
}

#[test]
fn a_long_wall_is_simulated_panel_by_panel_and_an_edit_redoes_one_panel() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("long.ifc");
    long_wall(&model);
    let m = model.to_str().unwrap();
    let plan = json_of(&["plan", m, "--json", "--no-cache"]);
    let wall_id = plan["walls"][0]["wall_id"].as_str().unwrap().to_string();
    let panels = plan_panels(&plan);
    assert_eq!(panels.len(), 3, "20 m on a cell that carries 7.5 m");
    // The whole 20 m plates are cut: no plate of the model is a piece of a panel.
    let plates: Vec<&str> = plan["walls"][0]["panels"][0]["cut_pieces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["of"].as_str().unwrap())
        .collect();
    assert!(!plates.is_empty());

    // Whole, the wall cannot be fed: its plates are longer than the conveyors.
    let whole = json_of(&["simulate", m, "--json", "--no-cache", "--panels", "off"]);
    assert_eq!(whole["walls"][0]["material_feeding"], "Failed");

    let cache = dir.path().join("cache");
    let report = simulate(&model, &cache, &[]);
    assert_eq!(cache_counts(&report), (3, 0));
    // One verdict row per panel, named as the plan names it, of the one wall.
    let rows = report["panels"].as_array().unwrap();
    let row_ids: Vec<&str> = rows
        .iter()
        .map(|r| r["panel_id"].as_str().unwrap())
        .collect();
    assert_eq!(
        row_ids,
        panels.keys().map(String::as_str).collect::<Vec<_>>()
    );
    for row in rows {
        assert_eq!(row["wall_id"], wall_id.as_str());
        // Every piece of a panel is shorter than the conveyors: every panel is fed.
        assert_eq!(row["material_feeding"], "Completed", "{row}");
    }
    // The wall's row sums its panels.
    let walls = report["walls"].as_array().unwrap();
    assert_eq!(walls.len(), 1);
    let framing_time: f64 = rows
        .iter()
        .map(|r| r["framing"]["time_s"].as_f64().unwrap())
        .sum();
    assert!((walls[0]["framing"]["time_s"].as_f64().unwrap() - framing_time).abs() < 1e-5);
    // The elements are exactly the panels' pieces, each in its panel; the cut plates are not.
    let mut seen: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for e in report["elements"].as_array().unwrap() {
        assert_eq!(e["wall_id"], wall_id.as_str());
        seen.entry(e["panel_id"].as_str().unwrap().to_string())
            .or_default()
            .insert(e["id"].as_str().unwrap().to_string());
    }
    assert_eq!(seen, panels);
    for plate in &plates {
        assert!(!panels.values().any(|p| p.contains(*plate)));
    }
    // BCF topics are about the panel the cell built, and each names its panel.
    let bcf = dir.path().join("issues.bcfzip");
    let again = simulate(&model, &cache, &["--bcf", bcf.to_str().unwrap()]);
    assert_eq!(cache_counts(&again), (0, 3));
    let titles: Vec<String> = common::bcf::xml_documents(&bcf)
        .into_iter()
        .filter(|(name, _)| name.ends_with("markup.bcf"))
        .filter_map(|(_, xml)| {
            let start = xml.find("<Title>")? + "<Title>".len();
            Some(xml[start..start + xml[start..].find("</Title>")?].to_string())
        })
        .collect();
    assert!(!titles.is_empty(), "the run fails somewhere on this cell");
    for title in &titles {
        assert!(title.contains(", panel "), "{title}");
    }
    // Nails driven into cut plates and added studs land inside the pieces as built.
    let nails = &report["nailing_validation"];
    assert!(nails["checked"].as_u64().unwrap() > 0);
    assert_eq!(nails["all_inside_members"], true);

    // `why` explains a failure in a split wall by the panel it was built in: every wall size in
    // its derivation is a panel's, none the whole 20 m wall's.
    let failed = report["elements"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["framing"]["status"] == "failed" && !e["id"].as_str().unwrap().contains('~'))
        .expect("a modelled piece fails on this cell");
    let why = framewright(&[
        "why",
        m,
        failed["id"].as_str().unwrap(),
        "--no-cache",
        "--verbose",
    ]);
    assert!(
        why.status.success(),
        "{}",
        String::from_utf8_lossy(&why.stderr)
    );
    let text = String::from_utf8_lossy(&why.stdout);
    // The panel named as `simulate` names it.
    let panel = failed["panel_id"].as_str().unwrap();
    assert!(
        text.lines().nth(1).unwrap().contains(", panel ")
            && text.contains(&format!(" ({panel})\n")),
        "{text}"
    );
    let sizes: Vec<f64> = text
        .split("wall_size(\"")
        .skip(1)
        .filter_map(|rest| rest.split(", ").nth(1)?.parse().ok())
        .collect();
    assert!(!sizes.is_empty(), "{text}");
    assert!(sizes.iter().all(|l| *l <= 7.5 + 1e-6), "{sizes:?}");

    // Move a stud that no break lies beside: the breaks stay, one panel is simulated again.
    let text = std::fs::read_to_string(&model).unwrap();
    let moved = dir.path().join("moved.ifc");
    let breaks = |plan: &Value| plan["walls"][0]["panel_breaks"].to_string();
    let points = stud_points(&text);
    let point = points
        .iter()
        .skip(2)
        .find(|p| {
            std::fs::write(&moved, move_point(&text, p, 0.02)).unwrap();
            let after = json_of(&["plan", moved.to_str().unwrap(), "--json", "--no-cache"]);
            breaks(&after) == breaks(&plan)
        })
        .expect("a stud whose move keeps the breaks");
    std::fs::write(&moved, move_point(&text, point, 0.02)).unwrap();
    let again = simulate(&moved, &cache, &[]);
    assert_eq!(cache_counts(&again), (1, 2), "moving {point}");
    // `diff` compares panel with panel: the model against itself changes no wall; moving one
    // stud along its wall changes that stud and no panel's extent or members.
    let diff = |new: &Path| json_of(&["diff", m, new.to_str().unwrap(), "--json", "--no-cache"]);
    let same = diff(&model);
    assert!(same["walls"].as_array().unwrap().is_empty(), "{same}");
    let edited = diff(&moved);
    assert!(edited["walls"].as_array().unwrap().is_empty(), "{edited}");
    assert_eq!(edited["elements"].as_array().unwrap().len(), 1, "{edited}");
    let changed: Vec<&str> = rows
        .iter()
        .zip(again["panels"].as_array().unwrap())
        .filter(|(a, b)| a != b)
        .map(|(a, _)| a["panel_id"].as_str().unwrap())
        .collect();
    assert!(changed.len() <= 1, "{changed:?}");
}

#[test]
fn the_three_storey_models_longest_wall_is_fed_and_judged_panel_by_panel() {
    let Some(model) = common::shared_path("ifc-testcases/g_scale_3storey.ifc") else {
        return;
    };
    let m = model.to_str().unwrap();
    let plan = json_of(&["plan", m, "--json"]);
    let wall = plan["walls"]
        .as_array()
        .unwrap()
        .iter()
        .max_by(|a, b| {
            a["length"]
                .as_f64()
                .unwrap()
                .total_cmp(&b["length"].as_f64().unwrap())
        })
        .unwrap();
    let id = wall["wall_id"].as_str().unwrap();
    let panels: Vec<&str> = wall["panels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["panel_id"].as_str().unwrap())
        .collect();
    assert!(wall["length"].as_f64().unwrap() > 50.0 && panels.len() >= 8);
    let report = json_of(&["simulate", m, "--json", "--no-cache", "--wall", id]);
    let rows = report["panels"].as_array().unwrap();
    let row_ids: Vec<&str> = rows
        .iter()
        .map(|r| r["panel_id"].as_str().unwrap())
        .collect();
    assert_eq!(row_ids, panels);
    for row in rows {
        assert_eq!(row["wall_id"], id);
        assert_eq!(row["material_feeding"], "Completed", "{row}");
    }
    // No piece is refused by the conveyors; whole, the wall's plates are.
    let refused = |report: &Value| -> usize {
        report["elements"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|e| e["framing"]["reasons"].as_array().unwrap())
            .filter(|r| r["message"].as_str().unwrap().contains("cannot carry"))
            .count()
    };
    assert_eq!(refused(&report), 0);
    let whole = json_of(&[
        "simulate",
        m,
        "--json",
        "--no-cache",
        "--wall",
        id,
        "--panels",
        "off",
    ]);
    assert!(refused(&whole) > 0);
}
