//! `simulate … --bcf`: one topic per root cause per wall, read back by an independent BCF
//! reader (IfcOpenShell's `bcf` package, `bench/bcf_oracle.py`, skipped when absent) for
//! BCF 3.0 and 2.1; every XML document valid against buildingSMART's BCF-XML schemas of its
//! version (when installed); stable GUIDs and identical bytes on a re-run; hostile names intact.

mod common;

use quick_xml::Reader;
use quick_xml::events::Event;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `simulate MODEL --json --bcf OUT [extra]`; returns the JSON report.
fn simulate(model: &Path, out: &Path, extra: &[&str]) -> Value {
    let run = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("simulate")
        .arg(model)
        .args(["--json", "--bcf"])
        .arg(out)
        // Walls where the study laid TM3: TM1's bottom plate is then out of the arm's range.
        .args(["--offset-x", "0.531"])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    serde_json::from_slice(&run.stdout).unwrap()
}

/// Every entry of the archive, by name; each XML entry must be well-formed.
fn entries(bcfzip: &Path) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (name, bytes) in common::bcf::entries(bcfzip) {
        if common::bcf::is_image(&name) {
            assert!(
                bytes.starts_with(b"\x89PNG\r\n\x1a\n") && bytes.len() > 100,
                "{name} is not a PNG image"
            );
            out.push((name, String::new()));
            continue;
        }
        let text = String::from_utf8(bytes).unwrap();
        let mut reader = Reader::from_str(&text);
        loop {
            match reader.read_event() {
                Ok(Event::Eof) => break,
                Ok(_) => {}
                Err(e) => panic!("{name} is not well-formed: {e}"),
            }
        }
        out.push((name, text));
    }
    out
}

/// Validates every XML document of the archive against buildingSMART's BCF-XML schemas of
/// `version` with `xmlschema`. The schemas come from bcf-client 0.7.10 (IfcOpenShell's BCF
/// package, which ships them as `bcf/v2/xsd` and `bcf/v3/xsd`; later releases do not), installed
/// apart as `.ci/run` does (`pip install --no-deps --target target/bcf-xsd bcf-client==0.7.10`;
/// another folder through `FRAMEWRIGHT_BCF_XSD_DIR`), or from the installed `bcf` package when
/// it carries them. Skips, saying so, without them.
const XSD_CHECK: &str = r#"
import importlib.util, os, sys, zipfile
import xmlschema
version, path = sys.argv[1], sys.argv[2]
sub = os.path.join("bcf", "v3" if version == "3.0" else "v2", "xsd")
bases = [b for b in sys.argv[3:] if b]
spec = importlib.util.find_spec("bcf")
if spec and spec.submodule_search_locations:
    bases.append(os.path.dirname(list(spec.submodule_search_locations)[0]))
folders = [os.path.join(b, sub) for b in bases if os.path.isdir(os.path.join(b, sub))]
if not folders:
    print("NO-XSD " + " ".join(bases))
    sys.exit(0)
folder = folders[0]
print("SCHEMAS " + folder)
by_name = {"bcf.version": "version.xsd", "project.bcfp": "project.xsd",
           "extensions.xml": "extensions.xsd", "documents.xml": "documents.xsd"}
by_ext = {".bcf": "markup.xsd", ".bcfv": "visinfo.xsd"}
schemas, failed = {}, 0
with zipfile.ZipFile(path) as z:
    for name in sorted(z.namelist()):
        if name.endswith(".png"):
            continue
        base = name.rsplit("/", 1)[-1]
        xsd = by_name.get(base) or by_ext.get(os.path.splitext(base)[1])
        if xsd is None:
            print("UNKNOWN " + name)
            failed += 1
            continue
        if xsd not in schemas:
            schemas[xsd] = xmlschema.XMLSchema(os.path.join(folder, xsd))
        errors = list(schemas[xsd].iter_errors(z.read(name).decode("utf-8")))
        for e in errors:
            print("INVALID %s (%s): %s" % (name, xsd, e.reason))
        failed += bool(errors)
        print("CHECKED %s %s" % (name, xsd))
