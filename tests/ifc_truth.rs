//! Every member of every shared truth model is read within 0.5 mm:
//! axis end points (as an unordered pair), width, thickness and length.

mod common;

use framewright::ifc::Model;
use serde_json::Value;
use std::path::{Path, PathBuf};

const TOLERANCE: f64 = 0.0005;

fn testcases() -> Option<PathBuf> {
    common::shared_path("ifc-testcases")
}

fn point(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("point");
    [0, 1, 2].map(|i| a[i].as_f64().expect("coordinate"))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

fn truth_files(dir: &Path) -> Vec<PathBuf> {
    let mut truths: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".truth.json"))
        .collect();
    truths.sort();
    assert!(!truths.is_empty(), "no truth files in {}", dir.display());
    truths
}

#[test]
fn shared_truth_models_within_half_a_millimetre() {
    let Some(dir) = testcases() else { return };
    check_all(truth_files(&dir));
}

/// The project's own models (bundled examples and fixtures written by `synth`).
#[test]
fn own_truth_models_within_half_a_millimetre() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = truth_files(&root.join("examples/models"));
    files.extend(truth_files(&root.join("tests/fixtures")));
    check_all(files);
}

fn check_all(truths: Vec<PathBuf>) {
    for truth_path in truths {
        let ifc = PathBuf::from(truth_path.to_string_lossy().replace(".truth.json", ".ifc"));
        let truth: Value =
            serde_json::from_str(&std::fs::read_to_string(&truth_path).unwrap()).unwrap();
        let model = Model::open(&ifc).unwrap_or_else(|e| panic!("{e}"));
        assert!(
            model.warnings.is_empty(),
            "{}: {:?}",
            ifc.display(),
            model.warnings
        );
        let expected_unit = truth["length_unit"]["metres_per_unit"].as_f64().unwrap();
        assert!((model.length_unit.metres_per_unit - expected_unit).abs() < 1e-12);
        let members = truth["members"].as_array().unwrap();
        assert_eq!(model.pieces().len(), members.len(), "{}", ifc.display());
        for m in members {
            let gid = m["global_id"].as_str().unwrap();
            let piece = model
                .pieces()
                .iter()
                .find(|p| p.id == gid)
                .unwrap_or_else(|| panic!("{gid} missing"));
            let (s, e) = piece.axis();
            let (s, e) = ([s.x, s.y, s.z], [e.x, e.y, e.z]);
            let (ts, te) = (point(&m["axis_start"]), point(&m["axis_end"]));
            let ends =
                (distance(s, ts).max(distance(e, te))).min(distance(s, te).max(distance(e, ts)));
            let what = format!("{} {gid} ({})", ifc.display(), m["role"]);
            assert!(ends < TOLERANCE, "{what}: axis off by {ends}");
            for (name, got) in [
                ("width", piece.obox.width()),
                ("thickness", piece.obox.thickness()),
                ("length", piece.obox.length()),
            ] {
                let want = m[name].as_f64().unwrap();
                assert!(
                    (got - want).abs() < TOLERANCE,
                    "{what}: {name} {got} vs {want}"
                );
            }
            assert_eq!(piece.ifc_type, m["ifc_type"].as_str().unwrap(), "{what}");
            let parent = piece
                .parent
                .and_then(|p| model.groups.get(&p))
                .map(|g| g.global_id.as_str());
            assert_eq!(parent, m["wall_global_id"].as_str(), "{what}: parent");
        }
    }
}
