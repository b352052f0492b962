//! The executor on the bundled models: placement accuracy, the study's reach findings on its
//! test model 3, a bad cell's collision, determinism.

use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::report::simulate::SimReport;
use framewright::sim::{SimOptions, Simulation};
use std::path::Path;

fn model(name: &str) -> Model {
    Model::open(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/models")
            .join(name),
    )
    .expect("bundled model")
}

fn run(model_name: &str, cell: &str, walls: &[&str]) -> (Simulation, SimReport) {
    run_cell(model_name, Cell::load(cell).expect("cell"), walls)
}

/// A shipped cell with every wall at a fixed offset (m from the base to the bottom plate),
/// run at the joints' limits with short dwells (the defaults before the calibrated speeds).
fn fixed_layout(cell: &str, offset: &str) -> Cell {
    let mut cell = Cell::load(cell).expect("cell");
    cell.set_offset_x(offset).unwrap();
    cell.motion = framewright::cell::Motion::default();
    cell
}

fn run_cell(model_name: &str, cell: Cell, walls: &[&str]) -> (Simulation, SimReport) {
    let options = SimOptions {
        walls: walls.iter().map(|w| w.to_string()).collect(),
        ..SimOptions::default()
    };
    let sim = simulate(&model(model_name), &cell, &options).expect("simulation runs");
    let report = SimReport::new(&sim, options.dt).expect("report");
    (sim, report)
}

/// Every placed piece of the first simulated wall within 2 mm and 1° of its target.
fn assert_placed_within_2_mm_and_1_degree(sim: &Simulation, context: &str) {
    for p in &sim.records[0].placements {
        assert!(
            p.position_error <= 0.002,
            "{context}: {} off by {} m",
            p.piece,
            p.position_error
        );
        assert!(
            p.angle_error <= 1f64.to_radians(),
            "{context}: {} turned {} rad",
            p.piece,
            p.angle_error
        );
    }
}

#[test]
fn tm2_frames_and_nails_every_piece_within_2_mm_and_1_degree() {
    let (sim, report) = run("tm2.ifc", "study-abb", &[]);
    assert_eq!(report.walls.len(), 1);
    assert_eq!(
        report.walls[0].framing.status,
        "Completed",
        "{}",
        report.to_text()
    );
    assert_eq!(report.walls[0].material_feeding, "Completed");
    let placements = &sim.records[0].placements;
    assert_eq!(placements.len(), 4, "every piece placed");
    assert_placed_within_2_mm_and_1_degree(&sim, "tm2");
    // Every driven nail is checked against the as-built pieces.
    let v = &report.nailing_validation;
    assert_eq!(v.planned, 8);
    let fired = v.targets.iter().filter(|t| t.status == "fired").count();
    // All eight are driven. This is what the tool's `max_lean_deg` (20°) was CALIBRATED
    // against (the study drove all eight, Table 5), so it holds by construction; the
    // calibration's consequences that it does not fix are tested in
    // `tm2_nail_lean_calibration_is_tight_and_only_the_top_plate_leans`.
    assert_eq!(fired, 8, "{}", report.to_text());
    assert_eq!(report.walls[0].nailing.status, "Completed");
    assert_eq!(v.checked, fired);
    assert_leans_are_true_and_bounded(&sim, &report);
    assert!(
        v.targets
            .iter()
            .filter(|t| t.status == "fired")
            .all(|t| t.error_mm.is_some())
    );
    assert!(v.max_error_mm < 2.0, "max nail error {} mm", v.max_error_mm);
    assert!(v.all_inside_members);
    // Every skipped nail says why.
    for e in &report.elements {
        if e.nailing.status != "nailed" && e.nailing.status != "none" {
            assert!(
                !e.nailing.reasons.is_empty(),
                "{} has no nailing reason",
                e.id
            );
        }
    }
}

