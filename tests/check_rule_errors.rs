//! User rule files that are wrong: syntax and type errors with file:line:col
//! and a caret, redefinitions of built-in relations naming both places, and
//! rule files that run away (limits).

use framewright::frame::RuleEngine;
use framewright::logic::Limits;
use framewright::user_rules::{UserRules, UserRulesError};
use std::path::{Path, PathBuf};
use std::process::Command;

fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

fn load_err(text: &str) -> (String, PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "shop.dl", text);
    let err = match UserRules::load(std::slice::from_ref(&f), &RuleEngine::Compiled) {
        Ok(_) => panic!("{text} should be refused"),
        Err(e) => e,
    };
    assert!(matches!(err, UserRulesError::Rules(_)), "{err:?}");
    (err.to_string(), f, dir)
}

/// The line number in rules/roles.dl where `role` is declared.
fn role_decl_line() -> usize {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("rules/roles.dl"))
            .unwrap();
    1 + text
        .lines()
        .position(|l| l.starts_with(".decl role("))
        .expect("rules/roles.dl declares role")
}

#[test]
fn redeclaring_a_builtin_relation_names_both_places() {
    let (msg, f, _d) = load_err("// mine\n.decl role(p: symbol, r: symbol)\n");
    let here = format!("{}:2:7: error:", f.display());
    assert!(msg.contains(&here), "{msg}");
    assert!(
        msg.contains(&format!(
            "declares the built-in relation `role`, declared at rules/roles.dl:{}",
            role_decl_line()
        )),
        "{msg}"
    );
    assert!(
        msg.contains("2 | .decl role(p: symbol, r: symbol)"),
        "{msg}"
    );
    assert!(msg.contains("  |       ^^^^"), "{msg}");
    assert!(
        msg.contains("hint: user rules may read `role` but not change it"),
        "{msg}"
    );
}

#[test]
fn deriving_into_a_builtin_relation_is_refused() {
    let (msg, f, _d) = load_err("role(p, \"stud\") :- piece(p, _, _, _).\n");
    assert!(msg.contains(&format!("{}:1:1: error: this file derives into the built-in relation `role`, declared at rules/roles.dl:{}", f.display(), role_decl_line())), "{msg}");
    // A fact is a rule too.
    let (msg, _, _d) = load_err("cell_value(\"gripper_spacing\", 0.1).\n");
    assert!(
        msg.contains(
            "derives into the built-in relation `cell_value`, declared at rules/facts.dl:"
        ),
        "{msg}"
    );
}

#[test]
fn a_shop_preference_for_the_built_in_rules_points_to_a_rule_base() {
    // `break_forbidden` is left empty by the built-in rules for a shop to fill; it feeds the
    // panel breaks, which run before user rule files: the hint says where such a rule goes.
    let (msg, _, _d) = load_err(
        "break_forbidden(w, 0.0, 1.0, \"no joint at the start\") :- wall_size(w, _, _, _).\n",
    );
    assert!(
        msg.contains(
            "derives into the built-in relation `break_forbidden`, declared at rules/panels.dl:"
        ) && msg.contains("`break_forbidden` feeds the built-in rules")
            && msg.contains("--rules-dir DIR"),
        "{msg}"
    );
    // A relation the built-in rules derive keeps the other hint.
    let (msg, _, _d) = load_err("role(p, \"stud\") :- piece(p, _, _, _).\n");
    assert!(msg.contains("may read `role` but not change it"), "{msg}");
}

#[test]
fn redeclaring_the_findings_relations_is_refused() {
    let (msg, _, _d) = load_err(".decl violation(id: symbol, rule: symbol, message: symbol)\n");
    assert!(
        msg.contains(
            "declares the findings relation `violation`, declared at src/user_rules/findings.dl:10"
        ),
        "{msg}"
    );
}

