//! `plan` through the cache on the command line: cached runs print the bytes an uncached run
//! prints (apart from the `cache` counts), an edit to one wall reasons that wall only, and
//! faults (torn or altered entries, two processes at once, a folder that cannot be written)
//! still give the right answer.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::OnceLock;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
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

fn plan_json(model: &Path, cache: Option<&Path>) -> String {
    let m = model.to_str().unwrap();
    match cache {
        Some(dir) => ok(&["plan", m, "--json", "--cache", dir.to_str().unwrap()]),
        None => ok(&["plan", m, "--json", "--no-cache"]),
    }
}

/// (computed, cached, rejected) walls of a cached run's JSON.
fn counts(json: &str) -> (u64, u64, u64) {
    let v: serde_json::Value = serde_json::from_str(json).unwrap();
    let c = &v["cache"];
    (
        c["computed"].as_u64().unwrap(),
        c["cached"].as_u64().unwrap(),
        c["rejected"].as_u64().unwrap(),
    )
}

/// The JSON without its `cache` block (the only part a cache may change).
fn without_counts(json: &str) -> String {
    let block = regex::Regex::new(r#",\n  "cache": \{\n[^}]*\n  \}"#).unwrap();
    assert_eq!(
        block.find_iter(json).count(),
        1,
        "one cache block in the plan"
    );
    block.replace(json, "").into_owned()
}

/// Two storeys of a block of two units, walls grouped in IfcWall, doors and windows.
struct Block {
    _dir: tempfile::TempDir,
    model: PathBuf,
    reference: String,
    walls: u64,
}

fn block() -> &'static Block {
    static BLOCK: OnceLock<Block> = OnceLock::new();
    BLOCK.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("block.ifc");
        ok(&[
            "synth",
            "block",
            "--blocks",
            "1",
            "--storeys",
            "2",
            "--grid",
            "1x2",
            "--grouping",
            "wall",
            "--openings",
            "--psets",
            "-o",
            model.to_str().unwrap(),
        ]);
        let reference = plan_json(&model, None);
        assert!(
            !reference.contains("\"cache\""),
            "--no-cache prints no counts"
        );
        let v: serde_json::Value = serde_json::from_str(&reference).unwrap();
        let walls = v["walls"].as_array().unwrap().len() as u64;
        assert!(walls >= 16, "{walls} walls");
        Block {
            _dir: dir,
            model,
            reference,
            walls,
        }
    })
}

/// A cache folder filled by a first run on the block model.
fn warm_cache() -> tempfile::TempDir {
    let b = block();
    let dir = tempfile::tempdir().unwrap();
    let cold = plan_json(&b.model, Some(dir.path()));
    assert_eq!(counts(&cold), (b.walls, 0, 0));
    assert_eq!(without_counts(&cold), b.reference);
    dir
}

/// The part entries of a cache folder, sorted.
fn entries(dir: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for sub in std::fs::read_dir(dir.join("plans")).unwrap() {
        for e in std::fs::read_dir(sub.unwrap().path()).unwrap() {
            files.push(e.unwrap().path());
        }
    }
    files.sort();
    files
}

#[test]
fn cached_plans_print_the_uncached_bytes_and_count_walls() {
    let b = block();
    let cache = warm_cache();
    let warm = plan_json(&b.model, Some(cache.path()));
    assert_eq!(counts(&warm), (0, b.walls, 0));
    assert_eq!(without_counts(&warm), b.reference);
    // The text report has no counts at all.
    let m = b.model.to_str().unwrap();
    let c = cache.path().to_str().unwrap();
    assert_eq!(
        ok(&["plan", m, "--cache", c]),
        ok(&["plan", m, "--no-cache"])
    );
    // The study's model and a cell with a fixed placement (no placement search).
    let tm3 = root().join("examples/models/tm3.ifc");
    let t = tm3.to_str().unwrap();
    for extra in [&[][..], &["--offset-x", "0.531"][..]] {
        let uncached = ok(&[&["plan", t, "--json", "--no-cache"][..], extra].concat());
        for expect in [(4, 0, 0), (0, 4, 0)] {
            let cached = ok(&[&["plan", t, "--json", "--cache", c][..], extra].concat());
            assert_eq!(counts(&cached), expect, "{extra:?}");
            assert_eq!(without_counts(&cached), uncached);
        }
    }
}

/// The block model with the middle stud of one wall moved 20 mm along the wall: studs are
/// placed in their wall's frame, x along the wall.
fn block_with_a_moved_stud(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(&block().model).unwrap();
    let lines: BTreeMap<&str, &str> = text
        .lines()
        .filter_map(|l| l.split_once('='))
        .filter(|(id, _)| id.starts_with('#'))
        .collect();
    let inside = |id: &str| {
        let body = lines[id.trim()];
        body[body.find('(').unwrap() + 1..body.rfind(')').unwrap()].to_string()
    };
    // Stud placement points by the placement they are relative to (their wall's).
    let mut by_wall: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for body in lines.values() {
        if body.starts_with("IFCMEMBER(") && body.contains(".STUD.") {
            let placement = body.split(',').nth(5).unwrap().to_string();
            let local = inside(&placement);
            let (relative_to, axis) = local.split_once(',').unwrap();
            let point = inside(axis).split(',').next().unwrap().trim().to_string();
            by_wall
                .entry(relative_to.trim().to_string())
                .or_default()
                .push(point);
        }
    }
    let studs = by_wall.values().max_by_key(|s| s.len()).unwrap();
    let point = &studs[studs.len() / 2];
    let old = format!("{point}={}", lines[point.as_str()]);
    let xyz: Vec<f64> = inside(point)
        .trim_matches(|c| c == '(' || c == ')')
        .split(',')
        .map(|c| c.trim().parse().unwrap())
        .collect();
    let new = format!(
        "{point}=IFCCARTESIANPOINT(({:?},{:?},{:?}));",
        xyz[0] + 0.02,
        xyz[1],
        xyz[2]
    );
    assert_eq!(text.matches(&old).count(), 1);
    let path = dir.join("block-moved.ifc");
    std::fs::write(&path, text.replacen(&old, &new, 1)).unwrap();
    path
}

