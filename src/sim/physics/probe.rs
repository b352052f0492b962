//! Queries of the world without stepping it: the robot's shapes at some joint values, how far
//! they are from the rest (clearances), what touches the sensor, the robot's contacts.

use super::world::*;
use crate::cell::JointKind;
use nalgebra::{Isometry3, Vector3};
use rapier3d::prelude::*;

/// How far a piece's box is shrunk on every side when looking for what lies beneath it (m):
/// pieces abutting it side by side are not beneath it.
const BESIDE: f64 = 0.002;

/// Which touches a caller records: a clearance's `any` measures how far the robot is from
/// the first of them (lumber that can move is always measured: the robot may push it).
#[derive(Debug, Clone, Copy)]
pub enum Watch<'a> {
    /// Touches of anything but these bodies (by name, as `name` gives them); those of the
    /// held piece with anything and of the robot with what is not lumber only deeper than
    /// `tolerance` (m), those of the robot with lumber at any depth.
    AllBut {
        bodies: &'a [String],
        tolerance: f64,
    },
    /// None.
    Nothing,
}

impl Watch<'_> {
    /// How deep a touch between a robot shape (`held`: the held piece) and a body (`name`,
    /// `lumber`: whether it is a piece) goes unrecorded; None: it is never recorded.
    fn unrecorded_depth(&self, held: bool, name: Option<&String>, lumber: bool) -> Option<f64> {
        match self {
            Watch::AllBut { bodies, .. } if name.is_some_and(|n| bodies.contains(n)) => None,
            Watch::AllBut { .. } if lumber && !held => Some(0.0),
            Watch::AllBut { tolerance, .. } => Some(*tolerance),
            Watch::Nothing => None,
        }
    }
}

/// The robot's moving shapes at some joint values (see `Physics::probe`): the poses of the
/// bodies they belong to, each shape's own pose worked out only when it is measured.
#[derive(Debug, Clone)]
pub struct Probe {
    /// Every link's cell-frame pose, and the tool's.
    pub(super) links: Vec<Isometry3<f64>>,
    pub(super) tool: Isometry3<f64>,
    /// Per moving joint: its index in the joint values, kind and a point of its axis.
    pub(super) axes: Vec<(usize, JointKind, Vector3<f64>)>,
    pub(super) dofs: usize,
    /// The held piece's body: with the robot's own, a clearance leaves it out.
    pub(super) held_body: Option<RigidBodyHandle>,
    /// The held piece's collider and its pose in tool0: the last shape.
    pub(super) held: Option<(ColliderHandle, Isometry3<f64>)>,
    /// How many shapes: the robot's moving colliders, then the held piece.
    pub(super) count: usize,
    pub(super) riders: Vec<LumberBody>,
}

impl Probe {
    /// How many shapes it holds.
    pub fn shape_count(&self) -> usize {
        self.count
    }

    /// The held piece's shape, if a piece is held: the last.
    pub fn held_shape(&self) -> Option<usize> {
        self.held.map(|_| self.count - 1)
    }
}

/// How far the robot, its tool and a held piece are from the rest of the world (m), each
/// capped at the reach asked for.
#[derive(Debug, Clone, Copy)]
pub struct Clearance {
    /// To a touch the caller records (`Watch`): the distance to it plus how deep it may go
    /// unrecorded, and for a touch already deeper than 0 that depth less the touch's
    /// (0 or less: touching).
    pub any: f64,
    /// To lumber that can move (dynamic bodies).
    pub loose: f64,
    /// To lumber parked on the stopped belts (see `set_belts`).
    pub parked: f64,
}

/// A box covering everything within `margin` of `shape` (its bounding box grown by the
/// margin, a coarse candidate filter; exact distances are measured afterwards) and the box's
/// centre in the shape's frame.
pub(super) fn grown_box(shape: &dyn rapier3d::parry::shape::Shape, margin: f64) -> (Cuboid, Pose) {
    let aabb = shape.compute_local_aabb();
    let half = aabb.half_extents() + Vector::splat(margin as f32);
    (Cuboid::new(half), Pose::from_translation(aabb.center()))
}

