//! `framewright rules run` on corpus programs behaves as Soufflé documents for
//! problems at run time: a `match` pattern that is not a regular expression is
//! a warning (the run goes on), a division by zero stops the run naming the
//! rule's file and line and writes nothing.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn corpus(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/souffle")
        .join(name)
}

fn run(program: &str, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["rules", "run"])
        .arg(corpus(&format!("{program}.dl")))
        .arg("-F")
        .arg(corpus(program))
        .arg("-D")
        .arg(out)
        .output()
        .unwrap()
}

#[test]
fn a_bad_match_pattern_warns_and_the_run_goes_on() {
    let out = tempfile::tempdir().unwrap();
    let o = run("match_invalid_regex", out.path());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stderr.contains("warning: wrong pattern provided for match(\"(\", ...)"),
        "{stderr}"
    );
    assert_eq!(
        std::fs::read_to_string(out.path().join("r.csv")).unwrap(),
        ""
    );
    // Soufflé's !match is false too on a pattern it cannot read (its interpreter returns the
    // `false` it started from when std::regex throws).
    assert_eq!(
        std::fs::read_to_string(out.path().join("nr.csv")).unwrap(),
        ""
    );
}

#[test]
fn division_by_zero_names_the_rule_and_writes_nothing() {
    let out = tempfile::tempdir().unwrap();
    let o = run("division_by_zero", out.path());
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains("division by zero")
            && stderr.contains("ratio (")
            && stderr.contains("division_by_zero.dl:7)")
            && stderr.contains("x = 0"),
        "{stderr}"
    );
    assert!(!out.path().join("b.csv").exists());
}
