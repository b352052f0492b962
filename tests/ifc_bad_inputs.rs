//! Bad inputs: exit 2 with one clear message naming the problem and the
//! entity or line, or exit 0 with a warning naming the skipped member. Never
//! a panic or a hang.

mod common;

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn run(path: &Path) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["inspect", "--json"])
        .arg(path)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(30) {
            child.kill().unwrap();
            panic!("{} hangs", path.display());
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into(),
        String::from_utf8_lossy(&out.stderr).into(),
    )
}

fn shared_bad_inputs() -> Vec<PathBuf> {
    let Some(dir) = common::shared_path("ifc-testcases") else {
        return Vec::new();
    };
    let entries = std::fs::read_dir(&dir).unwrap();
    let mut files: Vec<PathBuf> = entries
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name().unwrap().to_string_lossy().starts_with("h_")
                && p.extension().is_some_and(|x| x == "ifc")
        })
        .collect();
    files.sort();
    files
}

#[test]
fn shared_bad_inputs_fail_clearly() {
    for ifc in shared_bad_inputs() {
        let expected: Value = serde_json::from_str(
            &std::fs::read_to_string(ifc.with_extension("expected.json")).unwrap(),
        )
        .unwrap();
        let outcome = expected["expected"]["outcome"].as_str().unwrap();
        let (code, stdout, stderr) = run(&ifc);
        assert!(!stderr.contains("panicked"), "{}: {stderr}", ifc.display());
        let name = ifc.file_name().unwrap().to_string_lossy();
        match code {
            2 => {
                assert!(
                    outcome.starts_with("error"),
                    "{name}: error but expected {outcome}: {stderr}"
                );
                assert_eq!(
                    stderr.lines().filter(|l| l.starts_with("error:")).count(),
                    1,
                    "{name}: {stderr}"
                );
                assert!(
                    stderr.contains(&*name),
                    "{name}: the message names the file: {stderr}"
                );
                assert!(
                    stderr.contains("line "),
                    "{name}: the message names a line: {stderr}"
                );
                let entities = &expected["location"]["entities"];
                if let Some(list) = entities.as_array() {
                    for e in list {
                        assert!(
                            stderr.contains(e.as_str().unwrap()),
                            "{name}: names {e}: {stderr}"
                        );
                    }
                }
                if let Some(e) = expected["location"]["entity"].as_str() {
                    assert!(stderr.contains(e), "{name}: names {e}: {stderr}");
                }
                assert!(stdout.is_empty(), "{name}: nothing printed on error");
            }
            0 => {
                assert!(
                    outcome.contains("skip") || outcome.contains("replace"),
                    "{name}: exit 0 but expected {outcome}"
                );
                let report: Value = serde_json::from_str(&stdout).unwrap();
                let warnings = report["warnings"].as_array().unwrap();
                assert!(
                    !warnings.is_empty(),
                    "{name}: a warning explains what was skipped"
                );
                let text = serde_json::to_string(warnings).unwrap();
                if let Some(e) = expected["location"]["entity"].as_str() {
                    assert!(text.contains(e), "{name}: warning names {e}: {text}");
                }
                if outcome.contains("skip")
                    && let Some(gid) = expected["expected"]["member_global_id"].as_str()
                {
                    assert!(text.contains(gid), "{name}: warning names {gid}");
                    let members = report["members"].as_array().unwrap();
                    assert!(
                        members.iter().all(|m| m["global_id"] != gid),
                        "{name}: {gid} is skipped"
                    );
                    assert_eq!(members.len(), 3, "{name}: the other members are read");
                }
                if let Some(missing) = expected["location"]["missing_id"].as_str() {
                    assert!(text.contains(missing), "{name}: warning names {missing}");
                }
            }
            other => panic!("{name}: exit {other}: {stderr}"),
        }
    }
}
