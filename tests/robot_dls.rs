//! The numeric IK fallback on arms without a closed form (fixtures: a 7-axis arm, a 6-axis arm
//! whose wrist axes do not meet, a 5-axis arm). A returned solution always reproduces the pose;
//! a pose the arm cannot take is refused with the residual.

use framewright::cell::{IkFailure, Robot};
use nalgebra::{Isometry3, UnitQuaternion, Vector3};
use std::path::Path;

fn fixture(name: &str) -> Robot {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures/robots")
        .join(name);
    Robot::load(path.to_str().unwrap()).unwrap()
}

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Joints inside the limits, at most ±π (so a sample does not sit on a limit stop).
    fn joints(&mut self, robot: &Robot) -> Vec<f64> {
        robot
            .limits()
            .iter()
            .map(|&(lo, hi)| {
                let (lo, hi) = (lo.max(-3.0) * 0.9, hi.min(3.0) * 0.9);
                lo + (hi - lo) * self.next()
            })
            .collect()
    }
}

fn exact(robot: &Robot, q: &[f64], pose: &Isometry3<f64>) -> bool {
    let got = robot.fk_tip(q);
    (got.translation.vector - pose.translation.vector).norm() <= 1e-6
        && got.rotation.angle_to(&pose.rotation) <= 1e-6
}

fn within_limits(robot: &Robot, q: &[f64]) -> bool {
    q.iter()
        .zip(robot.limits())
        .all(|(v, (lo, hi))| *v >= lo && *v <= hi)
}

/// Round trip from a near seed (tracking a path) must always succeed; from the home pose most
/// poses must. Every answer is checked.
fn round_trip(name: &str, n: usize, min_cold_success: f64) {
    let robot = fixture(name);
    assert!(!robot.has_closed_form_ik());
    let tcp = Isometry3::identity();
    let mut rng = Lcg(11);
    let mut cold = 0;
    for i in 0..n {
        let q = rng.joints(&robot);
        let pose = robot.fk_tip(&q);
        let near: Vec<f64> = q.iter().map(|v| v + 0.2 * (rng.next() - 0.5)).collect();
        let sols = robot
            .ik(&pose, &tcp, &near)
            .unwrap_or_else(|e| panic!("{name} #{i}: {e}"));
        assert_eq!(sols.len(), 1);
        assert!(
            exact(&robot, &sols[0], &pose) && within_limits(&robot, &sols[0]),
            "{name} #{i}"
        );
        match robot.ik(&pose, &tcp, &robot.home()) {
            Ok(sols) => {
                assert!(exact(&robot, &sols[0], &pose) && within_limits(&robot, &sols[0]));
                cold += 1;
            }
            Err(IkFailure::NoExactSolution {
                position_error,
                rotation_error,
            }) => {
                assert!(position_error > 1e-6 || rotation_error > 1e-6);
            }
            Err(other) => panic!("{name} #{i}: reachable pose reported as {other}"),
        }
    }
    let rate = cold as f64 / n as f64;
    eprintln!("{name}: {cold}/{n} solved from the home pose");
    assert!(
        rate >= min_cold_success,
        "{name}: only {cold}/{n} solved from the home pose"
    );
}

#[test]
fn seven_axis_arm_round_trip() {
    round_trip("arm7.urdf", 300, 0.95);
}

#[test]
fn non_spherical_wrist_arm_round_trip() {
    round_trip("ur_like6.urdf", 300, 0.95);
}

#[test]
fn five_axis_arm_solves_its_own_poses_and_refuses_others() {
    let robot = fixture("arm5.urdf");
    assert_eq!(robot.dof(), 5);
    let tcp = Isometry3::identity();
    let mut rng = Lcg(3);
    let (mut refused, mut n) = (0, 0);
    for i in 0..200 {
        let q = rng.joints(&robot);
        let pose = robot.fk_tip(&q);
        let near: Vec<f64> = q.iter().map(|v| v + 0.1 * (rng.next() - 0.5)).collect();
        let sols = robot
            .ik(&pose, &tcp, &near)
            .unwrap_or_else(|e| panic!("#{i}: {e}"));
        assert!(exact(&robot, &sols[0], &pose));
        // Tilt the pose about an axis the arm cannot turn about: no 5-axis configuration takes it.
        let tilt = UnitQuaternion::from_axis_angle(&(pose.rotation * Vector3::x_axis()), 0.3);
        let off = Isometry3::from_parts(pose.translation, tilt * pose.rotation);
        n += 1;
        match robot.ik(&off, &tcp, &near) {
            Ok(sols) => assert!(
                exact(&robot, &sols[0], &off),
                "#{i}: a wrong answer returned as a solution"
            ),
            Err(IkFailure::NoExactSolution {
                position_error,
                rotation_error,
            }) => {
                assert!(position_error > 1e-6 || rotation_error > 1e-6);
                refused += 1;
            }
            Err(other) => panic!("#{i}: {other}"),
        }
    }
    assert_eq!(refused, n, "every tilted pose is refused");
}

#[test]
fn numeric_ik_reports_out_of_reach() {
    let robot = fixture("arm7.urdf");
    let pose = Isometry3::translation(2.0, 0.5, 0.3);
    match robot.ik(&pose, &Isometry3::identity(), &robot.home()) {
        Err(IkFailure::OutOfReach {
            distance, reach, ..
        }) => {
            assert!(
                distance > reach && (reach - 0.976).abs() < 1e-9,
                "{distance} {reach}"
            );
        }
        other => panic!("expected out_of_reach, got {other:?}"),
    }
}
