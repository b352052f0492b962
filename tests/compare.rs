//! `framewright compare`: the bid table's figures recomputed from each cell's own `simulate
//! --json` and `plan --json` (counts, times, metres, the rate), its failure classes against the
//! rules' reasons, the cache shared with `simulate`, the page in a browser, bad input.

mod common;

use common::browser::{browse, chromium, console_errors};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn framewright(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(args)
        .output()
        .expect("framewright runs")
}

fn json_of(args: &[&str]) -> Value {
    let out = framewright(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("JSON")
}

fn example(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/models")
        .join(name)
}

fn num(v: &Value) -> f64 {
    v.as_f64().expect("a number")
}

/// The nailing tolerance of rules/verdicts.dl (`nailing_tolerance`), mm.
const NAILING_TOLERANCE_MM: f64 = 5.0;

/// One cell's figures recomputed from `simulate --json` and `plan --json`.
struct Expected {
    pieces: usize,
    framed: usize,
    nails: usize,
    driven: usize,
    framing_s: f64,
    nailing_s: f64,
    wall_metres: f64,
    complete_panels: usize,
    metres_per_hour: Option<f64>,
}

fn expected(sim: &Value, plan: &Value) -> Expected {
    let elements = sim["elements"].as_array().unwrap();
    let targets = sim["nailing_validation"]["targets"].as_array().unwrap();
    let length_of = |panel_id: &str| -> f64 {
        plan["walls"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|w| w["panels"].as_array().unwrap())
            .find(|p| p["panel_id"] == panel_id)
            .map(|p| num(&p["length"]))
            .unwrap_or_else(|| panic!("plan has panel {panel_id}"))
    };
    let panels = sim["panels"].as_array().unwrap();
    let time = |p: &Value, stage: &str| num(&p[stage]["time_s"]);
    let complete: Vec<&Value> = panels
        .iter()
        .filter(|p| p["framing"]["status"] == "Completed" && p["nailing"]["status"] == "Completed")
        .collect();
    let complete_metres: f64 = complete
        .iter()
        .map(|p| length_of(p["panel_id"].as_str().unwrap()))
        .sum();
    let complete_time: f64 = complete
        .iter()
        .map(|p| time(p, "framing") + time(p, "nailing"))
        .sum();
    Expected {
        pieces: elements.len(),
        framed: elements
            .iter()
            .filter(|e| e["framing"]["status"] == "framed")
            .count(),
        nails: targets.len(),
        driven: targets
            .iter()
            .filter(|t| {
                t["status"] == "fired"
                    && t["member_inside"] == true
                    && num(&t["error_mm"]) <= NAILING_TOLERANCE_MM
            })
            .count(),
        framing_s: panels.iter().map(|p| time(p, "framing")).sum(),
        nailing_s: panels.iter().map(|p| time(p, "nailing")).sum(),
        wall_metres: panels
            .iter()
            .map(|p| length_of(p["panel_id"].as_str().unwrap()))
            .sum(),
        complete_panels: complete.len(),
        metres_per_hour: (complete_time > 0.0).then(|| complete_metres / complete_time * 3600.0),
    }
}

/// Words the rules' reason for a piece's failure holds for each class the bid counts it in.
fn reason_words(cause: &str) -> &'static [&'static str] {
    match cause {
        "beyond_reach" => &["beyond reach"],
        "joint_limit" => &["limit"],
        "collision_with_fixture"
        | "collision_with_piece"
        | "collision_with_floor"
        | "collision_with_robot" => &["collide", "touched", "blocked"],
        "shorter_than_gripper_spacing" => &["shorter than the gripper spacing"],
        "too_long_for_conveyors" => &["cannot carry it"],
        "off_target" => &["came to rest"],
        _ => &[],
    }
}

