//! The motion planner in the executor: an obstacle on the direct path is gone around without
//! a contact; a move no path makes is a failure that names the obstacle, and the arm never
//! drives through it.

use framewright::cell::{Cell, IkFailure};
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::report::simulate::SimReport;
use framewright::sim::{SimOptions, Simulation};
use nalgebra::Point3;
use std::path::Path;

fn tm2() -> Model {
    Model::open(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm2.ifc"))
        .expect("bundled model")
}

/// The study's ABB cell with its tool table moved to `centre` (its top's upper face) and
/// resized to `size` (length, width, top thickness).
fn cell_with_table(centre: [f64; 3], size: [f64; 3]) -> Cell {
    let mut cell = Cell::load("study-abb").expect("cell");
    cell.tool_table.top_centre = Point3::from(centre);
    cell.tool_table.size = size;
    cell.tool_table.leg_height = centre[2] - size[2];
    cell
}

fn run(cell: &Cell) -> (Simulation, SimReport) {
    let options = SimOptions::default();
    let sim = simulate(&tm2(), cell, &options).expect("simulation runs");
    let report = SimReport::new(&sim, options.dt).expect("report");
    (sim, report)
}

/// A table raised to 0.8..1.6 m beside the robot, where the arm swings from the pick belt
/// behind it to the wall in front of it.
fn raised_table() -> Cell {
    cell_with_table([0.0, 1.4, 1.6], [0.8, 0.6, 0.8])
}

#[test]
fn a_raised_tool_table_on_the_way_is_gone_around_without_a_contact() {
    let (_, free) = run(&Cell::load("study-abb").unwrap());
    let (sim, report) = run(&raised_table());
    let text = report.to_text();
    assert_eq!(report.walls[0].framing.status, "Completed", "{text}");
    assert!(report.contacts.is_empty(), "{text}");
    assert!(sim.records[0].contacts.is_empty());
    // The table stands on the direct path: going around it takes longer than the free cell's
    // straight moves.
    assert!(
        report.walls[0].framing.time_s > free.walls[0].framing.time_s + 1.0,
        "framing {} s with the table, {} s without",
        report.walls[0].framing.time_s,
        free.walls[0].framing.time_s
    );
}

#[test]
fn planned_paths_are_deterministic() {
    let cell = raised_table();
    assert_eq!(run(&cell).1.to_json(), run(&cell).1.to_json());
}

#[test]
fn a_move_walled_off_by_the_tool_table_fails_naming_it_and_touches_nothing() {
    // A block 3.5 m tall beside the base, between the pick belt behind the robot and the wall
    // in front of it: the arm cannot turn from one to the other (its first axis cannot go the
    // other way round), though both ends are clear of it.
    let cell = cell_with_table([0.0, 0.9, 3.55], [1.2, 0.8, 3.5]);
    let (sim, report) = run(&cell);
    let record = &sim.records[0];
    assert!(record.contacts.is_empty(), "{:?}", record.contacts);
    assert!(report.contacts.is_empty());
    assert!(record.placements.is_empty(), "nothing can be placed");
    let blocked: Vec<_> = record
        .ik
        .iter()
        .filter_map(|r| match &r.result {
            Err(IkFailure::PathBlocked { pair }) => Some((r.piece.as_str(), pair)),
            _ => None,
        })
        .collect();
    assert!(!blocked.is_empty(), "{}", report.to_text());
    for (piece, pair) in &blocked {
        assert_eq!(pair[1], "tool table", "{piece}: {pair:?}");
    }
    // The element verdicts give the reason in words.
    let text = report.to_text();
    assert!(text.contains("no collision-free path"), "{text}");
    assert_eq!(report.walls[0].framing.status, "Failed", "{text}");
}
