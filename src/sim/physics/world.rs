//! The rapier world of one wall's run as the executor holds it: the bodies and colliders with
//! their handles, the collision groups, the f32/f64 conversions (rapier works in f32 with glam
//! types, the rest of framewright in f64 with nalgebra), and the stepping of the world.

use super::belts::Belts;
use crate::cell::Cell;
use nalgebra::{Isometry3, Vector3};
use rapier3d::prelude::*;
use std::collections::{BTreeMap, HashMap};

/// Which pairs lumber collides in: the defaults, and a held (kinematic) piece with fixed
/// bodies too. A piece riding a belt (`start_ride`) drops the latter.
pub(super) fn lumber_collision_types() -> ActiveCollisionTypes {
    ActiveCollisionTypes::default() | ActiveCollisionTypes::KINEMATIC_FIXED
}

/// rapier pose of an f64 isometry.
pub fn to_pose(iso: &Isometry3<f64>) -> Pose {
    iso.cast::<f32>().into()
}

/// f64 isometry of a rapier pose.
pub fn to_iso(pose: &Pose) -> Isometry3<f64> {
    let iso: Isometry3<f32> = (*pose).into();
    iso.cast::<f64>()
}

// Collision groups: what may touch what.
pub(super) const FIXED: Group = Group::GROUP_1;
pub(super) const LUMBER: Group = Group::GROUP_2;
pub(super) const ROBOT: Group = Group::GROUP_3;
pub(super) const SENSOR: Group = Group::GROUP_4;

pub(super) fn groups(member: Group, filter: Group) -> InteractionGroups {
    InteractionGroups::new(member, filter, InteractionTestMode::And)
}

/// Lumber friction against the belts, the floor and other lumber.
pub(super) const LUMBER_FRICTION: f32 = 0.6;
pub(super) const BELT_FRICTION: f32 = 0.8;
/// Friction of the jaw fingers' steel faces against lumber: dry wood on metal runs about
/// 0.2-0.6 in published tables; 0.3 (estimate). Combined by the lower of the two, so that it
/// is what a finger meets on lumber. Left at rapier's default (0.5, averaged with the
/// lumber's to 0.55), a finger pushing a jack along the table rolled it onto its leading edge
/// and turned it, and it came to rest 13-16 mm short of its king.
pub(super) const FINGER_FRICTION: f32 = 0.3;
/// Thickness of a belt slab under its top surface.
pub(super) const BELT_SLAB: f64 = 0.10;
/// Conveyor 2's belt lies this much below its nominal height: lumber sliding across a seam
/// between two flush slabs catches on the second slab's end face; a small step down does not.
pub(super) const TRANSFER_STEP: f64 = 0.002;
/// The stop rail at the downstream end of a side-by-side conveyor 1: thickness along the
/// travel, height above the belt (m).
pub(super) const RAIL_SIZE: [f64; 2] = [0.01, 0.03];
/// How far in front of the end stop the sensor zone reaches.
pub(super) const SENSOR_REACH: f64 = 0.005;
/// Finger plate thickness of a parallel gripper's jaws.
pub const FINGER: f64 = 0.010;

/// A lumber piece in the world.
#[derive(Debug, Clone, Copy)]
pub struct LumberBody {
    pub body: RigidBodyHandle,
    pub collider: ColliderHandle,
}

/// The jaws of one gripper: two finger plates on either side of the TCP x axis.
#[derive(Debug, Clone, Copy)]
pub(super) struct Finger {
    pub(super) collider: ColliderHandle,
    /// The jaw part's centre in tool0 and the finger's side (+1 or -1 along the jaw axis).
    pub(super) centre: Isometry3<f64>,
    pub(super) side: f64,
}

