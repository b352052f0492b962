//! TCP poses the executor and the placement search both work with: the grip at a piece's
//! centre of mass, the nailer on a nail line, and how low the arm and its tool reach.

use super::layout::Cell;
use super::shapes::{PlacedShape, Shape};
use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// Steps of the grip point from a piece's middle towards either end (m)...
pub const GRIP_SHIFT_STEP: f64 = 0.1;
/// ...keeping the outer gripper this far inside the piece's end (m).
pub const GRIP_END_MARGIN: f64 = 0.05;

/// How far (m) the middle of two grippers `spacing` apart may move from the middle of a piece
/// `length` long while both stay on it, GRIP_END_MARGIN inside its ends.
pub fn two_gripper_reach(length: f64, spacing: f64) -> f64 {
    (length / 2.0 - spacing / 2.0 - GRIP_END_MARGIN).max(0.0)
}

/// The shifts (m, from the piece's middle, 0 first) at which two grippers take a piece: the
/// executor's grips, and what a remedy checks.
pub fn two_gripper_shifts(length: f64, spacing: f64) -> Vec<f64> {
    let furthest = two_gripper_reach(length, spacing);
    (0..)
        .map(|k| k as f64 * GRIP_SHIFT_STEP)
        .take_while(|s| *s <= furthest + 1e-9)
        .collect()
}

/// Roll angles about the nail line tried in turn (0: the flange above the nose): six fixed
/// ones, then the one that turns the tool's x axis towards the robot's base axis through
/// `base` (for a nail at the edge of the reach, the flange then lies nearest the shoulder).
pub fn nail_rolls(point: &Point3<f64>, direction: &Vector3<f64>, base: &Point3<f64>) -> Vec<f64> {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let mut rolls = vec![0.0, FRAC_PI_4, -FRAC_PI_4, FRAC_PI_2, -FRAC_PI_2, PI];
    let z = direction.normalize();
    let x0 = nail_pose(point, direction, 0.0).rotation * Vector3::x();
    let mut to_base = base - point;
    to_base.z = 0.0;
    let towards = to_base - z * to_base.dot(&z);
    if towards.norm() > 1e-6 {
        let t = towards.normalize();
        rolls.push(x0.cross(&t).dot(&z).atan2(x0.dot(&t)));
    }
    rolls
}

/// The step between the leans tried, rad (5°).
const LEAN_STEP: f64 = 5.0 * std::f64::consts::PI / 180.0;

/// The driving directions tried for a nail planned along `direction`, with their lean off it
/// (rad): square first, then leaning in steps of at most 5° up to `max_lean`, the tip down
/// before the tip up, in the vertical plane through the nail (lumber on edge is deepest
/// that way). A vertical nail has no such plane and is driven square.
pub fn nail_lines(direction: &Vector3<f64>, max_lean: f64) -> Vec<(Vector3<f64>, f64)> {
    let d = direction.normalize();
    let mut lines = vec![(d, 0.0)];
    let up = Vector3::z() - d * d.z;
    if max_lean <= 0.0 || up.norm() < 1e-6 {
        return lines;
    }
    let up = up.normalize();
    let steps = (max_lean / LEAN_STEP - 1e-9).ceil().max(1.0) as usize;
    for k in 1..=steps {
        let lean = max_lean * k as f64 / steps as f64;
        for tip in [-up, up] {
            lines.push(((d * lean.cos() + tip * lean.sin()).normalize(), lean));
        }
    }
    lines
}

/// The nail TCP at `point` driving along `direction`, its x axis turned `roll` from up.
pub fn nail_pose(point: &Point3<f64>, direction: &Vector3<f64>, roll: f64) -> Isometry3<f64> {
    let z = direction.normalize();
    let mut x = Vector3::z() - z * z.z;
    if x.norm() < 1e-6 {
        x = Vector3::x() - z * z.x;
    }
    let x =
        UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(z), roll) * x.normalize();
    let y = z.cross(&x);
    let rotation = Rotation3::from_basis_unchecked(&[x, y, z]);
    Isometry3::from_parts(
        Translation3::from(point.coords),
        UnitQuaternion::from_rotation_matrix(&rotation),
    )
}

/// The pose moved back `d` against its z axis (the tool's approach direction).
pub fn retreat(pose: &Isometry3<f64>, d: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(pose.translation.vector - pose.rotation * Vector3::z() * d),
        pose.rotation,
    )
}

