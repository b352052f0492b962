//! `why` on the study's TM3 top plate on the ABB cell. Until the executor
//! runs inside these tests, the simulation facts it would record for that
//! plate (its place pose is beyond the arm's reach) are inserted by hand:
//! the test checks the explanation machinery (verdict rules, provenance down
//! to IFC entities and cell keys), not the simulation. The numbers stand in
//! for the executor's (distance of the wrist centre and the arm's reach).

use framewright::cell::Cell;
use framewright::frame::{Facts, RuleEngine, cell_facts, model_facts};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
use framewright::logic::provenance::{How, Premise};
use framewright::logic::{Explanation, Origin, Value};
use framewright::user_rules::render::render_why;
use framewright::user_rules::why::{Context, WhyReport, why};
use std::path::Path;

/// The shipped cell as the study laid its TM3 (bottom plate 0.531 m from the base) with
/// lumber end to end on conveyor 1: the fixed layout these tests were written against.
fn pinned(mut cell: Cell) -> Cell {
    cell.set_offset_x("0.531").unwrap();
    cell.arrangement = framewright::cell::Arrangement::EndToEnd;
    cell
}

/// The W1 top plate of TM3 (entity #174, its box from representation item #171).
const TOP_PLATE: &str = "#174";
const DISTANCE: f64 = 2.987;
const REACH: f64 = 2.552;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn facts(model: &Model, sim: bool) -> Facts {
    let cell = pinned(Cell::load("study-abb").unwrap());
    let mut facts = model_facts(model, &ContactOptions::default());
    facts.extend(cell_facts(&cell));
    if sim {
        let p = model
            .pieces()
            .iter()
            .find(|p| p.entity == 174)
            .unwrap()
            .id
            .clone();
        let s = Value::sym;
        let ev = |e: &str| Origin::Event(e.to_string());
        facts.add(
            "sim_operation",
            vec![s(&p), s("feed"), Value::float(0.0), Value::float(4.0)],
            ev("feed"),
        );
        facts.add(
            "sim_operation",
            vec![s(&p), s("pick"), Value::float(4.0), Value::float(6.5)],
            ev("pick"),
        );
        facts.add(
            "sim_operation",
            vec![s(&p), s("place"), Value::float(6.5), Value::float(6.5)],
            ev("place"),
        );
        facts.add(
            "sim_ik_solved",
            vec![s(&p), s("pick"), Value::float(0.31)],
            ev("pick"),
        );
        facts.add(
            "sim_ik_failed",
            vec![
                s(&p),
                s("place"),
                s("out_of_reach"),
                s(""),
                Value::float(DISTANCE),
                Value::float(REACH),
                s("wrist centre beyond reach"),
            ],
            ev("place at t = 6.50 s"),
        );
    }
    facts
}

fn explain(sim: bool) -> (Vec<WhyReport>, Model) {
    let model = Model::open(root().join("examples/models/tm3.ifc")).unwrap();
    let f = facts(&model, sim);
    let ctx = Context {
        model: &model,
        facts: &f,
        base: &RuleEngine::Compiled,
        user_files: &[],
    };
    (why(&ctx, TOP_PLATE).unwrap(), model)
}

/// Line of the rule labelled `label` in a built-in rule file (the line after the label).
fn rule_line(file: &str, label: &str) -> usize {
    let text = std::fs::read_to_string(root().join(file)).unwrap();
    2 + text
        .lines()
        .position(|l| l.trim() == format!("// @rule {label}"))
        .unwrap_or_else(|| panic!("{file} has no rule {label}"))
}

fn nodes<'a>(e: &'a Explanation, out: &mut Vec<&'a Explanation>) {
    out.push(e);
    if let How::Rule { premises, .. } = &e.how {
        for p in premises {
            if let Premise::Tuple(t) = p {
                nodes(t, out);
            }
        }
    }
}