/// The bid of `cell` (from `compare --json`) against that cell's own runs.
fn assert_bid_matches_simulate(bid: &Value, model: &Path, cache: &Path) {
    let cell = bid["cell"].as_str().unwrap();
    let m = model.to_str().unwrap();
    let c = cache.to_str().unwrap();
    let sim = json_of(&["simulate", m, "--cell", cell, "--json", "--cache", c]);
    // compare simulated every wall into the cache: this run finds them all there.
    let counts = &sim["sim"]["cache"];
    assert_eq!(counts["computed"], 0, "{cell}: {counts}");
    assert!(counts["cached"].as_u64() > Some(0), "{cell}: {counts}");
    let plan = json_of(&["plan", m, "--cell", cell, "--json", "--no-cache"]);
    let e = expected(&sim, &plan);
    let close = |a: f64, b: f64, what: &str| {
        assert!((a - b).abs() < 1e-5, "{cell} {what}: bid {a}, expected {b}")
    };
    assert_eq!(bid["pieces"]["planned"], e.pieces, "{cell}");
    assert_eq!(bid["pieces"]["done"], e.framed, "{cell}");
    assert_eq!(bid["pieces"]["failed"], e.pieces - e.framed, "{cell}");
    assert_eq!(bid["nails"]["planned"], e.nails, "{cell}");
    assert_eq!(bid["nails"]["done"], e.driven, "{cell}");
    close(num(&bid["framing_s"]), e.framing_s, "framing");
    close(num(&bid["nailing_s"]), e.nailing_s, "nailing");
    close(num(&bid["total_s"]), e.framing_s + e.nailing_s, "total");
    close(num(&bid["wall_metres"]), e.wall_metres, "metres");
    assert_eq!(bid["complete_panels"], e.complete_panels, "{cell}");
    match (bid["metres_per_hour"].as_f64(), e.metres_per_hour) {
        (Some(a), Some(b)) => close(a, b, "metres per hour"),
        (None, None) => {}
        (a, b) => panic!("{cell}: metres per hour {a:?}, expected {b:?}"),
    }
    // The classes account for every failure, and each failed piece's class agrees with the
    // reason the rules gave it.
    for what in ["pieces", "nails"] {
        let t = &bid[what];
        let by: u64 = t["by_cause"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c["count"].as_u64().unwrap())
            .sum();
        assert_eq!(by, t["failed"].as_u64().unwrap(), "{cell} {what}");
    }
    for c in bid["pieces"]["by_cause"].as_array().unwrap() {
        let cause = c["cause"].as_str().unwrap();
        assert_ne!(
            cause, "decided_by_rule",
            "{cell}: the built-in rules' failures all have a class"
        );
        let words = reason_words(cause);
        for id in c["ids"].as_array().unwrap() {
            let element = sim["elements"]
                .as_array()
                .unwrap()
                .iter()
                .find(|e| &e["id"] == id)
                .expect("failed piece in simulate --json");
            assert_eq!(element["framing"]["status"], "failed", "{cell} {id}");
            let reasons = element["framing"]["reasons"].to_string();
            assert!(
                words.is_empty() || words.iter().any(|w| reasons.contains(w)),
                "{cell} {id} counted as {cause}, the rules say {reasons}"
            );
        }
    }
}

#[test]
fn figures_equal_each_cells_own_simulation() {
    let cache = tempfile::tempdir().unwrap();
    let model = example("tm3.ifc");
    let cells = ["study-abb", "study-abb-track", "framing-line"];
    let mut args = vec!["compare", model.to_str().unwrap(), "--json"];
    for c in cells {
        args.extend(["--cell", c]);
    }
    args.extend(["--cache", cache.path().to_str().unwrap()]);
    let cmp = json_of(&args);
    assert_eq!(cmp["schema"], "framewright.compare/1");
    let bids = cmp["cells"].as_array().unwrap();
    assert_eq!(bids.len(), cells.len());
    for (bid, cell) in bids.iter().zip(cells) {
        assert_eq!(bid["cell"], cell);
        assert_bid_matches_simulate(bid, &model, cache.path());
    }
    // The track reaches farther along the wall: it frames more of TM3 than the fixed base;
    // the gantry reaches across the whole table: more again.
    let done = |i: usize| bids[i]["pieces"]["done"].as_u64().unwrap();
    assert!(done(1) > done(0));
    assert!(done(2) > done(1));
}

