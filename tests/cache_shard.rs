//! `simulate --shard K/N`: the shards split the walls between them, fill one cache, and a
//! plain run afterwards assembles the result every wall of which comes from the cache,
//! byte for byte the result of one uncached run (apart from the `sim.cache` counts).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_framewright")
}

fn run(args: &[&str]) -> Output {
    Command::new(bin()).args(args).output().unwrap()
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

fn without_counts(json: &str) -> String {
    let block = regex::Regex::new(r#",\n    "cache": \{\n[^}]*\n    \}"#).unwrap();
    assert_eq!(block.find_iter(json).count(), 1, "one sim.cache block");
    block.replace(json, "").into_owned()
}

fn cached(json: &str) -> (u64, u64) {
    let v: serde_json::Value = serde_json::from_str(json).unwrap();
    (
        v["sim"]["cache"]["computed"].as_u64().unwrap(),
        v["sim"]["cache"]["cached"].as_u64().unwrap(),
    )
}

/// Runs N shards one after another, checks they split the walls, then assembles.
fn shards_then_assemble(model: &Path, n: u64) {
    let m = model.to_str().unwrap();
    let reference = ok(&["simulate", m, "--json", "--no-cache"]);
    let cache = tempfile::tempdir().unwrap();
    let c = cache.path().to_str().unwrap();
    let mut walls: Vec<String> = Vec::new();
    for k in 1..=n {
        let shard = format!("{k}/{n}");
        let v: serde_json::Value = serde_json::from_str(&ok(&[
            "simulate", m, "--cache", c, "--shard", &shard, "--json",
        ]))
        .unwrap();
        assert_eq!(v["shard"], shard.as_str());
        let mine: Vec<String> = v["walls"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w.as_str().unwrap().to_string())
            .collect();
        assert_eq!(
            v["cache"]["computed"].as_u64().unwrap() as usize,
            mine.len()
        );
        walls.extend(mine);
    }
    let all: serde_json::Value = serde_json::from_str(&reference).unwrap();
    let mut expected: Vec<String> = all["walls"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["wall_id"].as_str().unwrap().to_string())
        .collect();
    walls.sort();
    expected.sort();
    assert_eq!(walls, expected, "every wall in exactly one shard");
    let assembled = ok(&["simulate", m, "--json", "--cache", c]);
    assert_eq!(cached(&assembled), (0, expected.len() as u64));
    assert_eq!(without_counts(&assembled), reference);
}

#[test]
fn three_shards_of_tm3_assemble_to_one_full_run() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc");
    shards_then_assemble(&model, 3);
}

/// A generated model of two buildings (8 walls, two spatial containers).
fn generated_model(dir: &Path) -> PathBuf {
    let path = dir.join("grid.ifc");
    ok(&[
        "synth",
        "building",
        "--grid",
        "2x1",
        "--length",
        "2.4m",
        "--depth",
        "2.4m",
        "--no-openings",
        "-o",
        path.to_str().unwrap(),
    ]);
    path
}

#[test]
fn three_shards_of_a_generated_two_building_model_assemble_to_one_full_run() {
    let dir = tempfile::tempdir().unwrap();
    shards_then_assemble(&generated_model(dir.path()), 3);
}

/// A generated block of two storeys, one unit each (8 walls over two levels).
fn generated_block(dir: &Path) -> PathBuf {
    let path = common::synth_block(dir, &["--blocks", "1", "--storeys", "2", "--grid", "1x1"]);
    let plan: serde_json::Value =
        serde_json::from_str(&ok(&["plan", path.to_str().unwrap(), "--json"])).unwrap();
    let walls = plan["walls"].as_array().unwrap();
    assert!(walls.len() >= 6, "{} walls", walls.len());
    path
}

#[test]
fn three_shards_of_a_generated_two_storey_block_assemble_to_one_full_run() {
    let dir = tempfile::tempdir().unwrap();
    shards_then_assemble(&generated_block(dir.path()), 3);
}

#[test]
fn a_shard_is_checked() {
    let m = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc");
    let m = m.to_str().unwrap();
    for bad in ["0/3", "4/3", "x"] {
        let out = run(&["simulate", m, "--shard", bad, "--cache", "/tmp"]);
        assert_eq!(out.status.code(), Some(2), "{bad}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("K/N"));
    }
}

#[test]
fn the_gnu_parallel_example_script_assembles_the_full_result() {
    if Command::new("parallel").arg("--version").output().is_err() {
        common::skip::missing_tool("GNU parallel", "apt-get install parallel");
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let model = root.join("examples/models/tm3.ifc");
    let m = model.to_str().unwrap();
    let reference = ok(&["simulate", m, "--json", "--no-cache"]);
    let cache = tempfile::tempdir().unwrap();
    let out = Command::new(root.join("examples/shards/parallel.sh"))
        .args([m, "3", cache.path().to_str().unwrap(), "--json"])
        .env("FRAMEWRIGHT", bin())
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json = String::from_utf8(out.stdout).unwrap();
    assert_eq!(cached(&json), (0, 4));
    assert_eq!(without_counts(&json), reference);
}