impl Physics {
    /// The probe's shape `i` (the robot's moving colliders, then the held piece) and its
    /// cell-frame pose.
    pub(super) fn probe_shape(&self, probe: &Probe, i: usize) -> (ColliderHandle, Isometry3<f64>) {
        match self.moving_shapes.get(i) {
            Some(&(c, owner)) => {
                let body = match owner {
                    ShapeOwner::Tool => probe.tool,
                    ShapeOwner::Link(link) => probe.links[link],
                };
                let local = self.world.colliders[c]
                    .position_wrt_parent()
                    .map_or_else(Isometry3::identity, to_iso);
                (c, body * local)
            }
            None => {
                let (c, in_tool) = probe.held.expect("a shape of the probe");
                (c, probe.tool * in_tool)
            }
        }
    }

    /// The robot's moving shapes (its colliders, base link excluded, and the held piece's) and
    /// its joints' axes at joint values `q`, for measuring each shape's clearance apart.
    pub fn probe(&self, q: &[f64], held: Option<(&str, &Isometry3<f64>)>) -> Probe {
        let links: Vec<Isometry3<f64>> = self
            .cell
            .robot
            .fk_all(q)
            .into_iter()
            .map(|pose| self.cell.robot_base * pose)
            .collect();
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(q);
        let axes = self
            .cell
            .robot
            .joints
            .iter()
            .filter_map(|joint| {
                let i = joint.dof_index?;
                // The child frame's origin lies on the joint's axis.
                Some((i, joint.kind, links[joint.child].translation.vector))
            })
            .collect();
        let held_body = held.and_then(|(id, in_tool)| Some((self.lumber.get(id)?, *in_tool)));
        Probe {
            links,
            tool,
            axes,
            dofs: q.len(),
            held_body: held_body.map(|(b, _)| b.body),
            held: held_body.map(|(b, in_tool)| (b.collider, in_tool)),
            count: self.moving_shapes.len() + usize::from(held_body.is_some()),
            // Riders are measured apart, where they are now: between steps the broad phase
            // holds them where the last step left them.
            riders: self.riding.values().copied().collect(),
        }
    }

    /// Per joint, a bound on how far any point of the probe's shape `i` moves per unit of
    /// that joint's motion while it moves less than `slack` (m): for a revolute joint the
    /// largest distance of its bounding box's corners from a point of the axis plus `slack`
    /// (m per rad; a rigid motion moves a box's points at most as far as its furthest
    /// corner), for a prismatic one 1. Summed over |Δq|, it bounds the shape's motion without
    /// forward kinematics.
    pub fn levers(&self, probe: &Probe, i: usize, slack: f64) -> Vec<f64> {
        let corners = self.shape_corners(probe, i);
        let mut levers = vec![0.0; probe.dofs];
        for &(i, kind, origin) in &probe.axes {
            levers[i] = match kind {
                JointKind::Prismatic => 1.0,
                JointKind::Fixed => 0.0,
                JointKind::Revolute | JointKind::Continuous => {
                    let far = corners
                        .iter()
                        .map(|c| (c - origin).norm())
                        .fold(0.0, f64::max);
                    far + slack
                }
            };
        }
        levers
    }

    /// The corners of the local bounding box of the probe's shape `i`, in the cell frame.
    pub(super) fn shape_corners(&self, probe: &Probe, i: usize) -> [Vector3<f64>; 8] {
        let (c, pose) = &self.probe_shape(probe, i);
        let aabb = self.world.colliders[*c].shape().compute_local_aabb();
        let (lo, hi) = (aabb.mins, aabb.maxs);
        std::array::from_fn(|k| {
            let pick = |bit: usize, a: f32, b: f32| f64::from(if k & bit == 0 { a } else { b });
            let local = nalgebra::Point3::new(
                pick(1, lo.x, hi.x),
                pick(2, lo.y, hi.y),
                pick(4, lo.z, hi.z),
            );
            (pose * local).coords
        })
    }

    /// How far the robot, its tool and the held piece at joint values `q` are from what they
    /// can touch that `watch` names or that can move (`any`), and from loose lumber;
    /// distances beyond `reach` read as `reach`. (The executor measures shape by shape.)
    #[cfg(test)]
    pub fn clearance(
        &self,
        q: &[f64],
        held: Option<(&str, &Isometry3<f64>)>,
        reach: f64,
        watch: Watch,
    ) -> Clearance {
        let probe = self.probe(q, held);
        (0..probe.shape_count())
            .map(|i| self.shape_clearance(&probe, i, reach, watch))
            .fold(
                Clearance {
                    any: reach,
                    loose: reach,
                    parked: reach,
                },
                |a, b| Clearance {
                    any: a.any.min(b.any),
                    loose: a.loose.min(b.loose),
                    parked: a.parked.min(b.parked),
                },
            )
    }

