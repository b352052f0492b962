//! `framewright watch`: start it on a copy of TM1, save edits the ways editors do (a new file
//! renamed over the model, then truncate-and-write in place), read its JSON events, save half
//! a file, and end it with Ctrl-C (SIGINT).

mod common;

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

const STUD_AT: &str = "#47=IFCCARTESIANPOINT((0.97155,-0.04445,0.0381));";
const STUD_MOVED: &str = "#47=IFCCARTESIANPOINT((0.95155,-0.04445,0.0381));";
const STUD: &str = "2bXwYoWlYif2Nljrw$aJRx";

/// Ends the watcher when a failed assertion unwinds the test.
struct KillOnDrop(std::process::Child);

impl Drop for KillOnDrop {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn next_event(rx: &mpsc::Receiver<String>, want: &str) -> serde_json::Value {
    loop {
        let line = rx
            .recv_timeout(Duration::from_secs(300))
            .unwrap_or_else(|_| panic!("no `{want}` event"));
        let v: serde_json::Value = serde_json::from_str(&line).unwrap();
        if v["event"] == want {
            return v;
        }
        // An in-place save can be seen half written; that only delays the result.
        assert_eq!(v["event"], "waiting", "{line}");
    }
}

#[test]
fn watch_redoes_changed_walls_on_saves_and_keeps_the_last_result_on_a_torn_save() {
    if !Path::new("/bin/kill").exists() && !Path::new("/usr/bin/kill").exists() {
        common::skip::missing_tool(
            "the kill command (to send Ctrl-C)",
            "apt-get install procps",
        );
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let original = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc"),
    )
    .unwrap();
    assert!(
        original.contains(STUD_AT),
        "tm1.ifc changed; pick the stud again"
    );
    let model = dir.path().join("wall.ifc");
    std::fs::write(&model, &original).unwrap();
    let out = dir.path().join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("watch")
        .arg(&model)
        .args(["--json", "--cache"])
        .arg(dir.path().join("cache"))
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let mut child = KillOnDrop(child);
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });

    let ready = next_event(&rx, "ready");
    assert_eq!(ready["cache"]["computed"], 1);
    let first = std::fs::read_to_string(out.join("simulate.json")).unwrap();

    // Save 1: a new file renamed over the model.
    let edited = original.replace(STUD_AT, STUD_MOVED);
    let tmp = dir.path().join("wall.ifc.tmp");
    std::fs::write(&tmp, &edited).unwrap();
    std::fs::rename(&tmp, &model).unwrap();
    let ev = next_event(&rx, "regenerated");
    assert_eq!(ev["cache"]["computed"], 1, "{ev}");
    let moved = ev["changes"]["elements"].as_array().unwrap();
    assert_eq!(moved.len(), 1, "{ev}");
    assert_eq!(moved[0]["id"], STUD);
    assert_eq!(moved[0]["change"], "moved");
    assert_eq!(moved[0]["moved_mm"], 20.0);
    assert!(
        ev["changes"]["verdicts"].is_array(),
        "both results are at hand"
    );
    let second = std::fs::read_to_string(out.join("simulate.json")).unwrap();
    assert_ne!(second, first);

    // Save 2: the original written in place; its wall is in the cache.
    std::fs::write(&model, &original).unwrap();
    let ev = next_event(&rx, "regenerated");
    assert_eq!(ev["cache"]["computed"], 0, "{ev}");
    assert_eq!(ev["cache"]["cached"], 1, "{ev}");
    let third = std::fs::read_to_string(out.join("simulate.json")).unwrap();
    // The same result as the first run, apart from the cache counts.
    assert_eq!(
        third.replace(
            "\"computed\": 0,\n      \"cached\": 1",
            "\"computed\": 1,\n      \"cached\": 0"
        ),
        first
    );

    // Save 3: half a file. The last results stay, and the event says why.
    std::fs::write(&model, &edited[..edited.len() / 2]).unwrap();
    let ev = rx.recv_timeout(Duration::from_secs(120)).unwrap();
    let ev: serde_json::Value = serde_json::from_str(&ev).unwrap();
    assert_eq!(ev["event"], "waiting", "{ev}");
    assert!(!ev["error"].as_str().unwrap().is_empty());
    assert_eq!(
        std::fs::read_to_string(out.join("simulate.json")).unwrap(),
        third
    );

    // Ctrl-C.
    let status = Command::new("kill")
        .args(["-INT", &child.0.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let ev = next_event(&rx, "stopped");
    assert_eq!(ev["event"], "stopped");
    assert!(child.0.wait().unwrap().success());
    let left: Vec<_> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    assert_eq!(
        left.len(),
        2,
        "only the outputs, no temporary files: {left:?}"
    );
}

/// Every file of a report folder by name (the JSON without its cache counts).
fn report_files(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let counts = regex::Regex::new(r#",\n    "cache": \{\n[^}]*\n    \}"#).unwrap();
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            let name = e.file_name().into_string().unwrap();
            let mut bytes = std::fs::read(e.path()).unwrap();
            if name == "simulate.json" {
                let text = String::from_utf8(bytes).unwrap();
                bytes = counts.replace(&text, "").into_owned().into_bytes();
            }
            (name, bytes)
        })
        .collect()
}

/// The report `simulate --report` writes for `model` without a cache.
fn fresh_report(model: &Path, dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("simulate")
        .arg(model)
        .args(["--no-cache", "--report"])
        .arg(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    report_files(dir)
}

#[test]
fn watch_rewrites_the_report_folder_on_every_save() {
    let dir = tempfile::tempdir().unwrap();
    let original = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc"),
    )
    .unwrap();
    let model = dir.path().join("wall.ifc");
    std::fs::write(&model, &original).unwrap();
    let report = dir.path().join("report");
    let child = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .arg("watch")
        .arg(&model)
        .args(["--json", "--cache"])
        .arg(dir.path().join("cache"))
        .arg("--out")
        .arg(dir.path().join("out"))
        .arg("--report")
        .arg(&report)
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut child = KillOnDrop(child);
    let stdout = child.0.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });

    next_event(&rx, "ready");
    let first = report_files(&report);
    assert_eq!(first, fresh_report(&model, &dir.path().join("expected-1")));

    // A save renamed over the model: the report is the edited model's.
    let edited = original.replace(STUD_AT, STUD_MOVED);
    let tmp = dir.path().join("wall.ifc.tmp");
    std::fs::write(&tmp, &edited).unwrap();
    std::fs::rename(&tmp, &model).unwrap();
    next_event(&rx, "regenerated");
    let second = report_files(&report);
    assert_ne!(second["index.html"], first["index.html"]);
    assert_eq!(second, fresh_report(&model, &dir.path().join("expected-2")));

    // The original saved in place: its wall and motion come from the cache, and the report
    // is the first one again.
    std::fs::write(&model, &original).unwrap();
    let ev = next_event(&rx, "regenerated");
    assert_eq!(ev["cache"]["cached"], 1, "{ev}");
    assert_eq!(report_files(&report), first);

    // Half a file: the report stays.
    std::fs::write(&model, &edited[..edited.len() / 2]).unwrap();
    let ev: serde_json::Value =
        serde_json::from_str(&rx.recv_timeout(Duration::from_secs(120)).unwrap()).unwrap();
    assert_eq!(ev["event"], "waiting", "{ev}");
    assert_eq!(report_files(&report), first);

    // Nothing left beside the report folder but the outputs.
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| !n.starts_with("expected-"))
        .collect();
    left.sort();
    assert_eq!(left, ["cache", "out", "report", "wall.ifc"]);
}