#[test]
fn moving_one_stud_reasons_its_wall_only_and_matches_an_uncached_run() {
    let b = block();
    let cache = warm_cache();
    let dir = tempfile::tempdir().unwrap();
    let moved = block_with_a_moved_stud(dir.path());
    let cached = plan_json(&moved, Some(cache.path()));
    assert_eq!(counts(&cached), (1, b.walls - 1, 0));
    let uncached = plan_json(&moved, None);
    assert_eq!(without_counts(&cached), uncached);
    assert_ne!(uncached, b.reference, "the moved stud changes the plan");
}

#[test]
fn torn_altered_and_foreign_entries_are_reasoned_again() {
    let b = block();
    let cache = warm_cache();
    let files = entries(cache.path());
    assert!(files.len() as u64 >= b.walls, "{} entries", files.len());
    // A torn write, one altered byte, and another part's entry under this part's name.
    let whole = std::fs::read(&files[0]).unwrap();
    std::fs::write(&files[0], &whole[..whole.len() / 2]).unwrap();
    let mut altered = std::fs::read(&files[1]).unwrap();
    let middle = altered.len() / 2;
    altered[middle] ^= 0x20;
    std::fs::write(&files[1], altered).unwrap();
    std::fs::copy(&files[3], &files[2]).unwrap();

    let json = plan_json(&b.model, Some(cache.path()));
    let (computed, cached, rejected) = counts(&json);
    assert!(computed >= 3 && rejected == computed, "{:?}", counts(&json));
    assert_eq!(computed + cached, b.walls);
    assert_eq!(without_counts(&json), b.reference);
    let again = plan_json(&b.model, Some(cache.path()));
    assert_eq!(
        counts(&again),
        (0, b.walls, 0),
        "the bad entries were written again"
    );
}

#[test]
fn two_processes_sharing_one_cache_both_get_the_right_answer() {
    let b = block();
    let cache = tempfile::tempdir().unwrap();
    let spawn = || {
        Command::new(env!("CARGO_BIN_EXE_framewright"))
            .args(["plan", b.model.to_str().unwrap(), "--json", "--cache"])
            .arg(cache.path())
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap()
    };
    let (one, two) = (spawn(), spawn());
    for child in [one, two] {
        let out = child.wait_with_output().unwrap();
        assert!(out.status.success());
        assert_eq!(
            without_counts(&String::from_utf8(out.stdout).unwrap()),
            b.reference
        );
    }
    let names: Vec<String> = entries(cache.path())
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.iter().all(|n| n.ends_with(".part")),
        "no temporary files left"
    );
    let after = plan_json(&b.model, Some(cache.path()));
    assert_eq!(counts(&after), (0, b.walls, 0));
}

#[test]
fn a_cache_folder_that_cannot_be_written_warns_once_and_answers_right() {
    let b = block();
    let dir = tempfile::tempdir().unwrap();
    // A folder inside a regular file cannot be created, whoever runs the test.
    let blocker = dir.path().join("not-a-folder");
    std::fs::write(&blocker, "x").unwrap();
    let cache = blocker.join("cache");
    let out = run(&[
        "plan",
        b.model.to_str().unwrap(),
        "--json",
        "--cache",
        cache.to_str().unwrap(),
    ]);
    assert!(out.status.success());
    let stderr = String::from_utf8(out.stderr).unwrap();
    let warnings = stderr
        .matches("warning: cannot write to the cache folder")
        .count();
    assert_eq!(warnings, 1, "{stderr}");
    let json = String::from_utf8(out.stdout).unwrap();
    assert_eq!(counts(&json), (b.walls, 0, 0));
    assert_eq!(without_counts(&json), b.reference);
}

#[test]
fn a_rules_directory_plans_without_the_cache_and_info_and_clear_see_plan_entries() {
    let b = block();
    let cache = warm_cache();
    let c = cache.path().to_str().unwrap();
    let rules = root().join("rules");
    let m = b.model.to_str().unwrap();
    let with_dir = ok(&[
        "plan",
        m,
        "--json",
        "--cache",
        c,
        "--rules-dir",
        rules.to_str().unwrap(),
    ]);
    assert!(
        !with_dir.contains("\"cache\""),
        "user rule bases are not cached"
    );
    let info: serde_json::Value =
        serde_json::from_str(&ok(&["cache", "info", "--cache", c, "--json"])).unwrap();
    let parts = info["plan_parts"].as_u64().unwrap();
    assert!(parts >= b.walls, "{info}");
    let cleared = ok(&["cache", "clear", "--cache", c]);
    assert!(
        cleared.starts_with(&format!("removed {parts} entries")),
        "{cleared}"
    );
    let info: serde_json::Value =
        serde_json::from_str(&ok(&["cache", "info", "--cache", c, "--json"])).unwrap();
    assert_eq!(
        (info["plan_parts"].as_u64(), info["bytes"].as_u64()),
        (Some(0), Some(0))
    );
    assert_eq!(
        std::fs::read_dir(cache.path()).unwrap().count(),
        0,
        "nothing left"
    );
}
