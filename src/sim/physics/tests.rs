use super::world::*;
use super::*;
use crate::cell::Cell;
use crate::world::ScenePiece;
use nalgebra::Isometry3;
use rapier3d::prelude::*;

/// A 0.5 m piece standing on conveyor 1's deck, its centre on the deck's centre.
fn piece_on_deck(cell: &Cell) -> (ScenePiece, Isometry3<f64>) {
    let size = [0.5, 0.1, 0.1];
    let pose = cell.conveyor1.pose * Isometry3::translation(0.0, 0.0, size[2] / 2.0);
    let piece = ScenePiece {
        id: "p".into(),
        name: "p".into(),
        ifc_type: "IfcMember".into(),
        wall: "W1".into(),
        slot: 0,
        size,
        material: "wood".into(),
        density: 450.0,
        mass: 450.0 * size.iter().product::<f64>(),
        spawn: pose,
        beyond_belt: None,
        target_robot: pose,
        target_cell: pose,
        on_edge: true,
        plies: Vec::new(),
    };
    (piece, pose)
}

/// A world with piece "p" on conveyor 1 and the belts running.
fn piece_on_running_belt(cell: &Cell, dt: f64) -> Physics {
    let mut phys = Physics::new(cell, &cell.robot.home(), dt);
    let (piece, pose) = piece_on_deck(cell);
    phys.add_lumber(&piece, &pose);
    phys.set_belts(true, false);
    phys
}

#[test]
fn a_riding_piece_moves_at_the_belt_speed_and_is_dynamic_again_when_the_belts_stop() {
    let cell = Cell::load("study-abb").expect("cell");
    let dt = 1.0 / 240.0;
    let mut phys = piece_on_running_belt(&cell, dt);
    for _ in 0..240 {
        phys.step();
    }
    let before = phys.lumber_pose("p").expect("piece");
    let velocity = cell.conveyor1.direction() * cell.conveyor1.speed;
    phys.start_ride("p", &velocity);
    let steps = 480;
    for _ in 0..steps {
        phys.step();
    }
    let after = phys.lumber_pose("p").expect("piece");
    let expected = velocity * (steps as f64 * dt);
    let moved = after.translation.vector - before.translation.vector;
    // The world is f32: each step rounds the position by up to about one unit in the last
    // place at the piece's distance from the origin.
    let rounding = steps as f64 * 2.0 * f64::from(f32::EPSILON) * after.translation.vector.amax();
    assert!(
        (moved - expected).norm() < rounding,
        "moved {moved:?}, the belt {expected:?}"
    );
    assert!(after.rotation.angle_to(&before.rotation) < 1e-6);
    let body = phys.lumber["p"].body;
    assert!(phys.world.bodies[body].is_kinematic());
    // Stopping the belts ends the ride: a dynamic body at rest.
    phys.set_belts(false, false);
    assert!(phys.world.bodies[body].is_dynamic());
    assert!(phys.lumber_speed("p").expect("piece").0 < 1e-9);
}

#[test]
fn a_parked_rider_stays_put_without_the_solver_and_is_dynamic_when_the_belts_start() {
    let cell = Cell::load("study-abb").expect("cell");
    let dt = 1.0 / 240.0;
    let mut phys = piece_on_running_belt(&cell, dt);
    let velocity = cell.conveyor1.direction() * cell.conveyor1.speed;
    phys.start_ride("p", &velocity);
    for _ in 0..24 {
        phys.step();
        phys.advance_rides(dt);
    }
    phys.set_belts(false, true);
    let body = phys.lumber["p"].body;
    let parked_at = phys.lumber_pose("p").expect("piece");
    // Parked: kinematic, at rest, not counted as lumber the solver must watch.
    assert!(phys.world.bodies[body].is_kinematic());
    assert!(phys.lumber_calm(1e-9, 1e-9));
    for _ in 0..240 {
        phys.step();
        phys.advance_rides(dt);
    }
    assert_eq!(phys.lumber_pose("p").expect("piece"), parked_at);
    // The robot's clearance sees it as parked lumber.
    let clear = phys.clearance(&cell.robot.home(), None, 100.0, EVERY_TOUCH);
    assert!(clear.parked < 100.0 && clear.parked >= clear.loose);
    // Starting the belts leaves it as stopping them without parking does: dynamic, at rest.
    phys.set_belts(true, false);
    assert!(phys.world.bodies[body].is_dynamic());
    assert!(!phys.is_riding("p"));
    assert!(phys.lumber_speed("p").expect("piece").0 < 1e-9);
    assert_eq!(phys.lumber_pose("p").expect("piece"), parked_at);
}

