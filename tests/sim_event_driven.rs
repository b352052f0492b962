//! Event-driven stepping against fixed steps: the same element verdicts, placements and nails
//! within 1 mm, on the study's test models with both shipped cells and on a sample of the
//! 3-storey model's walls, far fewer solver steps, and byte-identical repeated runs.

mod common;

use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::report::simulate::SimReport;
use framewright::sim::record::NailOutcome;
use framewright::sim::{SimOptions, Simulation, Stepping};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Largest difference of an as-built error between the two modes (m).
const AS_BUILT_TOLERANCE: f64 = 0.001;

fn bundled(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/models")
        .join(name)
}

fn run(
    model: &Model,
    cell: &Cell,
    walls: &[String],
    stepping: Stepping,
) -> (Simulation, SimReport) {
    let options = SimOptions {
        walls: walls.to_vec(),
        stepping,
        ..SimOptions::default()
    };
    let sim = simulate(model, cell, &options).expect("simulation runs");
    let report = SimReport::new(&sim, options.dt).expect("report");
    (sim, report)
}

/// Per element: its framing and nailing status.
fn verdicts(report: &SimReport) -> BTreeMap<String, [String; 2]> {
    report
        .elements
        .iter()
        .map(|e| {
            (
                format!("{} {}", e.wall_id, e.id),
                [e.framing.status.clone(), e.nailing.status.clone()],
            )
        })
        .collect()
}

/// Per placed piece its position error (m); per fired nail its as-built error (m); per
/// skipped nail its kind.
fn as_built(sim: &Simulation) -> (BTreeMap<String, f64>, BTreeMap<String, Result<f64, String>>) {
    let mut placed = BTreeMap::new();
    let mut nails = BTreeMap::new();
    for r in &sim.records {
        for p in &r.placements {
            placed.insert(format!("{} {}", r.wall, p.piece), p.position_error);
        }
        for n in &r.nails {
            let key = format!("{} {} {} {}", r.wall, n.plate, n.member, n.k);
            let outcome = match &n.outcome {
                NailOutcome::Fired { position_error, .. } => Ok(*position_error),
                NailOutcome::Skipped { kind, .. } => Err(kind.clone()),
            };
            nails.insert(key, outcome);
        }
    }
    (placed, nails)
}

/// Runs `walls` of a model both ways and checks that they agree; returns the solver steps
/// (fixed, events).
fn compare(model_path: &Path, cell_name: &str, walls: &[String]) -> (u64, u64) {
    let context = format!("{} on {cell_name}", model_path.display());
    let model = Model::open(model_path).expect("model opens");
    let cell = Cell::load(cell_name).expect("cell");
    let (fixed_sim, fixed) = run(&model, &cell, walls, Stepping::Fixed);
    let (events_sim, events) = run(&model, &cell, walls, Stepping::Events);

    let (vf, ve) = (verdicts(&fixed), verdicts(&events));
    assert_eq!(vf.len(), ve.len(), "{context}: element count");
    let differing: Vec<String> = vf
        .iter()
        .filter(|(k, v)| ve.get(*k) != Some(v))
        .map(|(k, v)| format!("{k}: fixed {v:?}, events {:?}", ve.get(k)))
        .collect();
    assert!(
        differing.is_empty(),
        "{context}: verdicts differ:\n{}",
        differing.join("\n")
    );
    // Wall rows: framing and nailing. (Where the robot shoves loose lumber on the belts, which
    // piece reaches the sensor first is chaotic in either mode: a wall's feeding verdict may
    // then differ while its elements' verdicts agree.)
    for (f, e) in fixed.walls.iter().zip(&events.walls) {
        assert_eq!(
            (&f.framing.status, &f.nailing.status),
            (&e.framing.status, &e.nailing.status),
            "{context}: wall {}",
            f.wall_id
        );
    }

    let ((pf, nf), (pe, ne)) = (as_built(&fixed_sim), as_built(&events_sim));
    assert_eq!(
        pf.keys().collect::<Vec<_>>(),
        pe.keys().collect::<Vec<_>>(),
        "{context}: placed pieces"
    );
    for (piece, f) in &pf {
        let e = pe[piece];
        assert!(
            (f - e).abs() <= AS_BUILT_TOLERANCE,
            "{context}: {piece} placed {:.2} mm off (fixed) against {:.2} mm (events)",
            f * 1e3,
            e * 1e3
        );
    }
    assert_eq!(
        nf.keys().collect::<Vec<_>>(),
        ne.keys().collect::<Vec<_>>(),
        "{context}: nails"
    );
    for (nail, f) in &nf {
        match (f, &ne[nail]) {
            (Ok(f), Ok(e)) => assert!(
                (f - e).abs() <= AS_BUILT_TOLERANCE || (f.is_nan() && e.is_nan()),
                "{context}: nail {nail} {:.2} mm off (fixed) against {:.2} mm (events)",
                f * 1e3,
                e * 1e3
            ),
            (f, e) => assert_eq!(f, e, "{context}: nail {nail}"),
        }
    }

    let steps = |s: &Simulation| s.records.iter().map(|r| r.steps).sum::<u64>();
    let (sf, se) = (steps(&fixed_sim), steps(&events_sim));
    eprintln!("{context}: {sf} solver steps fixed, {se} event-driven");
    (sf, se)
}