sys.exit(1 if failed else 0)
"#;

fn validate_against_schemas(bcfzip: &Path, version: &str) {
    let Some(python) = common::python::python_with(&["xmlschema"], "xmlschema") else {
        return;
    };
    let run = Command::new(python)
        .args(["-c", XSD_CHECK, version])
        .arg(bcfzip)
        .arg(std::env::var("FRAMEWRIGHT_BCF_XSD_DIR").unwrap_or_default())
        .arg(root().join("target/bcf-xsd"))
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&run.stdout);
    if let Some(looked) = out.strip_prefix("NO-XSD ") {
        common::skip::missing_tool(
            &format!("the BCF-XML schemas (looked in {})", looked.trim()),
            "python3 -m pip install --no-deps --target target/bcf-xsd bcf-client==0.7.10",
        );
        return;
    }
    assert!(
        run.status.success(),
        "{} does not follow the BCF {version} schemas:\n{out}{}",
        bcfzip.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    let names: Vec<String> = entries(bcfzip)
        .into_iter()
        .map(|(n, _)| n)
        .filter(|n| !common::bcf::is_image(n))
        .collect();
    assert_eq!(
        out.lines().filter(|l| l.starts_with("CHECKED ")).count(),
        names.len(),
        "every XML document checked: {out}"
    );
}

/// The oracle's reading, or None (after saying so) when python3 or bcf-client is absent.
fn read_back(bcfzip: &Path) -> Option<Value> {
    let python = common::python::python_with(&["bcf.bcfxml"], "bcf-client")?;
    let run = Command::new(python)
        .arg(root().join("bench/bcf_oracle.py"))
        .arg(bcfzip)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "the BCF reader refused {}: {}",
        bcfzip.display(),
        String::from_utf8_lossy(&run.stderr)
    );
    Some(serde_json::from_slice(&run.stdout).unwrap())
}

/// The pieces whose framing failed on their own account, per the simulate report.
fn framing_failures(report: &Value) -> Vec<String> {
    report["elements"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["framing"]["status"] == "failed")
        .filter(|e| !e["framing"]["reasons"].as_array().unwrap().is_empty())
        .map(|e| e["id"].as_str().unwrap().to_string())
        .collect()
}

/// Checks one archive against the report: a framing topic per own framing failure naming
/// that element, selections red and inside the visible wall, version as asked.
fn check(bcfzip: &Path, version: &str, report: &Value) -> Option<Value> {
    let names: Vec<String> = entries(bcfzip).into_iter().map(|(n, _)| n).collect();
    assert!(names.contains(&"bcf.version".to_string()));
    assert_eq!(
        names.contains(&"extensions.xml".to_string()),
        version == "3.0"
    );
    // Every topic's viewpoint carries its wall's elevation as a PNG, referenced by the markup.
    for (name, text) in entries(bcfzip) {
        if let Some(folder) = name.strip_suffix("/markup.bcf") {
            assert!(
                names.contains(&format!("{folder}/snapshot.png")),
                "{folder} has no snapshot"
            );
            assert!(text.contains("<Snapshot>snapshot.png</Snapshot>"), "{text}");
        }
    }
    validate_against_schemas(bcfzip, version);
    let read = read_back(bcfzip)?;
    assert_eq!(read["version"], version);
    let topics = read["topics"].as_array().unwrap();
    let failures = framing_failures(report);
    let framing: Vec<&Value> = topics
        .iter()
        .filter(|t| t["labels"][0] == "framing")
        .collect();
    assert_eq!(
        framing.len(),
        failures.len(),
        "one framing topic per failing element"
    );
    for id in &failures {
        let gid = id.split('/').next().unwrap();
        assert!(
            framing
                .iter()
                .any(|t| t["viewpoints"][0]["selected"] == serde_json::json!([gid])),
            "no topic selects {gid}"
        );
    }
    for t in topics {
        let vp = &t["viewpoints"][0];
        assert_eq!(vp["selected"], vp["red"]);
        assert_eq!(vp["default_visibility"], false);
        let visible = vp["visible_exceptions"].as_array().unwrap();
        for g in vp["selected"].as_array().unwrap() {
            assert!(visible.contains(g), "{g} selected but hidden");
        }
        assert_eq!(vp["snapshot"], true, "the reader finds the snapshot");
        let d = vp["camera"]["direction"].as_array().unwrap();
        let norm: f64 = d.iter().map(|x| x.as_f64().unwrap().powi(2)).sum();
        assert!((norm - 1.0).abs() < 1e-5);
    }
    Some(read)
}