    /// `clearance` of the probe's shape `i` alone.
    pub fn shape_clearance(&self, probe: &Probe, i: usize, reach: f64, watch: Watch) -> Clearance {
        let riders = &probe.riders;
        let own = |b: RigidBodyHandle| {
            b == self.tool || probe.held_body == Some(b) || self.links.iter().any(|l| l.1 == b)
        };
        let predicate = |_: ColliderHandle, c: &Collider| {
            !c.is_sensor()
                && !c
                    .parent()
                    .is_some_and(|b| own(b) || riders.iter().any(|r| r.body == b))
        };
        let mut found = Clearance {
            any: reach,
            loose: reach,
            parked: reach,
        };
        let (c, pose) = self.probe_shape(probe, i);
        let collider = &self.world.colliders[c];
        let shape = collider.shape();
        let pose = to_pose(&pose);
        let (grown, centre) = grown_box(shape, reach);
        let filter = QueryFilter::default()
            .groups(collider.collision_groups())
            .predicate(&predicate);
        let held = probe.held_shape() == Some(i);
        for (h, other) in self.world.intersect_shape(pose * centre, &grown, filter) {
            let loose = other
                .parent()
                .is_some_and(|b| self.world.bodies[b].is_dynamic());
            let lumber = self.lumber_of.contains_key(&h);
            let unrecorded = watch.unrecorded_depth(held, self.names.get(&h), lumber);
            if !loose && unrecorded.is_none() {
                continue;
            }
            let (at, other_shape) = (other.position(), other.shape());
            let Ok(d) = rapier3d::parry::query::distance(&pose, shape, at, other_shape) else {
                // A pair parry cannot measure counts as touching.
                found.any = 0.0;
                found.loose = 0.0;
                continue;
            };
            let d = f64::from(d.distance);
            // How far from a recorded touch: a touch shallower than `unrecorded` is not one.
            let to_record = match unrecorded {
                Some(depth) if depth > 0.0 && d <= 0.0 => {
                    rapier3d::parry::query::contact(&pose, shape, at, other_shape, 0.0)
                        .ok()
                        .flatten()
                        .map_or(0.0, |contact| depth + f64::from(contact.dist))
                }
                Some(depth) => d + depth,
                None => d,
            };
            found.any = found.any.min(to_record);
            if loose {
                found.loose = found.loose.min(d);
            }
        }
        // A rider moves on its own: it counts as loose.
        let reach_box = shape.compute_aabb(&pose).loosened(reach as f32);
        for r in riders.iter() {
            if !collider
                .collision_groups()
                .test(self.world.colliders[r.collider].collision_groups())
            {
                continue;
            }
            let other = &self.world.colliders[r.collider];
            let at = *self.world.bodies[r.body].position()
                * *other.position_wrt_parent().unwrap_or(&Pose::IDENTITY);
            // Farther than `reach` changes nothing (distances are capped at it).
            if !reach_box.intersects(&other.shape().compute_aabb(&at)) {
                continue;
            }
            let d = rapier3d::parry::query::distance(&pose, shape, &at, other.shape())
                .map_or(0.0, |d| f64::from(d.distance).min(reach));
            found.any = found.any.min(d);
            found.loose = found.loose.min(d);
            if !self.belts.running {
                found.parked = found.parked.min(d);
            }
        }
        found
    }

    /// The lumber pieces in the sensor zone.
    pub fn at_sensor(&self) -> Vec<String> {
        let mut ids: Vec<String> = self
            .world
            .narrow_phase
            .intersection_pairs_with(self.sensor)
            .filter(|&(_, _, touching)| touching)
            .filter_map(|(a, b, _)| {
                let other = if a == self.sensor { b } else { a };
                self.lumber_of.get(&other).cloned()
            })
            .collect();
        ids.sort();
        ids
    }

