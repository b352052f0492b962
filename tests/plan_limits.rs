//! The bounds on what the rule base derives from a model: each is hit with an error naming
//! the bound and the environment variable that raises it, and the same model plans once the
//! bound is raised to what it needs.
use std::path::PathBuf;
use std::process::{Command, Output};

fn plan_tm3(variable: &str, value: &str) -> Output {
    let tm3 = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc");
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["plan", "--json"])
        .arg(&tm3)
        .env(variable, value)
        .output()
        .expect("run framewright")
}

#[test]
fn the_wall_bound_names_itself_and_can_be_raised() {
    // TM3 holds four wall frames (examples/models/tm3.truth.json).
    let o = plan_tm3("FRAMEWRIGHT_MAX_WALLS", "3");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(o.stdout.is_empty(), "no half output");
    assert!(err.contains("4 wall frames"), "{err}");
    assert!(err.contains("bound of 3"), "{err}");
    assert!(err.contains("FRAMEWRIGHT_MAX_WALLS=N"), "{err}");
    let o = plan_tm3("FRAMEWRIGHT_MAX_WALLS", "4");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn the_rule_tuple_bound_names_itself() {
    let o = plan_tm3("FRAMEWRIGHT_MAX_RULE_TUPLES", "1000");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(o.stdout.is_empty(), "no half output");
    assert!(err.contains("more than 1000 tuples"), "{err}");
    assert!(err.contains("FRAMEWRIGHT_MAX_RULE_TUPLES=N"), "{err}");
    let o = plan_tm3("FRAMEWRIGHT_MAX_RULE_TUPLES", "100000000");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn a_bound_that_is_not_a_number_is_refused() {
    let o = plan_tm3("FRAMEWRIGHT_MAX_RULE_TUPLES", "lots");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(
        err.contains("FRAMEWRIGHT_MAX_RULE_TUPLES=\"lots\" is not a whole number"),
        "{err}"
    );
}
