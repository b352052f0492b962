//! The per-wall cache on the command line: a cached run prints the bytes an uncached run
//! prints (apart from the `sim.cache` counts), an edit to one wall simulates that wall only,
//! and faults (torn or corrupt entries, two processes at once, a folder that cannot be
//! written) still give the right answer.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn model(name: &str) -> PathBuf {
    root().join("examples/models").join(name)
}

fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .unwrap()
}

fn ok(args: &[&str]) -> String {
    let out = run(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn simulate_json(model: &Path, cache: Option<&Path>) -> String {
    let m = model.to_str().unwrap();
    match cache {
        Some(dir) => ok(&["simulate", m, "--json", "--cache", dir.to_str().unwrap()]),
        None => ok(&["simulate", m, "--json", "--no-cache"]),
    }
}

/// (computed, cached, rejected) of a cached run's JSON.
fn counts(json: &str) -> (u64, u64, u64) {
    let v: serde_json::Value = serde_json::from_str(json).unwrap();
    let c = &v["sim"]["cache"];
    (
        c["computed"].as_u64().unwrap(),
        c["cached"].as_u64().unwrap(),
        c["rejected"].as_u64().unwrap(),
    )
}

/// The JSON without the `sim.cache` block (the only part a cache may change).
fn without_counts(json: &str) -> String {
    let block = regex::Regex::new(r#",\n    "cache": \{\n[^}]*\n    \}"#).unwrap();
    assert_eq!(
        block.find_iter(json).count(),
        1,
        "one sim.cache block in\n{json}"
    );
    block.replace(json, "").into_owned()
}

/// TM3 (4 walls) simulated without a cache, and a cache folder filled by a first run.
struct Tm3 {
    reference: String,
    warm: tempfile::TempDir,
}

fn tm3() -> &'static Tm3 {
    static TM3: OnceLock<Tm3> = OnceLock::new();
    TM3.get_or_init(|| {
        let reference = simulate_json(&model("tm3.ifc"), None);
        assert!(
            !reference.contains("\"cache\""),
            "--no-cache prints no counts"
        );
        let warm = tempfile::tempdir().unwrap();
        let cold = simulate_json(&model("tm3.ifc"), Some(warm.path()));
        assert_eq!(counts(&cold), (4, 0, 0));
        assert_eq!(without_counts(&cold), reference);
        Tm3 { reference, warm }
    })
}

/// A copy of the warm cache folder, for a test to change.
fn copy_of_warm() -> tempfile::TempDir {
    let to = tempfile::tempdir().unwrap();
    copy_dir(tm3().warm.path(), to.path());
    to
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        let target = to.join(e.file_name());
        if e.file_type().unwrap().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).unwrap();
        }
    }
}

/// The wall entries of a cache folder, sorted.
fn entries(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for sub in std::fs::read_dir(dir.join("walls")).unwrap() {
        for e in std::fs::read_dir(sub.unwrap().path()).unwrap() {
            files.push(e.unwrap().path());
        }
    }
    files.sort();
    files
}

#[test]
fn a_warm_run_reads_every_wall_and_prints_the_uncached_bytes() {
    let t = tm3();
    let warm = simulate_json(&model("tm3.ifc"), Some(t.warm.path()));
    assert_eq!(counts(&warm), (0, 4, 0));
    assert_eq!(without_counts(&warm), t.reference);
    // The text report has no counts at all.
    let m = model("tm3.ifc");
    let m = m.to_str().unwrap();
    assert_eq!(
        ok(&["simulate", m, "--cache", t.warm.path().to_str().unwrap()]),
        ok(&["simulate", m, "--no-cache"])
    );
}

/// TM3 with stud F-003 (`3TLsQVRMRPdj7_IjoyfN1U`, wall 1, along x) moved 20 mm along its wall.
fn tm3_with_a_moved_stud(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(model("tm3.ifc")).unwrap();
    let from = "#55=IFCCARTESIANPOINT((6.0452,0.04445,0.0381));";
    assert!(text.contains(from), "tm3.ifc changed; pick the stud again");
    assert!(text.contains("#56=IFCAXIS2PLACEMENT3D(#55,"));
    assert!(
        text.contains("IFCCOLUMN('3TLsQVRMRPdj7_IjoyfN1U',#5,'2x4 stud F-003',$,'2x4 SPF',#50,")
    );
    let moved = text.replace(from, "#55=IFCCARTESIANPOINT((6.0652,0.04445,0.0381));");
    let path = dir.join("tm3-moved.ifc");
    std::fs::write(&path, moved).unwrap();
    path
}

