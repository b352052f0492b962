//! `simulate --report` through the cache: the report animates every wall from its pose trace,
//! so a wall whose trace the cache lacks is simulated again and its trace stored; a warm run
//! writes the report an uncached run writes, byte for byte (the JSON apart from the
//! `sim.cache` counts), and a damaged trace entry is recomputed, never drawn wrong.

use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

fn framewright(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Every file of a report folder by name.
fn files(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().into_string().unwrap(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect()
}

/// (computed, cached, rejected) of a run's JSON.
fn counts(json: &str) -> (u64, u64, u64) {
    let v: serde_json::Value = serde_json::from_str(json).unwrap();
    let c = &v["sim"]["cache"];
    let n = |k: &str| c[k].as_u64().unwrap();
    (n("computed"), n("cached"), n("rejected"))
}

/// The JSON without the `sim.cache` block.
fn without_counts(json: &[u8]) -> String {
    let json = std::str::from_utf8(json).unwrap();
    let block = regex::Regex::new(r#",\n    "cache": \{\n[^}]*\n    \}"#).unwrap();
    assert_eq!(block.find_iter(json).count(), 1, "one sim.cache block");
    block.replace(json, "").into_owned()
}

/// The report of a cached run equals the uncached one: every file byte for byte, the JSON
/// apart from its cache counts.
fn assert_same_report(uncached: &BTreeMap<String, Vec<u8>>, cached: &BTreeMap<String, Vec<u8>>) {
    assert_eq!(
        uncached.keys().collect::<Vec<_>>(),
        cached.keys().collect::<Vec<_>>()
    );
    for (name, bytes) in uncached {
        if name == "simulate.json" {
            assert_eq!(
                without_counts(&cached[name]),
                String::from_utf8(bytes.clone()).unwrap()
            );
        } else {
            assert!(
                &cached[name] == bytes,
                "{name} differs from the uncached run"
            );
        }
    }
}

/// The trace entries of a cache folder, sorted.
fn traces(cache: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for sub in std::fs::read_dir(cache.join("walls")).unwrap() {
        for e in std::fs::read_dir(sub.unwrap().path()).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "trace") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn a_report_from_the_cache_equals_the_uncached_report() {
    let model = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc");
    let m = model.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let d = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    let cache = d("cache");

    framewright(&["simulate", m, "--no-cache", "--report", &d("plain")]);
    let reference = files(&dir.path().join("plain"));
    assert!(reference.len() >= 3, "{:?}", reference.keys());

    // A run without a report stores records only: the report's run simulates again for the
    // traces, and stores them.
    framewright(&["simulate", m, "--json", "--cache", &cache]);
    assert!(traces(Path::new(&cache)).is_empty());
    let json = framewright(&[
        "simulate",
        m,
        "--json",
        "--cache",
        &cache,
        "--report",
        &d("a"),
    ]);
    assert_eq!(counts(&json), (4, 0, 0));
    assert_eq!(traces(Path::new(&cache)).len(), 4);
    assert_same_report(&reference, &files(&dir.path().join("a")));

    // Warm: every wall and its motion from the cache, the same report.
    let json = framewright(&[
        "simulate",
        m,
        "--json",
        "--cache",
        &cache,
        "--report",
        &d("b"),
    ]);
    assert_eq!(counts(&json), (0, 4, 0));
    assert_same_report(&reference, &files(&dir.path().join("b")));

    // A torn trace entry and an altered one: those walls are simulated again, the report
    // is still the same.
    let entries = traces(Path::new(&cache));
    let bytes = std::fs::read(&entries[0]).unwrap();
    std::fs::write(&entries[0], &bytes[..bytes.len() / 2]).unwrap();
    let mut bytes = std::fs::read(&entries[1]).unwrap();
    let last = bytes.len() - 3;
    bytes[last] ^= 0x55;
    std::fs::write(&entries[1], &bytes).unwrap();
    let json = framewright(&[
        "simulate",
        m,
        "--json",
        "--cache",
        &cache,
        "--report",
        &d("c"),
    ]);
    assert_eq!(counts(&json), (2, 2, 0));
    assert_same_report(&reference, &files(&dir.path().join("c")));

    // Rewriting a report folder in place leaves nothing beside it.
    framewright(&["simulate", m, "--cache", &cache, "--report", &d("c")]);
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    left.sort();
    assert_eq!(left, ["a", "b", "c", "cache", "plain"]);
}
