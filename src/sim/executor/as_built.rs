//! As built: the placed pieces settle, then their rest poses and the nails are measured.

use super::WallRun;
use super::framing::box_symmetries;
use super::nailing::NailPlan;
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
        let poses = self.phys.lumber_poses();
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
            let best = box_symmetries()
                .into_iter()
                .min_by(|a, b| {
                    let ea = (target * a).rotation.angle_to(&actual.rotation);
                    let eb = (target * b).rotation.angle_to(&actual.rotation);
                    ea.total_cmp(&eb)
                })
                .unwrap_or_else(Isometry3::identity);
            delta.insert(id.clone(), actual * (target * best).inverse());
        }
        let sizes: BTreeMap<&str, [f64; 3]> = self
            .pieces
            .iter()
            .map(|p| (p.id.as_str(), p.size))
            .collect();
        let wall_inv = self.wall_cell.inverse();
        for record in &mut self.record.nails {
            let NailOutcome::Fired {
                as_built,
                position_error,
                member_inside,
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
            // A point past the plate, along the as-built nail line, must lie in the member.
            let direction = plate_delta.rotation * (self.wall_cell.rotation * nail.direction);
            let plate_pose = poses
                .get(&record.plate)
                .copied()
                .unwrap_or_else(Isometry3::identity);
            let local_dir = plate_pose.rotation.inverse() * direction;
            let depth: f64 = (0..3).map(|i| local_dir[i].abs() * plate_size[i]).sum();
            let tip = built + direction * (depth + 0.02);
            let member_size = sizes
                .get(record.member.as_str())
                .copied()
                .unwrap_or([0.0; 3]);
            let local = member_pose.inverse() * tip;
            *member_inside = (0..3).all(|i| local[i].abs() <= member_size[i] / 2.0 + 5e-4);
        }
    }
}