/// The grip TCP at a piece's centre of mass, on its top face: z down, y along the piece
/// (reversed when `flip`), x across it (the jaws close along x). `body`: the piece's box
/// frame (x along its length), `size`: length, width, thickness. None when no face is up.
pub fn centre_grip(body: &Isometry3<f64>, size: &[f64; 3], flip: bool) -> Option<Isometry3<f64>> {
    let axes: [Vector3<f64>; 3] = std::array::from_fn(|i| body.rotation * Vector3::ith(i, 1.0));
    let (up_axis, height) = if axes[1].z.abs() >= axes[2].z.abs() {
        (axes[1], size[1])
    } else {
        (axes[2], size[2])
    };
    if up_axis.z.abs() < 0.5 {
        return None;
    }
    let up = up_axis * up_axis.z.signum();
    let z = -up;
    let long = axes[0] - z * axes[0].dot(&z);
    let y = if flip { -long } else { long }.try_normalize(1e-9)?;
    let x = y.cross(&z);
    let rotation = Rotation3::from_basis_unchecked(&[x, y, z]);
    Some(Isometry3::from_parts(
        Translation3::from(body.translation.vector + up * (height / 2.0)),
        UnitQuaternion::from_rotation_matrix(&rotation),
    ))
}

/// The lowest point (cell z) of the moving links and the tool at joint values `q`; the base
/// and the turntable on it (no more than one moving joint above them) are left out.
pub fn lowest_point(cell: &Cell, q: &[f64]) -> f64 {
    let robot = &cell.robot;
    let poses = robot.fk_all(q);
    let poses = &poses;
    let links = robot
        .links
        .iter()
        .enumerate()
        .filter(|(i, _)| robot.moving_joints_above(*i) > 1)
        .flat_map(|(i, link)| {
            link.collisions
                .iter()
                .map(move |c| lowest(&(cell.robot_base * poses[i]), c))
        });
    let tool = cell.robot_base * poses[robot.tip];
    let parts = cell.tool.parts.iter().map(|p| lowest(&tool, &p.shape));
    links.chain(parts).fold(f64::INFINITY, f64::min)
}

/// The lowest z of a placed shape whose owner is at `owner`.
fn lowest(owner: &Isometry3<f64>, shape: &PlacedShape) -> f64 {
    let pose = owner * shape.origin;
    let z = pose.translation.vector.z;
    let axis = |i: usize| (pose.rotation * Vector3::ith(i, 1.0)).z.abs();
    match shape.shape {
        Shape::Box { half_extents: h } => z - (0..3).map(|i| axis(i) * h[i]).sum::<f64>(),
        Shape::Cylinder { radius, length } => {
            let a = axis(2);
            z - a * length / 2.0 - radius * (1.0 - a * a).max(0.0).sqrt()
        }
        Shape::Capsule { radius, length } => z - axis(2) * length / 2.0 - radius,
        Shape::Sphere { radius } => z - radius,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_grip_is_on_the_top_face_pointing_down() {
        // A stud on edge along +x: its width (0.089 m) up.
        let body = Isometry3::from_parts(
            Translation3::new(1.0, 0.5, 0.0445),
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_basis_unchecked(&[
                Vector3::x(),
                Vector3::z(),
                -Vector3::y(),
            ])),
        );
        let g = centre_grip(&body, &[2.3, 0.089, 0.038], false).unwrap();
        assert!((g.translation.vector - Vector3::new(1.0, 0.5, 0.089)).norm() < 1e-12);
        assert!((g.rotation * Vector3::z() + Vector3::z()).norm() < 1e-12);
        assert!((g.rotation * Vector3::y() - Vector3::x()).norm() < 1e-12);
    }

    #[test]
    fn nail_lines_lean_in_the_vertical_plane_square_first() {
        let d = Vector3::new(-1.0, 0.0, 0.0);
        assert_eq!(nail_lines(&d, 0.0), vec![(d, 0.0)]);
        let lines = nail_lines(&d, 12f64.to_radians());
        // Square, then 4°, 8°, 12°, each tip down then up.
        assert_eq!(lines.len(), 7);
        assert_eq!(lines[0], (d, 0.0));
        for (k, (line, lean)) in lines.iter().enumerate().skip(1) {
            let step = k.div_ceil(2);
            assert!((lean - (4.0 * step as f64).to_radians()).abs() < 1e-12);
            assert!((line.angle(&d) - lean).abs() < 1e-9, "{k}");
            assert!(line.y.abs() < 1e-12, "stays in the vertical plane");
            assert_eq!(line.z < 0.0, k % 2 == 1, "tip down first");
        }
        // A vertical nail is driven square.
        assert_eq!(nail_lines(&-Vector3::z(), 0.3).len(), 1);
    }

    #[test]
    fn lowest_point_of_a_tilted_box() {
        // A 0.2 x 0.2 x 0.2 box at z = 1 turned 45° about x: its lowest edge is 0.1·√2 down.
        let shape = PlacedShape {
            origin: Isometry3::identity(),
            shape: Shape::Box {
                half_extents: [0.1, 0.1, 0.1],
            },
        };
        let owner = Isometry3::from_parts(
            Translation3::new(0.0, 0.0, 1.0),
            UnitQuaternion::from_euler_angles(std::f64::consts::FRAC_PI_4, 0.0, 0.0),
        );
        assert!((lowest(&owner, &shape) - (1.0 - 0.1 * 2f64.sqrt())).abs() < 1e-12);
    }
}