/// The (model, cell) pairs where the two modes agree; TM2 on study-kuka is known to differ
/// (see `tm2_on_study_kuka_agrees`).
fn agreeing(cell: &str, model: &str) -> bool {
    !(cell == "study-kuka" && model.ends_with("tm2.ifc"))
}

#[test]
fn bundled_models_agree_with_both_cells() {
    for cell in ["study-abb", "study-kuka"] {
        for model in ["tm1.ifc", "tm2.ifc", "tm3.ifc"] {
            if !agreeing(cell, model) {
                continue;
            }
            let (fixed, events) = compare(&bundled(model), cell, &[]);
            assert!(
                events * 2 < fixed,
                "{model} on {cell}: {events} solver steps is not far fewer than {fixed}"
            );
        }
    }
}

#[test]
fn study_test_models_agree_with_both_cells() {
    for cell in ["study-abb", "study-kuka"] {
        for model in ["a_paper_tm1.ifc", "a_paper_tm2.ifc", "a_paper_tm3.ifc"] {
            if !agreeing(cell, model) {
                continue;
            }
            let Some(path) = common::shared_path(&format!("ifc-testcases/{model}")) else {
                return;
            };
            compare(&path, cell, &[]);
        }
    }
}

/// Once diverged: the bottom plate's place failed (its grips near the touch sensor were
/// blocked by the 0.20 m stop) and the plate was released loose on the wall area, where the
/// two modes placed two studs differently. With the lower sensor the plate is placed, and the
/// modes agree; the loose-piece case itself was not explained.
#[test]
fn tm2_on_study_kuka_agrees() {
    compare(&bundled("tm2.ifc"), "study-kuka", &[]);
    if let Some(path) = common::shared_path("ifc-testcases/a_paper_tm2.ifc") {
        compare(&path, "study-kuka", &[]);
    }
}

/// Once diverged on one nail (driven with fixed steps, path_blocked event-driven): the
/// planner's seed hashed the exact bits of joint values that differ by micrometres between the
/// modes; it now rounds them to 0.1 mrad (`paths::move_seed`).
#[test]
fn twenty_walls_of_the_three_storey_model_agree() {
    let Some(path) = common::shared_path("ifc-testcases/g_scale_3storey.ifc") else {
        return;
    };
    // Every 7th wall of the plan: 22 of its 153, across storeys and wall kinds.
    let model = Model::open(&path).expect("model opens");
    let cell = Cell::load("study-abb").expect("cell");
    let mut facts =
        framewright::frame::model_facts(&model, &framewright::geom::ContactOptions::default());
    facts.extend(framewright::frame::cell_facts(&cell));
    let engine = framewright::frame::RuleEngine::Compiled;
    framewright::frame::Ask::new(&engine)
        .place(&mut facts, &cell)
        .unwrap();
    let reasoned = framewright::frame::Ask::new(&engine).over(&facts).unwrap();
    let plan = framewright::frame::plan::Plan::from_reasoned(&model, &reasoned)
        .expect("the rule base's tuples match their declarations");
    let walls: Vec<String> = plan.walls.iter().step_by(7).map(|w| w.id.clone()).collect();
    assert!(walls.len() >= 20, "{} walls sampled", walls.len());
    compare(&path, "study-abb", &walls);
}

#[test]
fn event_driven_runs_repeat_byte_for_byte() {
    let model = Model::open(bundled("tm3.ifc")).expect("bundled model");
    let cell = Cell::load("study-abb").expect("cell");
    let (first_sim, first) = run(&model, &cell, &[], Stepping::Events);
    let (second_sim, second) = run(&model, &cell, &[], Stepping::Events);
    assert_eq!(first.to_json(), second.to_json());
    for (a, b) in first_sim.records.iter().zip(&second_sim.records) {
        assert_eq!(a.trace.times, b.trace.times);
        assert_eq!(a.trace.joints, b.trace.joints);
        assert_eq!(
            format!("{:?}", a.trace.lumber),
            format!("{:?}", b.trace.lumber)
        );
    }
}
