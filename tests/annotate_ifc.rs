//! `framewright annotate`: the input's entities survive byte for byte, new ones follow with
//! fresh ids, the header names the tool, the same inputs give the same bytes, hostile
//! names survive, IFC2X3 is refused clearly; and IfcOpenShell (when installed) validates
//! the output and finds the plan in it (`bench/annotate_oracle.py`).

mod common;

use framewright::step::text::string as step_string;
use framewright::step::{ReadOptions, StepFile};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn framewright(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .unwrap()
}

fn annotate(model: &Path, out: &Path, extra: &[&str]) -> Vec<u8> {
    let mut args = vec![
        "annotate",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let run = framewright(&args);
    assert!(
        run.status.success(),
        "annotate {}: {}",
        model.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    std::fs::read(out).unwrap()
}

fn read(bytes: &[u8]) -> StepFile {
    StepFile::from_bytes(bytes.to_vec(), &ReadOptions::default()).unwrap()
}

/// Every input entity is in the output with the same type and the same parameter bytes;
/// every other output entity has an id above the input's highest. Returns the new ones' count.
fn assert_kept_byte_for_byte(input: &[u8], output: &[u8]) -> usize {
    let (a, b) = (read(input), read(output));
    let max_id = a.records().iter().map(|r| r.id).max().unwrap();
    for r in a.records() {
        let o = b
            .record(r.id)
            .unwrap_or_else(|| panic!("#{} is missing", r.id));
        assert_eq!(a.type_name(r.type_id), b.type_name(o.type_id), "#{}", r.id);
        assert_eq!(
            &input[r.start..r.params.1],
            &output[o.start..o.params.1],
            "#{} changed",
            r.id
        );
    }
    let new: Vec<u64> = b
        .records()
        .iter()
        .filter(|r| a.record(r.id).is_none())
        .map(|r| r.id)
        .collect();
    assert!(new.iter().all(|&id| id > max_id));
    // The new entities follow the input's last one, in one block of consecutive ids.
    let first = new.iter().min().copied().unwrap();
    assert_eq!(first, max_id + 1);
    assert_eq!(new.len() as u64, new.iter().max().unwrap() - first + 1);
    assert!(b.header.preprocessor_version.starts_with("framewright "));
    assert_eq!(a.header.file_name, b.header.file_name);
    assert_eq!(a.header.time_stamp, b.header.time_stamp);
    assert_eq!(a.header.originating_system, b.header.originating_system);
    new.len()
}

fn count(file: &StepFile, type_name: &str) -> usize {
    file.of_type(type_name).count()
}

#[test]
fn examples_keep_their_entities_and_gain_the_plan() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.ifc");
    for name in ["tm1.ifc", "tm2.ifc", "tm3.ifc"] {
        let model = root().join("examples/models").join(name);
        let input = std::fs::read(&model).unwrap();
        let output = annotate(&model, &out, &[]);
        assert!(assert_kept_byte_for_byte(&input, &output) > 0);
        // Counts against the plan, computed from `plan --json`.
        let plan = framewright(&["plan", model.to_str().unwrap(), "--json"]);
        let plan: serde_json::Value = serde_json::from_slice(&plan.stdout).unwrap();
        let walls = plan["walls"].as_array().unwrap();
        let sum =
            |key: &str| -> usize { walls.iter().map(|w| w[key].as_array().unwrap().len()).sum() };
        let f = read(&output);
        assert_eq!(count(&f, "IFCRELSEQUENCE"), sum("precedence"), "{name}");
        assert_eq!(
            count(&f, "IFCTASK"),
            sum("assembly_order") + walls.len(),
            "{name}: a task per piece and per wall"
        );
        assert_eq!(count(&f, "IFCRELASSIGNSTOPROCESS"), sum("assembly_order"));
        assert_eq!(count(&f, "IFCMECHANICALFASTENER"), sum("nailing_targets"));
        assert_eq!(count(&f, "IFCWORKSCHEDULE"), 1);
        // Same inputs, same bytes.
        assert_eq!(
            annotate(&model, &out, &[]),
            output,
            "{name}: not deterministic"
        );
    }
}

#[test]
fn ifc4x3_fixture_and_realworld_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.ifc");
    let mut models = vec![root().join("tests/fixtures/synth_tm3_ifc4x3.ifc")];
    for name in [
        "ifc-realworld/timber_constructivity_wall-elemented-case_IFC4.ifc",
        "ifc-realworld/timber_constructivity_wall-elemented-case_IFC4X3_ADD2.ifc",
    ] {
        models.extend(common::shared_path(name));
    }
    for model in models {
        let input = std::fs::read(&model).unwrap();
        let output = annotate(&model, &out, &[]);
        assert_kept_byte_for_byte(&input, &output);
    }
}

/// Writes `text` with every `from` replaced by the STEP literal of `to`.
fn hostile_copy(src: &Path, dir: &Path, swaps: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(src).unwrap();
    for (from, to) in swaps {
        assert!(text.contains(from), "{from}");
        text = text.replace(from, &step_string(to));
    }
    let path = dir.join("hostile.ifc");
    std::fs::write(&path, text).unwrap();
    path
}

