//! `why` on one element of every failure class a simulation produces, model by model and cell
//! by cell (the Constructivity wall and TM3 on both study cells, the 3-storey model on the ABB
//! cell, TM3 with a stud modelled proud of its wall): the element's first cause opens the
//! answer, and the cause `simulate` reported is there with its numbers and where it happened;
//! what it led to is one line per kind; a place pose the arm cannot take and a piece off
//! target come with a checked remedy that has a number (a pose refused for a collision with a
//! remedy or why none); and the whole answer
//! stays under 30 lines. The classes are read from `simulate --json`'s messages by this test's
//! own table, so a class the executor starts to produce is swept too (as `other`).

mod common;

use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use common::framewright_ok as framewright;

/// The class of a failure message (a nail's message after its `PLATE -> MEMBER #k: `).
fn class(message: &str) -> String {
    let with = |body: &str| {
        if body.starts_with("floor") {
            "floor"
        } else if body.starts_with("piece ") {
            "piece"
        } else {
            "fixture"
        }
    };
    if message.contains("beyond reach") || message.contains("out of reach") {
        "beyond_reach".to_string()
    } else if message.contains("joint limit") {
        "joint_limit".to_string()
    } else if let Some((_, b)) = message.split_once(" touched ") {
        format!("contact_{}", with(b))
    } else if let Some((_, b)) = message.split_once("collides: ") {
        let b = b.split_once(" with ").map_or(b, |(_, b)| b);
        format!("collides_{}", with(b))
    } else if message.starts_with("came to rest") {
        "off_target".to_string()
    } else if message.contains("shorter than") {
        "too_short".to_string()
    } else if message.contains("longer than") {
        "too_long".to_string()
    } else if message.contains("toppled") {
        "toppled".to_string()
    } else {
        let words: Vec<&str> = message.split_whitespace().take(3).collect();
        format!("other: {}", words.join(" "))
    }
}

/// One element per class: (stage:class) → (element, the message `simulate` gave).
fn one_per_class(sim: &Value) -> BTreeMap<String, (String, String)> {
    let mut out = BTreeMap::new();
    for e in sim["elements"].as_array().unwrap() {
        for stage in ["framing", "nailing"] {
            for r in e[stage]["reasons"].as_array().unwrap() {
                let message = r["message"].as_str().unwrap();
                // Nails not driven because a piece was not placed are consequences.
                if message.ends_with(" not placed") {
                    continue;
                }
                let body = match stage {
                    "nailing" => message.split_once(": ").map_or(message, |(_, m)| m),
                    _ => message,
                };
                out.entry(format!("{stage}:{}", class(body)))
                    .or_insert_with(|| (e["id"].as_str().unwrap().to_string(), body.to_string()));
            }
        }
    }
    out
}

/// Sweeps `model` on `cell` (with `extra` arguments): every class found is asked about.
fn sweep(model: &Path, cell: &str, extra: &[&str]) -> Vec<String> {
    let cache = tempfile::tempdir().unwrap();
    let cache = cache.path().to_str().unwrap();
    let base = [model.to_str().unwrap(), "--cell", cell, "--cache", cache];
    let args = [&["simulate"][..], &base, extra, &["--json"]].concat();
    let sim: Value = serde_json::from_str(&framewright(&args)).unwrap();
    let classes = one_per_class(&sim);
    assert!(!classes.is_empty(), "{model:?} on {cell}: nothing failed");
    for (class, (id, message)) in &classes {
        let args = [
            &["why"][..],
            &[model.to_str().unwrap(), id.as_str()],
            &base[1..],
            extra,
        ]
        .concat();
        let text = framewright(&args);
        let at = format!("{model:?} on {cell}, {class}, {id}");
        check_answer(&text, class, message, &at);
    }
    classes.into_keys().collect()
}