/// Every fired nail's recorded lean is the angle between the line it was driven along and
/// its planned line, within the tool's limit; the bottom plate's nails (near the base) go in
/// square; and every leaning nail still runs into its member.
fn assert_leans_are_true_and_bounded(sim: &Simulation, report: &SimReport) {
    use framewright::sim::record::NailOutcome;
    let limit = framewright::cell::Tool::study().max_nail_lean;
    let planned: std::collections::BTreeMap<(&str, &str), nalgebra::Vector3<f64>> = sim.plan.walls
        [0]
    .nailing_targets
    .iter()
    .map(|t| ((t.plate.as_str(), t.member.as_str()), t.direction))
    .collect();
    let frame = sim.plan.walls[0].frame;
    for n in &sim.records[0].nails {
        let NailOutcome::Fired {
            driven,
            lean,
            member_inside,
            ..
        } = &n.outcome
        else {
            continue;
        };
        // The plan's direction is in the model's frame; the record's in the wall's.
        let plan_dir = frame.rotation.inverse() * planned[&(n.plate.as_str(), n.member.as_str())];
        let angle = nalgebra::Vector3::from(*driven).angle(&plan_dir);
        assert!(
            (angle - lean).abs() < 1e-6,
            "{n:?}: lean {lean} but driven {angle} off"
        );
        assert!(*lean <= limit + 1e-9, "{n:?}");
        assert!(member_inside, "{n:?}");
        let role = &sim.plan.roles[&n.plate];
        if role == "bottom_plate" {
            assert_eq!(*lean, 0.0, "{n:?}");
        }
    }
    assert!(
        report
            .nailing_validation
            .targets
            .iter()
            .all(|t| t.lean_deg.is_none_or(|l| l <= limit.to_degrees() + 1e-6))
    );
}

/// What the ABB's 20° nail lean (CALIBRATED so that TM2's eight nails are driven) implies and
/// was not chosen for: one 5° step less leaves exactly the top plate's four nails undriven, each
/// for the robot (so 20° is the least lean that drives them, not a generous bound); the bottom
/// plate's nails, nearest the base, go in square; and the KUKA, which reaches 6 mm farther for
/// the square nail, drives all eight with less lean than the limit.
#[test]
fn tm2_nail_lean_calibration_is_tight_and_only_the_top_plate_leans() {
    let mut cell = Cell::load("study-abb").unwrap();
    assert!((cell.tool.max_nail_lean.to_degrees() - 20.0).abs() < 1e-9);
    cell.tool.max_nail_lean = 15f64.to_radians();
    let (sim, report) = run_cell("tm2.ifc", cell, &[]);
    let text = report.to_text();
    let not_fired: Vec<_> = report
        .nailing_validation
        .targets
        .iter()
        .filter(|t| t.status != "fired")
        .collect();
    assert_eq!(not_fired.len(), 4, "{text}");
    for t in &not_fired {
        assert_eq!(sim.plan.roles[&t.plate], "top_plate", "{text}");
    }
    let top_plate = &not_fired[0].plate;
    let element = report.elements.iter().find(|e| &e.id == top_plate).unwrap();
    assert_eq!(element.framing.status, "framed", "{text}");
    // Each for the robot (the arm cannot hold the nailer there: out of reach, or the tool
    // meets the floor), not for the framing.
    assert_eq!(element.nailing.reasons.len(), 4, "{text}");
    assert!(
        element
            .nailing
            .reasons
            .iter()
            .all(|r| r.component == "Robot"),
        "{:?}",
        element.nailing.reasons
    );

    let (sim, report) = run("tm2.ifc", "study-kuka", &[]);
    let limit = Cell::load("study-kuka")
        .unwrap()
        .tool
        .max_nail_lean
        .to_degrees();
    let leans: Vec<f64> = report
        .nailing_validation
        .targets
        .iter()
        .filter_map(|t| t.lean_deg)
        .collect();
    assert_eq!(leans.len(), 8, "{}", report.to_text());
    assert!(leans.iter().all(|l| *l < limit), "{leans:?}");
    for t in &report.nailing_validation.targets {
        if sim.plan.roles[&t.plate] == "bottom_plate" {
            assert_eq!(t.lean_deg, Some(0.0), "{t:?}");
        }
    }
}