#[test]
fn syntax_and_type_errors_point_at_the_user_file() {
    let (msg, f, _d) = load_err("violation(p, \"r\", \"m\") :- rol(p, _).\n");
    assert!(
        msg.contains(&format!(
            "{}:1:27: error: unknown relation `rol`",
            f.display()
        )),
        "{msg}"
    );
    assert!(msg.contains("did you mean `role`?"), "{msg}");
    let (msg, f, _d) = load_err("violation(p, \"r\", l) :- piece_size(p, l, _, _).\n");
    assert!(
        msg.contains(&format!(
            "{}:1:39: error: type mismatch: `l` is a float here",
            f.display()
        )),
        "{msg}"
    );
    let (msg, f, _d) = load_err("violation(p, \"r\", \"m\") :- piece(p, _, _, _)\n");
    assert!(
        msg.contains(&format!(
            "{}:2:1: error: expected `.` at the end of the clause",
            f.display()
        )),
        "{msg}"
    );
    assert!(msg.contains("  | ^\n"), "{msg}");
    assert!(
        msg.contains("hint: end every fact and rule with `.`"),
        "{msg}"
    );
}

#[test]
fn a_rule_file_that_runs_away_stops_at_the_limit() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(
        dir.path(),
        "count.dl",
        ".decl n(x: number)\nn(0) :- piece(_, _, _, _).\nn(x + 1) :- n(x).\nviolation(\"a\", \"b\", \"c\") :- n(5).\n",
    );
    let rules = UserRules::load(&[f], &RuleEngine::Compiled)
        .unwrap()
        .with_limits(Limits {
            max_tuples: 10_000,
            max_iterations: 1_000,
            ..Limits::default()
        });
    let mut relations = framewright::logic::compiled::Relations::new();
    relations.insert(
        "piece".into(),
        vec![vec![
            framewright::logic::Value::sym("p"),
            framewright::logic::Value::Number(1),
            framewright::logic::Value::sym("IfcMember"),
            framewright::logic::Value::sym(""),
        ]],
    );
    let err = rules.evaluate(&relations).unwrap_err();
    assert!(matches!(err, UserRulesError::Logic(_)), "{err}");
}

#[test]
fn the_command_line_reports_rule_errors_with_exit_code_2_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "bad.dl", ".decl wall(w: symbol)\n");
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc");
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("check")
        .arg(&model)
        .arg("--rules")
        .arg(&f)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.dl:1:7: error: this file declares the built-in relation `wall`, declared at rules/walls.dl:"), "{err}");
}

#[test]
fn only_the_relations_the_user_rules_read_are_copied_in() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(
        dir.path(),
        "short.dl",
        "violation(p, \"short\", \"x\") :- piece_size(p, l, _, _), l < 0.5, !role(p, \"sill\"), n = count : { wall_of(p, _) }, n > 0.\n",
    );
    let rules = UserRules::load(&[f], &RuleEngine::Compiled).unwrap();
    assert_eq!(rules.reads(), ["piece_size", "role", "wall_of"]);
}

/// A pipe (`--rules <(…)`) gives its text to one read only, and the rules are read more than
/// once: it is refused with what to do, never run as an empty rule file.
#[test]
fn a_rule_file_that_is_a_pipe_is_refused() {
    use std::io::Write;
    let model =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/synth_wall_door_window_in.ifc");
    let mut child = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("check")
        .arg(&model)
        .args(["--rules", "/dev/stdin"])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // A rule that would fire on every piece if it were read.
    let rules = ".decl warning(p: symbol, kind: symbol, message: symbol)\nwarning(p, \"x\", \"y\") :- wall_of(p, _).\n";
    // The refusal may come before the rules are written: a closed pipe here is that refusal.
    let _ = child.stdin.take().unwrap().write_all(rules.as_bytes());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("/dev/stdin"), "{err}");
    assert!(err.contains("not a regular file"), "{err}");
    assert!(out.stdout.is_empty());
}
