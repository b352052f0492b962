//! `framewright check`: JSON and text output, exit codes, determinism,
//! several rule files, `--rules-dir` replacing the built-in rule base, and
//! `--simulate` giving user rules the executor's facts.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn path(p: &str) -> PathBuf {
    root().join(p)
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .unwrap()
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

#[test]
fn json_lists_findings_with_entities_and_is_byte_identical() {
    let model = path("tests/fixtures/synth_wall_door_window_in.ifc");
    let a = path("examples/rules/gripper_spacing.dl");
    let b = path("examples/rules/nail_end_distance.dl");
    let args = [
        "check",
        s(&model),
        "--rules",
        s(&a),
        "--rules",
        s(&b),
        "--json",
    ];
    let out = run(&args);
    assert_eq!(out.status.code(), Some(1), "violations make exit code 1");
    assert_eq!(out.stdout, run(&args).stdout);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["cell"], "study-abb");
    assert_eq!(v["rule_files"].as_array().unwrap().len(), 2);
    let vs = v["violations"].as_array().unwrap();
    assert_eq!(vs.len(), 5 + 6);
    let first = &vs[0];
    for key in ["id", "entity", "name", "rule", "message"] {
        assert!(first.get(key).is_some(), "{key}");
    }
    // Sorted by id, then rule, then message.
    let keys: Vec<(String, String, String)> = vs
        .iter()
        .map(|f| {
            (
                f["id"].as_str().unwrap().into(),
                f["rule"].as_str().unwrap().into(),
                f["message"].as_str().unwrap().into(),
            )
        })
        .collect();
    let mut sorted = keys.clone();
    sorted.sort();
    assert_eq!(keys, sorted);
    let cripple = vs.iter().find(|f| f["entity"] == 213).unwrap();
    assert_eq!(cripple["name"], "2x4 cripple stud W1-024");
    assert_eq!(cripple["rule"], "shorter_than_gripper_spacing");
    assert!(v["warnings"].as_array().unwrap().is_empty());
}

#[test]
fn text_has_one_line_per_finding_and_a_total() {
    let model = path("examples/models/tm3.ifc");
    let rules = path("examples/rules/assembly_table.dl");
    let out = run(&["check", s(&model), "--rules", s(&rules)]);
    assert_eq!(out.status.code(), Some(1));
    let text = String::from_utf8(out.stdout).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "{text}");
    assert!(lines[0].starts_with("violation  wall_longer_than_table  07l14Rb8lVjg1i9SI4wpQJ (#38 '2x4 bottom plate F-001'): wall is 6.858 m long; the assembly table is 6.10 m"), "{text}");
    assert!(
        lines[2].starts_with("2 violations, 0 warnings from 1 rule file ("),
        "{text}"
    );
    // No finding: exit 0.
    let clean = run(&[
        "check",
        s(&path("examples/models/tm1.ifc")),
        "--rules",
        s(&rules),
    ]);
    assert_eq!(clean.status.code(), Some(0));
    assert!(String::from_utf8_lossy(&clean.stdout).starts_with("0 violations, 0 warnings"));
}

#[test]
fn warnings_do_not_fail_the_check() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("caps.dl");
    std::fs::write(&f, "// @rule cap_plate_seen\nwarning(p, \"cap\", \"a cap plate\") :- role(p, \"cap_plate\").\n").unwrap();
    let out = run(&[
        "check",
        s(&path("examples/models/tm3.ifc")),
        "--rules",
        s(&f),
        "--json",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["warnings"].as_array().unwrap().len(), 4);
}

/// Copies rules/ into a temporary directory.
fn copy_rules(dir: &Path) {
    for e in std::fs::read_dir(path("rules")).unwrap() {
        let p = e.unwrap().path();
        std::fs::copy(&p, dir.join(p.file_name().unwrap())).unwrap();
    }
}

