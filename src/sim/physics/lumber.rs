//! Lumber in the world: pieces put in and taken out, riding the belts, held, clamped and
//! nailed, and where they are.

use super::world::*;
use crate::world::ScenePiece;
use nalgebra::{Isometry3, Translation3, Vector3};
use rapier3d::prelude::*;
use std::collections::BTreeMap;

impl Physics {
    /// Puts a lumber piece into the world at `pose` (cell frame), at rest.
    pub fn add_lumber(&mut self, piece: &ScenePiece, pose: &Isometry3<f64>) {
        self.insert_lumber(piece, pose, true);
    }

    /// Puts a piece onto a running belt riding it from the start (see `start_ride`): it
    /// touches nothing, so nothing in the world has to settle.
    pub fn add_riding(
        &mut self,
        piece: &ScenePiece,
        pose: &Isometry3<f64>,
        velocity: &Vector3<f64>,
    ) {
        self.insert_lumber(piece, pose, false);
        self.start_ride(&piece.id, velocity);
    }

    pub(super) fn insert_lumber(
        &mut self,
        piece: &ScenePiece,
        pose: &Isometry3<f64>,
        disturbs: bool,
    ) {
        self.changed(disturbs);
        let [l, w, t] = piece.size.map(|v| v as f32 / 2.0);
        // Lumber on a belt never sleeps: the slow infeed belt moves it below rapier's sleep
        // threshold. Placed pieces may sleep again (see `detach`).
        let body = self.world.insert_body(
            RigidBodyBuilder::dynamic()
                .pose(to_pose(pose))
                .can_sleep(false),
        );
        let collider = self.world.insert_collider(
            ColliderBuilder::cuboid(l, w, t)
                .density(piece.density as f32)
                .friction(LUMBER_FRICTION)
                .collision_groups(groups(LUMBER, FIXED | LUMBER | ROBOT | SENSOR))
                .active_collision_types(lumber_collision_types()),
            Some(body),
        );
        self.names.insert(collider, format!("piece {}", piece.id));
        self.lumber_of.insert(collider, piece.id.clone());
        self.lumber
            .insert(piece.id.clone(), LumberBody { body, collider });
    }

    /// Lets a piece ride its running belt as a kinematic body at `velocity` (m/s): a piece
    /// that only rides has nothing for the solver to do, and without contacts to the belt it
    /// costs none. The feeder ends the ride (`end_ride`) before the piece nears anything;
    /// stopping the belts ends every ride or parks it. A standing belt carries nothing.
    pub fn start_ride(&mut self, id: &str, velocity: &Vector3<f64>) {
        let Some(b) = self.lumber.get(id).copied() else {
            return;
        };
        if !self.belts.running {
            return;
        }
        if self.riding.insert(id.to_string(), b).is_some() {
            return;
        }
        self.changed(false);
        let body = &mut self.world.bodies[b.body];
        body.set_body_type(RigidBodyType::KinematicVelocityBased, true);
        body.set_angvel(Vector::ZERO, true);
        body.set_linvel(
            Vector::new(velocity.x as f32, velocity.y as f32, velocity.z as f32),
            true,
        );
        if let Some(c) = self.world.colliders.get_mut(b.collider) {
            c.set_active_collision_types(ActiveCollisionTypes::default());
        }
    }

    /// A riding piece is a dynamic body again, moving as it rode.
    pub fn end_ride(&mut self, id: &str) {
        let Some(b) = self.riding.remove(id) else {
            return;
        };
        self.ride_exact.remove(&b.body);
        self.changed(true);
        let body = &mut self.world.bodies[b.body];
        let velocity = body.linvel();
        body.set_body_type(RigidBodyType::Dynamic, true);
        body.set_linvel(velocity, true);
        if let Some(c) = self.world.colliders.get_mut(b.collider) {
            c.set_active_collision_types(lumber_collision_types());
        }
    }

    /// Whether a piece rides its belt (see `start_ride`).
    pub fn is_riding(&self, id: &str) -> bool {
        self.riding.contains_key(id)
    }