/// The study framed TM2 completely on the KUKA too (Table 5). With a touch sensor taller than
/// the lumber (0.20 m) the bottom plate was not placed (the closest miss reported was joint
/// a3's limit at the place pose); with the 0.08 m one every piece is.
#[test]
fn tm2_frames_completely_on_the_kuka() {
    let (sim, report) = run("tm2.ifc", "study-kuka", &[]);
    assert_eq!(
        report.walls[0].framing.status,
        "Completed",
        "{}",
        report.to_text()
    );
    assert_eq!(sim.records[0].placements.len(), 4, "every piece placed");
    assert_placed_within_2_mm_and_1_degree(&sim, "tm2 on study-kuka");
    // ...and nailed it completely.
    assert_eq!(
        report.walls[0].nailing.status,
        "Completed",
        "{}",
        report.to_text()
    );
    assert_leans_are_true_and_bounded(&sim, &report);
}

#[test]
fn tm3_long_wall_plates_and_end_studs_are_beyond_reach() {
    // Wall 1 of the study's test model 3 (6.86 m long) on the ABB cell, where the study laid it.
    let (sim, report) = run_cell("tm3.ifc", fixed_layout("study-abb", "0.531"), &["Wall 1"]);
    let wall = &report.walls[0];
    assert_eq!(wall.framing.status, "Partial", "{}", report.to_text());
    assert!(wall.framing.failed_component.contains("Robot"));
    let beyond = |id: &str| {
        report
            .elements
            .iter()
            .find(|e| e.id == id)
            .is_some_and(|e| {
                e.framing
                    .reasons
                    .iter()
                    .any(|r| r.message.contains("beyond reach"))
            })
    };
    let plan_wall = &sim.plan.walls[0];
    for (id, role) in &sim.plan.roles {
        // The top and cap plates lie beyond reach, as in the study. (The 6.86 m bottom plate
        // is placed: the planner takes it round the infeed deck.)
        if plan_wall.members.contains(id) && (role == "top_plate" || role == "cap_plate") {
            assert!(beyond(id), "{role} {id} should be beyond reach");
        }
        if plan_wall.members.contains(id) && (role == "top_plate" || role == "cap_plate") {
            let e = report.elements.iter().find(|e| &e.id == id).unwrap();
            assert_eq!(e.framing.status, "failed", "{role} {id}");
        }
    }
    // The end studs: the first and last along the wall.
    let studs: Vec<&String> = plan_wall
        .framing_targets
        .iter()
        .map(|(id, _)| id)
        .filter(|id| sim.plan.roles.get(*id).is_some_and(|r| r == "stud"))
        .collect();
    let along = |id: &String| {
        let t = &plan_wall
            .framing_targets
            .iter()
            .find(|(p, _)| p == id)
            .unwrap()
            .1;
        t.translation.y
    };
    let first = studs
        .iter()
        .min_by(|a, b| along(a).total_cmp(&along(b)))
        .unwrap();
    let last = studs
        .iter()
        .max_by(|a, b| along(a).total_cmp(&along(b)))
        .unwrap();
    assert!(beyond(first) && beyond(last), "end studs beyond reach");
    // The reason carries the numbers: distance and reach.
    let reason = &report
        .elements
        .iter()
        .find(|e| &e.id == *first)
        .unwrap()
        .framing
        .reasons[0];
    assert!(
        reason
            .message
            .contains(" m from the shoulder, the arm reaches "),
        "{}",
        reason.message
    );
    // The verdict relation and the simulation fact behind it.
    let failed = sim.reasoned.get("sim_ik_failed");
    assert!(
        failed
            .iter()
            .any(|t| t[0].as_symbol() == Some(first.as_str()))
    );
}