#[test]
fn a_wall_built_whole_gives_its_length_over_its_time() {
    let model = example("tm1.ifc");
    let cmp = json_of(&[
        "compare",
        model.to_str().unwrap(),
        "--cell",
        "study-abb",
        "--cell",
        "study-kuka",
        "--cell",
        "framing-line",
        "--json",
        "--no-cache",
    ]);
    for bid in cmp["cells"].as_array().unwrap() {
        assert_eq!(bid["complete_panels"], 1, "{bid}");
        let p = &bid["per_panel"][0];
        let rate = num(&p["length_m"]) * 3600.0 / (num(&p["framing_s"]) + num(&p["nailing_s"]));
        assert!((num(&bid["metres_per_hour"]) - rate).abs() < 1e-6);
        assert_eq!(bid["pieces"]["failed"], 0);
        assert_eq!(bid["nails"]["failed"], 0);
    }
}

#[test]
fn failure_classes_on_a_real_wall_agree_with_the_rules_reasons() {
    let Some(model) =
        common::shared_path("ifc-realworld/timber_constructivity_wall-elemented-case_IFC4.ifc")
    else {
        return;
    };
    let cache = tempfile::tempdir().unwrap();
    let cmp = json_of(&[
        "compare",
        model.to_str().unwrap(),
        "--cell",
        "study-abb",
        "--json",
        "--cache",
        cache.path().to_str().unwrap(),
    ]);
    let bid = &cmp["cells"][0];
    assert_bid_matches_simulate(bid, &model, cache.path());
    // This wall fails for more than reach on the study cell (it is laid against the sensor).
    let causes: Vec<&str> = bid["pieces"]["by_cause"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["cause"].as_str().unwrap())
        .collect();
    assert!(causes.contains(&"beyond_reach"), "{causes:?}");
    assert!(causes.len() > 1, "{causes:?}");
}

#[test]
fn the_page_shows_the_cells_side_by_side_and_is_byte_identical_on_repeat() {
    let dir = tempfile::tempdir().unwrap();
    let model = example("tm3.ifc");
    let run = |out: &Path| {
        let o = framewright(&[
            "compare",
            model.to_str().unwrap(),
            "--cell",
            "study-abb",
            "--cell",
            "study-kuka",
            "--no-cache",
            "--json",
            "--report",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        o.stdout
    };
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    let stdout = run(&a);
    run(&b);
    for f in ["index.html", "compare.json"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f} differs between two runs"
        );
    }
    assert_eq!(std::fs::read(a.join("compare.json")).unwrap(), stdout);
    let cmp: Value = serde_json::from_slice(&stdout).unwrap();
    let bars: usize = cmp["cells"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["per_panel"].as_array().unwrap().len())
        .sum();
    let Some(browser) = chromium() else { return };
    let (dom, log) = browse(browser, &a.join("index.html"), &dir.path().join("shot.png"));
    assert!(console_errors(&log).is_empty(), "{log}");
    let header = regex::Regex::new(r"(?s)<table class=.bid.>\s*<tbody>\s*<tr>(.*?)</tr>").unwrap();
    let first_row = &header.captures(&dom).expect("the bid table")[1];
    assert_eq!(first_row.matches("<th").count(), 3, "{first_row}");
    assert!(first_row.contains("study-abb") && first_row.contains("study-kuka"));
    assert_eq!(dom.matches("<g class=\"bar\"").count(), bars);
    for bid in cmp["cells"].as_array().unwrap() {
        let cell = bid["cell"].as_str().unwrap();
        assert!(dom.contains(&format!("<section class=\"cell\" data-cell=\"{cell}\"")));
    }
}

#[test]
fn bad_cells_are_refused_before_anything_runs() {
    let model = example("tm1.ifc");
    let m = model.to_str().unwrap();
    let twice = framewright(&["compare", m, "--cell", "study-abb", "--cell", "study-abb"]);
    assert_eq!(twice.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&twice.stderr).contains("given twice"));
    let unknown = framewright(&[
        "compare",
        m,
        "--cell",
        "study-abb",
        "--cell",
        "no-such-cell",
    ]);
    assert_eq!(unknown.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&unknown.stderr).contains("no-such-cell"));
    assert!(unknown.stdout.is_empty());
    let none = framewright(&["compare", m]);
    assert_eq!(none.status.code(), Some(2));
}