    /// The fastest riding piece's speed (m/s), 0 with none riding.
    pub fn ride_speed(&self) -> f64 {
        self.riding
            .values()
            .map(|b| f64::from(self.world.bodies[b.body].linvel().length()))
            .fold(0.0, f64::max)
    }

    /// Moves every riding piece as a step would (position += velocity · dt), without the
    /// solver: a rider has no contacts to solve. rapier's own structures (broad
    /// phase, contacts) see the new positions at the next step or `detect`; `clearance`
    /// measures riders where they are.
    pub fn advance_rides(&mut self, dt: f64) {
        if !self.belts.running {
            return; // parked pieces stay put
        }
        for b in self.riding.values() {
            let body = &mut self.world.bodies[b.body];
            // Summed in f64 from where the last advance left it (unless a solver step moved
            // it since), then rounded: adding the same small step in f32 rounds the same way
            // every time, a drift of millimetres over a long ride.
            let v = body.linvel();
            let mut pose = to_iso(body.position());
            let unmoved = |exact: &Vector3<f64>| {
                let rounded = Isometry3::from_parts(Translation3::from(*exact), pose.rotation);
                to_pose(&rounded).translation == body.position().translation
            };
            let exact = self
                .ride_exact
                .entry(b.body)
                .or_insert(pose.translation.vector);
            if !unmoved(exact) {
                *exact = pose.translation.vector;
            }
            *exact += Vector3::new(v.x.into(), v.y.into(), v.z.into()) * dt;
            pose.translation.vector = *exact;
            body.set_position(to_pose(&pose), false);
        }
    }

    /// Takes a piece out of the world (an operator lifts it off the belt).
    pub fn remove_lumber(&mut self, id: &str) {
        self.riding.remove(id);
        self.changed(true);
        if let Some(b) = self.lumber.remove(id) {
            self.ride_exact.remove(&b.body);
            self.world.remove_body_with_colliders(b.body, true);
            self.lumber_of.remove(&b.collider);
        }
    }

    pub fn lumber_pose(&self, id: &str) -> Option<Isometry3<f64>> {
        if let Some((held, pose)) = self.pending_held()
            && held == id
        {
            return Some(pose);
        }
        let b = self.lumber.get(id)?;
        Some(to_iso(self.world.bodies[b.body].position()))
    }

    /// Linear (m/s) and angular (rad/s) speed of a piece.
    pub fn lumber_speed(&self, id: &str) -> Option<(f64, f64)> {
        let b = self.lumber.get(id)?;
        let body = &self.world.bodies[b.body];
        Some((
            f64::from(body.linvel().length()),
            f64::from(body.angvel().length()),
        ))
    }

    /// Holds a piece rigidly in the gripper: it becomes position-driven (it follows the tool).
    pub fn attach(&mut self, id: &str) {
        self.end_ride(id);
        self.changed(true);
        if let Some(b) = self.lumber.get(id) {
            self.world.bodies[b.body].set_body_type(RigidBodyType::KinematicPositionBased, true);
        }
    }

    /// Lets go of a piece: it is a dynamic body again, at rest where it is.
    pub fn detach(&mut self, id: &str) {
        self.changed(true);
        if let Some(b) = self.lumber.get(id) {
            let body = &mut self.world.bodies[b.body];
            body.set_body_type(RigidBodyType::Dynamic, true);
            let activation = body.activation_mut();
            activation.normalized_linear_threshold =
                RigidBodyActivation::default_normalized_linear_threshold();
            activation.angular_threshold = RigidBodyActivation::default_angular_threshold();
            activation.time_until_sleep = RigidBodyActivation::default_time_until_sleep();
            body.set_linvel(Vector::ZERO, true);
            body.set_angvel(Vector::ZERO, true);
        }
    }

    /// The fixture holds a placed piece where it came to rest (a framing table's stops and
    /// clamps): it no longer moves, whatever touches it later.
    pub fn clamp(&mut self, id: &str) {
        // Holding a piece still sets nothing moving: what rests on it keeps resting, and
        // lumber that still moves keeps the solver stepping anyway.
        self.changed(false);
        if let Some(b) = self.lumber.get(id) {
            self.world.bodies[b.body].set_body_type(RigidBodyType::Fixed, true);
        }
    }