const HOSTILE_WALL: &str = "Wall \"north\" <A&B> 'ß' ü 木 \\ end";
const HOSTILE_STUD: &str = "stud '1' </name> & façade — 柱";

#[test]
fn hostile_names_survive() {
    let dir = tempfile::tempdir().unwrap();
    let model = hostile_copy(
        &root().join("tests/fixtures/synth_tm3_ifc4x3.ifc"),
        dir.path(),
        &[
            ("'Front wall'", HOSTILE_WALL),
            ("'synth_tm3_ifc4x3.ifc'", "tm3 'copy' <&> é.ifc"),
        ],
    );
    // A stud name as well: the first IFCMEMBER's name.
    let text = std::fs::read_to_string(&model).unwrap();
    let at = text.find("IFCMEMBER('").unwrap();
    let name_start = at + text[at..].find(",#").unwrap() + 1;
    let name_start = name_start + text[name_start..].find(',').unwrap() + 1;
    let name_end = name_start + text[name_start..].find("',").unwrap() + 1;
    let text = format!(
        "{}{}{}",
        &text[..name_start],
        step_string(HOSTILE_STUD),
        &text[name_end..]
    );
    std::fs::write(&model, text).unwrap();

    let out = dir.path().join("out.ifc");
    let input = std::fs::read(&model).unwrap();
    let output = annotate(&model, &out, &[]);
    assert_kept_byte_for_byte(&input, &output);
    let f = read(&output);
    assert_eq!(f.header.file_name, "tm3 'copy' <&> é.ifc");
    let names: Vec<String> = f
        .of_type("IFCTASK")
        .map(|r| {
            let e = f.decode(r).unwrap();
            e.get(2).text().unwrap().0.into_owned()
        })
        .collect();
    assert!(
        names.contains(&format!("Frame {HOSTILE_WALL}")),
        "{names:?}"
    );
    assert!(
        names
            .iter()
            .any(|n| n.ends_with(&format!(" {HOSTILE_STUD}"))),
        "{names:?}"
    );
    if let Some(python) = common::python::ifcopenshell() {
        let script = "import sys, json, ifcopenshell\nf = ifcopenshell.open(sys.argv[1])\nprint(json.dumps(sorted(t.Name for t in f.by_type('IfcTask'))))";
        let run = Command::new(python)
            .args(["-c", script, out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let theirs: Vec<String> = serde_json::from_slice(&run.stdout).unwrap();
        let mut ours = names.clone();
        ours.sort();
        assert_eq!(theirs, ours, "IfcOpenShell reads other task names");
    }
}

#[test]
fn ifc2x3_is_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("examples/models/tm1.ifc")).unwrap();
    let model = dir.path().join("old.ifc");
    std::fs::write(
        &model,
        text.replace("FILE_SCHEMA(('IFC4'))", "FILE_SCHEMA(('IFC2X3'))"),
    )
    .unwrap();
    let out = dir.path().join("out.ifc");
    let run = framewright(&[
        "annotate",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(2));
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(err.contains("old.ifc") && err.contains("IFC2X3"), "{err}");
    assert!(!out.exists(), "no output on failure");
}

#[test]
fn an_annotated_model_is_not_annotated_twice() {
    let dir = tempfile::tempdir().unwrap();
    let once = dir.path().join("once.ifc");
    annotate(&root().join("examples/models/tm1.ifc"), &once, &[]);
    let twice = dir.path().join("twice.ifc");
    let run = framewright(&[
        "annotate",
        once.to_str().unwrap(),
        "-o",
        twice.to_str().unwrap(),
    ]);
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("Framewright_Assembly"));
    assert!(!twice.exists());
}

#[test]
fn a_bad_date_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out.ifc");
    let model = root().join("examples/models/tm1.ifc");
    let run = framewright(&[
        "annotate",
        model.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--date",
        "yesterday",
    ]);
    assert_eq!(run.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&run.stderr).contains("--date"));
    let dated = annotate(&model, &out, &["--date", "2026-03-01T08:00:00"]);
    assert!(String::from_utf8_lossy(&dated).contains("'2026-03-01T08:00:00'"));
}

