//! The robot on a linear track (`study-abb-track`): the carriage takes the arm along the wall,
//! so pieces the fixed base cannot reach are framed and nailed; what still fails lies beyond
//! the arm's reach from every point of the rail.

use framewright::cell::{Cell, IkFailure};
use framewright::ifc::Model;
use framewright::pipeline::simulate;
use framewright::report::simulate::SimReport;
use framewright::sim::{SimOptions, Simulation};
use std::path::Path;

fn tm3() -> Model {
    Model::open(Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/tm3.ifc"))
        .expect("bundled model")
}

/// Wall W1 of the bundled TM3: 6.86 m long, longer than the fixed arm can cover.
fn run(cell: &str) -> (Cell, Simulation, SimReport) {
    let cell = Cell::load(cell).expect("shipped cell");
    let options = SimOptions {
        walls: vec!["W1".into()],
        ..SimOptions::default()
    };
    let sim = simulate(&tm3(), &cell, &options).expect("simulation runs");
    let report = SimReport::new(&sim, options.dt).expect("report");
    (cell, sim, report)
}

fn unplaced(sim: &Simulation) -> Vec<String> {
    let placed: Vec<&str> = sim.records[0]
        .placements
        .iter()
        .map(|p| p.piece.as_str())
        .collect();
    let wall = &sim.records[0].wall;
    sim.scene
        .pieces
        .iter()
        .filter(|p| &p.wall == wall && !placed.contains(&p.id.as_str()))
        .map(|p| p.id.clone())
        .collect()
}

#[test]
fn the_track_frames_what_the_fixed_base_cannot_and_the_rest_lies_beyond_reach_of_the_rail() {
    let (_, fixed, _) = run("study-abb");
    let (cell, track, report) = run("study-abb-track");
    let text = report.to_text();
    let fixed_missing = unplaced(&fixed);
    let track_missing = unplaced(&track);
    // Every piece the track leaves out, the fixed base leaves out too, and the fixed base
    // leaves out studs at both ends of the wall that the track frames.
    assert!(
        track_missing.iter().all(|p| fixed_missing.contains(p)),
        "{track_missing:?} vs {fixed_missing:?}"
    );
    let role = |id: &str| {
        report
            .elements
            .iter()
            .find(|e| e.id == id)
            .map(|e| e.role.clone())
            .unwrap_or_default()
    };
    let studs_gained = fixed_missing
        .iter()
        .filter(|p| !track_missing.contains(p) && role(p) == "stud")
        .count();
    assert!(studs_gained >= 2, "{text}");
    // What still fails is out of reach from every carriage position. The carriage changes
    // only where the base stands along the rail, so a point's distance from the arm's shoulder
    // is smallest with the base abeam of it: a grip pose (pointing down on the piece's top)
    // out of reach there is out of reach everywhere. And the pieces left out are the ones
    // farthest from the rail.
    let t = cell.track.expect("the cell has a track");
    let grip = *cell.tool.tcp("grip").expect("grip TCP");
    let home = cell.robot.home();
    let from_rail = |p: &nalgebra::Point3<f64>| {
        let d = p.coords - t.home.translation.vector;
        (d - t.direction * d.dot(&t.direction)).norm()
    };
    let placed_farthest = track.records[0]
        .placements
        .iter()
        .filter_map(|pl| track.scene.pieces.iter().find(|p| p.id == pl.piece))
        .map(|p| from_rail(&(cell.robot_base * p.target_robot * nalgebra::Point3::origin())))
        .fold(0.0, f64::max);
    for id in &track_missing {
        let piece = track.scene.pieces.iter().find(|p| &p.id == id).unwrap();
        let body = cell.robot_base * piece.target_robot;
        let centre = body * nalgebra::Point3::origin();
        assert!(
            from_rail(&centre) > placed_farthest,
            "{id} ({}) is left out nearer the rail ({:.3} m) than a placed piece ({placed_farthest:.3} m)",
            role(id),
            from_rail(&centre)
        );
        let top = centre + nalgebra::Vector3::z() * (piece.size[1].min(piece.size[2]) / 2.0);
        let along = body.rotation * nalgebra::Vector3::x();
        let down = -nalgebra::Vector3::z();
        let rotation =
            nalgebra::Rotation3::from_basis_unchecked(&[along.cross(&down), along, down]);
        let pose = nalgebra::Isometry3::from_parts(
            nalgebra::Translation3::from(top.coords),
            nalgebra::UnitQuaternion::from_rotation_matrix(&rotation),
        );
        let abeam = t.base_at(t.abeam(&top));
        let ik = cell.robot.ik(&(abeam.inverse() * pose), &grip, &home);
        assert!(
            matches!(ik, Err(IkFailure::OutOfReach { .. })),
            "{id} ({}) is left out, but the arm abeam of it gives {ik:?}",
            role(id)
        );
        let reasons = &report
            .elements
            .iter()
            .find(|e| &e.id == id)
            .unwrap()
            .framing
            .reasons;
        assert!(
            reasons.iter().any(|r| r.message.contains("beyond reach")),
            "{id}: {reasons:?}"
        );
    }
    // The carriage moved: the base (tool0 less the arm's forward kinematics) travels along
    // the rail over most of the wall's length, and the arm touched nothing on the way.
    let trace = &track.records[0].trace;
    let ys: Vec<f64> = trace
        .tool
        .iter()
        .zip(&trace.joints)
        .map(|(tool, q)| (tool * cell.robot.fk_tip(q).inverse()).translation.y)
        .collect();
    let (lo, hi) = ys
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
            (a.min(*y), b.max(*y))
        });
    assert!(hi - lo > 3.0, "the base travelled {lo:.2}..{hi:.2} m");
    assert!(lo >= t.travel[0] - 1e-6 && hi <= t.travel[1] + 1e-6);
    assert!(report.contacts.is_empty(), "{text}");
}

#[test]
fn a_track_run_is_deterministic() {
    assert_eq!(
        run("study-abb-track").2.to_json(),
        run("study-abb-track").2.to_json()
    );
}

#[test]
fn a_bad_track_is_refused_naming_the_key() {
    let text = include_str!("../robots/cells/study-abb-track.toml");
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("robots/cells/x.toml");
    for (from, to, key) in [
        ("speed = 1.0 ", "speed = 0.0 ", "speed"),
        ("length = 6.0", "length = -6.0", "length"),
        ("accel = 1.0", "accel = nan", "accel"),
    ] {
        let bad = text.replacen(from, to, 1);
        assert_ne!(bad, text);
        let err = Cell::from_toml(&dir, &bad)
            .expect_err("refused")
            .to_string();
        assert!(err.contains("track") && err.contains(key), "{err}");
    }
}
