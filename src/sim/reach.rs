//! Inverse kinematics and collision checks the executor plans with: the robot's IK in the
//! cell frame, straight-line feasibility, and whether the arm, its tool and a held piece
//! would intersect anything at given joint values (parry queries on the rapier world).

use super::physics::{Physics, to_iso, to_pose};
use super::record::TouchAt;
use crate::cell::{Cell, IkFailure};
use nalgebra::{Isometry3, Vector3};
use rapier3d::prelude::*;

/// The largest joint step (rad or m) between two samples of a straight line before the
/// line counts as jumping between IK branches.
const MAX_BRANCH_STEP: f64 = 0.35;

/// The closest IK solution to `seed` for a TCP pose in the cell frame.
pub fn solve(
    cell: &Cell,
    pose_cell: &Isometry3<f64>,
    tcp: &Isometry3<f64>,
    seed: &[f64],
) -> Result<Vec<f64>, IkFailure> {
    cell.robot.ik_closest(&cell.to_robot(pose_cell), tcp, seed)
}

/// How far inside the arm's reach a TCP pose lies (m): the closed-form wrist-centre margin,
/// else the rated reach minus the tip's distance from the base.
pub fn reach_margin(cell: &Cell, pose_cell: &Isometry3<f64>, tcp: &Isometry3<f64>) -> f64 {
    let pose = cell.to_robot(pose_cell);
    cell.robot.reach_margin(&pose, tcp).unwrap_or_else(|| {
        let reach = cell.robot.meta.reach.unwrap_or(f64::INFINITY);
        reach - (pose * tcp.inverse()).translation.vector.norm()
    })
}

/// Joint values at the end of a straight TCP line from `q_from` (at `from`) to `to`, checked
/// at `samples` points along the way (each the solution closest to the previous one). Err
/// with `BranchJump` when the branch of `q_from` does not reach `to` without a jump.
pub fn line(
    cell: &Cell,
    q_from: &[f64],
    from: &Isometry3<f64>,
    to: &Isometry3<f64>,
    tcp: &Isometry3<f64>,
    samples: usize,
) -> Result<Vec<f64>, IkFailure> {
    let mut q = q_from.to_vec();
    for k in 1..=samples {
        let s = k as f64 / samples as f64;
        let t = from.translation.vector.lerp(&to.translation.vector, s);
        let r = from.rotation.slerp(&to.rotation, s);
        let next = solve(cell, &Isometry3::from_parts(t.into(), r), tcp, &q)?;
        check_step(cell, &q, &next, s)?;
        q = next;
    }
    Ok(q)
}

/// A straight TCP line from `from` to `to` on an IK branch that exists along all of it: the
/// solutions at `from`, nearest `seed` first, are followed in turn; Ok((joints at `from`,
/// joints at `to`)) of the first that gets there without a jump.
pub fn continuous_line(
    cell: &Cell,
    seed: &[f64],
    from: &Isometry3<f64>,
    to: &Isometry3<f64>,
    tcp: &Isometry3<f64>,
    samples: usize,
) -> Result<(Vec<f64>, Vec<f64>), IkFailure> {
    continuous_line_where(cell, seed, (from, to), tcp, samples, |_, _| None)
}

/// `continuous_line` whose branch must also pass `refuse` (given the joints at `from` and at
/// `to`; `Some(why)` refuses the branch). When none passes, the first refusal is the miss
/// (that branch got there), else the first branch's failure along the line.
pub fn continuous_line_where(
    cell: &Cell,
    seed: &[f64],
    (from, to): (&Isometry3<f64>, &Isometry3<f64>),
    tcp: &Isometry3<f64>,
    samples: usize,
    mut refuse: impl FnMut(&[f64], &[f64]) -> Option<IkFailure>,
) -> Result<(Vec<f64>, Vec<f64>), IkFailure> {
    let starts = cell.robot.ik(&cell.to_robot(from), tcp, seed)?;
    let (mut refused, mut first_failure) = (None, None);
    for start in starts {
        match line(cell, &start, from, to, tcp, samples) {
            Ok(end) => match refuse(&start, &end) {
                None => return Ok((start, end)),
                Some(why) => {
                    refused.get_or_insert(why);
                }
            },
            Err(f) => {
                first_failure.get_or_insert(f);
            }
        }
    }
    Err(refused.or(first_failure).unwrap_or(IkFailure::InvalidPose))
}

