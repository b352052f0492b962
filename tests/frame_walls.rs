//! Wall grouping and wall frames against the truth of every model: the
//! partition of pieces into walls and each wall's frame matrix and size.

mod common;

use framewright::frame::plan::Plan;
use framewright::frame::{Ask, RuleEngine, model_facts};
use framewright::ifc::Model;
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn truth_files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut dirs = vec![root.join("examples/models"), root.join("tests/fixtures")];
    dirs.extend(common::shared_path("ifc-testcases"));
    let mut files = Vec::new();
    for dir in dirs {
        for e in std::fs::read_dir(dir).unwrap() {
            let p = e.unwrap().path();
            if p.to_string_lossy().ends_with(".truth.json") {
                files.push(p);
            }
        }
    }
    files.sort();
    files
}

#[test]
fn walls_and_frames_match_the_truth() {
    let files = truth_files();
    assert!(files.len() >= 7);
    for truth_path in files {
        let ifc = PathBuf::from(truth_path.to_string_lossy().replace(".truth.json", ".ifc"));
        let truth: Value =
            serde_json::from_str(&std::fs::read_to_string(&truth_path).unwrap()).unwrap();
        let model = Model::open(&ifc).unwrap();
        let reasoned = Ask::new(&RuleEngine::Compiled)
            .over(&model_facts(&model, &Default::default()))
            .unwrap();
        let plan = Plan::from_reasoned(&model, &reasoned).expect("plan");
        let name = ifc.file_name().unwrap().to_string_lossy().to_string();

        // The partition: the same sets of pieces, whatever the walls are called.
        let ours: BTreeSet<BTreeSet<String>> = plan
            .walls
            .iter()
            .map(|w| w.members.iter().cloned().collect())
            .collect();
        let theirs: BTreeSet<BTreeSet<String>> = truth["walls"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| {
                w["member_global_ids"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|g| g.as_str().unwrap().to_string())
                    .collect()
            })
            .collect();
        assert_eq!(ours, theirs, "{name}: wall partition");

        // Each wall's frame (columns u, v, w, origin) and size.
        let by_members: BTreeMap<BTreeSet<String>, &framewright::frame::plan::Wall> = plan
            .walls
            .iter()
            .map(|w| (w.members.iter().cloned().collect(), w))
            .collect();
        for tw in truth["walls"].as_array().unwrap() {
            let key: BTreeSet<String> = tw["member_global_ids"]
                .as_array()
                .unwrap()
                .iter()
                .map(|g| g.as_str().unwrap().to_string())
                .collect();
            let wall = by_members[&key];
            let m = wall.frame.to_homogeneous();
            for i in 0..4 {
                for j in 0..4 {
                    let want = tw["frame_matrix"][i][j].as_f64().unwrap();
                    assert!(
                        (m[(i, j)] - want).abs() < 1e-6,
                        "{name} wall {}: frame[{i}][{j}] {} vs {want}",
                        tw["wall_id"],
                        m[(i, j)]
                    );
                }
            }
            for (field, got) in [
                ("length", wall.length),
                ("height", wall.height),
                ("thickness", wall.thickness),
            ] {
                let want = tw[field].as_f64().unwrap();
                assert!(
                    (got - want).abs() < 5e-4,
                    "{name} wall {}: {field} {got} vs {want}",
                    tw["wall_id"]
                );
            }
            // A wall grouped by an IfcWall or IfcElementAssembly is named after it.
            if let Some(group) = tw["wall_global_id"].as_str() {
                assert_eq!(wall.group_global_id.as_deref(), Some(group), "{name}");
            }
        }
        assert!(plan.warnings.is_empty(), "{name}: {:?}", plan.warnings);
    }
}

#[test]
fn no_framing_means_no_walls_and_a_reason() {
    let Some(path) =
        common::shared_path("ifc-realworld/timber_archicad20_FZK-Haus-roof-rafters_IFC4.ifc")
    else {
        return;
    };
    let model = Model::open(&path).unwrap();
    let reasoned = Ask::new(&RuleEngine::Compiled)
        .over(&model_facts(&model, &Default::default()))
        .unwrap();
    let plan = Plan::from_reasoned(&model, &reasoned).expect("plan");
    assert!(plan.walls.is_empty());
    assert_eq!(plan.warnings.len(), 1);
    assert!(
        plan.warnings[0].starts_with("no wall frames: of 46 pieces"),
        "{}",
        plan.warnings[0]
    );
}
