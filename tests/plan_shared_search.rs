//! The placement search shares one search among targets whose poses agree to 1 nm; on a
//! model of repeated walls (where sharing happens) the plan must be the one every target
//! searching on its own gives, byte for byte.
use framewright::cell::Cell;
use framewright::frame::placement::SearchOptions;
use framewright::frame::plan::Plan;
use framewright::frame::{Ask, RuleEngine, cell_facts, model_facts};
use framewright::ifc::Model;
use framewright::report::plan::PlanReport;
use framewright::synth::building::{BlockSpec, blocks};
use framewright::synth::{Grouping, WriteOptions, models, write_ifc};

fn plan_json(model: &Model, cell: &Cell, share: bool) -> Vec<u8> {
    let mut facts = model_facts(model, &Default::default());
    facts.extend(cell_facts(cell));
    let options = SearchOptions {
        share_equal_poses: share,
        ..SearchOptions::default()
    };
    Ask::new(&RuleEngine::Compiled)
        .search(options)
        .place(&mut facts, cell)
        .expect("search");
    let reasoned = Ask::new(&RuleEngine::Compiled)
        .over(&facts)
        .expect("reason");
    let mut json = Vec::new();
    PlanReport::new(model, &Plan::from_reasoned(model, &reasoned).expect("plan"))
        .write_json(&mut json)
        .expect("json");
    json
}

#[test]
fn shared_search_gives_the_plan_of_one_search_per_target() {
    // Two storeys of two identical units: every wall has three copies elsewhere.
    let spec = BlockSpec::new(models::default_building_spec(), 1, 2, 1, 2);
    let layout = blocks(&spec, "shared").expect("layout");
    let written = write_ifc(
        &layout,
        &WriteOptions {
            grouping: Grouping::Wall,
            ..WriteOptions::default()
        },
    )
    .expect("write");
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("shared.ifc");
    std::fs::write(&path, &written.ifc).expect("write model");
    let model = Model::open(&path).expect("read");
    for name in ["study-abb", "study-kuka"] {
        let cell = Cell::load(name).expect("cell");
        let shared = plan_json(&model, &cell, true);
        let own = plan_json(&model, &cell, false);
        assert!(
            String::from_utf8_lossy(&shared).contains("\"wall_id\""),
            "the plan has walls"
        );
        assert!(shared == own, "{name}: sharing the search changed the plan");
    }
}
