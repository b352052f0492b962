//! Every reader limit stops bad input with a message naming the bound and how to raise it.

use std::path::PathBuf;
use std::process::Command;

fn tm1() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc")
}

fn inspect_with(var: &str, value: &str) -> String {
    let o = Command::new(env!("CARGO_BIN_EXE_framewright"))
        // `plan` reads the model with the limits of every command (`inspect --max-size`
        // sets its own size bound).
        .arg("plan")
        .arg(tm1())
        .env(var, value)
        .output()
        .unwrap();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{var}={value} did not stop the read"
    );
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn step_reader_limits_name_the_bound_and_the_variable() {
    let cases = [
        (
            "FRAMEWRIGHT_MAX_IFC_BYTES",
            "100",
            "over the limit of 100 bytes",
        ),
        (
            "FRAMEWRIGHT_MAX_IFC_INSTANCES",
            "10",
            "more than 10 entity instances",
        ),
        (
            "FRAMEWRIGHT_MAX_IFC_STRING_BYTES",
            "3",
            "a string is longer than 3 bytes",
        ),
        (
            "FRAMEWRIGHT_MAX_IFC_DEPTH",
            "0",
            "nested deeper than 0 levels",
        ),
        ("FRAMEWRIGHT_MAX_IFC_BYTES", "lots", "is not a whole number"),
    ];
    for (var, value, message) in cases {
        let err = inspect_with(var, value);
        assert!(err.contains(message), "{var}: {err}");
        assert!(err.contains(var), "{var} is not named: {err}");
    }
}

#[test]
fn a_rule_program_stops_at_the_iteration_limit_it_is_given() {
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("runaway.dl");
    // Needs a million iterations of one recursive stratum: by default it runs to its end (no
    // iteration bound, as in Soufflé); with --max-iterations 100000 it stops, naming the flag.
    std::fs::write(
        &prog,
        ".decl n(x: number)\nn(0).\nn(x + 1) :- n(x), x < 1000000.\n.output n\n",
    )
    .unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["rules", "run", "--max-iterations", "100000"])
        .arg(&prog)
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{err}");
    assert!(err.contains("evaluation stopped"), "{err}");
    assert!(err.contains("--max-iterations"), "{err}");
    assert!(!dir.path().join("n.csv").exists());
}
