//! As built: the placed pieces settle, then their rest poses and the nails are measured.

use super::WallRun;
use super::framing::box_symmetries;
use super::nail_plan::NailPlan;
use crate::sim::record::{NailOutcome, Placement};
use nalgebra::{Isometry3, Point3, Vector3};
use std::collections::BTreeMap;

/// How long placed pieces settle before their rest poses are measured (s).
pub(super) const SETTLE_TIME: f64 = 1.0;

impl<'a> WallRun<'a> {
    pub(super) fn settle(&mut self) {
        let home = self.cell.robot.home();
        let tcp = *self.cell.tool.tcp("grip").expect("cells have a grip TCP");
        // A way home that is blocked leaves the arm where it is: nothing left to build.
        let _ = self.move_to(&home, &tcp, &[], self.transfer_speed());
        self.wait(SETTLE_TIME);
    }

    /// Rest poses against targets, and every fired nail's as-built point and member check.
    pub(super) fn measure(&mut self, nails: &[NailPlan]) {
        let mut poses = self.phys.lumber_poses();
        // A ply of a pre-assembled member moved as its member did (the lead's body).
        for (ply, (lead, target)) in &self.plies {
            if let (Some(actual), Some(planned)) = (poses.get(lead), self.placed.get(lead))
                && self.placed.contains_key(ply)
            {
                let moved = actual * nearest_symmetry(planned, actual).inverse();
                poses.insert(ply.clone(), moved * target);
            }
        }
        let mut delta: BTreeMap<String, Isometry3<f64>> = BTreeMap::new();
        for (id, target) in &self.placed {
            let Some(actual) = poses.get(id) else {
                continue;
            };
            let position_error = (actual.translation.vector - target.translation.vector).norm();
            let angle_error = box_symmetries()
                .into_iter()
                .map(|s| (target * s).rotation.angle_to(&actual.rotation))
                .fold(f64::INFINITY, f64::min);
            self.record.placements.push(Placement {
                piece: id.clone(),
                position_error,
                angle_error,
            });
            delta.insert(
                id.clone(),
                actual * nearest_symmetry(target, actual).inverse(),
            );
        }
        // Plies and copies riding in a fed piece by their own sizes.
        let sizes = &self.sizes;
        let wall_inv = self.wall_cell.inverse();
        for record in &mut self.record.nails {
            let NailOutcome::Fired {
                as_built,
                position_error,
                member_inside,
                driven,
                ..
            } = &mut record.outcome
            else {
                continue;
            };
            let Some(nail) = nails
                .iter()
                .find(|n| n.plate == record.plate && n.member == record.member && n.k == record.k)
            else {
                continue;
            };
            let (Some(plate_delta), Some(member_pose), Some(plate_size)) = (
                delta.get(&record.plate),
                poses.get(&record.member),
                sizes.get(record.plate.as_str()),
            ) else {
                continue;
            };
            let planned = self.wall_cell * Point3::from(Vector3::from(nail.uvw));
            let built = plate_delta * planned;
            *position_error = (built - planned).norm();
            let b = wall_inv * built;
            *as_built = [b.x, b.y, b.z];
            // The nail as driven, carried by the as-built plate, must run into the member.
            let direction =
                plate_delta.rotation * (self.wall_cell.rotation * Vector3::from(*driven));
            let plate_pose = poses
                .get(&record.plate)
                .copied()
                .unwrap_or_else(Isometry3::identity);
            let member_size = sizes
                .get(record.member.as_str())
                .copied()
                .unwrap_or([0.0; 3]);
            *member_inside = nail_runs_into(
                &built,
                &direction,
                (&plate_pose, plate_size),
                (member_pose, &member_size),
            );
        }
    }
}

/// The target turned by the box symmetry that brings it nearest `actual`'s orientation (a box
/// has no preferred sign of its axes).
fn nearest_symmetry(target: &Isometry3<f64>, actual: &Isometry3<f64>) -> Isometry3<f64> {
    box_symmetries()
        .into_iter()
        .map(|s| target * s)
        .min_by(|a, b| {
            let ea = a.rotation.angle_to(&actual.rotation);
            let eb = b.rotation.angle_to(&actual.rotation);
            ea.total_cmp(&eb)
        })
        .unwrap_or(*target)
}

/// How far a nail reaches past the plate into the member (m) for the check below.
const MEMBER_PENETRATION: f64 = 0.02;

/// Whether a nail entering at `point` along `direction` (both in the cell frame) runs through
/// the plate and on into the member: the point `MEMBER_PENETRATION` past where the line
/// leaves the plate's box lies inside the member's box (0.5 mm tolerance). Poses are box
/// centres with the boxes' full sizes.
pub(super) fn nail_runs_into(
    point: &Point3<f64>,
    direction: &Vector3<f64>,
    (plate_pose, plate_size): (&Isometry3<f64>, &[f64; 3]),
    (member_pose, member_size): (&Isometry3<f64>, &[f64; 3]),
) -> bool {
    let local_point = plate_pose.inverse() * point;
    let local_dir = plate_pose.rotation.inverse() * direction;
    // Where the line leaves the plate's box (slab method; the point lies on or in it).
    let exit = (0..3)
        .filter(|&i| local_dir[i].abs() > 1e-12)
        .map(|i| (plate_size[i] / 2.0 * local_dir[i].signum() - local_point[i]) / local_dir[i])
        .fold(f64::INFINITY, f64::min)
        .max(0.0);
    let tip = point + direction * (exit + MEMBER_PENETRATION);
    let local = member_pose.inverse() * tip;
    (0..3).all(|i| local[i].abs() <= member_size[i] / 2.0 + 5e-4)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Translation3, UnitQuaternion};

    /// A 2x4 plate on edge along y (38 mm thick along x, 89 mm high) and a stud on edge along
    /// x butting against it, as a wall lies on the floor; the nail enters the plate's outer
    /// face at height `z`, driven along -x leaning `lean` (tip down when positive).
    fn runs_into(z: f64, lean: f64, yaw: f64) -> bool {
        let plate = Isometry3::from_parts(
            Translation3::new(0.019, 0.0, 0.0445),
            UnitQuaternion::identity(),
        );
        let stud = Isometry3::from_parts(
            Translation3::new(-0.5, 0.0, 0.0445),
            UnitQuaternion::identity(),
        );
        let direction = Vector3::new(-lean.cos() * yaw.cos(), yaw.sin(), -lean.sin());
        nail_runs_into(
            &Point3::new(0.038, 0.0, z),
            &direction,
            (&plate, &[0.038, 1.0, 0.089]),
            (&stud, &[1.0, 0.038, 0.089]),
        )
    }

    #[test]
    fn a_square_or_moderately_leaning_nail_runs_into_the_member() {
        assert!(runs_into(0.029, 0.0, 0.0));
        assert!(runs_into(0.029, 15f64.to_radians(), 0.0));
        assert!(runs_into(0.059, -15f64.to_radians(), 0.0));
    }

    #[test]
    fn a_nail_leaving_the_member_is_caught() {
        // 29 mm up, 0.066 m along a line leaning 35° down is 38 mm lower: below the stud.
        assert!(!runs_into(0.029, 35f64.to_radians(), 0.0));
        // Turned 25° sideways, 0.062 m along the line lies 26 mm off a 38 mm stud's centre.
        assert!(!runs_into(0.029, 0.0, 25f64.to_radians()));
        // Missing the stud altogether: a nail entering beside it.
        assert!(!runs_into(0.100, 0.0, 0.0));
    }
}
