//! Joint motion between poses that keeps the arm, its tool and a held piece clear of the cell.

use super::WallRun;
use crate::sim::motion::JointMove;
use crate::sim::reach::{solve, touches};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// How far the arm, its tool and a held piece keep from everything on a move between poses
/// (m): a kinematic arm grazing a piece on the belt knocks it over.
pub(super) const PATH_MARGIN: f64 = 0.005;
/// Travel over which the margin grows from nothing at a move's ends to PATH_MARGIN (m).
pub(super) const MARGIN_TAPER: f64 = 0.05;
/// Largest travel of any point of the arm between two checked samples of a move (m).
pub(super) const SWEEP_STEP: f64 = 0.02;

impl<'a> WallRun<'a> {
    /// A collision-checked joint move from the current joints to `to`: straight in joint
    /// space if that is clear, else over the highest of a few raised waypoints that are; if
    /// none is clear, straight (the contacts are then recorded as they happen).
    pub(super) fn move_to(
        &mut self,
        to: &[f64],
        tcp: &Isometry3<f64>,
        ignore: &[&str],
        speed: f64,
    ) {
        let from = self.q.clone();
        let path = self.clear_path(&from, to, tcp, ignore);
        for q in path.windows(2) {
            let mv = JointMove::new(&self.cell.robot, &q[0], &q[1], speed);
            self.run_joint(&mv);
        }
    }

    fn clear_path(
        &self,
        from: &[f64],
        to: &[f64],
        tcp: &Isometry3<f64>,
        ignore: &[&str],
    ) -> Vec<Vec<f64>> {
        let direct = vec![from.to_vec(), to.to_vec()];
        if self.path_clear(&direct, ignore) {
            return direct;
        }
        // An arc about the robot's base that keeps the tool's orientation turning evenly
        // (a held piece stays level) and rises over the middle.
        for bump in [0.3, 0.7] {
            if let Some(path) = self.arc(from, to, tcp, bump)
                && self.path_clear(&path, ignore)
            {
                return path;
            }
        }
        let up = |q: &[f64], h: f64| -> Option<Vec<f64>> {
            let pose = self.cell.robot_base * self.cell.robot.fk_tip(q) * tcp;
            let raised = Isometry3::from_parts(
                Translation3::from(pose.translation.vector + Vector3::new(0.0, 0.0, h)),
                pose.rotation,
            );
            solve(self.cell, &raised, tcp, q).ok()
        };
        // Raised waypoints over both ends, then the same through the robot's home pose (a
        // transit pose that turns the wrist high above the work).
        let home = self.cell.robot.home();
        for h in [0.4, 0.8] {
            let (Some(a), Some(b)) = (up(from, h), up(to, h)) else {
                continue;
            };
            for path in [
                vec![from.to_vec(), a.clone(), b.clone(), to.to_vec()],
                vec![from.to_vec(), a, home.clone(), b, to.to_vec()],
            ] {
                if self.path_clear(&path, ignore) {
                    return path;
                }
            }
        }
        direct
    }