    /// Moves a held piece with the tool by the end of the next step.
    pub fn carry(&mut self, id: &str, pose: &Isometry3<f64>) {
        self.bodies_may_move();
        if let Some(b) = self.lumber.get(id) {
            self.world.bodies[b.body].set_next_kinematic_position(to_pose(pose));
        }
    }

    /// Joins two pieces where they are (a nail).
    pub fn nail(&mut self, a: &str, b: &str) {
        self.changed(true);
        let (Some(a), Some(b)) = (self.lumber.get(a).copied(), self.lumber.get(b).copied()) else {
            return;
        };
        let pa = *self.world.bodies[a.body].position();
        let pb = *self.world.bodies[b.body].position();
        let joint = FixedJointBuilder::new()
            .local_frame1(pa.inv_mul(&pb))
            .local_frame2(Pose::IDENTITY)
            .contacts_enabled(false);
        self.world.insert_impulse_joint(a.body, b.body, joint);
    }

    /// Starts or stops both belts; a started belt wakes the lumber on it. Stopping them ends
    /// every ride: the riders become dynamic bodies at rest where they are, or, with `park`,
    /// stay kinematic bodies at rest (they touch nothing, so the solver has nothing to do for
    /// them; see `unpark`). Parked pieces become dynamic when the belts start again.
    pub fn set_belts(&mut self, running: bool, park: bool) {
        self.changed(true);
        if !running {
            let riding: Vec<String> = self.riding.keys().cloned().collect();
            for id in riding {
                if park {
                    // Still a rider, at rest: `advance_rides` leaves it where it is.
                    if let Some(b) = self.riding.get(&id) {
                        self.ride_exact.remove(&b.body);
                    }
                } else {
                    self.end_ride(&id);
                }
                if let Some(b) = self.lumber.get(&id) {
                    self.world.bodies[b.body].set_linvel(Vector::ZERO, true);
                }
            }
        }
        if running && !self.belts.running {
            self.unpark();
            let bodies: Vec<RigidBodyHandle> = self.lumber.values().map(|b| b.body).collect();
            for b in bodies {
                self.world.wake_up(b, true);
            }
        }
        self.belts.running = running;
    }

    /// Every parked piece becomes a dynamic body at rest where it lies, as stopping the belts
    /// without parking leaves it: before the belts start, or before the robot comes near one.
    pub fn unpark(&mut self) {
        if self.belts.running {
            return; // riders of running belts are not parked
        }
        let parked: Vec<String> = self.riding.keys().cloned().collect();
        for id in parked {
            self.end_ride(&id);
            if let Some(b) = self.lumber.get(&id) {
                self.world.bodies[b.body].set_linvel(Vector::ZERO, true);
            }
        }
    }

    /// Whether some piece is a dynamic body (not held, clamped, riding or parked).
    pub fn any_dynamic_lumber(&self) -> bool {
        self.lumber
            .values()
            .any(|b| self.world.bodies[b.body].is_dynamic())
    }

    /// Whether every dynamic lumber body moves slower than `linear` (m/s) and `angular` (rad/s).
    pub fn lumber_calm(&self, linear: f64, angular: f64) -> bool {
        self.lumber.values().all(|b| {
            let body = &self.world.bodies[b.body];
            !body.is_dynamic()
                || (f64::from(body.linvel().length()) < linear
                    && f64::from(body.angvel().length()) < angular)
        })
    }

    /// Current pose of every piece in the world.
    pub fn lumber_poses(&self) -> BTreeMap<String, Isometry3<f64>> {
        self.lumber_poses_in_order()
            .into_iter()
            .map(|(id, pose)| (id.to_string(), pose))
            .collect()
    }

    /// Current pose of every piece in the world, in id order, without copying the ids.
    pub fn lumber_poses_in_order(&self) -> Vec<(&str, Isometry3<f64>)> {
        let held = self.pending_held();
        self.lumber
            .iter()
            .map(|(id, b)| match held {
                Some((h, pose)) if h == id => (id.as_str(), pose),
                _ => (id.as_str(), to_iso(self.world.bodies[b.body].position())),
            })
            .collect()
    }
}