#[test]
fn moving_one_stud_simulates_its_wall_only_and_matches_an_uncached_run() {
    let cache = copy_of_warm();
    let dir = tempfile::tempdir().unwrap();
    let moved = tm3_with_a_moved_stud(dir.path());
    let cached = simulate_json(&moved, Some(cache.path()));
    assert_eq!(counts(&cached), (1, 3, 0));
    let uncached = simulate_json(&moved, None);
    assert_eq!(without_counts(&cached), uncached);
    assert_ne!(
        uncached,
        tm3().reference,
        "the moved stud changes the result"
    );
}

#[test]
fn torn_and_corrupt_entries_are_simulated_again() {
    let cache = copy_of_warm();
    let files = entries(cache.path());
    assert_eq!(files.len(), 4);
    // A torn write: the first half of an entry.
    let whole = std::fs::read(&files[0]).unwrap();
    std::fs::write(&files[0], &whole[..whole.len() / 2]).unwrap();
    // Valid JSON whose record was changed: the digest no longer matches.
    let text = std::fs::read_to_string(&files[1]).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    let steps = v["record"]["steps"].as_u64().unwrap();
    v["record"]["steps"] = (steps + 1).into();
    std::fs::write(&files[1], v.to_string()).unwrap();
    // An entry of another wall under this wall's name.
    std::fs::copy(&files[3], &files[2]).unwrap();

    let json = simulate_json(&model("tm3.ifc"), Some(cache.path()));
    assert_eq!(counts(&json), (3, 1, 3));
    assert_eq!(without_counts(&json), tm3().reference);
    // The bad entries were written again.
    let again = simulate_json(&model("tm3.ifc"), Some(cache.path()));
    assert_eq!(counts(&again), (0, 4, 0));
}

#[test]
fn two_processes_sharing_one_cache_both_get_the_right_answer() {
    let cache = tempfile::tempdir().unwrap();
    let m = model("tm3.ifc");
    let spawn = || {
        Command::new(env!("CARGO_BIN_EXE_framewright"))
            .args(["simulate", m.to_str().unwrap(), "--json", "--cache"])
            .arg(cache.path())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (a, b) = (spawn(), spawn());
    for child in [a, b] {
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success());
        let json = String::from_utf8(out.stdout).unwrap();
        assert_eq!(without_counts(&json), tm3().reference);
    }
    assert_eq!(entries(cache.path()).len(), 4, "no temporary files left");
    let after = simulate_json(&m, Some(cache.path()));
    assert_eq!(counts(&after), (0, 4, 0));
    assert_eq!(without_counts(&after), tm3().reference);
}

#[test]
fn a_cache_folder_that_cannot_be_written_warns_once_and_answers_right() {
    let dir = tempfile::tempdir().unwrap();
    // A folder inside a regular file cannot be created, whoever runs the test.
    let blocker = dir.path().join("not-a-folder");
    std::fs::write(&blocker, "x").unwrap();
    let cache = blocker.join("cache");
    let m = model("tm3.ifc");
    let out = run(&[
        "simulate",
        m.to_str().unwrap(),
        "--json",
        "--cache",
        cache.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert_eq!(
        stderr
            .matches("warning: cannot write to the cache folder")
            .count(),
        1,
        "{stderr}"
    );
    let json = String::from_utf8(out.stdout).unwrap();
    assert_eq!(counts(&json), (4, 0, 0));
    assert_eq!(without_counts(&json), tm3().reference);
}

#[test]
fn cache_info_counts_and_clear_removes_only_entries() {
    let cache = copy_of_warm();
    let c = cache.path().to_str().unwrap();
    let info: serde_json::Value =
        serde_json::from_str(&ok(&["cache", "info", "--cache", c, "--json"])).unwrap();
    assert_eq!(info["walls"], 4);
    assert!(info["bytes"].as_u64().unwrap() > 0);
    std::fs::write(cache.path().join("notes.txt"), "mine").unwrap();
    assert!(ok(&["cache", "clear", "--cache", c]).starts_with("removed 4 entries"));
    let info: serde_json::Value =
        serde_json::from_str(&ok(&["cache", "info", "--cache", c, "--json"])).unwrap();
    assert_eq!(info["walls"], 0);
    assert_eq!(info["bytes"], 0);
    assert!(
        cache.path().join("notes.txt").exists(),
        "a user's file stays"
    );
    // A cleared cache fills again.
    let json = simulate_json(&model("tm1.ifc"), Some(cache.path()));
    assert_eq!(counts(&json), (1, 0, 0));
}
