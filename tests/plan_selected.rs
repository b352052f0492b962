//! `plan` reads only the relations it needs from the compiled rule base, the placement
//! search hands the rules only the offsets where a wall's count can rise, and with walls
//! placed by search each part runs the rule base once and then only the rules the search's
//! facts reach. None of it may change the plan: the JSON equals, byte for byte, the one of
//! the full conversion of every relation with every offset a candidate and the rule base run
//! twice (the path before), on TM1–TM3 and a generated multi-storey model with grouped
//! walls, openings and property sets, with both shipped cells.
use framewright::cell::Cell;
use framewright::frame::builtin;
use framewright::frame::placement::SearchOptions;
use framewright::frame::plan::Plan;
use framewright::frame::{Ask, Reasoned, RuleEngine, cell_facts, model_facts};
use framewright::ifc::Model;
use framewright::report::plan::PlanReport;
use framewright::synth::building::{BlockSpec, blocks};
use framewright::synth::{Grouping, WriteOptions, models, write_ifc};
use std::path::{Path, PathBuf};

/// How the plan is reasoned.
#[derive(Clone, Copy, Debug)]
enum Route {
    /// Every relation converted, every offset a candidate, the rule base run twice.
    Before,
    /// Only the plan's relations, the rule base run twice.
    TwoPasses,
    /// Only the plan's relations, one pass and the placement slice per part.
    Fused,
}

/// `plan --json` of the model, reasoned along `path`.
fn plan_json(model: &Model, cell: &Cell, path: Route) -> Vec<u8> {
    let mut facts = model_facts(model, &Default::default());
    facts.extend(cell_facts(cell));
    let reasoned = match path {
        Route::Fused => Ask::new(&RuleEngine::Compiled)
            .only(Plan::RELATIONS)
            .placed(facts, cell)
            .expect("reason"),
        Route::Before | Route::TwoPasses => {
            let before = matches!(path, Route::Before);
            let options = SearchOptions {
                every_offset: before,
                ..SearchOptions::default()
            };
            let ask = Ask::new(&RuleEngine::Compiled).search(options);
            ask.place(&mut facts, cell).expect("search");
            if before {
                ask.over(&facts)
            } else {
                ask.only(Plan::RELATIONS).over(&facts)
            }
            .expect("reason")
        }
    };
    let mut json = Vec::new();
    PlanReport::new(model, &Plan::from_reasoned(model, &reasoned).expect("plan"))
        .write_json(&mut json)
        .expect("json");
    json
}

fn assert_same_plan(path: &Path, label: &str) {
    let model = Model::open(path).expect("read");
    for name in ["study-abb", "study-kuka"] {
        let cell = Cell::load(name).expect("cell");
        let before = plan_json(&model, &cell, Route::Before);
        assert!(
            String::from_utf8_lossy(&before).contains("\"wall_id\""),
            "{label}: the plan has walls"
        );
        for path in [Route::TwoPasses, Route::Fused] {
            assert!(
                plan_json(&model, &cell, path) == before,
                "{label}, {name}: the plan along {path:?} differs from the full conversion \
                 with every offset"
            );
        }
    }
}

#[test]
fn the_test_models_plan_as_before() {
    for tm in ["tm1", "tm2", "tm3"] {
        let path =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("examples/models/{tm}.ifc"));
        assert_same_plan(&path, tm);
    }
}

#[test]
fn a_generated_block_plans_as_before() {
    // One block of two storeys of 1 x 2 units: grouped walls with doors and windows.
    let spec = BlockSpec::new(models::default_building_spec(), 1, 2, 1, 2);
    let layout = blocks(&spec, "selected").expect("layout");
    let written = write_ifc(
        &layout,
        &WriteOptions {
            grouping: Grouping::Wall,
            property_sets: true,
            openings: true,
            ..WriteOptions::default()
        },
    )
    .expect("write");
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("selected.ifc");
    std::fs::write(&path, &written.ifc).expect("write model");
    assert_same_plan(&path, "generated block");
}

/// Every relation the compiled rule base derives, sorted, reasoned in two passes (the
/// search's facts added to the model's, the rule base run again) or fused.
fn every_relation(model: &Model, cell: &Cell, fused: bool) -> Reasoned {
    let mut facts = model_facts(model, &Default::default());
    facts.extend(cell_facts(cell));
    assert!(
        facts.tuples.keys().all(|k| builtin::INPUTS.contains(k)),
        "the model's and the cell's facts are all typed inputs, so the fused path applies"
    );
    let ask = Ask::new(&RuleEngine::Compiled).only(builtin::OUTPUTS);
    let mut reasoned = if fused {
        ask.placed(facts, cell)
    } else {
        ask.place(&mut facts, cell).expect("search");
        ask.over(&facts)
    }
    .expect("reason");
    for tuples in reasoned.relations.values_mut() {
        tuples.sort();
    }
    reasoned
}

#[test]
fn the_fused_placement_pass_derives_every_relation_as_two_passes_do() {
    for tm in ["tm1", "tm3"] {
        let path =
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("examples/models/{tm}.ifc"));
        let model = Model::open(&path).expect("read");
        for name in ["study-kuka", "study-abb-track"] {
            let cell = Cell::load(name).expect("cell");
            let two = every_relation(&model, &cell, false);
            let fused = every_relation(&model, &cell, true);
            assert!(!two.get("wall_frame").is_empty(), "{tm}: walls placed");
            assert!(!two.get("nailing_target").is_empty(), "{tm}: nails placed");
            for relation in builtin::OUTPUTS {
                assert!(
                    two.get(relation) == fused.get(relation),
                    "{tm}, {name}: `{relation}` differs ({} tuples in two passes, {} fused)",
                    two.get(relation).len(),
                    fused.get(relation).len()
                );
            }
        }
    }
}