#[test]
fn unparking_makes_parked_lumber_dynamic_at_rest() {
    let cell = Cell::load("study-abb").expect("cell");
    let mut phys = piece_on_running_belt(&cell, 1.0 / 240.0);
    phys.start_ride("p", &(cell.conveyor1.direction() * cell.conveyor1.speed));
    phys.set_belts(false, true);
    let generation = phys.generation();
    phys.unpark();
    let body = phys.lumber["p"].body;
    assert!(phys.world.bodies[body].is_dynamic());
    assert!(!phys.is_riding("p"));
    assert!(
        phys.generation() > generation,
        "unparking changes the world"
    );
    assert_eq!(
        phys.clearance(&cell.robot.home(), None, 100.0, EVERY_TOUCH)
            .parked,
        100.0
    );
    // A standing belt carries nothing: no ride starts on it.
    phys.start_ride("p", &(cell.conveyor1.direction() * cell.conveyor1.speed));
    assert!(!phys.is_riding("p") && phys.world.bodies[body].is_dynamic());
}

#[test]
fn advancing_a_ride_without_the_solver_moves_it_as_steps_do_and_clearance_sees_it_there() {
    let cell = Cell::load("study-abb").expect("cell");
    let dt = 1.0 / 240.0;
    let velocity = cell.conveyor1.direction() * cell.conveyor1.speed;
    let ride = |advance: bool| {
        let mut phys = Physics::new(&cell, &cell.robot.home(), dt);
        let (piece, pose) = piece_on_deck(&cell);
        phys.add_lumber(&piece, &pose);
        phys.set_belts(true, false);
        phys.start_ride("p", &velocity);
        for _ in 0..480 {
            if advance {
                phys.advance_rides(dt);
            } else {
                phys.step();
            }
        }
        phys
    };
    let stepped = ride(false).lumber_pose("p").expect("piece");
    let advanced_world = ride(true);
    let advanced = advanced_world.lumber_pose("p").expect("piece");
    let expected = (velocity * 480.0 * dt).norm();
    assert!(expected > 0.05, "the ride covers {expected} m");
    // Against the belt's travel: the advanced ride is off by the f32 rounding of its
    // start and end (not per step); the stepped one within rapier's per-step rounding.
    let start = piece_on_deck(&cell).1.translation.vector;
    let error =
        |pose: &Isometry3<f64>| (pose.translation.vector - start - velocity * 480.0 * dt).norm();
    let ulp = f64::from(f32::EPSILON) * advanced.translation.vector.amax();
    assert!(
        error(&advanced) < 4.0 * ulp,
        "advanced ride off by {}",
        error(&advanced)
    );
    assert!(
        error(&stepped) < 480.0 * 2.0 * ulp,
        "stepped ride off by {}",
        error(&stepped)
    );
    assert!((advanced_world.ride_speed() - cell.conveyor1.speed).abs() < 1e-6);
    // The rider counts as loose where it is now, not where the broad phase last saw it:
    // its distance to the robot at home equals that of a world stepped to the same place.
    let home = cell.robot.home();
    let measured = |phys: &Physics| phys.clearance(&home, None, 100.0, EVERY_TOUCH);
    let (a, b) = (measured(&ride(false)), measured(&advanced_world));
    // (within the stepped ride's rounding; the broad phase's stale place is the whole
    // ride, 0.1 m, away)
    assert!(
        (a.loose - b.loose).abs() < 1e-3,
        "{} vs {}",
        a.loose,
        b.loose
    );
    assert!(b.loose < 100.0);
}

/// The robot's bodies move when looked at (`place_robot` is lazy): the held piece is seen
/// where the grip puts it on the tool at the last joints asked for, before and after the
/// bodies move, and the tool body stands at those joints afterwards.
#[test]
fn a_placement_is_seen_before_the_bodies_move_where_they_then_move() {
    let cell = Cell::load("study-abb").expect("cell");
    let mut phys = piece_on_running_belt(&cell, 1.0 / 240.0);
    phys.attach("p");
    let in_tool = Isometry3::translation(0.01, -0.02, 0.2);
    let home = cell.robot.home();
    let near = |a: &Isometry3<f64>, b: &Isometry3<f64>| {
        (a.translation.vector - b.translation.vector).norm() < 1e-5
            && a.rotation.angle_to(&b.rotation) < 1e-5
    };
    let mut last = None;
    for k in 1..=5 {
        let q: Vec<f64> = home
            .iter()
            .enumerate()
            .map(|(j, v)| v + 0.01 * k as f64 * (j as f64 + 1.0))
            .collect();
        phys.place_robot(&q, Some(("p", &in_tool)));
        let seen = phys.lumber_pose("p").expect("piece");
        let tool = cell.robot_base * cell.robot.fk_tip(&q);
        assert!(near(&seen, &(tool * in_tool)), "k = {k}");
        assert_eq!(phys.lumber_poses_in_order()[0], ("p", seen));
        last = Some((tool, seen));
    }
    let (tool, seen) = last.expect("placed");
    phys.detect();
    assert_eq!(
        phys.lumber_pose("p"),
        Some(seen),
        "the body is where it was seen"
    );
    assert!(near(
        &to_iso(phys.world.bodies[phys.tool].position()),
        &tool
    ));
}

