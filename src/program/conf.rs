//! The arm configuration a controller stores with a Cartesian target, so that it takes the
//! same joint solution as the simulation: ABB's `confdata` (quadrants of axes 1, 4 and 6 and
//! `cfx`) and KUKA's Status and Turn bits. Both are read off the simulated joints with the
//! robot's own forward kinematics (where the wrist centre lies), not from a table per model.

use crate::cell::Robot;
use nalgebra::{Point3, Vector3};

/// Where the arm is at some joint values, as the configuration data ask.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArmPosture {
    /// The wrist centre lies behind axis 1 (negative x in the frame that turns with axis 1):
    /// KUKA's overhead area.
    pub behind_axis1: bool,
    /// The wrist centre lies behind the lower arm (the line from axis 2 to axis 3).
    pub behind_lower_arm: bool,
    /// The elbow is bent so that axis 3 stands at or beyond the stretched arm's angle φ
    /// (KUKA Status bit 1: A3 ≥ φ).
    pub elbow_at_or_past_stretch: bool,
}

/// The posture of the robot at `q`; None for a robot of fewer than six joints.
pub fn posture(robot: &Robot, q: &[f64]) -> Option<ArmPosture> {
    if robot.dof() < 6 {
        return None;
    }
    let poses = robot.fk_all(q);
    // Each moving joint's axis as a line in the base frame: through its child link's origin
    // (every link sits on its joint's axis), along the joint's axis.
    let lines: Vec<(Point3<f64>, Vector3<f64>)> = robot
        .active_joints()
        .take(6)
        .map(|j| {
            let pose = poses[j.child];
            (
                Point3::from(pose.translation.vector),
                pose.rotation * j.axis.into_inner(),
            )
        })
        .collect();
    let wrist = closest_point(&lines[4], &lines[3]);
    let a1 = &poses[robot.active_joints().next()?.child];
    let x1 = a1.rotation * Vector3::x();
    let y1 = a1.rotation * Vector3::y();
    let (p1, p2, p3) = (lines[0].0, lines[1].0, lines[2].0);
    let behind_axis1 = (wrist - p1).dot(&x1) < 0.0;
    let behind_lower_arm = (p3 - p2).cross(&(wrist - p2)).dot(&y1) < 0.0;
    // The elbow's bend measured about axis 3 itself, so that it grows with axis 3's value.
    let bend = (p3 - p2).cross(&(wrist - p3)).dot(&lines[2].1);
    Some(ArmPosture {
        behind_axis1,
        behind_lower_arm,
        elbow_at_or_past_stretch: bend >= 0.0,
    })
}

/// The point on line `a` closest to line `b` (their intersection when they meet).
fn closest_point(a: &(Point3<f64>, Vector3<f64>), b: &(Point3<f64>, Vector3<f64>)) -> Point3<f64> {
    let (pa, da) = (a.0, a.1.normalize());
    let (pb, db) = (b.0, b.1.normalize());
    let w = pa - pb;
    let (dd, ea, eb) = (da.dot(&db), da.dot(&w), db.dot(&w));
    let denom = 1.0 - dd * dd;
    if denom.abs() < 1e-12 {
        return pa;
    }
    let s = (dd * eb - ea) / denom;
    pa + da * s
}

/// A joint this close to a quadrant's boundary (rad) counts as on it: the simulation's
/// joints carry rounding noise (−1e−16 on an axis at 0; a target printed to 1 µm solves
/// to joints some 1e−7 rad apart), and the program prints
/// the value rounded, so the configuration must read as the printed value does.
const ON_BOUNDARY: f64 = 1e-6;

/// ABB quadrant of a joint angle: 0 for [0°, 90°), 1 for [90°, 180°), −1 for [−90°, 0°), …
pub fn quadrant(angle: f64) -> i64 {
    ((angle + ON_BOUNDARY) / std::f64::consts::FRAC_PI_2).floor() as i64
}