#[test]
fn a_tool_table_in_the_arm_s_path_is_never_driven_through() {
    let cell =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/cells/bad-tool-table.toml");
    let (sim, report) = run("tm2.ifc", cell.to_str().unwrap(), &[]);
    let text = report.to_text();
    let hits: Vec<_> = report
        .contacts
        .iter()
        .filter(|c| c.body_b.starts_with("tool table"))
        .collect();
    // The planner goes around the table or reports the move as blocked; it never drives
    // through it (it used to, and the contacts were recorded).
    assert!(hits.is_empty(), "{text}");
    // The table does stand in the arm's way: a move it blocks is a failure naming it (a run
    // whose arm never came near the table would pass the check above too).
    let blocked: Vec<&str> = sim.records[0]
        .ik
        .iter()
        .filter_map(|r| match &r.result {
            Err(framewright::cell::IkFailure::PathBlocked { pair }) if pair[1] == "tool table" => {
                Some(r.piece.as_str())
            }
            _ => None,
        })
        .collect();
    assert!(!blocked.is_empty(), "{text}");
    for piece in &blocked {
        let e = report.elements.iter().find(|e| e.id == *piece).unwrap();
        assert_eq!(e.framing.status, "failed", "{text}");
        assert!(
            e.framing
                .reasons
                .iter()
                .any(|r| r.message.contains("runs into tool table")
                    && r.message.contains("no way around")),
            "{piece}: {:?}",
            e.framing.reasons
        );
    }
    // Every other piece is placed, or fails for a reason of its own.
    for e in &report.elements {
        assert!(
            e.framing.status == "framed" || !e.framing.reasons.is_empty(),
            "{}: {text}",
            e.id
        );
    }
}

#[test]
fn the_arm_does_not_knock_lumber_off_the_belt_on_its_way_to_a_pick() {
    // On the KUKA cell the tool swung low over conveyor 2 on its way above a stud and a jaw
    // grazed it (0.2 mm), knocking it over: moves now keep a margin from everything.
    let (sim, report) = run_cell("tm2.ifc", fixed_layout("study-kuka", "0.70"), &[]);
    let text = report.to_text();
    assert!(report.contacts.is_empty(), "{text}");
    let studs: Vec<_> = report
        .elements
        .iter()
        .filter(|e| e.role == "stud")
        .collect();
    assert_eq!(studs.len(), 2);
    for e in &studs {
        assert_eq!(e.framing.status, "framed", "{text}");
    }
    assert!(!report.walls[0].framing.failed_component.contains("Gripper"));
    assert_placed_within_2_mm_and_1_degree(&sim, "tm2 on study-kuka");
}

/// The shipped cell with one line of its file replaced (the line starting with `key = `).
fn shipped_cell_with(cell: &str, key: &str, value: f64, dir: &Path) -> String {
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("robots/cells/{cell}.toml"));
    let text = std::fs::read_to_string(shipped).unwrap();
    let mut replaced = 0;
    let lines: Vec<String> = text
        .lines()
        .map(|l| {
            if l.starts_with(&format!("{key} = ")) {
                replaced += 1;
                format!("{key} = {value}")
            } else {
                l.to_string()
            }
        })
        .collect();
    assert_eq!(replaced, 1, "{cell} has one `{key}` line");
    let path = dir.join(format!("{cell}-{key}-{value}.toml"));
    std::fs::write(&path, lines.join("\n")).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn tm1_completes_on_both_robots_on_the_floor_and_on_a_framing_table() {
    // The study: TM1 framed and nailed completely. With the shipped cells each wall is laid
    // where the arm reaches it (the ABB's TM1 at 0.882 m, the study's 0.881 m), and the whole
    // wall is framed and nailed on the floor. Laid where the study laid TM3 (0.531 m), its
    // bottom plate lies where neither arm can fold far enough (joint 3 limit); on a 0.6 m
    // framing table both frame and nail the whole wall.
    let dir = tempfile::tempdir().unwrap();
    for cell in ["study-abb", "study-kuka"] {
        let (auto_sim, auto) = run("tm1.ifc", cell, &[]);
        let text = auto.to_text();
        assert_eq!(auto.walls[0].framing.status, "Completed", "{cell}: {text}");
        assert_eq!(auto.walls[0].nailing.status, "Completed", "{cell}: {text}");
        assert_placed_within_2_mm_and_1_degree(&auto_sim, cell);
        drop(auto_sim);
        let (floor_sim, floor) = run_cell("tm1.ifc", fixed_layout(cell, "0.531"), &[]);
        assert_eq!(floor.walls[0].framing.status, "Partial", "{cell}");
        let bottom = floor
            .elements
            .iter()
            .find(|e| e.role == "bottom_plate")
            .unwrap();
        assert!(
            bottom.framing.reasons[0].message.contains("joint limit"),
            "{cell}: {:?}",
            bottom.framing.reasons
        );
        drop(floor_sim);

        let table = shipped_cell_with(cell, "surface_z", 0.6, dir.path());
        let (sim, report) = run("tm1.ifc", &table, &[]);
        let text = report.to_text();
        assert_eq!(
            report.walls[0].framing.status, "Completed",
            "{cell}: {text}"
        );
        assert_eq!(
            report.walls[0].nailing.status, "Completed",
            "{cell}: {text}"
        );
        assert!(report.contacts.is_empty(), "{cell}: {text}");
        let placements = &sim.records[0].placements;
        assert_eq!(placements.len(), 4);
        // Within 2 mm of targets on the table top: the table holds the wall up.
        assert_placed_within_2_mm_and_1_degree(&sim, cell);
        assert_eq!(report.nailing_validation.checked, 8);
        assert!(report.nailing_validation.max_error_mm < 2.0);
    }
}