/// Every touch, at any depth.
const EVERY_TOUCH: Watch = Watch::AllBut {
    bodies: &[],
    tolerance: 0.0,
};

/// How far the held piece is from a recorded touch when it lies `gap` from a clamped piece
/// end to end (negative: pressed that deep into it), leaving out the pieces `ignored`.
fn held_piece_to_record(gap: f64, ignored: &[String]) -> f64 {
    let cell = Cell::load("study-abb").expect("cell");
    let home = cell.robot.home();
    let mut phys = Physics::new(&cell, &home, 1.0 / 240.0);
    let (mut piece, _) = piece_on_deck(&cell);
    let in_tool = Isometry3::translation(0.0, 0.0, 0.3);
    let held_at = cell.robot_base * cell.robot.fk_tip(&home) * in_tool;
    phys.add_lumber(&piece, &held_at);
    piece.id = "w".into();
    let beside = held_at * Isometry3::translation(piece.size[0] + gap, 0.0, 0.0);
    phys.add_lumber(&piece, &beside);
    phys.attach("p");
    phys.clamp("w");
    phys.place_robot(&home, Some(("p", &in_tool)));
    phys.detect();
    let probe = phys.probe(&home, Some(("p", &in_tool)));
    let held = probe.held_shape().expect("the held piece is a shape");
    let watch = Watch::AllBut {
        bodies: ignored,
        tolerance: 0.001,
    };
    phys.shape_clearance(&probe, held, 0.1, watch).any
}

#[test]
fn a_held_piece_is_a_recorded_touch_only_deeper_than_the_tolerance() {
    // Apart: the gap plus the depth that goes unrecorded.
    assert!((held_piece_to_record(0.003, &[]) - 0.004).abs() < 1e-5);
    // Pressed in less than the tolerance: not yet a recorded touch.
    assert!((held_piece_to_record(-0.0005, &[]) - 0.0005).abs() < 1e-5);
    // Deeper: recorded, by how much.
    assert!((held_piece_to_record(-0.002, &[]) + 0.001).abs() < 1e-5);
    // A piece the operation may touch is left out.
    assert!(held_piece_to_record(-0.002, &["piece w".to_string()]) > 0.05);
}

#[test]
fn joint_levers_bound_how_far_every_corner_of_each_shape_moves() {
    for name in ["study-abb", "study-kuka"] {
        let cell = Cell::load(name).expect("cell");
        let phys = Physics::new(&cell, &cell.robot.home(), 1.0 / 240.0);
        let home = cell.robot.home();
        let at_home = phys.probe(&home, None);
        let slack = 0.10;
        let mut checked = 0;
        for i in 0..at_home.shape_count() {
            let corners = phys.shape_corners(&at_home, i);
            let levers = phys.levers(&at_home, i, slack);
            let mut farthest: f64 = 0.0;
            // Small moves of every joint together, both ways: each corner moves no
            // further than the bound while the bound stays under the slack.
            for k in 0..200 {
                let dq: Vec<f64> = (0..home.len())
                    .map(|j| 0.004 * (((k * 7 + j * 3) % 11) as f64 - 5.0) / 5.0)
                    .collect();
                let q: Vec<f64> = home.iter().zip(&dq).map(|(a, d)| a + d).collect();
                let bound: f64 = dq.iter().zip(&levers).map(|(d, l)| d.abs() * l).sum();
                if bound >= slack {
                    continue;
                }
                let moved = phys
                    .shape_corners(&phys.probe(&q, None), i)
                    .iter()
                    .zip(&corners)
                    .map(|(a, b)| (a - b).norm())
                    .fold(0.0, f64::max);
                assert!(
                    moved <= bound + 1e-9,
                    "{name} shape {i}: moved {moved} > bound {bound}"
                );
                farthest = farthest.max(moved);
                checked += 1;
            }
            // The moves move every shape (the bound is not checked on a standstill).
            assert!(farthest > 0.0, "{name} shape {i} never moved");
        }
        assert!(
            checked > 100 * at_home.shape_count(),
            "{name}: only {checked} moves within the slack"
        );
    }
}