/// IfcOpenShell's validator and the plan checks of `bench/annotate_oracle.py`.
#[test]
fn ifcopenshell_validates_and_finds_the_plan() {
    let Some(python) = common::python::ifcopenshell() else {
        return;
    };
    let rules = Command::new(python)
        .args(["-c", "import _pytest"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !rules {
        common::skip::missing_tool(
            "pytest (IfcOpenShell's EXPRESS where-rules)",
            "python3 -m pip install pytest",
        );
    }
    let dir = tempfile::tempdir().unwrap();
    let mut models: Vec<PathBuf> = ["tm1.ifc", "tm2.ifc", "tm3.ifc"]
        .iter()
        .map(|n| root().join("examples/models").join(n))
        .collect();
    models.push(root().join("tests/fixtures/synth_tm3_ifc4x3.ifc"));
    for name in [
        "ifc-realworld/timber_constructivity_wall-elemented-case_IFC4X3_ADD2.ifc",
        // Feet, 3048 nails; and a model with walls but no framing (nothing to schedule).
        "ifc-realworld/timber_autotimber-xbim-generated_outer-walls-5-framed_IFC4_feet.ifc",
        "ifc-realworld/timber_autotimber-input_revit2016_outer-walls-5-unframed_IFC4_feet.ifc",
    ] {
        models.extend(common::shared_path(name));
    }
    // Walls longer than the cell carries: split into panels, written as assemblies (one model
    // whose members an IfcWall aggregates, one whose members are loose).
    for (name, grouping) in [("long20.ifc", "wall"), ("long9.ifc", "none")] {
        let path = dir.path().join(name);
        let length = if grouping == "wall" { "20" } else { "9" };
        let synth = framewright(&[
            "synth",
            "wall",
            "--length",
            length,
            "--grouping",
            grouping,
            "--window",
            "2.0,1.2,1.2,0.9",
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(synth.status.success());
        models.push(path);
    }
    for model in models {
        let out = dir.path().join("out.ifc");
        annotate(&model, &out, &[]);
        let plan = framewright(&["plan", model.to_str().unwrap(), "--json"]);
        let plan_path = dir.path().join("plan.json");
        std::fs::write(&plan_path, &plan.stdout).unwrap();
        let mut args = vec![
            root()
                .join("bench/annotate_oracle.py")
                .to_str()
                .unwrap()
                .to_string(),
            model.to_str().unwrap().to_string(),
            out.to_str().unwrap().to_string(),
            plan_path.to_str().unwrap().to_string(),
        ];
        if rules {
            args.push("--rules".into());
        }
        let run = Command::new(python).args(&args).output().unwrap();
        assert!(
            run.status.success(),
            "{}:\n{}{}",
            model.display(),
            String::from_utf8_lossy(&run.stdout),
            String::from_utf8_lossy(&run.stderr)
        );
    }
}

/// With --simulate each element's property set carries its verdicts as `simulate --json`
/// reports them.
#[test]
fn simulate_verdicts_agree_with_the_simulate_report() {
    let dir = tempfile::tempdir().unwrap();
    let model = root().join("examples/models/tm1.ifc");
    let out = dir.path().join("out.ifc");
    // TM1 laid where the study laid TM3 (0.531 m): its bottom plate is out of the arm's
    // range, so a failed element's reason is checked too.
    let output = annotate(&model, &out, &["--simulate", "--offset-x", "0.531"]);
    let report = framewright(&[
        "simulate",
        model.to_str().unwrap(),
        "--json",
        "--offset-x",
        "0.531",
    ]);
    let report: serde_json::Value = serde_json::from_slice(&report.stdout).unwrap();
    let f = read(&output);
    // Property name → value text, per element GlobalId (one-piece products here).
    let text = |id: u64, i: usize| -> String {
        let e = f.entity(id).unwrap().unwrap();
        e.get(i)
            .text()
            .map(|(t, _)| t.into_owned())
            .unwrap_or_default()
    };
    let mut failed = 0;
    for element in report["elements"].as_array().unwrap() {
        let gid = element["id"].as_str().unwrap();
        let product = f
            .records()
            .iter()
            .find(|r| text(r.id, 0) == gid && f.type_name(r.type_id) != "IFCRELDEFINESBYPROPERTIES")
            .unwrap()
            .id;
        let rel = f
            .of_type("IFCRELDEFINESBYPROPERTIES")
            .find(|r| {
                let e = f.decode(r).unwrap();
                e.get(4).as_list().unwrap()[0].as_ref_id() == Some(product)
            })
            .unwrap();
        let pset = f.decode(rel).unwrap().get(5).as_ref_id().unwrap();
        let props: std::collections::BTreeMap<String, String> = f
            .entity(pset)
            .unwrap()
            .unwrap()
            .get(4)
            .as_list()
            .unwrap()
            .iter()
            .map(|p| {
                let id = p.as_ref_id().unwrap();
                let e = f.entity(id).unwrap().unwrap();
                (
                    text(id, 0),
                    e.get(2)
                        .text()
                        .map(|(t, _)| t.into_owned())
                        .unwrap_or_default(),
                )
            })
            .collect();
        assert_eq!(
            props["FramingVerdict"], element["framing"]["status"],
            "{gid}"
        );
        assert_eq!(
            props["NailingVerdict"], element["nailing"]["status"],
            "{gid}"
        );
        if element["framing"]["status"] == "failed" {
            failed += 1;
            let first = &element["framing"]["reasons"][0];
            let line = format!(
                "{}: {}",
                first["component"].as_str().unwrap(),
                first["message"].as_str().unwrap()
            );
            assert_eq!(props["Reason"], line, "{gid}");
        }
    }
    assert!(failed > 0, "TM1 at x = 0.531 m fails its bottom plate");
}
