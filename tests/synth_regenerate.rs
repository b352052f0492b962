//! The committed example models and fixtures are exactly what the commands in
//! their README write: regenerate each and compare bytes, so they never drift.
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Lines `framewright synth ...` of a README's code blocks, split on spaces.
fn commands(readme: &Path) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(readme).unwrap();
    text.lines()
        .filter(|l| l.starts_with("framewright synth "))
        .map(|l| l.split_whitespace().skip(1).map(String::from).collect())
        .collect()
}

fn regenerate_all(readme: &str, expected_commands: usize) {
    let readme = root().join(readme);
    let cmds = commands(&readme);
    assert_eq!(
        cmds.len(),
        expected_commands,
        "commands listed in {}",
        readme.display()
    );
    let tmp = tempfile::tempdir().unwrap();
    for args in cmds {
        // Write into the temp dir under the same file names; remember what to compare.
        let mut compare = Vec::new();
        let mut run_args = Vec::new();
        let mut it = args.iter();
        while let Some(a) = it.next() {
            run_args.push(a.clone());
            if a == "-o" || a == "--truth" {
                let committed = root().join(it.next().unwrap());
                let fresh = tmp.path().join(committed.file_name().unwrap());
                run_args.push(fresh.to_string_lossy().into_owned());
                compare.push((committed, fresh));
            }
        }
        let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
            .args(&run_args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(compare.len(), 2, "{args:?} names an IFC and a truth file");
        for (committed, fresh) in compare {
            let (a, b) = (
                std::fs::read(&committed).unwrap(),
                std::fs::read(&fresh).unwrap(),
            );
            assert!(
                a == b,
                "{} differs from a fresh `framewright {}`",
                committed.display(),
                args.join(" ")
            );
        }
    }
}

#[test]
fn example_models_are_what_their_readme_commands_write() {
    regenerate_all("examples/models/README.md", 3);
}

#[test]
fn fixtures_are_what_their_readme_commands_write() {
    regenerate_all("tests/fixtures/README.md", 6);
}
