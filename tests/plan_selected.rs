//! `plan` reads only the relations it needs from the compiled rule base, and the placement
//! search hands the rules only the offsets where a wall's count can rise. Both must leave
//! the plan as it was: the JSON equals, byte for byte, the one of the full conversion of
//! every relation with every offset a candidate (the path before), on TM1–TM3 and a
//! generated multi-storey model with grouped walls, openings and property sets, with both
//! shipped cells.
use framewright::cell::Cell;
use framewright::frame::placement::{SearchOptions, add_placement_facts_with};
use framewright::frame::plan::Plan;
use framewright::frame::{RuleEngine, cell_facts, model_facts, reason, reason_selected};
use framewright::ifc::Model;
use framewright::report::plan::PlanReport;
use framewright::synth::building::{BlockSpec, blocks};
use framewright::synth::{Grouping, WriteOptions, models, write_ifc};
use std::path::{Path, PathBuf};

/// `plan --json` of the model: the earlier path (`before`) or the current one.
fn plan_json(model: &Model, cell: &Cell, before: bool) -> Vec<u8> {
    let mut facts = model_facts(model, &Default::default());
    facts.extend(cell_facts(cell));
    let options = SearchOptions {
        every_offset: before,
        ..SearchOptions::default()
    };
    add_placement_facts_with(&mut facts, cell, &RuleEngine::Compiled, &options).expect("search");
    let reasoned = if before {
        reason(&facts, &RuleEngine::Compiled, false)
    } else {
        reason_selected(&facts, &RuleEngine::Compiled, Plan::RELATIONS)
    }
    .expect("reason");
    let mut json = Vec::new();
    PlanReport::new(model, &Plan::from_reasoned(model, &reasoned))
        .write_json(&mut json)
        .expect("json");
    json
}

fn assert_same_plan(path: &Path, label: &str) {
    let model = Model::open(path).expect("read");
    for name in ["study-abb", "study-kuka"] {
        let cell = Cell::load(name).expect("cell");
        let now = plan_json(&model, &cell, false);
        let before = plan_json(&model, &cell, true);
        assert!(
            String::from_utf8_lossy(&now).contains("\"wall_id\""),
            "{label}: the plan has walls"
        );
        assert!(
            now == before,
            "{label}, {name}: the plan differs from the full conversion with every offset"
        );
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
    let spec = BlockSpec {
        unit: models::default_building_spec(),
        blocks: 1,
        storeys: 2,
        rows: 1,
        cols: 2,
        gap: 3.0,
        floor_depth: 0.3,
    };
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
