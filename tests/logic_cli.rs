//! `framewright rules run|check` behaves like `souffle -F DIR -D DIR PROG.dl`.

use std::path::Path;
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
}

fn logic_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/logic")
}

#[test]
fn run_writes_outputs_and_explains() {
    let out = tempfile::tempdir().unwrap();
    let o = bin()
        .args(["rules", "run"])
        .arg(logic_dir().join("tc.dl"))
        .arg("--facts")
        .arg(logic_dir().join("tc"))
        .arg("--out")
        .arg(out.path())
        .args(["--explain", "path(1, 4)", "--explain", "not path(4, 1)"])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let got = std::fs::read_to_string(out.path().join("path.csv")).unwrap();
    assert_eq!(
        got,
        std::fs::read_to_string(logic_dir().join("tc/expected/path.csv")).unwrap()
    );
    assert!(
        stdout.contains("path(1, 4)  [by path_step (") && stdout.contains("tc.dl:9)"),
        "{stdout}"
    );
    assert!(
        stdout.contains("edge(1, 2)  [input: ") && stdout.contains("edge.facts:1]"),
        "{stdout}"
    );
    assert!(stdout.contains("path(4, 1) is not derived"), "{stdout}");
    assert!(stdout.contains("no match for edge(4, 1)"), "{stdout}");
}

#[test]
fn errors_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let prog = dir.path().join("bad.dl");
    std::fs::write(
        &prog,
        ".decl a(x: number)\n.output a\na(1).\n.decl b(x: number)\n.output b\nb(x / 0) :- a(x).\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = bin()
        .args(["rules", "run"])
        .arg(&prog)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("division by zero") && err.contains("bad.dl:6"),
        "{err}"
    );
    assert!(!out.exists(), "nothing may be written on error");

    std::fs::write(&prog, ".decl a(x: number)\na(y) :- a(x).\n").unwrap();
    let o = bin().args(["rules", "check"]).arg(&prog).output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("bad.dl:2:3: error: variable `y` in the head is not grounded"),
        "{err}"
    );

    let o = bin()
        .args(["rules", "check"])
        .arg(logic_dir().join("features.dl"))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn missing_facts_file_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let o = bin()
        .args(["rules", "run"])
        .arg(logic_dir().join("tc.dl"))
        .arg("--facts")
        .arg(dir.path())
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("edge.facts"));
    assert!(!dir.path().join("path.csv").exists());
}