#[test]
fn nailing_does_not_shift_the_placed_frame() {
    // With the wall 0.80 m out the ABB reaches TM1's bottom plate and nails into it from the
    // robot's side; the nailer must not push the frame across the floor (the fixture holds
    // placed pieces).
    let dir = tempfile::tempdir().unwrap();
    let cell = shipped_cell_with("study-abb", "offset_x", 0.8, dir.path());
    let (sim, report) = run("tm1.ifc", &cell, &[]);
    let text = report.to_text();
    assert_eq!(report.walls[0].framing.status, "Completed", "{text}");
    assert_eq!(report.walls[0].nailing.status, "Completed", "{text}");
    assert_placed_within_2_mm_and_1_degree(&sim, "study-abb at 0.80 m");
    assert_eq!(report.nailing_validation.checked, 8);
    assert!(report.nailing_validation.max_error_mm < 1.0, "{text}");
}

#[test]
fn two_runs_give_byte_identical_json() {
    let (_, a) = run("tm1.ifc", "study-abb", &[]);
    let (_, b) = run("tm1.ifc", "study-abb", &[]);
    assert_eq!(a.to_json(), b.to_json());
}

#[test]
fn an_unknown_wall_is_an_error_naming_the_walls() {
    let cell = Cell::load("study-abb").unwrap();
    let options = SimOptions {
        walls: vec!["nope".into()],
        ..SimOptions::default()
    };
    let Err(e) = simulate(&model("tm1.ifc"), &cell, &options) else {
        panic!("an unknown wall must be refused");
    };
    let message = e.to_string();
    assert!(
        message.contains("`nope`") && message.contains("Wall 1"),
        "{message}"
    );
}

#[test]
fn simulate_with_user_rules_adds_their_findings_to_the_elements() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_framewright"))
        .args(["simulate", "examples/models/tm1.ifc", "--json", "--rules"])
        .arg(root.join("tests/fixtures/rules/placed_precisely.dl"))
        .current_dir(root)
        .output()
        .expect("runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let elements = report["elements"].as_array().unwrap();
    for e in elements {
        let framed = e["framing"]["status"] == "framed";
        let warned = e["rule_findings"].as_array().is_some_and(|f| {
            f.iter()
                .any(|f| f["rule"] == "placed_precisely" && f["kind"] == "warning")
        });
        // The rule fires exactly on the pieces placed within 2 mm: the framed ones.
        assert_eq!(framed, warned, "{e}");
    }
    assert!(elements.iter().any(|e| e["framing"]["status"] == "framed"));
}
