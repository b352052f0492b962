//! Shared by the frame reasoning tests: the truth models (the shared test
//! cases when `../shared` is present, and the project's own models), and the
//! rule base's relations over them.
#![allow(dead_code)]

use framewright::frame::{Reasoned, RuleEngine, model_facts, reason};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::logic::Value;
use serde_json::Value as Json;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One model with its truth.
pub struct Case {
    pub name: String,
    pub ifc: PathBuf,
    pub truth: Json,
}

fn truth_files(dir: &Path) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".truth.json"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no truth files in {}", dir.display());
    files
}

fn cases_in(files: Vec<PathBuf>) -> Vec<Case> {
    files
        .into_iter()
        .map(|truth_path| {
            let ifc = PathBuf::from(truth_path.to_string_lossy().replace(".truth.json", ".ifc"));
            let name = ifc.file_name().unwrap().to_string_lossy().into_owned();
            let text = std::fs::read_to_string(&truth_path).unwrap();
            Case {
                name,
                ifc,
                truth: serde_json::from_str(&text).unwrap(),
            }
        })
        .collect()
}

/// The shared truth models, or None (with a message) when `../shared` is absent.
pub fn shared_cases() -> Option<Vec<Case>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/ifc-testcases");
    if !dir.is_dir() {
        eprintln!("skipped: {} is absent", dir.display());
        return None;
    }
    Some(cases_in(truth_files(&dir)))
}

/// The project's own truth models: bundled examples and `synth` fixtures.
pub fn own_cases() -> Vec<Case> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = truth_files(&root.join("examples/models"));
    files.extend(truth_files(&root.join("tests/fixtures")));
    cases_in(files)
}

/// The rule base's relations over a model.
pub fn reasoned(case: &Case, engine: &RuleEngine) -> Reasoned {
    let model = Model::open(&case.ifc).unwrap_or_else(|e| panic!("{}: {e}", case.name));
    let facts = model_facts(&model, &ContactOptions::default());
    reason(&facts, engine, false).unwrap_or_else(|e| panic!("{}: {e}", case.name))
}

pub fn sym(v: &Value) -> &str {
    v.as_symbol().expect("a symbol")
}

pub fn float(v: &Value) -> f64 {
    v.as_float().expect("a float")
}

/// A binary relation `rel(p: symbol, x)` as a map from p to x (panics on a second x).
pub fn by_piece<'a>(r: &'a Reasoned, relation: &str) -> BTreeMap<&'a str, &'a Value> {
    let mut map = BTreeMap::new();
    for t in r.get(relation) {
        if let Some(old) = map.insert(sym(&t[0]), &t[1]) {
            panic!("{relation}: {} has both {old} and {}", sym(&t[0]), t[1]);
        }
    }
    map
}

pub fn members(truth: &Json) -> &Vec<Json> {
    truth["members"].as_array().expect("members")
}

pub fn walls(truth: &Json) -> &Vec<Json> {
    truth["walls"].as_array().expect("walls")
}

/// An array field of a truth object (empty when absent or null).
pub fn list<'a>(v: &'a Json, field: &str) -> &'a [Json] {
    v[field].as_array().map_or(&[], Vec::as_slice)
}

pub fn text(v: &Json) -> &str {
    v.as_str().expect("a string")
}

pub fn number(v: &Json) -> f64 {
    v.as_f64().expect("a number")
}
