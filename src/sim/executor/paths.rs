//! Joint motion between poses that keeps the arm, its tool and a held piece clear of the cell.

use super::WallRun;
use crate::cell::IkFailure;
use crate::sim::motion::JointMove;
use crate::sim::planner::{self, Budget, sampling_bounds};
use crate::sim::reach::{solve, touches};
use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

/// How far the arm, its tool and a held piece keep from everything on a move between poses
/// (m): a kinematic arm grazing a piece on the belt knocks it over.
pub(super) const PATH_MARGIN: f64 = 0.005;
/// Travel over which the margin grows from nothing at a move's ends to PATH_MARGIN (m).
pub(super) const MARGIN_TAPER: f64 = 0.05;
/// Largest travel of any point of the arm between two checked samples of a move (m).
pub(super) const SWEEP_STEP: f64 = 0.02;
/// Joint travel (rad) over which the planner's clearance grows from nothing at a move's ends
/// to PATH_MARGIN.
const END_TAPER: f64 = 0.05;

/// What the planner may spend on one move that the direct path and the simple detours do
/// not solve: a coarse search first, then a finer one with another seed.
const PLANNER_TRIES: [Budget; 2] = [
    Budget {
        samples: 1500,
        step: 0.08,
    },
    Budget {
        samples: 3000,
        step: 0.04,
    },
];

impl<'a> WallRun<'a> {
    /// A collision-free joint move from the current joints to `to`: straight in joint space
    /// if that is clear, else over an arc or raised waypoints (the moves a robot programmer
    /// would teach), else along a path RRT-Connect finds. If none is found, the arm stays
    /// where it is and the failure names the pair of bodies that block the direct path:
    /// the executor never drives through an obstacle.
    pub(super) fn move_to(
        &mut self,
        to: &[f64],
        tcp: &Isometry3<f64>,
        ignore: &[&str],
        speed: f64,
    ) -> Result<(), IkFailure> {
        let from = self.q.clone();
        let path = self.clear_path(&from, to, tcp, ignore)?;
        for q in path.windows(2) {
            let mv = JointMove::new(&self.cell.robot, &q[0], &q[1], speed);
            self.run_joint(&mv, speed, tcp);
        }
        Ok(())
    }

    fn clear_path(
        &self,
        from: &[f64],
        to: &[f64],
        tcp: &Isometry3<f64>,
        ignore: &[&str],
    ) -> Result<Vec<Vec<f64>>, IkFailure> {
        let direct = vec![from.to_vec(), to.to_vec()];
        let Some(blocked) = self.path_contact(&direct, ignore) else {
            return Ok(direct);
        };
        if let Some(path) = self.taught_detour(from, to, tcp, ignore) {
            return Ok(path);
        }
        if let Some(path) = self.planned_detour(from, to, ignore) {
            return Ok(path);
        }
        Err(IkFailure::PathBlocked {
            pair: [blocked.0, blocked.1],
        })
    }

    /// The detours a programmer teaches: an arc about the base that rises over the middle,
    /// or raised waypoints over both ends (through the home pose if need be).
    fn taught_detour(
        &self,
        from: &[f64],
        to: &[f64],
        tcp: &Isometry3<f64>,
        ignore: &[&str],
    ) -> Option<Vec<Vec<f64>>> {
        // An arc about the robot's base that keeps the tool's orientation turning evenly
        // (a held piece stays level) and rises over the middle.
        for bump in [0.3, 0.7] {
            if let Some(path) = self.arc(from, to, tcp, bump)
                && self.path_clear(&path, ignore)
            {
                return Some(path);
            }
        }
        let up = |q: &[f64], h: f64| -> Option<Vec<f64>> {
            let pose = self.cell.robot_base * self.cell.robot.fk_tip(q) * tcp;
            let raised = Isometry3::from_parts(
                Translation3::from(pose.translation.vector + Vector3::new(0.0, 0.0, h)),
                pose.rotation,
            );
            solve(&self.cell, &raised, tcp, q).ok()
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
                    return Some(path);
                }
            }
        }
        None
    }

    /// A path RRT-Connect finds in joint space, every configuration PATH_MARGIN clear (less
    /// near the two ends, which may lie close to what they work on) and every leg checked
    /// along its sweep. Seeded from the move itself: the same move, the same path.
    fn planned_detour(&self, from: &[f64], to: &[f64], ignore: &[&str]) -> Option<Vec<Vec<f64>>> {
        let held = self
            .held
            .as_ref()
            .map(|h| (h.id.as_str(), &h.in_tool, h.half));
        let bounds = sampling_bounds(&self.cell.robot.limits(), from, to);
        let seed = move_seed(from, to);
        PLANNER_TRIES.iter().enumerate().find_map(|(k, &budget)| {
            let point_free = |q: &[f64]| {
                let near_end = joint_gap(q, from).min(joint_gap(q, to));
                let margin = PATH_MARGIN * (near_end / END_TAPER).clamp(0.0, 1.0);
                touches(&self.phys, &self.cell, q, held, ignore, margin).is_none()
            };
            let leg_free =
                |a: &[f64], b: &[f64]| self.path_clear(&[a.to_vec(), b.to_vec()], ignore);
            planner::connect(
                from,
                to,
                &bounds,
                seed.wrapping_add(k as u64),
                budget,
                point_free,
                leg_free,
            )
        })
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
            q = solve(&self.cell, &pose, tcp, &q).ok()?;
            path.push(q.clone());
        }
        path.push(to.to_vec());
        Some(path)
    }

    /// Whether the arm sweeps along `path` (straight in joint space between waypoints) at
    /// least PATH_MARGIN clear of everything away from its two ends.
    fn path_clear(&self, path: &[Vec<f64>], ignore: &[&str]) -> bool {
        self.path_contact(path, ignore).is_none()
    }

    /// The first pair of bodies (arm part, obstacle) closer than PATH_MARGIN along `path`,
    /// away from its two ends: checked at samples no further apart than SWEEP_STEP for the
    /// fastest-moving point of the arm, its tool and a held piece.
    fn path_contact(&self, path: &[Vec<f64>], ignore: &[&str]) -> Option<(String, String)> {
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
                if let Some(pair) = touches(&self.phys, &self.cell, &q, held, ignore, margin) {
                    return Some(pair);
                }
            }
            travelled += length;
        }
        None
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

/// Largest single-joint difference between two configurations (rad or m).
fn joint_gap(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// Joint values are rounded to this before they seed the planner (rad or m): ends that differ
/// by the physics' micrometre noise (a piece's rest pose one way or another) get the same
/// search.
const SEED_QUANTUM: f64 = 1e-4;

/// A seed for the planner from the move's two ends (rounded to SEED_QUANTUM).
fn move_seed(from: &[f64], to: &[f64]) -> u64 {
    let mut hasher = blake3::Hasher::new();
    for v in from.iter().chain(to) {
        let q = (v / SEED_QUANTUM).round() as i64;
        hasher.update(&q.to_le_bytes());
    }
    let bytes = hasher.finalize();
    u64::from_le_bytes(bytes.as_bytes()[..8].try_into().expect("32-byte hash"))
}

pub(super) fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum()
}
