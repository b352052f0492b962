//! `framewright world`: Webots and JSON output, structure of the .wbt, errors and atomic writes.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn example(name: &str) -> PathBuf {
    root().join("examples/models").join(name)
}

fn world(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("world")
        .args(args)
        .output()
        .unwrap()
}

fn run_ok(args: &[&str]) {
    let out = world(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Braces and brackets balance outside strings and comments, never going negative.
fn balanced(text: &str) -> bool {
    let (mut braces, mut brackets) = (0i64, 0i64);
    for line in text.lines() {
        let mut in_string = false;
        let mut escaped = false;
        for c in line.chars() {
            if in_string {
                match (escaped, c) {
                    (true, _) => escaped = false,
                    (false, '\\') => escaped = true,
                    (false, '"') => in_string = false,
                    _ => {}
                }
                continue;
            }
            match c {
                '#' => break,
                '"' => in_string = true,
                '{' => braces += 1,
                '}' => braces -= 1,
                '[' => brackets += 1,
                ']' => brackets -= 1,
                _ => {}
            }
            if braces < 0 || brackets < 0 {
                return false;
            }
        }
        if in_string {
            return false;
        }
    }
    braces == 0 && brackets == 0
}

fn piece_ids(json_path: &Path) -> Vec<String> {
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(json_path).unwrap()).unwrap();
    v["pieces"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["id"].as_str().unwrap().to_string())
        .collect()
}

#[test]
fn wbt_holds_every_piece_once_in_spawn_order() {
    let dir = tempfile::tempdir().unwrap();
    for (model, cell) in [("tm1.ifc", "study-abb"), ("tm3.ifc", "study-kuka")] {
        let wbt = dir.path().join(format!("{model}.{cell}.wbt"));
        let js = dir.path().join(format!("{model}.{cell}.json"));
        let m = example(model);
        let m = m.to_str().unwrap();
        run_ok(&[
            m,
            "--cell",
            cell,
            "--format",
            "wbt",
            "-o",
            wbt.to_str().unwrap(),
        ]);
        run_ok(&[
            m,
            "--cell",
            cell,
            "--format",
            "json",
            "-o",
            js.to_str().unwrap(),
        ]);
        let text = std::fs::read_to_string(&wbt).unwrap();
        assert!(text.starts_with("#VRML_SIM R2023b utf8\n"), "{model}");
        assert!(
            text.lines().nth(1).unwrap().contains(model),
            "header names the model"
        );
        assert!(balanced(&text), "{model}: unbalanced braces");
        for node in ["WorldInfo {", "basicTimeStep", "Viewpoint {", "Floor {"] {
            assert!(text.contains(node), "{model}: no {node}");
        }
        let ids = piece_ids(&js);
        assert!(!ids.is_empty());
        let mut last = 0;
        for id in &ids {
            let name = format!("  name \"{id}\"\n");
            assert_eq!(text.matches(&name).count(), 1, "{model}: {id}");
            let at = text.find(&name).unwrap();
            assert!(at > last, "{model}: {id} out of spawn order");
            last = at;
        }
        assert_eq!(
            text.matches("physics Physics { density ").count(),
            ids.len(),
            "{model}: only the lumber is dynamic"
        );
        if cell == "study-abb" {
            assert!(text.contains("EXTERNPROTO \"https://raw.githubusercontent.com/cyberbotics/webots/R2023b/projects/robots/abb/irb/protos/Irb4600-40.proto\""));
            assert!(text.contains("\nIrb4600-40 {\n"));
        } else {
            assert!(!text.contains("Irb4600-40"));
            assert!(text.contains("Webots ships no proto of this robot"));
            assert!(text.contains("base (placeholder)"));
        }
    }
}

#[test]
fn json_output_is_byte_identical_across_runs() {
    let dir = tempfile::tempdir().unwrap();
    let m = example("tm3.ifc");
    let (a, b) = (dir.path().join("a.json"), dir.path().join("b.json"));
    for out in [&a, &b] {
        run_ok(&[
            m.to_str().unwrap(),
            "--format",
            "json",
            "-o",
            out.to_str().unwrap(),
        ]);
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    let (c, d) = (dir.path().join("c.wbt"), dir.path().join("d.wbt"));
    for out in [&c, &d] {
        run_ok(&[
            m.to_str().unwrap(),
            "--format",
            "wbt",
            "-o",
            out.to_str().unwrap(),
        ]);
    }
    assert_eq!(std::fs::read(&c).unwrap(), std::fs::read(&d).unwrap());
}

#[test]
fn bad_inputs_exit_2_and_leave_the_output_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("world.json");
    std::fs::write(&out, "previous").unwrap();
    let o = out.to_str().unwrap();
    let bad_model = dir.path().join("broken.ifc");
    std::fs::write(&bad_model, "ISO-10303-21;\nDATA;\n#1=IFCWALL(;\n").unwrap();
    let tm1 = example("tm1.ifc");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["missing.ifc", "--format", "json", "-o", o],
            "missing.ifc",
        ),
        (
            vec![bad_model.to_str().unwrap(), "--format", "json", "-o", o],
            "broken.ifc",
        ),
        (
            vec![
                tm1.to_str().unwrap(),
                "--cell",
                "no-such-cell",
                "--format",
                "json",
                "-o",
                o,
            ],
            "no-such-cell",
        ),
    ];
    for (args, named) in cases {
        let r = world(&args);
        assert_eq!(r.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&r.stderr);
        assert!(err.contains(named), "{args:?}: {err}");
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            "previous",
            "{args:?}"
        );
    }
    // An output directory that does not exist: exit 2, nothing written, no temp file left.
    let nowhere = dir.path().join("no/such/dir/world.wbt");
    let r = world(&[
        tm1.to_str().unwrap(),
        "--format",
        "wbt",
        "-o",
        nowhere.to_str().unwrap(),
    ]);
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("cannot write the world"));
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left.len(), 2, "only world.json and broken.ifc: {left:?}");
}
