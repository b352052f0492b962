//! `pipeline::Run::wall_facts` (what `why` simulates for one element's wall) plans the wall from its
//! storey's facts alone; its facts must be the ones a simulation of the whole model gives
//! for that wall.

mod common;

use framewright::cell::Cell;
use framewright::frame::{Ask, cell_facts, model_facts};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::pipeline::{Run, simulate};
use framewright::sim::SimOptions;
use std::path::Path;

/// A generated block of two storeys (two spatial containers), walls grouped in IfcWall.
fn two_storey_block(dir: &Path) -> Model {
    let path = common::synth_block(
        dir,
        &[
            "--blocks",
            "1",
            "--storeys",
            "2",
            "--grid",
            "1x1",
            "--grouping",
            "wall",
            "--openings",
        ],
    );
    Model::open(&path).expect("the generated model reads")
}

/// The wall keys (`wall_of`'s second column) of the model's upper storey, with the count of
/// their pieces, smallest first.
fn upper_storey_walls(model: &Model, cell: &Cell) -> Vec<(usize, String)> {
    let mut facts = model_facts(model, &ContactOptions::default());
    facts.extend(cell_facts(cell));
    let reasoned = Ask::new(&Default::default())
        .over(&facts)
        .expect("reasoning");
    let containers: Vec<String> = {
        let mut c: Vec<String> = facts.tuples["piece_container"]
            .iter()
            .filter_map(|(t, _)| t[1].as_symbol().map(str::to_string))
            .collect();
        c.sort();
        c.dedup();
        c
    };
    assert_eq!(containers.len(), 2, "two storeys: {containers:?}");
    let container_of = |p: &str| {
        facts.tuples["piece_container"]
            .iter()
            .find(|(t, _)| t[0].as_symbol() == Some(p))
            .and_then(|(t, _)| t[1].as_symbol().map(str::to_string))
    };
    let mut counts = std::collections::BTreeMap::<String, usize>::new();
    for t in reasoned.get("wall_of") {
        *counts
            .entry(t[1].as_symbol().unwrap().to_string())
            .or_default() += 1;
    }
    // The storey whose container sorts last.
    let upper = containers.last().unwrap().clone();
    let mut walls: Vec<(usize, String)> = counts
        .into_iter()
        .filter(|(w, _)| container_of(w).as_deref() == Some(upper.as_str()))
        .map(|(w, n)| (n, w))
        .collect();
    walls.sort();
    walls
}

#[test]
fn one_wall_from_its_storey_gives_the_facts_of_a_whole_model_run() {
    let dir = tempfile::tempdir().unwrap();
    let model = two_storey_block(dir.path());
    let cell = Cell::load("study-abb").expect("cell");
    let walls = upper_storey_walls(&model, &cell);
    let (_, wall) = walls.first().expect("the upper storey has walls").clone();
    let options = SimOptions {
        walls: vec![wall.clone()],
        ..SimOptions::default()
    };
    let whole = simulate(&model, &cell, &options)
        .expect("whole-model run")
        .facts;
    let alone = Run::new(&model, &cell, &options)
        .wall_facts(None)
        .map(|(facts, _)| facts)
        .expect("one-wall run");
    assert!(
        whole
            .tuples
            .get("sim_operation")
            .is_some_and(|t| !t.is_empty()),
        "the wall was simulated"
    );
    assert_eq!(
        format!("{alone:?}"),
        format!("{whole:?}"),
        "facts of wall {wall}"
    );
}

#[test]
fn an_unknown_wall_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let model = two_storey_block(dir.path());
    let cell = Cell::load("study-abb").expect("cell");
    let options = SimOptions {
        walls: vec!["no such wall".into()],
        ..SimOptions::default()
    };
    let err = Run::new(&model, &cell, &options)
        .wall_facts(None)
        .expect_err("an unknown wall is an error");
    assert!(err.to_string().contains("no such wall"), "{err}");
}