/// Whether a joint value is below zero (beyond rounding noise).
fn negative(angle: f64) -> bool {
    angle < -ON_BOUNDARY
}

/// ABB `confdata` [cf1, cf4, cf6, cfx] of joint values `q` (rad) with their posture.
pub fn abb_confdata(q: &[f64], posture: &ArmPosture) -> [i64; 4] {
    let cfx = 4 * i64::from(posture.behind_axis1)
        + 2 * i64::from(posture.behind_lower_arm)
        + i64::from(negative(q[4]));
    [quadrant(q[0]), quadrant(q[3]), quadrant(q[5]), cfx]
}

/// KUKA Status: bit 0 overhead area, bit 1 A3 ≥ φ, bit 2 A5 ≤ 0.
pub fn kuka_status(q: &[f64], posture: &ArmPosture) -> u32 {
    u32::from(posture.behind_axis1)
        | u32::from(posture.elbow_at_or_past_stretch) << 1
        | u32::from(!negative(-q[4])) << 2
}

/// KUKA Turn: bit i set where axis i+1 is below 0°.
pub fn kuka_turn(q: &[f64]) -> u32 {
    q.iter()
        .take(6)
        .enumerate()
        .map(|(i, v)| u32::from(negative(*v)) << i)
        .sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::Robot;

    fn robot(name: &str) -> Robot {
        crate::cell::Cell::load(name).expect("built-in cell").robot
    }

    #[test]
    fn quadrants_follow_abb_counting() {
        let deg = |d: f64| d.to_radians();
        assert_eq!(quadrant(deg(0.0)), 0);
        assert_eq!(quadrant(deg(89.0)), 0);
        assert_eq!(quadrant(deg(95.0)), 1);
        assert_eq!(quadrant(deg(-10.0)), -1);
        assert_eq!(quadrant(deg(-100.0)), -2);
        assert_eq!(quadrant(deg(370.0)), 4);
    }

    #[test]
    fn abb_zero_pose_is_configuration_zero() {
        // Lower arm upright, forearm level and forward, axis 5 tilted positive: the wrist
        // centre is in front of axis 1 and of the lower arm.
        let r = robot("study-abb");
        let q = [0.0, 0.0, 0.0, 0.0, 0.5, 0.0];
        let p = posture(&r, &q).expect("six joints");
        assert_eq!(abb_confdata(&q, &p), [0, 0, 0, 0]);
        // Axis 1 half a turn round does not move the wrist behind axis 1 (the frame turns).
        let q = [3.0, 0.0, 0.0, 0.0, -0.5, 0.0];
        let p = posture(&r, &q).expect("six joints");
        assert_eq!(abb_confdata(&q, &p), [1, 0, 0, 1]);
        // Lower arm and forearm swung back over the base: behind axis 1 and the lower arm.
        let q = [0.0, -1.2, -2.5, 0.0, 0.5, 0.0];
        let p = posture(&r, &q).expect("six joints");
        assert!(p.behind_axis1 && p.behind_lower_arm, "{p:?}");
    }

    #[test]
    fn kuka_home_is_status_2() {
        // KUKA HOME {A1 0, A2 -90, A3 90, A4 0, A5 30, A6 0}: basic area, A3 ≥ φ, A5 > 0.
        let r = robot("study-kuka");
        let q: Vec<f64> = [0.0f64, -90.0, 90.0, 0.0, 30.0, 0.0]
            .iter()
            .map(|d| d.to_radians())
            .collect();
        let p = posture(&r, &q).expect("six joints");
        assert_eq!(kuka_status(&q, &p), 0b010);
        assert_eq!(kuka_turn(&q), 0b000010);
        // The elbow bent the other way (A3 well below φ) clears bit 1.
        let mut down = q.clone();
        down[2] = (-60f64).to_radians();
        let p = posture(&r, &down).expect("six joints");
        assert_eq!(kuka_status(&down, &p) & 0b010, 0);
    }
}