/// Err(BranchJump) when a joint moves more than MAX_BRANCH_STEP between two line samples,
/// `at` (0..1) of the way along.
pub fn check_step(cell: &Cell, q: &[f64], next: &[f64], at: f64) -> Result<(), IkFailure> {
    let (i, jump) = next
        .iter()
        .zip(q)
        .map(|(a, b)| (a - b).abs())
        .enumerate()
        .fold(
            (0, 0.0),
            |best, (i, d)| if d > best.1 { (i, d) } else { best },
        );
    if jump > MAX_BRANCH_STEP {
        let joint = cell
            .robot
            .active_joints()
            .nth(i)
            .map_or_else(|| format!("joint {}", i + 1), |j| j.name.clone());
        return Err(IkFailure::BranchJump { joint, jump, at });
    }
    Ok(())
}

/// What the arm would touch at joint values `q` holding `held` (its id, its pose in tool0 and
/// its box half sizes): the first (robot body, other body) pair found, ignoring the bodies
/// in `ignore` and sensors. With `margin` > 0 the arm, tool and held piece are dilated by it:
/// a pair closer than `margin` counts as touching.
pub fn touches(
    phys: &Physics,
    cell: &Cell,
    q: &[f64],
    held: Option<(&str, &Isometry3<f64>, [f64; 3])>,
    ignore: &[&str],
    margin: f64,
) -> Option<(String, String)> {
    touch(phys, cell, q, held, ignore, margin).map(|t| (t.body_a, t.body_b))
}

/// A touch `touches` finds, with where it is.
#[derive(Debug, Clone)]
pub struct Touch {
    pub body_a: String,
    pub body_b: String,
    /// In the cell frame (the wall frame left at zero).
    pub at: TouchAt,
}

/// As `touches`, with where the two bodies meet: the deepest point, each body's centre and
/// the depth (0 where they are only within `margin`).
pub fn touch(
    phys: &Physics,
    cell: &Cell,
    q: &[f64],
    held: Option<(&str, &Isometry3<f64>, [f64; 3])>,
    ignore: &[&str],
    margin: f64,
) -> Option<Touch> {
    let world = &phys.world;
    let poses = cell.robot.fk_all(q);
    let tool = cell.robot_base * cell.robot.fk_tip(q);
    let mut excluded: Vec<RigidBodyHandle> = phys.links.iter().map(|l| l.1).collect();
    excluded.push(phys.tool);
    for id in ignore.iter().copied().chain(held.map(|h| h.0)) {
        if let Some(b) = phys.lumber.get(id) {
            excluded.push(b.body);
        }
    }
    let skip = |_: ColliderHandle, c: &Collider| {
        c.is_sensor() || c.parent().is_some_and(|b| excluded.contains(&b))
    };
    let predicate = |h: ColliderHandle, c: &Collider| !skip(h, c);
    let hit = |pose: Isometry3<f64>, shape: &dyn rapier3d::parry::shape::Shape, filter| {
        let (h, other) = world
            .intersect_shape(to_pose(&pose), shape, filter)
            .next()?;
        Some((phys.name(h), where_touching(&pose, shape, other)))
    };
    let body_pose = |body: RigidBodyHandle| -> Option<Isometry3<f64>> {
        if body == phys.tool {
            return Some(tool);
        }
        let &(i, _) = phys.links.iter().find(|l| l.1 == body)?;
        Some(cell.robot_base * poses[i])
    };
    for &c in &phys.robot_colliders {
        let collider = &world.colliders[c];
        let Some(parent) = collider.parent() else {
            continue;
        };
        // The base never moves and stands on the floor.
        if phys
            .links
            .first()
            .is_some_and(|l| l.1 == parent && l.0 == 0)
        {
            continue;
        }
        let Some(body) = body_pose(parent) else {
            continue;
        };
        // With a piece held, the jaws stand closed on its thickness (the jaws close across
        // the piece's z, as `set_jaws` does), wherever they stand in the world now.
        let local = held
            .and_then(|(_, _, half)| phys.finger_at(c, 2.0 * half[2]))
            .unwrap_or_else(|| {
                collider
                    .position_wrt_parent()
                    .map_or_else(Isometry3::identity, super::physics::to_iso)
            });
        let filter = QueryFilter::default()
            .groups(collider.collision_groups())
            .predicate(&predicate);
        let dilated = dilate(collider.shape(), margin);
        let shape = dilated.as_ref().map_or(collider.shape(), |s| s.as_ref());
        if let Some((other, at)) = hit(body * local, shape, filter) {
            return Some(Touch {
                body_a: phys.name(c),
                body_b: other,
                at,
            });
        }
    }
    if let Some((id, in_tool, half)) = held {
        // Shrunk by 2 mm: a placed piece may touch its neighbours.
        // Grown by the margin as a box (corners a little more cautious than a dilation).
        let h = half.map(|v| ((v - 0.002).max(0.001) + margin.max(0.0)) as f32);
        let shape = Cuboid::new(Vector::new(h[0], h[1], h[2]));
        let filter = QueryFilter::default().predicate(&predicate);
        if let Some((other, at)) = hit(tool * in_tool, &shape, filter) {
            return Some(Touch {
                body_a: format!("piece {id}"),
                body_b: other,
                at,
            });
        }
    }
    None
}

