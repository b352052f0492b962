//! Roles on wall frames that framewright's own generator never wrote: `bench/roles_unseen.py`
//! writes them with IfcOpenShell from wood-framing practice (21 styles: built-up, solid, flat
//! and tight headers, double jacks, sills king to king, openings sharing a king, blocking rows,
//! triple top plates, California, three-stud and ladder corners and shared corner studs with
//! both walls present, T-intersections with the partition present, let-in braces, gable walls
//! with raked top plates, small buildings; mm, m and ft; IfcMember, IfcColumn, IfcBeam,
//! IfcPlate; names in English, German, French, Japanese and misleading ones) with
//! hand-assigned truth files. Every role must reach 99.5 % precision and recall, with no error
//! or warning.

mod common;

use std::process::Command;

#[test]
fn roles_on_independently_written_framing_styles() {
    let Some(python) = common::python::ifcopenshell() else {
        return;
    };
    let out = tempfile::tempdir().unwrap();
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/bench/roles_unseen.py");
    let run = Command::new(python)
        .args([
            script,
            "--binary",
            env!("CARGO_BIN_EXE_framewright"),
            "--out",
        ])
        .arg(out.path())
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let report = String::from_utf8_lossy(&run.stdout);
    let results: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.path().join("results.json")).unwrap()).unwrap();
    let notes = results["notes"].as_array().unwrap();
    assert!(notes.is_empty(), "{report}");
    let roles = results["roles"].as_object().unwrap();
    for role in common::FRAMING_ROLES {
        let n = |k: usize| roles[role][k].as_u64().unwrap() as f64;
        let (truth, found, right) = (n(0), n(1), n(2));
        assert!(truth > 0.0, "no {role} in the models\n{report}");
        assert!(
            right / found >= 0.995 && right / truth >= 0.995,
            "{role}: {right} right of {found} found, {truth} labelled\n{report}"
        );
    }
    // Every piece of every model was labelled and found (no role outside the list).
    assert!(
        roles
            .keys()
            .all(|r| r != "other" && r != "(none)" && r != "(missing)"),
        "{report}"
    );
}
