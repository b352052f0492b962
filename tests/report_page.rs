//! `simulate --report`: the page in a real browser (Debian's chromium, headless), the scene
//! through the Khronos glTF validator (npm `gltf-validator`), the animation against the
//! executor's own tool poses, hostile names, byte-identical repeats. Tests that need a tool
//! skip with a message when it is absent; `.ci/run` installs both.

mod common;

use common::browser::{browse, chromium, console_errors};
use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::report::html::{
    DEFAULT_MAX_REPORT_BYTES, ReportInput, report_files, write_report,
};
use framewright::report::simulate::SimReport;
use framewright::report::verdict;
use framewright::sim::{SimOptions, Simulation};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use regex::Regex;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Where the tests leave what a person may look at (screenshots).
fn output_dir() -> PathBuf {
    let dir = root().join("target/test-output/report");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

struct Run {
    model: Model,
    name: String,
    cell: Cell,
    sim: Simulation,
    report: SimReport,
}

fn run(path: &Path) -> Run {
    let model = Model::open(path).expect("model");
    let cell = Cell::load("study-abb").unwrap();
    let sim = simulate(&model, &cell, &SimOptions::default()).expect("simulation runs");
    let report = SimReport::new(&sim, SimOptions::default().dt).expect("report");
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    Run {
        model,
        name,
        cell,
        sim,
        report,
    }
}

fn files(r: &Run) -> BTreeMap<String, Vec<u8>> {
    report_files(&ReportInput {
        model: &r.model,
        model_name: &r.name,
        cell: &r.cell,
        sim: &r.sim,
        report: &r.report,
    })
    .into_iter()
    .collect()
}

fn write(r: &Run, dir: &Path) {
    write_report(
        dir,
        &ReportInput {
            model: &r.model,
            model_name: &r.name,
            cell: &r.cell,
            sim: &r.sim,
            report: &r.report,
        },
        DEFAULT_MAX_REPORT_BYTES,
    )
    .expect("report written");
}

/// Each wall's elevation in `page` (the written HTML, or the DOM a browser built from it) shows
/// every piece of the wall once with the class of its verdicts in `json` (`simulate.json`), and
/// one dot per nailing target.
fn assert_elevations_show_the_verdicts(dom: &str, json: &serde_json::Value, walls: usize) {
    let section = Regex::new(r#"<section class="wall" id="[^"]*" data-wall="([^"]+)">"#).unwrap();
    let piece =
        Regex::new(r#"<g class="piece ([a-z-]+)" data-id="([^"]+)" data-guid="([^"]+)""#).unwrap();
    let nail = Regex::new(r#"<circle class="nail (driven|failed)""#).unwrap();
    let starts: Vec<(usize, String)> = section
        .captures_iter(dom)
        .map(|c| (c.get(0).unwrap().start(), c[1].to_string()))
        .collect();
    assert_eq!(starts.len(), walls, "one section per wall");
    for (k, (start, wall)) in starts.iter().enumerate() {
        let end = starts.get(k + 1).map_or(dom.len(), |s| s.0);
        let text = &dom[*start..end];
        let elevation = &text[text.find("<svg").unwrap()..];
        let elevation = &elevation[..elevation.find("</svg>").unwrap()];
        let shown: BTreeMap<String, String> = piece
            .captures_iter(elevation)
            .map(|c| (c[2].to_string(), c[1].to_string()))
            .collect();
        let expected: BTreeMap<String, String> = json["elements"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|e| e["wall_id"] == wall.as_str())
            .map(|e| {
                let f = e["framing"]["status"].as_str().unwrap();
                let n = e["nailing"]["status"].as_str().unwrap();
                let class = match (f, n) {
                    ("framed", "nailed" | "none") => "framed",
                    ("framed", _) => "nailing-failed",
                    ("failed", _) => "framing-failed",
                    _ => "not-attempted",
                };
                (e["id"].as_str().unwrap().to_string(), class.to_string())
            })
            .collect();
        assert_eq!(
            piece.captures_iter(elevation).count(),
            expected.len(),
            "{wall}: one shape per piece"
        );
        assert_eq!(shown, expected, "{wall}");
        let targets = json["nailing_validation"]["targets"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|t| t["wall_id"] == wall.as_str())
            .count();
        assert_eq!(
            nail.captures_iter(elevation).count(),
            targets,
            "{wall}: one dot per nail"
        );
    }
}

/// The page's static mapping (verdict to class, nail to dot) holds in the HTML as written, so
/// it is checked where no browser is installed.
#[test]
fn tm3_page_as_written_shows_every_piece_with_its_verdict_and_every_nail() {
    let r = run(&root().join("examples/models/tm3.ifc"));
    let files = files(&r);
    let page = String::from_utf8(files["index.html"].clone()).unwrap();
    let json: serde_json::Value = serde_json::from_slice(&files["simulate.json"]).unwrap();
    assert_elevations_show_the_verdicts(&page, &json, r.report.walls.len());
    // Not every piece is framed: the drawing's classes are told apart.
    for class in ["class=\"piece framed\"", "class=\"piece framing-failed\""] {
        assert!(page.contains(class), "{class}");
    }
    assert!(page.contains("beyond reach"));
}

#[test]
fn tm3_page_in_a_browser_shows_every_piece_with_its_verdict_and_every_nail() {
    let Some(browser) = chromium() else { return };
    let r = run(&root().join("examples/models/tm3.ifc"));
    let dir = tempfile::tempdir().unwrap();
    let report_dir = dir.path().join("report");
    write(&r, &report_dir);
    let shot = output_dir().join("tm3-index.png");
    let (dom, log) = browse(browser, &report_dir.join("index.html"), &shot);
    assert!(console_errors(&log).is_empty(), "{log}");
    eprintln!("screenshot: {}", shot.display());

    // The JSON beside the page is the truth the drawing must show.
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(report_dir.join("simulate.json")).unwrap()).unwrap();
    assert_elevations_show_the_verdicts(&dom, &json, r.report.walls.len());
    // The study's finding is on the page: the ends of TM3's long walls are out of reach.
    assert!(dom.contains("beyond reach"));
    assert!(dom.contains("consequences</summary>"));
    assert_eq!(verdict::CLASSES.len(), 4);
}

/// A copy of TM1 whose names and GlobalIds hold markup, quotes and ampersands.
fn hostile_model(dir: &Path) -> PathBuf {
    let text =
        std::fs::read_to_string(root().join("tests/fixtures/report_hostile_names.ifc")).unwrap();
    let path = dir.join("hostile.ifc");
    std::fs::write(&path, text).unwrap();
    path
}

/// The page's only scripts are one wall's view: its scene and the viewer's code.
fn assert_only_the_viewers_scripts(page: &str) {
    assert_eq!(
        common::page_scripts::viewer_scripts(page),
        (1, 1),
        "one wall's view and the viewer's script"
    );
}

#[test]
fn hostile_names_render_as_text_and_nothing_executes() {
    let dir = tempfile::tempdir().unwrap();
    let r = run(&hostile_model(dir.path()));
    let files = files(&r);
    let page = String::from_utf8(files["index.html"].clone()).unwrap();
    // The page's only scripts are the 3D view's: its scene (base64) and the viewer's code.
    assert_only_the_viewers_scripts(&page);
    assert!(page.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    let Some(browser) = chromium() else { return };
    let report_dir = dir.path().join("report");
    write(&r, &report_dir);
    let shot = output_dir().join("hostile-index.png");
    let (dom, log) = browse(browser, &report_dir.join("index.html"), &shot);
    assert!(console_errors(&log).is_empty(), "{log}");
    // The browser built no script element but the view's and shows the name as text.
    assert_only_the_viewers_scripts(&dom);
    assert!(dom.contains("&lt;script&gt;alert(1)&lt;/script&gt;"));
    assert!(
        dom.contains("O'Brien &amp; \"Sons\"") || dom.contains("O'Brien &amp; &quot;Sons&quot;"),
        "names shown as text"
    );
}

/// Runs the Khronos validator (npm gltf-validator) on a GLB: its report as JSON.
fn validate(glb: &Path) -> Option<serde_json::Value> {
    let Ok(npm_root) = Command::new("npm").args(["root", "-g"]).output() else {
        common::skip::missing_tool("npm (for the glTF validator)", "apt-get install npm");
        return None;
    };
    let npm_root = String::from_utf8_lossy(&npm_root.stdout).trim().to_string();
    if !Path::new(&npm_root).join("gltf-validator").exists() {
        common::skip::missing_tool("the glTF validator", "npm install -g gltf-validator");
        return None;
    }
    let script = "const v = require('gltf-validator'); const fs = require('fs');\
        v.validateBytes(new Uint8Array(fs.readFileSync(process.argv[1])), {maxIssues: 0})\
        .then(r => console.log(JSON.stringify(r))).catch(e => { console.error(e); process.exit(1); });";
    let out = Command::new("node")
        .env("NODE_PATH", &npm_root)
        .args(["-e", script])
        .arg(glb)
        .output()
        .ok()?;
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(serde_json::from_slice(&out.stdout).expect("validator JSON"))
}

/// The JSON chunk and the BIN chunk of a GLB.
fn chunks(glb: &[u8]) -> (serde_json::Value, &[u8]) {
    assert_eq!(&glb[0..4], b"glTF");
    let word = |i: usize| u32::from_le_bytes(glb[i..i + 4].try_into().unwrap()) as usize;
    assert_eq!(word(8), glb.len());
    let json_len = word(12);
    let doc = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    let bin_len = word(bin_at);
    (doc, &glb[bin_at + 8..bin_at + 8 + bin_len])
}

fn floats(doc: &serde_json::Value, bin: &[u8], accessor: usize) -> Vec<f32> {
    let a = &doc["accessors"][accessor];
    let view = &doc["bufferViews"][a["bufferView"].as_u64().unwrap() as usize];
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
        + a["byteOffset"].as_u64().unwrap_or(0) as usize;
    let width = match a["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC3" => 3,
        "VEC4" => 4,
        t => panic!("{t}"),
    };
    let n = a["count"].as_u64().unwrap() as usize * width;
    (0..n)
        .map(|k| f32::from_le_bytes(bin[start + 4 * k..start + 4 * k + 4].try_into().unwrap()))
        .collect()
}

/// A node's animated (translation, rotation) at time t, read back from the file.
fn animated(
    doc: &serde_json::Value,
    bin: &[u8],
    node: usize,
    t: f64,
) -> (Vector3<f64>, UnitQuaternion<f64>) {
    let anim = &doc["animations"][0];
    let mut translation = None;
    let mut rotation = None;
    for ch in anim["channels"].as_array().unwrap() {
        if ch["target"]["node"].as_u64() != Some(node as u64) {
            continue;
        }
        let sampler = &anim["samplers"][ch["sampler"].as_u64().unwrap() as usize];
        assert_eq!(sampler["interpolation"], "LINEAR");
        let times = floats(doc, bin, sampler["input"].as_u64().unwrap() as usize);
        let values = floats(doc, bin, sampler["output"].as_u64().unwrap() as usize);
        let k = times
            .iter()
            .rposition(|x| f64::from(*x) <= t)
            .unwrap_or(0)
            .min(times.len() - 2);
        let s = ((t - f64::from(times[k])) / f64::from(times[k + 1] - times[k])).clamp(0.0, 1.0);
        match ch["target"]["path"].as_str().unwrap() {
            "translation" => {
                let v = |i: usize| {
                    Vector3::new(values[3 * i], values[3 * i + 1], values[3 * i + 2]).cast::<f64>()
                };
                translation = Some(v(k).lerp(&v(k + 1), s));
            }
            "rotation" => {
                let q = |i: usize| {
                    UnitQuaternion::from_quaternion(Quaternion::new(
                        f64::from(values[4 * i + 3]),
                        f64::from(values[4 * i]),
                        f64::from(values[4 * i + 1]),
                        f64::from(values[4 * i + 2]),
                    ))
                };
                rotation = Some(q(k).slerp(&q(k + 1), s));
            }
            _ => {}
        }
    }
    (
        translation.expect("translation keys"),
        rotation.expect("rotation keys"),
    )
}

#[test]
fn tm1_scene_is_valid_gltf_lasting_the_run_and_its_tool_follows_the_executor() {
    let r = run(&root().join("examples/models/tm1.ifc"));
    let files = files(&r);
    let glb = &files["scene.glb"];
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scene.glb");
    std::fs::write(&path, glb).unwrap();
    if let Some(v) = validate(&path) {
        assert_eq!(v["issues"]["numErrors"], 0, "{v:#}");
    }
    let (doc, bin) = chunks(glb);
    let record = &r.sim.records[0];
    // The animation lasts the wall's simulated time.
    let anim = &doc["animations"][0];
    let last = anim["samplers"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| {
            doc["accessors"][s["input"].as_u64().unwrap() as usize]["max"][0]
                .as_f64()
                .unwrap()
        })
        .fold(0.0, f64::max);
    assert!(
        (last - record.nailing_end).abs() < 1e-3,
        "{last} vs {}",
        record.nailing_end
    );

    // The tool node hangs under one link node; its pose there is the link's animated pose.
    let nodes = doc["nodes"].as_array().unwrap();
    let tool = nodes
        .iter()
        .position(|n| n["name"] == "tool")
        .expect("a tool node");
    let link = nodes
        .iter()
        .position(|n| {
            n["children"]
                .as_array()
                .is_some_and(|c| c.iter().any(|i| i.as_u64() == Some(tool as u64)))
        })
        .expect("the tool's link");
    assert!(nodes[tool].get("translation").is_none() && nodes[tool].get("rotation").is_none());
    let scene_root = nodes
        .iter()
        .position(|n| n["name"] == "cell (Z up)")
        .unwrap();
    let r0 = &nodes[scene_root]["rotation"];
    let up = UnitQuaternion::from_quaternion(Quaternion::new(
        r0[3].as_f64().unwrap(),
        r0[0].as_f64().unwrap(),
        r0[1].as_f64().unwrap(),
        r0[2].as_f64().unwrap(),
    ));
    // Five times over the run, compared with the tool pose the executor computed then.
    let trace = &record.trace;
    let n = trace.times.len();
    for k in 1..=5 {
        let i = n * k / 6;
        let t = trace.times[i];
        let (pos, _) = animated(&doc, bin, link, t);
        let shown = up * pos;
        let executor = up * trace.tool[i].translation.vector;
        let err = (shown - executor).norm();
        assert!(err < 1e-3, "t = {t:.3} s: tool {:.1} mm off", err * 1000.0);
    }
}

#[test]
fn report_files_are_byte_identical_on_repeat() {
    let a = files(&run(&root().join("examples/models/tm1.ifc")));
    let b = files(&run(&root().join("examples/models/tm1.ifc")));
    assert_eq!(
        a.keys().collect::<Vec<_>>(),
        ["index.html", "scene.glb", "simulate.json"]
    );
    for (name, bytes) in &a {
        assert!(bytes == &b[name], "{name} differs between two runs");
    }
}

#[test]
fn writing_over_a_folder_that_is_no_report_is_refused() {
    let r = run(&root().join("examples/models/tm1.ifc"));
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("notes.txt"), "mine").unwrap();
    let err = write_report(
        dir.path(),
        &ReportInput {
            model: &r.model,
            model_name: &r.name,
            cell: &r.cell,
            sim: &r.sim,
            report: &r.report,
        },
        DEFAULT_MAX_REPORT_BYTES,
    )
    .unwrap_err();
    assert!(err.to_string().contains("no earlier report"), "{err}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("notes.txt")).unwrap(),
        "mine"
    );
    // A report folder is replaced whole.
    let out = dir.path().join("report");
    write(&r, &out);
    write(&r, &out);
    assert!(out.join("index.html").exists() && out.join("scene.glb").exists());
}

#[test]
fn world_as_gltf_is_a_valid_static_scene_with_every_piece() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("world.glb");
    let run = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["world", "examples/models/tm1.ifc", "--format", "gltf", "-o"])
        .arg(&out)
        .current_dir(root())
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let glb = std::fs::read(&out).unwrap();
    let (doc, _) = chunks(&glb);
    let pieces = doc["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n["name"].as_str().is_some_and(|s| s.starts_with("piece ")))
        .count();
    let model = Model::open(root().join("examples/models/tm1.ifc")).unwrap();
    assert_eq!(pieces, model.pieces.len());
    assert!(doc.get("animations").is_none());
    if let Some(v) = validate(&out) {
        assert_eq!(v["issues"]["numErrors"], 0, "{v:#}");
    }
    // A binary is not written to the terminal.
    let refused = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args([
            "world",
            "examples/models/tm1.ifc",
            "--format",
            "gltf",
            "-o",
            "-",
        ])
        .current_dir(root())
        .output()
        .unwrap();
    assert!(!refused.status.success());
    assert!(String::from_utf8_lossy(&refused.stderr).contains("-o FILE.glb"));
}

#[test]
fn a_report_past_its_size_bound_is_refused_naming_the_bound() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("report");
    let model = root().join("examples/models/tm1.ifc");
    let run = |bound: &str| {
        std::process::Command::new(env!("CARGO_BIN_EXE_framewright"))
            .arg("simulate")
            .arg(&model)
            .args(["--no-cache", "--report"])
            .arg(&out)
            .env("FRAMEWRIGHT_MAX_REPORT_BYTES", bound)
            .output()
            .unwrap()
    };
    // TM1's page alone is larger than 10 kB.
    let r = run("10000");
    assert_eq!(r.status.code(), Some(2));
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(
        err.contains("FRAMEWRIGHT_MAX_REPORT_BYTES")
            && err.contains("10000 bytes")
            && err.contains("index.html"),
        "{err}"
    );
    assert!(!out.exists(), "no report folder, not half of one");
    let r = run("ten");
    assert_eq!(r.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&r.stderr).contains("FRAMEWRIGHT_MAX_REPORT_BYTES=\"ten\""));
    // A bound the report fits in.
    assert!(run("100000000").status.success());
    assert!(out.join("index.html").exists());
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "no temporary folder left");
}
