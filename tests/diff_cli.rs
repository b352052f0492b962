//! `framewright diff`: a stud moved 20 mm along its wall is reported as moved by 20 mm and
//! nothing else changes in the plan; verdicts are compared once both models are simulated
//! into the cache; a model against itself has no changes.

use std::path::{Path, PathBuf};
use std::process::Command;

const STUD_AT: &str = "#47=IFCCARTESIANPOINT((0.97155,-0.04445,0.0381));";
const STUD_MOVED: &str = "#47=IFCCARTESIANPOINT((0.95155,-0.04445,0.0381));";
const STUD: &str = "2bXwYoWlYif2Nljrw$aJRx";

fn ok(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn tm1() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc")
}

fn moved(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(tm1()).unwrap();
    assert!(
        text.contains(STUD_AT),
        "tm1.ifc changed; pick the stud again"
    );
    let path = dir.join("tm1-moved.ifc");
    std::fs::write(&path, text.replace(STUD_AT, STUD_MOVED)).unwrap();
    path
}

#[test]
fn a_moved_stud_is_the_only_change_and_verdicts_need_both_simulations() {
    let dir = tempfile::tempdir().unwrap();
    let (old, new) = (tm1(), moved(dir.path()));
    let (old, new) = (old.to_str().unwrap(), new.to_str().unwrap());
    let cache = dir.path().join("cache");
    let c = cache.to_str().unwrap();
    let d: serde_json::Value =
        serde_json::from_str(&ok(&["diff", old, new, "--json", "--cache", c])).unwrap();
    let elements = d["elements"].as_array().unwrap();
    assert_eq!(elements.len(), 1, "{d}");
    assert_eq!(elements[0]["id"], STUD);
    assert_eq!(elements[0]["change"], "moved");
    assert_eq!(elements[0]["moved_mm"], 20.0);
    assert_eq!(d["roles"].as_array().unwrap().len(), 0);
    assert_eq!(
        d["walls"].as_array().unwrap().len(),
        0,
        "the wall's outline stays"
    );
    assert!(d["verdicts"].is_null(), "nothing simulated yet");
    let text = ok(&["diff", old, new, "--cache", c]);
    assert!(
        text.contains(&format!("element {STUD} (2x4 stud TM1-003): moved 20.0 mm")),
        "{text}"
    );
    assert!(text.contains("verdicts: not compared"), "{text}");

    ok(&["simulate", old, "--cache", c]);
    ok(&["simulate", new, "--cache", c]);
    let d: serde_json::Value =
        serde_json::from_str(&ok(&["diff", old, new, "--json", "--cache", c])).unwrap();
    assert!(d["verdicts"].is_array(), "{d}");
}

#[test]
fn a_model_against_itself_has_no_changes() {
    let m = tm1();
    let m = m.to_str().unwrap();
    let text = ok(&["diff", m, m, "--no-cache"]);
    assert!(text.ends_with("no changes\n"), "{text}");
}
