//! `simulate` reasons the model's facts in full once to plan and once for the verdicts (over
//! the plan's facts and the simulation's), cached or not; the placement search reads one
//! pass cut down to what it needs (`placement::FIRST_PASS`). A run that finds every wall in
//! the cache reasons as often and simulates nothing. One test in this file: the counter is
//! the process's.

use framewright::cache::Cache;
use framewright::cell::{Cell, OffsetX};
use framewright::frame::{RuleBaseRuns, rule_base_runs};
use framewright::ifc::Model;
use framewright::pipeline::Run;
use framewright::report::simulate::SimReport;
use framewright::sim::SimOptions;
use std::path::Path;

fn runs_of<T>(f: impl FnOnce() -> T) -> (T, RuleBaseRuns) {
    let before = rule_base_runs();
    let out = f();
    let after = rule_base_runs();
    (
        out,
        RuleBaseRuns {
            whole: after.whole - before.whole,
            cut: after.cut - before.cut,
        },
    )
}

fn json(sim: &framewright::sim::Simulation, options: &SimOptions) -> Vec<u8> {
    let mut out = Vec::new();
    SimReport::new(sim, options.dt)
        .expect("report")
        .write_json(&mut out)
        .expect("JSON");
    out
}

#[test]
fn simulate_reasons_the_model_once_to_plan_and_once_for_the_verdicts() {
    let model = Model::open(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm1.ifc"))
        .expect("bundled model");
    let cell = Cell::load("study-abb").expect("cell");
    assert!(
        matches!(cell.assembly.offset_x, OffsetX::Auto { .. }),
        "the study cell places walls by search, so the first pass is counted too"
    );
    let options = SimOptions::default();
    let planned_once = RuleBaseRuns { whole: 2, cut: 1 };

    let ((fresh, counts), runs) = runs_of(|| Run::new(&model, &cell, &options).simulate().unwrap());
    assert_eq!(counts, None, "no cache, no counts");
    assert_eq!(runs, planned_once, "uncached");

    let dir = tempfile::tempdir().unwrap();
    let cache = Cache::new(dir.path().join("cache"));
    let cached = || {
        let run = Run::new(&model, &cell, &options).cache(Some(&cache));
        let (sim, counts) = run.simulate().unwrap();
        cache.wait_for_writes();
        (sim, counts.expect("a cached run counts"))
    };
    let ((filled, counts), runs) = runs_of(cached);
    assert_eq!((counts.computed, counts.cached), (1, 0), "{counts:?}");
    assert_eq!(runs, planned_once, "filling the cache");

    let ((hit, counts), runs) = runs_of(cached);
    assert_eq!((counts.computed, counts.cached), (0, 1), "{counts:?}");
    assert_eq!(runs, planned_once, "every wall from the cache");

    // The three runs say the same, byte for byte.
    let expected = json(&fresh, &options);
    assert_eq!(json(&filled, &options), expected);
    assert_eq!(json(&hit, &options), expected);

    // The plan alone (what `world` builds) reasons once, its search included.
    let (_, runs) = runs_of(|| Run::new(&model, &cell, &options).prepare().unwrap());
    assert_eq!(runs, RuleBaseRuns { whole: 1, cut: 1 });
}