    /// Joint waypoints along a TCP arc about the base from the pose at `from` to the pose at
    /// `to`: radius, angle and height interpolated, the height raised by `bump` mid-way.
    fn arc(
        &self,
        from: &[f64],
        to: &[f64],
        tcp: &Isometry3<f64>,
        bump: f64,
    ) -> Option<Vec<Vec<f64>>> {
        let base = self.cell.robot_base;
        let a = base * self.cell.robot.fk_tip(from) * tcp;
        let b = base * self.cell.robot.fk_tip(to) * tcp;
        let local = |p: &Isometry3<f64>| base.inverse() * Point3::from(p.translation.vector);
        let (pa, pb) = (local(&a), local(&b));
        let (ra, rb) = (pa.xy().coords.norm(), pb.xy().coords.norm());
        let ta = pa.y.atan2(pa.x);
        let mut tb = pb.y.atan2(pb.x);
        while tb - ta > std::f64::consts::PI {
            tb -= 2.0 * std::f64::consts::PI;
        }
        while ta - tb > std::f64::consts::PI {
            tb += 2.0 * std::f64::consts::PI;
        }
        const SAMPLES: usize = 12;
        let mut path = vec![from.to_vec()];
        let mut q = from.to_vec();
        for k in 1..SAMPLES {
            let s = k as f64 / SAMPLES as f64;
            let (r, th) = (ra + (rb - ra) * s, ta + (tb - ta) * s);
            let z = pa.z + (pb.z - pa.z) * s + bump * (std::f64::consts::PI * s).sin();
            let yaw = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), (tb - ta) * s);
            let rotation = base.rotation * yaw * (base.rotation.inverse() * a.rotation);
            let point = base * Point3::new(r * th.cos(), r * th.sin(), z);
            let pose = Isometry3::from_parts(Translation3::from(point.coords), rotation);
            q = solve(self.cell, &pose, tcp, &q).ok()?;
            path.push(q.clone());
        }
        path.push(to.to_vec());
        Some(path)
    }

    /// Whether the arm sweeps along `path` (straight in joint space between waypoints) at
    /// least PATH_MARGIN clear of everything away from its two ends: checked at samples no
    /// further apart than SWEEP_STEP for the fastest-moving point of the arm, its tool and a
    /// held piece.
    fn path_clear(&self, path: &[Vec<f64>], ignore: &[&str]) -> bool {
        let held = self
            .held
            .as_ref()
            .map(|h| (h.id.as_str(), &h.in_tool, h.half));
        let lengths: Vec<f64> = path
            .windows(2)
            .map(|leg| self.sweep_length(&leg[0], &leg[1]))
            .collect();
        let total: f64 = lengths.iter().sum();
        let mut travelled = 0.0;
        for (leg, length) in path.windows(2).zip(&lengths) {
            let samples = (length / SWEEP_STEP).ceil().max(1.0) as usize;
            for k in 0..=samples {
                let s = k as f64 / samples as f64;
                // The margin grows from nothing at the two ends (poses already checked, which
                // may lie close to what they work on) to PATH_MARGIN after MARGIN_TAPER.
                let from_end = (travelled + s * length).min(total - travelled - s * length);
                let margin = PATH_MARGIN * (from_end / MARGIN_TAPER).clamp(0.0, 1.0);
                let q = lerp(&leg[0], &leg[1], s);
                if touches(&self.phys, self.cell, &q, held, ignore, margin).is_some() {
                    return false;
                }
            }
            travelled += length;
        }
        true
    }

    /// How far the fastest-moving of the arm's key points travels on the joint-space line
    /// from `a` to `b` (m), measured over a few sub-steps: link origins, tool part centres and
    /// the ends of a held piece.
    fn sweep_length(&self, a: &[f64], b: &[f64]) -> f64 {
        const SUB_STEPS: usize = 8;
        let points = |q: &[f64]| -> Vec<Vector3<f64>> {
            let base = self.cell.robot_base;
            let tool = base * self.cell.robot.fk_tip(q);
            let mut pts: Vec<Vector3<f64>> = self
                .cell
                .robot
                .fk_all(q)
                .iter()
                .map(|p| (base * p).translation.vector)
                .collect();
            pts.extend(
                self.cell
                    .tool
                    .parts
                    .iter()
                    .map(|p| (tool * p.shape.origin).translation.vector),
            );
            if let Some(h) = &self.held {
                for end in [-h.half[0], h.half[0]] {
                    pts.push((tool * h.in_tool * Point3::new(end, 0.0, 0.0)).coords);
                }
            }
            pts
        };
        let mut before = points(a);
        let mut total = 0.0;
        for k in 1..=SUB_STEPS {
            let now = points(&lerp(a, b, k as f64 / SUB_STEPS as f64));
            total += before
                .iter()
                .zip(&now)
                .map(|(p, n)| (n - p).norm())
                .fold(0.0, f64::max);
            before = now;
        }
        total
    }
}

fn lerp(a: &[f64], b: &[f64], s: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + (y - x) * s).collect()
}

pub(super) fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum()
}