/// The world and the handles the executor needs.
pub struct Physics {
    pub world: PhysicsWorld,
    pub belts: Belts,
    /// Robot link index → body (links with collision shapes), in link order.
    pub links: Vec<(usize, RigidBodyHandle)>,
    pub tool: RigidBodyHandle,
    pub(super) fingers: Vec<Finger>,
    /// The nailer's parts on their slide (a tool with `[nailer] slide`): each collider and its
    /// pose in tool0 when the nailer is out (as the tool file places it).
    pub(super) nailer: Vec<(ColliderHandle, Isometry3<f64>)>,
    /// Whether the nailer is out on its slide (`cell.tool.nailer_slide` says how far back it
    /// stands otherwise).
    pub(super) nailer_out: bool,
    /// Every collider of the robot and its tool.
    pub robot_colliders: Vec<ColliderHandle>,
    /// The robot's colliders that move (not the base link's) and the body each belongs to.
    pub(super) moving_shapes: Vec<(ColliderHandle, ShapeOwner)>,
    pub sensor: ColliderHandle,
    pub lumber: BTreeMap<String, LumberBody>,
    /// Body names for contact reports.
    pub(super) names: HashMap<ColliderHandle, String>,
    /// Lumber id by collider.
    pub(super) lumber_of: HashMap<ColliderHandle, String>,
    pub(super) cell: Cell,
    /// Counts the changes to what is in the world and how it may move (lumber added, removed,
    /// gripped, released, clamped, nailed; jaws; belts): a clearance measured at one count
    /// holds only at that count.
    pub(super) generation: u64,
    /// Counts the changes that may set lumber moving: all but a piece starting to ride (it
    /// moves at its belt's speed, touching nothing). Settling is judged from the last one.
    pub(super) disturbances: u64,
    /// Pieces riding a running belt as kinematic bodies (see `start_ride`); while the belts
    /// stand, the riders they left parked (see `set_belts`).
    pub(super) riding: BTreeMap<String, LumberBody>,
    /// The joints and held piece `place_robot` last put the robot's bodies at, until
    /// anything else may have moved them (a step, a drive, a carry, a change to the world).
    pub(super) placed: Option<RobotPlacement>,
    /// Where `place_robot` was last asked to put them, not done yet: the bodies move when
    /// something may look at them (`flush`), not every tick of a quiet run.
    pub(super) pending: Option<RobotPlacement>,
    /// Where `advance_rides` last put each rider, unrounded.
    pub(super) ride_exact: HashMap<RigidBodyHandle, Vector3<f64>>,
}

/// Joint values and the held piece (id, pose in tool0) the robot's bodies were placed at.
#[derive(Debug, Clone)]
pub(super) struct RobotPlacement {
    pub(super) q: Vec<f64>,
    pub(super) held: Option<(String, Isometry3<f64>)>,
}

/// The body a robot collider belongs to: a link (by index) or the tool.
#[derive(Debug, Clone, Copy)]
pub(super) enum ShapeOwner {
    Link(usize),
    Tool,
}

/// Standard gravity, m/s².
pub const GRAVITY: f64 = 9.81;

impl Finger {
    /// The finger's pose in tool0 when the jaws stand `width` apart.
    pub(super) fn offset(&self, width: f64) -> Isometry3<f64> {
        self.centre * Isometry3::translation(self.side * (width + FINGER) / 2.0, 0.0, 0.0)
    }
}
impl Physics {
    /// One physics step.
    pub fn step(&mut self) {
        self.bodies_may_move();
        let dt = self.world.integration_parameters.dt;
        self.belts.slow_down(&self.world, dt);
        self.world.step_with_events(&self.belts, &());
    }

    /// The count of changes to the world's contents (see `generation`).
    pub fn generation(&self) -> u64 {
        self.generation
    }

    /// The count of changes that may set lumber moving (see `disturbances`).
    pub fn disturbances(&self) -> u64 {
        self.disturbances
    }

    pub(super) fn changed(&mut self, disturbs: bool) {
        self.bodies_may_move();
        self.generation += 1;
        if disturbs {
            self.disturbances += 1;
        }
    }

    /// Updates the contacts for where the bodies are now, without advancing time (no solver,
    /// nothing moves).
    pub fn detect(&mut self) {
        self.flush();
        self.world.detect_collisions(&self.belts, &());
    }

    pub fn name(&self, c: ColliderHandle) -> String {
        self.names.get(&c).cloned().unwrap_or_else(|| "?".into())
    }
}