/// The answer's shape for one element whose root cause `simulate` gave as `message`.
fn check_answer(text: &str, class: &str, message: &str, at: &str) {
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines.len() < 30, "{at}: {} lines\n{text}", lines.len());
    let (stage, kind) = class.split_once(':').unwrap();
    // The cause first: after the simulated wall, the element and its statuses (a plate
    // segment's answer opens with where the plan cut it, two lines).
    let cause = lines
        .iter()
        .position(|l| l.starts_with(&format!("{stage} failed (")) && l.contains(message))
        .unwrap_or_else(|| panic!("{at}: no cause line with `{message}`\n{text}"));
    let simulated = lines
        .iter()
        .position(|l| l.starts_with("simulated "))
        .unwrap_or_else(|| panic!("{at}: no simulated wall\n{text}"));
    assert!(
        simulated <= 3,
        "{at}: simulated on line {}\n{text}",
        simulated + 1
    );
    // The element's first cause (framing before nailing) opens the answer; this class's
    // cause may follow it.
    let first = lines
        .iter()
        .position(|l| l.contains(" failed ("))
        .unwrap_or_else(|| panic!("{at}: no cause\n{text}"));
    assert!(
        first <= simulated + 4 && first <= cause,
        "{at}: the first cause on line {}\n{text}",
        first + 1
    );
    assert!(
        lines[cause].chars().any(|c| c.is_ascii_digit()),
        "{at}: no number in the cause\n{text}"
    );
    // Then where it happened, with its numbers (a piece that toppled on the conveyor says
    // where in its message: the conveyor's end stop).
    let block: Vec<&str> = lines[cause + 1..]
        .iter()
        .take_while(|l| l.starts_with("  "))
        .copied()
        .collect();
    if kind != "toppled" {
        let wheres: Vec<&&str> = block
            .iter()
            .filter(|l| l.starts_with("  where: "))
            .collect();
        assert!(!wheres.is_empty(), "{at}: no where line\n{text}");
        assert!(
            wheres
                .iter()
                .all(|l| l.contains(" m in the") || l.contains(" mm above")),
            "{at}: a where line without its numbers\n{text}"
        );
    }
    // What it led to: one line per kind.
    let mut kinds: Vec<&str> = block
        .iter()
        .filter_map(|l| l.strip_prefix("  so "))
        .map(|l| l.split_once(": ").map_or(l, |(k, _)| k))
        .map(|k| k.trim_start_matches(|c: char| c.is_ascii_digit() || c == ' '))
        .collect();
    let n = kinds.len();
    kinds.sort_unstable();
    kinds.dedup();
    assert_eq!(
        kinds.len(),
        n,
        "{at}: a kind of consequence on two lines\n{text}"
    );
    // A place pose the arm cannot take, a piece off target: a remedy with a number, checked.
    if stage == "framing" && ["beyond_reach", "joint_limit", "off_target"].contains(&kind) {
        assert!(
            block.iter().any(|l| l.starts_with("  would pass: ")
                && l.chars().any(|c| c.is_ascii_digit())
                && l.contains("; checked by ")),
            "{at}: no checked remedy with a number\n{text}"
        );
    }
    // A place pose refused otherwise: a remedy, or what was (not) searched.
    if stage == "framing" && kind.starts_with("collides_") {
        assert!(
            block
                .iter()
                .any(|l| l.starts_with("  would pass: ") || l.starts_with("  no remedy: ")),
            "{at}: neither a remedy nor why none\n{text}"
        );
    }
    // One derivation tree, not one per verdict.
    let trees = lines
        .iter()
        .filter(|l| l.starts_with("element_reason("))
        .count();
    assert!(trees <= 1, "{at}: {trees} trees without --verbose\n{text}");
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/models")
        .join(name)
}

#[test]
fn the_classes_of_tm3_on_both_study_cells() {
    for cell in ["study-abb", "study-kuka"] {
        let classes = sweep(&example("tm3.ifc"), cell, &[]);
        // The study's finding: the plates beyond reach (STUDY-FACTS, Table 5).
        assert!(
            classes.contains(&"framing:beyond_reach".to_string()),
            "{classes:?}"
        );
    }
}

#[test]
fn the_classes_of_the_constructivity_wall_on_both_study_cells() {
    let Some(model) =
        common::shared_path("ifc-realworld/timber_constructivity_wall-elemented-case_IFC4.ifc")
    else {
        return;
    };
    for cell in ["study-abb", "study-kuka"] {
        let classes = sweep(&model, cell, &[]);
        eprintln!("Constructivity on {cell}: {classes:?}");
    }
}

#[test]
fn the_classes_of_the_three_storey_model_on_the_abb_cell() {
    let Some(model) = common::shared_path("ifc-testcases/g_scale_3storey.ifc") else {
        return;
    };
    let classes = sweep(&model, "study-abb", &[]);
    eprintln!("3-storey on study-abb: {classes:?}");
    assert!(classes.len() >= 3, "{classes:?}");
}

#[test]
fn a_stud_modelled_proud_of_its_wall_comes_to_rest_off_target() {
    let dir = tempfile::tempdir().unwrap();
    let model = common::ifc_edit::tm3_stud_moved(dir.path(), 0.020);
    // At offset_x 0.742 the arm reaches the stud: what fails is where it comes to rest.
    let classes = sweep(&model, "study-abb", &["--offset-x", "0.742"]);
    assert!(
        classes.contains(&"framing:off_target".to_string()),
        "{classes:?}"
    );
}