#[test]
fn the_top_plate_failed_framing_because_its_place_pose_is_beyond_reach() {
    let (reports, _) = explain(true);
    assert_eq!(reports.len(), 1);
    let r = &reports[0];
    assert_eq!(r.element.entity, 174);
    assert_eq!(r.element.item, 171);
    let reason = r
        .verdicts
        .iter()
        .find(|v| v.relation == "element_reason")
        .expect("a framing reason");
    let msg = reason.tuple[3].as_symbol().unwrap();
    assert_eq!(reason.tuple[1].as_symbol(), Some("framing"));
    assert_eq!(reason.tuple[2].as_symbol(), Some("Robot"));
    assert!(
        msg.contains("2.987 m from the shoulder, the arm reaches 2.552 m (435 mm too far)"),
        "{msg}"
    );
    let rule = format!(
        "framing_place_beyond_reach (rules/verdicts.dl:{})",
        rule_line("rules/verdicts.dl", "framing_place_beyond_reach")
    );
    let How::Rule {
        rule: by, premises, ..
    } = &reason.explanation.how
    else {
        panic!("derived")
    };
    assert_eq!(by, &rule);
    // Its premises: the executor's failure, the framing target, the role.
    let rels: Vec<&str> = premises
        .iter()
        .filter_map(|p| match p {
            Premise::Tuple(t) => Some(t.relation.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(rels, ["sim_ik_failed", "framing_target", "role"]);
    // Down to the IFC entities of the plate and the cell keys that place the wall.
    let s = &reason.sources;
    assert!(
        s.ifc_entities.contains(&171) && s.ifc_entities.contains(&174),
        "{:?}",
        s.ifc_entities
    );
    for key in [
        "assembly_offset_x",
        "assembly_centre_y",
        "assembly_orientation",
    ] {
        assert!(
            s.cell_keys.iter().any(|k| k == key),
            "{key} in {:?}",
            s.cell_keys
        );
    }
    assert_eq!(s.simulation_facts, 1);
    assert!(
        s.rules
            .iter()
            .any(|r| r.starts_with("framing_target (rules/targets.dl:"))
    );
    assert!(
        s.rules
            .iter()
            .any(|r| r.starts_with("wall_laid_flat_parallel (rules/targets.dl:"))
    );
    assert!(
        s.rules
            .iter()
            .any(|r| r.starts_with("wall_frame (rules/frame.dl:"))
    );
    assert!(
        s.rules
            .iter()
            .any(|r| r.starts_with("top_plate (rules/roles.dl:"))
    );
    assert!(!s.truncated);
    // The simulation fact keeps its event.
    let mut all = Vec::new();
    nodes(&reason.explanation, &mut all);
    let sim = all.iter().find(|n| n.relation == "sim_ik_failed").unwrap();
    assert!(
        matches!(&sim.how, How::Input { origin: Origin::Event(e) } if e == "place at t = 6.50 s")
    );
    // The framing status is failed, and so the wall's framing stage.
    let status = r
        .verdicts
        .iter()
        .find(|v| v.relation == "element_framing")
        .unwrap();
    assert_eq!(status.tuple[1].as_symbol(), Some("failed"));
}

#[test]
fn the_text_tree_shows_the_numbers_the_rules_and_the_ifc_ids() {
    let (reports, _) = explain(true);
    let text = render_why(&reports);
    assert!(text.starts_with("32H5oapRpM57uELNCcVku8 '2x4 top plate F-020' (IfcBeam #174, GlobalId 32H5oapRpM57uELNCcVku8), wall "), "{text}");
    let first = text.lines().nth(2).unwrap();
    assert!(first.starts_with("element_reason(\"32H5oapRpM57uELNCcVku8\", \"framing\", \"Robot\", \"place pose beyond reach: the wrist centre would be 2.987 m from the shoulder, the arm reaches 2.552 m (435 mm too far)\")  [by framing_place_beyond_reach (rules/verdicts.dl:"), "{first}");
    assert!(text.contains("sim_ik_failed(\"32H5oapRpM57uELNCcVku8\", \"place\", \"out_of_reach\", \"\", 2.987, 2.552, \"wrist centre beyond reach\")  [simulation: place at t = 6.50 s]"), "{text}");
    assert!(
        text.contains("cell_value(\"assembly_offset_x\", 0.531)  [cell "),
        "{text}"
    );
    assert!(text.contains("[IFC #171]"), "{text}");
    assert!(
        text.contains(
            "role(\"32H5oapRpM57uELNCcVku8\", \"top_plate\")  [by role_fitted (rules/roles.dl:"
        ),
        "{text}"
    );
    assert!(text.contains("IFC #24 #35 #38 #44 #171 #174; cell keys: assembly_centre_y, assembly_offset, assembly_offset_x, assembly_orientation, assembly_surface_z; 1 simulation facts"), "{text}");
    // Deep trees are cut on a terminal with a count, never silently.
    assert!(text.contains("more facts below (--json has the whole tree)"));
    // Widest first: under the reason, the framing target (most facts) comes before the role.
    let reason_block: &str = text.split("\n\n").nth(1).unwrap();
    let target = reason_block.find("├─ framing_target(").unwrap();
    let role = reason_block.find("role(\"32H5").unwrap();
    let sim = reason_block.find("sim_ik_failed(").unwrap();
    assert!(target < role && role < sim, "{reason_block}");
}

#[test]
fn without_simulation_the_plate_has_only_plan_verdicts() {
    let (reports, _) = explain(false);
    let rels: Vec<&str> = reports[0]
        .verdicts
        .iter()
        .map(|v| v.relation.as_str())
        .collect();
    assert_eq!(
        rels,
        [
            "role",
            "wall_of",
            "assembly_rank",
            "framing_target",
            "spawn_beyond_belt"
        ]
    );
    let target = &reports[0].verdicts[3];
    // The framing target lies 2.94 m out along the robot's x axis: the reach problem's cause.
    let Value::Iso(iso) = &target.tuple[1] else {
        panic!()
    };
    let t = iso.0.translation.vector;
    assert!((t.x - 2.940825).abs() < 1e-6 && t.y.abs() < 1e-9, "{t:?}");
}

#[test]
fn ids_resolve_by_piece_id_global_id_and_entity() {
    let model = Model::open(root().join("examples/models/tm3.ifc")).unwrap();
    let f = facts(&model, false);
    let ctx = Context {
        model: &model,
        facts: &f,
        base: &RuleEngine::Compiled,
        user_files: &[],
    };
    let by_entity = why(&ctx, "#174").unwrap();
    let by_item = why(&ctx, "#171").unwrap();
    let by_id = why(&ctx, "32H5oapRpM57uELNCcVku8").unwrap();
    assert_eq!(by_entity[0].element.id, "32H5oapRpM57uELNCcVku8");
    assert_eq!(by_item[0].element.id, by_id[0].element.id);
    let json = |r: &Vec<WhyReport>| serde_json::to_string(r).unwrap();
    assert_eq!(json(&by_entity), json(&by_id));
    let err = why(&ctx, "#175").unwrap_err().to_string();
    assert!(
        err.contains(
            "no piece of the model has the id `#175` (nearest: #174 (2x4 top plate F-020)"
        ),
        "{err}"
    );
    let err = why(&ctx, "32H5oapRpM").unwrap_err().to_string();
    assert!(
        err.contains("nearest: 32H5oapRpM57uELNCcVku8 (#174)"),
        "{err}"
    );
}