/// Where a shape at `pose` meets a collider it intersects: the midpoint of the two shapes'
/// deepest points, both centres and the depth, in the cell frame.
fn where_touching(
    pose: &Isometry3<f64>,
    shape: &dyn rapier3d::parry::shape::Shape,
    other: &Collider,
) -> TouchAt {
    let centre_a = pose.translation.vector;
    let centre_b = to_iso(other.position()).translation.vector;
    let contact = rapier3d::parry::query::contact(
        &to_pose(pose),
        shape,
        other.position(),
        other.shape(),
        0.0,
    )
    .ok()
    .flatten();
    // A pair parry cannot measure: its centres' midpoint, depth unknown (0).
    let (point, depth) = contact.map_or(((centre_a + centre_b) / 2.0, 0.0), |c| {
        let p = |v: rapier3d::math::Vector| Vector3::new(v.x, v.y, v.z).cast::<f64>();
        ((p(c.point1) + p(c.point2)) / 2.0, -f64::from(c.dist))
    });
    TouchAt {
        point: point.into(),
        point_wall: [0.0; 3],
        centre_a: centre_a.into(),
        centre_b: centre_b.into(),
        depth: depth.max(0.0),
    }
}

/// The shape grown by `margin` on every side (its Minkowski sum with a ball), for the shapes
/// robots and tools are made of; None when there is nothing to grow.
fn dilate(shape: &dyn rapier3d::parry::shape::Shape, margin: f64) -> Option<SharedShape> {
    if margin <= 0.0 {
        return None;
    }
    let m = margin as f32;
    if let Some(b) = shape.as_cuboid() {
        let h = b.half_extents;
        Some(SharedShape::round_cuboid(h.x, h.y, h.z, m))
    } else if let Some(c) = shape.as_cylinder() {
        Some(SharedShape::round_cylinder(c.half_height, c.radius, m))
    } else if let Some(b) = shape.as_ball() {
        Some(SharedShape::ball(b.radius + m))
    } else if let Some(c) = shape.as_capsule() {
        Some(SharedShape::capsule(c.segment.a, c.segment.b, c.radius + m))
    } else {
        shape.as_round_cuboid().map(|r| {
            let h = r.inner_shape.half_extents;
            SharedShape::round_cuboid(h.x, h.y, h.z, r.border_radius + m)
        })
    }
}