    /// What lies beneath piece `id` as it is now, within `max` (m) straight down: the first
    /// body its box would meet falling (the robot, the tool and sensors aside) and the gap
    /// between them (m).
    pub fn below(&self, id: &str, max: f64) -> Option<(String, f64)> {
        let b = self.lumber.get(id)?;
        let pose = self.lumber_pose(id)?;
        let collider = &self.world.colliders[b.collider];
        let own = |body: RigidBodyHandle| {
            body == b.body || body == self.tool || self.links.iter().any(|l| l.1 == body)
        };
        let predicate =
            |_: ColliderHandle, c: &Collider| !c.is_sensor() && !c.parent().is_some_and(own);
        let filter = QueryFilter::default().predicate(&predicate);
        let options = rapier3d::parry::query::ShapeCastOptions::with_max_time_of_impact(max as f32);
        // The box shrunk on every side, so that neighbours it abuts side by side do not count
        // as beneath it; its underside rises by the shrink times the axes' vertical parts.
        let half = collider.shape().as_cuboid()?.half_extents;
        let shrink = BESIDE;
        let shape = Cuboid::new(half - Vector::splat(shrink as f32));
        let rise: f64 = (0..3)
            .map(|i| (pose.rotation * Vector3::ith(i, 1.0)).z.abs() * shrink)
            .sum();
        let (h, hit) = self.world.cast_shape(
            &to_pose(&pose),
            Vector::new(0.0, 0.0, -1.0),
            &shape,
            options,
            filter,
        )?;
        Some((
            self.name(h),
            (f64::from(hit.time_of_impact) - rise).max(0.0),
        ))
    }

    /// Contacts of the robot, its tool and the piece `held` with anything else, deeper than
    /// `tolerance` (any depth between the arm or tool and lumber): (body, other body, where:
    /// the deepest point and the two bodies' centres in the cell frame, the depth), excluding
    /// the held piece against the tool.
    pub fn robot_contacts(
        &self,
        held: Option<&str>,
        tolerance: f64,
    ) -> Vec<(String, String, crate::sim::record::TouchAt)> {
        let held_collider = held.and_then(|id| self.lumber.get(id)).map(|b| b.collider);
        let mut found = Vec::new();
        let mut sources = self.robot_colliders.clone();
        sources.extend(held_collider);
        for c in sources {
            for pair in self.world.contact_pairs_with(c) {
                let other = if pair.collider1 == c {
                    pair.collider2
                } else {
                    pair.collider1
                };
                if self.robot_colliders.contains(&other) || Some(other) == held_collider {
                    continue;
                }
                let Some((_, contact)) = pair.find_deepest_contact() else {
                    continue;
                };
                let Some((depth, mid)) = self.penetration(pair, contact) else {
                    continue;
                };
                // Any touch of the arm or tool on a piece counts: a graze knocks it over.
                // A held piece set down against its neighbours may touch them.
                let limit = if Some(c) != held_collider && self.lumber_of.contains_key(&other) {
                    0.0
                } else {
                    tolerance
                };
                if depth > limit {
                    let colliders = &self.world.colliders;
                    let centre = |h: ColliderHandle| {
                        let t = to_iso(colliders[h].position()).translation.vector;
                        [t.x, t.y, t.z]
                    };
                    let at = crate::sim::record::TouchAt {
                        point: [mid.x, mid.y, mid.z],
                        point_wall: [0.0; 3],
                        centre_a: centre(c),
                        centre_b: centre(other),
                        depth,
                    };
                    found.push((self.name(c), self.name(other), at));
                }
            }
        }
        found
    }

    /// How deep a touching pair goes, and the point midway between its two shapes' deepest
    /// points (cell frame): parry's least separating translation, as the event-driven stepping
    /// measures it, where parry measures the pair; otherwise the deepest point of rapier's
    /// manifold (`deepest`). The manifold keeps the normal it was found with: a piece lowered
    /// beside a neighbour standing 0.2 mm into its footprint kept the vertical normal while
    /// it came down and reported 87.8 mm. None: the shapes do not overlap.
    fn penetration(
        &self,
        pair: &ContactPair,
        deepest: &TrackedContact<ContactData>,
    ) -> Option<(f64, nalgebra::Point3<f64>)> {
        let colliders = &self.world.colliders;
        // A pair of a collider just removed lasts until the next step.
        let (c1, c2) = (
            colliders.get(pair.collider1)?,
            colliders.get(pair.collider2)?,
        );
        let point = |v: Vector| nalgebra::Point3::new(v.x, v.y, v.z).cast::<f64>();
        match rapier3d::parry::query::contact(
            c1.position(),
            c1.shape(),
            c2.position(),
            c2.shape(),
            0.0,
        ) {
            Ok(Some(contact)) => Some((
                -f64::from(contact.dist),
                nalgebra::center(&point(contact.point1), &point(contact.point2)),
            )),
            Ok(None) => None,
            Err(_) => {
                let world_point = |c: &Collider, local: Vector| to_iso(c.position()) * point(local);
                Some((
                    -f64::from(deepest.dist),
                    nalgebra::center(
                        &world_point(c1, deepest.local_p1),
                        &world_point(c2, deepest.local_p2),
                    ),
                ))
            }
        }
    }
}