#[test]
fn tm1_topics_in_both_versions_and_stable() {
    let dir = tempfile::tempdir().unwrap();
    let model = root().join("examples/models/tm1.ifc");
    let (v3, v2) = (dir.path().join("a.bcfzip"), dir.path().join("b.bcfzip"));
    let report = simulate(&model, &v3, &[]);
    assert!(
        !framing_failures(&report).is_empty(),
        "TM1 at x = 0.531 m fails its bottom plate"
    );
    simulate(&model, &v2, &["--bcf-version", "2.1"]);
    let read3 = check(&v3, "3.0", &report);
    let read2 = check(&v2, "2.1", &report);
    if let (Some(a), Some(b)) = (read3, read2) {
        let guids = |r: &Value| -> Vec<Value> {
            r["topics"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| t["guid"].clone())
                .collect()
        };
        assert_eq!(guids(&a), guids(&b), "the same topics in both versions");
    }
    // A re-run: the same bytes, hence the same GUIDs.
    let again = dir.path().join("c.bcfzip");
    simulate(&model, &again, &[]);
    assert_eq!(std::fs::read(&v3).unwrap(), std::fs::read(&again).unwrap());
}

#[test]
fn tm3_on_the_study_cell() {
    let dir = tempfile::tempdir().unwrap();
    let model = root().join("examples/models/tm3.ifc");
    for version in ["3.0", "2.1"] {
        let out = dir.path().join(format!("tm3-{version}.bcfzip"));
        let report = simulate(&model, &out, &["--bcf-version", version]);
        check(&out, version, &report);
    }
}

const HOSTILE: &str = "Plate \"A\" <b> & 'c' — façade 木";

#[test]
fn hostile_names_survive() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("examples/models/tm1.ifc")).unwrap();
    // The bottom plate (the element that fails) gets a hostile name.
    let line = text
        .lines()
        .find(|l| l.contains("'1Rf9dQR5zAWDDanhuLOyBj'"))
        .unwrap();
    let name_start = line.find(",'").unwrap() + 1;
    let name_end = name_start + 1 + line[name_start + 1..].find('\'').unwrap() + 1;
    let hostile_line = format!(
        "{}{}{}",
        &line[..name_start],
        framewright::step::text::string(HOSTILE),
        &line[name_end..]
    );
    let model: PathBuf = dir.path().join("tm1 'x' <&> é.ifc");
    std::fs::write(&model, text.replace(line, &hostile_line)).unwrap();
    for version in ["3.0", "2.1"] {
        let out = dir.path().join(format!("h-{version}.bcfzip"));
        simulate(&model, &out, &["--bcf-version", version]);
        validate_against_schemas(&out, version);
        let all: String = entries(&out).into_iter().map(|(_, t)| t).collect();
        assert!(all.contains("&lt;b&gt; &amp;"), "escaped in the XML");
        if let Some(read) = read_back(&out) {
            let t = &read["topics"][0];
            assert!(
                t["title"].as_str().unwrap().contains(HOSTILE),
                "{}",
                t["title"]
            );
            assert!(t["description"].as_str().unwrap().contains(HOSTILE));
        }
    }
}