#[test]
fn rules_dir_replaces_the_builtin_rule_base() {
    let dir = tempfile::tempdir().unwrap();
    copy_rules(dir.path());
    // A shop's own relation in its rule base, read by a user rule.
    std::fs::write(
        dir.path().join("shop.dl"),
        ".decl long_plate(p: symbol)\n// @rule long_plate\nlong_plate(p) :- role(p, \"top_plate\"), piece_size(p, l, _, _), l > 6.0.\n",
    )
    .unwrap();
    let elsewhere = tempfile::tempdir().unwrap();
    let user = elsewhere.path().join("user.dl");
    std::fs::write(
        &user,
        "violation(p, \"long_plate\", \"top plate over 6 m\") :- long_plate(p).\n",
    )
    .unwrap();
    let model = path("examples/models/tm3.ifc");
    let out = run(&[
        "check",
        s(&model),
        "--rules",
        s(&user),
        "--rules-dir",
        s(dir.path()),
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let ids: Vec<&str> = v["violations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["id"].as_str().unwrap())
        .collect();
    assert_eq!(ids.len(), 2, "the two 6.858 m top plates: {ids:?}");
    // A user file inside the directory would be read as part of the rule base too.
    let inside = dir.path().join("mine.dl");
    std::fs::copy(&user, &inside).unwrap();
    let out = run(&[
        "check",
        s(&model),
        "--rules",
        s(&inside),
        "--rules-dir",
        s(dir.path()),
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("lies in the rules directory"));
    std::fs::remove_file(&inside).unwrap();
    // Without the directory the relation does not exist.
    let out = run(&["check", s(&model), "--rules", s(&user)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown relation `long_plate`"));
    // Redefining one of the directory's relations names the directory's file.
    std::fs::write(&user, ".decl long_plate(p: symbol)\n").unwrap();
    let out = run(&[
        "check",
        s(&model),
        "--rules",
        s(&user),
        "--rules-dir",
        s(dir.path()),
    ]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("user.dl:1:7: error: this file declares the built-in relation `long_plate`, declared at "), "{err}");
    assert!(err.contains("shop.dl:1"), "{err}");
}

#[test]
fn bad_inputs_exit_2() {
    let rules = path("examples/rules/assembly_table.dl");
    let out = run(&["check", "no-such.ifc", "--rules", s(&rules)]);
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let out = run(&[
        "check",
        s(&path("examples/models/tm1.ifc")),
        "--rules",
        "no-such.dl",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot read rule file no-such.dl"));
    let out = run(&[
        "check",
        s(&path("examples/models/tm1.ifc")),
        "--rules",
        s(&rules),
        "--rules-dir",
        "/no/such/dir",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(
        String::from_utf8_lossy(&out.stderr)
            .contains("/no/such/dir: cannot read the rules directory")
    );
    let out = run(&["check", s(&path("examples/models/tm1.ifc"))]);
    assert_eq!(out.status.code(), Some(2), "--rules is required");
}

#[test]
fn simulate_gives_rules_the_executor_facts() {
    // A rule on the executor's verdicts: TM3's W2 frames, W1 does not.
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("failed.dl");
    std::fs::write(
        &f,
        "violation(p, \"framing_failed\", m) :- element_framing(p, \"failed\"), element_reason(p, \"framing\", _, m).\n",
    )
    .unwrap();
    let model = path("examples/models/tm3.ifc");
    let out = run(&[
        "check",
        s(&model),
        "--rules",
        s(&f),
        "--simulate",
        "--offset-x",
        "0.531",
        "--wall",
        "W1",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(1),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let top = v["violations"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["entity"] == 174)
        .expect("the top plate failed");
    assert!(
        top["message"]
            .as_str()
            .unwrap()
            .starts_with("place pose beyond reach: the wrist centre would be "),
        "{top}"
    );
    // Without --simulate the verdicts are empty.
    let out = run(&["check", s(&model), "--rules", s(&f)]);
    assert_eq!(out.status.code(), Some(0));
}

#[test]
fn plan_and_check_refuse_an_absurd_contact_tolerance() {
    let model = path("examples/models/tm1.ifc");
    let rules = path("examples/rules/gripper_spacing.dl");
    for args in [
        vec!["plan", s(&model), "--contact-tolerance=-1"],
        vec!["plan", s(&model), "--contact-tolerance=NaN"],
        vec![
            "check",
            s(&model),
            "--rules",
            s(&rules),
            "--contact-tolerance=500",
        ],
    ] {
        let out = run(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--contact-tolerance") && err.contains("give 0 to 100 mm"),
            "{err}"
        );
        assert!(out.stdout.is_empty());
    }
    assert!(
        run(&["plan", s(&model), "--contact-tolerance=2"])
            .status
            .success()
    );
}
