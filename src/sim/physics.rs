//! The rapier world of one wall's run: floor, conveyors (belts that carry lumber by friction),
//! the touch sensor and its end stop, the tool table, the robot's links and tool as
//! position-driven bodies, and the lumber as dynamic bodies with their sizes and densities.
//!
//! rapier works in f32 with glam types; the rest of framewright in f64 with nalgebra. The
//! conversions live here.

use crate::cell::{Arrangement, Cell, JointKind, PlacedShape, Shape};
use crate::world::ScenePiece;
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rapier3d::prelude::*;
use std::collections::{BTreeMap, HashMap};

/// Which pairs lumber collides in: the defaults, and a held (kinematic) piece with fixed
/// bodies too. A piece riding a belt (`start_ride`) drops the latter.
fn lumber_collision_types() -> ActiveCollisionTypes {
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
const FIXED: Group = Group::GROUP_1;
const LUMBER: Group = Group::GROUP_2;
const ROBOT: Group = Group::GROUP_3;
const SENSOR: Group = Group::GROUP_4;

fn groups(member: Group, filter: Group) -> InteractionGroups {
    InteractionGroups::new(member, filter, InteractionTestMode::And)
}

/// Lumber friction against the belts, the floor and other lumber.
const LUMBER_FRICTION: f32 = 0.6;
const BELT_FRICTION: f32 = 0.8;
/// Thickness of a belt slab under its top surface.
const BELT_SLAB: f64 = 0.10;
/// Conveyor 2's belt lies this much below its nominal height: lumber sliding across a seam
/// between two flush slabs catches on the second slab's end face; a small step down does not.
const TRANSFER_STEP: f64 = 0.002;
/// The stop rail at the downstream end of a side-by-side conveyor 1: thickness along the
/// travel, height above the belt (m).
const RAIL_SIZE: [f64; 2] = [0.01, 0.03];
/// How far in front of the end stop the sensor zone reaches.
const SENSOR_REACH: f64 = 0.005;
/// Finger plate thickness of a parallel gripper's jaws.
pub const FINGER: f64 = 0.010;

/// The belts: fixed colliders whose contacts get a tangential velocity (rapier's way of
/// modelling a moving belt surface).
pub struct Belts {
    belts: Vec<Belt>,
    /// Both belts stop while the sensor holds a piece.
    pub running: bool,
}

/// One belt's slab, travel direction and speed; its slow end section, where it has one: (the
/// downstream end's distance along the travel direction from the origin, the section's length
/// and speed).
struct Belt {
    collider: ColliderHandle,
    direction: Vector,
    speed: f32,
    creep: Option<(f32, f32, f32)>,
}

impl Belt {
    /// The belt surface's speed under a contact point (world frame).
    fn speed_at(&self, point: Vector) -> f32 {
        match self.creep {
            Some((end, length, creep)) if end - point.dot(self.direction) <= length => creep,
            _ => self.speed,
        }
    }
}

impl PhysicsHooks for Belts {
    fn modify_solver_contacts(&self, ctx: &mut ContactModificationContext) {
        if !self.running {
            return;
        }
        for belt in &self.belts {
            // tangent_velocity is the surface velocity of collider 1 relative to collider 2.
            let sign = if ctx.collider1 == belt.collider {
                1.0
            } else if ctx.collider2 == belt.collider {
                -1.0
            } else {
                continue;
            };
            if let Some(contacts) = ctx.rigid_mut() {
                // Inside this hook a contact's anchor1 is its world point.
                for c in contacts.solver_contacts.iter_mut() {
                    c.tangent_velocity = belt.direction * (belt.speed_at(c.anchor1) * sign);
                }
            }
            return;
        }
    }
}

/// A lumber piece in the world.
#[derive(Debug, Clone, Copy)]
pub struct LumberBody {
    pub body: RigidBodyHandle,
    pub collider: ColliderHandle,
}

/// The jaws of one gripper: two finger plates on either side of the TCP x axis.
#[derive(Debug, Clone, Copy)]
struct Finger {
    collider: ColliderHandle,
    /// The jaw part's centre in tool0 and the finger's side (+1 or -1 along the jaw axis).
    centre: Isometry3<f64>,
    side: f64,
}

/// The world and the handles the executor needs.
pub struct Physics {
    pub world: PhysicsWorld,
    pub belts: Belts,
    /// Robot link index → body (links with collision shapes), in link order.
    pub links: Vec<(usize, RigidBodyHandle)>,
    pub tool: RigidBodyHandle,
    fingers: Vec<Finger>,
    /// The nailer's parts on their slide (a tool with `[nailer] slide`): each collider and its
    /// pose in tool0 when the nailer is out (as the tool file places it).
    nailer: Vec<(ColliderHandle, Isometry3<f64>)>,
    /// Whether the nailer is out on its slide (`cell.tool.nailer_slide` says how far back it
    /// stands otherwise).
    nailer_out: bool,
    /// Every collider of the robot and its tool.
    pub robot_colliders: Vec<ColliderHandle>,
    /// The robot's colliders that move (not the base link's) and the body each belongs to.
    moving_shapes: Vec<(ColliderHandle, ShapeOwner)>,
    pub sensor: ColliderHandle,
    pub lumber: BTreeMap<String, LumberBody>,
    /// Body names for contact reports.
    names: HashMap<ColliderHandle, String>,
    /// Lumber id by collider.
    lumber_of: HashMap<ColliderHandle, String>,
    cell: Cell,
    /// Counts the changes to what is in the world and how it may move (lumber added, removed,
    /// gripped, released, clamped, nailed; jaws; belts): a clearance measured at one count
    /// holds only at that count.
    generation: u64,
    /// Counts the changes that may set lumber moving: all but a piece starting to ride (it
    /// moves at its belt's speed, touching nothing). Settling is judged from the last one.
    disturbances: u64,
    /// Pieces riding a running belt as kinematic bodies (see `start_ride`); while the belts
    /// stand, the riders they left parked (see `set_belts`).
    riding: BTreeMap<String, LumberBody>,
    /// The joints and held piece `place_robot` last put the robot's bodies at, until
    /// anything else may have moved them (a step, a drive, a carry, a change to the world).
    placed: Option<RobotPlacement>,
    /// Where `place_robot` was last asked to put them, not done yet: the bodies move when
    /// something may look at them (`flush`), not every tick of a quiet run.
    pending: Option<RobotPlacement>,
    /// Where `advance_rides` last put each rider, unrounded.
    ride_exact: HashMap<RigidBodyHandle, Vector3<f64>>,
}

/// Joint values and the held piece (id, pose in tool0) the robot's bodies were placed at.
#[derive(Debug, Clone)]
struct RobotPlacement {
    q: Vec<f64>,
    held: Option<(String, Isometry3<f64>)>,
}

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

/// The body a robot collider belongs to: a link (by index) or the tool.
#[derive(Debug, Clone, Copy)]
enum ShapeOwner {
    Link(usize),
    Tool,
}

/// The robot's moving shapes at some joint values (see `Physics::probe`): the poses of the
/// bodies they belong to, each shape's own pose worked out only when it is measured.
#[derive(Debug, Clone)]
pub struct Probe {
    /// Every link's cell-frame pose, and the tool's.
    links: Vec<Isometry3<f64>>,
    tool: Isometry3<f64>,
    /// Per moving joint: its index in the joint values, kind and a point of its axis.
    axes: Vec<(usize, JointKind, Vector3<f64>)>,
    dofs: usize,
    /// The held piece's body: with the robot's own, a clearance leaves it out.
    held_body: Option<RigidBodyHandle>,
    /// The held piece's collider and its pose in tool0: the last shape.
    held: Option<(ColliderHandle, Isometry3<f64>)>,
    /// How many shapes: the robot's moving colliders, then the held piece.
    count: usize,
    riders: Vec<LumberBody>,
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

/// Standard gravity, m/s².
pub const GRAVITY: f64 = 9.81;

impl Physics {
    /// The cell without lumber; the robot at `q`.
    pub fn new(cell: &Cell, q: &[f64], dt: f64) -> Physics {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, 0.0, -GRAVITY as f32);
        world.integration_parameters.dt = dt as f32;
        let mut names = HashMap::new();
        let fixed_groups = groups(FIXED, LUMBER | ROBOT);

        let add_fixed = |world: &mut PhysicsWorld,
                         names: &mut HashMap<ColliderHandle, String>,
                         name: &str,
                         pose: Isometry3<f64>,
                         builder: ColliderBuilder| {
            let (_, c) = world.insert(
                RigidBodyBuilder::fixed().pose(to_pose(&pose)),
                builder.collision_groups(fixed_groups),
            );
            names.insert(c, name.to_string());
            c
        };

        // The floor: a slab whose top is the floor plane.
        let f = cell.floor;
        add_fixed(
            &mut world,
            &mut names,
            "floor",
            Isometry3::translation(0.0, 0.0, f.z - 0.05),
            ColliderBuilder::cuboid(f.size[0] as f32 / 2.0, f.size[1] as f32 / 2.0, 0.05),
        );

        // Conveyors: a belt slab (with the belt hook) on a frame down to the floor.
        let mut belts = Vec::new();
        for (name, c, drop) in [
            ("conveyor 1", &cell.conveyor1, 0.0),
            ("conveyor 2", &cell.conveyor2, TRANSFER_STEP),
        ] {
            let slab = c.pose * Isometry3::translation(0.0, 0.0, -BELT_SLAB / 2.0 - drop);
            let belt = add_fixed(
                &mut world,
                &mut names,
                name,
                slab,
                ColliderBuilder::cuboid(
                    c.length as f32 / 2.0,
                    c.width as f32 / 2.0,
                    BELT_SLAB as f32 / 2.0,
                )
                .friction(BELT_FRICTION)
                .active_hooks(ActiveHooks::MODIFY_SOLVER_CONTACTS),
            );
            let direction = c.direction().cast::<f32>();
            let direction = Vector::new(direction.x, direction.y, direction.z);
            let end = c.downstream_end().coords.cast::<f32>();
            belts.push(Belt {
                collider: belt,
                direction,
                speed: c.speed as f32,
                creep: c.creep.map(|k| {
                    (
                        Vector::new(end.x, end.y, end.z).dot(direction),
                        k.length as f32,
                        k.speed as f32,
                    )
                }),
            });
            let frame_height = c.pose.translation.z - BELT_SLAB - f.z;
            if frame_height > 0.01 {
                let frame =
                    c.pose * Isometry3::translation(0.0, 0.0, -BELT_SLAB - frame_height / 2.0);
                add_fixed(
                    &mut world,
                    &mut names,
                    &format!("{name} frame"),
                    frame,
                    ColliderBuilder::cuboid(
                        c.length as f32 / 2.0,
                        (c.width * 0.8) as f32 / 2.0,
                        frame_height as f32 / 2.0,
                    ),
                );
            }
        }

        // Side by side, conveyor 1 pushes its lumber against a low stop rail along its
        // downstream end; the transfer (the executor's feeder) lifts each piece over it onto
        // conveyor 2 when that belt is free.
        if cell.arrangement == Arrangement::SideBySide {
            let c = &cell.conveyor1;
            let rail = c.pose
                * Isometry3::translation(
                    c.length / 2.0 + RAIL_SIZE[0] / 2.0,
                    0.0,
                    RAIL_SIZE[1] / 2.0,
                );
            add_fixed(
                &mut world,
                &mut names,
                "conveyor 1 stop rail",
                rail,
                ColliderBuilder::cuboid(
                    RAIL_SIZE[0] as f32 / 2.0,
                    c.width as f32 / 2.0,
                    RAIL_SIZE[1] as f32 / 2.0,
                ),
            );
        }

        // The touch sensor: a solid end stop the lumber runs into, and a thin sensing zone
        // in front of its face.
        let s = cell.touch_sensor;
        let half = |v: f64| v as f32 / 2.0;
        add_fixed(
            &mut world,
            &mut names,
            "touch sensor",
            s.pose,
            ColliderBuilder::cuboid(half(s.size[0]), half(s.size[1]), half(s.size[2])),
        );
        let zone = s.pose * Isometry3::translation(-(s.size[0] + SENSOR_REACH) / 2.0, 0.0, 0.0);
        let (_, sensor) = world.insert(
            RigidBodyBuilder::fixed().pose(to_pose(&zone)),
            ColliderBuilder::cuboid(half(SENSOR_REACH * 2.0), half(s.size[1]), half(s.size[2]))
                .sensor(true)
                .collision_groups(groups(SENSOR, LUMBER)),
        );
        names.insert(sensor, "touch sensor zone".into());

        // The tool table: a top on four legs.
        let t = cell.tool_table;
        let top = Isometry3::translation(
            t.top_centre.x,
            t.top_centre.y,
            t.top_centre.z - t.size[2] / 2.0,
        );
        add_fixed(
            &mut world,
            &mut names,
            "tool table",
            top,
            ColliderBuilder::cuboid(half(t.size[0]), half(t.size[1]), half(t.size[2])),
        );
        let leg = 0.05;
        let leg_height = t.top_centre.z - t.size[2] - f.z;
        if leg_height > 0.01 {
            for (sx, sy) in [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)] {
                let pose = Isometry3::translation(
                    t.top_centre.x + sx * (t.size[0] / 2.0 - leg),
                    t.top_centre.y + sy * (t.size[1] / 2.0 - leg),
                    f.z + leg_height / 2.0,
                );
                add_fixed(
                    &mut world,
                    &mut names,
                    "tool table leg",
                    pose,
                    ColliderBuilder::cuboid(half(leg), half(leg), half(leg_height)),
                );
            }
        }

        // The robot: one position-driven body per link with collision shapes; the base does
        // not touch the floor it stands on.
        let robot_types = ActiveCollisionTypes::default() | ActiveCollisionTypes::KINEMATIC_FIXED;
        let poses = cell.robot.fk_all(q);
        let mut links = Vec::new();
        let mut robot_colliders = Vec::new();
        for (i, link) in cell.robot.links.iter().enumerate() {
            if link.collisions.is_empty() {
                continue;
            }
            let body = world.insert_body(
                RigidBodyBuilder::kinematic_position_based()
                    .pose(to_pose(&(cell.robot_base * poses[i]))),
            );
            let filter = if i == 0 { LUMBER } else { FIXED | LUMBER };
            for shape in &link.collisions {
                let c = world.insert_collider(
                    collider(shape)
                        .collision_groups(groups(ROBOT, filter))
                        .active_collision_types(robot_types),
                    Some(body),
                );
                names.insert(c, link.name.clone());
                robot_colliders.push(c);
            }
            links.push((i, body));
        }

        // The tool on the flange; gripper jaws become two finger plates each, which open and
        // close with the gripper.
        let tool_pose = cell.robot_base * cell.robot.fk_tip(q);
        let tool = world
            .insert_body(RigidBodyBuilder::kinematic_position_based().pose(to_pose(&tool_pose)));
        let mut fingers = Vec::new();
        let mut nailer = Vec::new();
        let open = cell
            .tool
            .gripper
            .as_ref()
            .and_then(|g| g.jaws())
            .map_or(0.1, |j| j.open_width);
        for part in &cell.tool.parts {
            let name = format!("tool {}", part.name);
            match (&part.shape.shape, part.name.ends_with("_jaws")) {
                (Shape::Box { half_extents: h }, true) => {
                    for side in [-1.0, 1.0] {
                        let finger = Finger {
                            collider: ColliderHandle::invalid(),
                            centre: part.shape.origin,
                            side,
                        };
                        let c = world.insert_collider(
                            ColliderBuilder::cuboid(half(FINGER), h[1] as f32, h[2] as f32)
                                .position(to_pose(&finger.offset(open)))
                                .collision_groups(groups(ROBOT, FIXED | LUMBER))
                                .active_collision_types(robot_types),
                            Some(tool),
                        );
                        names.insert(c, format!("{name} finger"));
                        robot_colliders.push(c);
                        fingers.push(Finger {
                            collider: c,
                            ..finger
                        });
                    }
                }
                _ => {
                    let c = world.insert_collider(
                        collider(&part.shape)
                            .collision_groups(groups(ROBOT, FIXED | LUMBER))
                            .active_collision_types(robot_types),
                        Some(tool),
                    );
                    names.insert(c, name);
                    robot_colliders.push(c);
                    if cell.tool.nailer_slide > 0.0 && part.name.starts_with("nailer") {
                        // The run starts with the nailer back on its slide.
                        let back = retracted(&part.shape.origin, cell.tool.nailer_slide);
                        world.colliders[c].set_position_wrt_parent(to_pose(&back));
                        nailer.push((c, part.shape.origin));
                    }
                }
            }
        }

        let moving_shapes = robot_colliders
            .iter()
            .filter_map(|&c| {
                let parent = world.colliders[c].parent()?;
                if parent == tool {
                    return Some((c, ShapeOwner::Tool));
                }
                match links.iter().find(|l| l.1 == parent) {
                    Some(&(0, _)) | None => None,
                    Some(&(i, _)) => Some((c, ShapeOwner::Link(i))),
                }
            })
            .collect();
        Physics {
            world,
            belts: Belts {
                belts,
                running: true,
            },
            links,
            tool,
            fingers,
            nailer,
            nailer_out: false,
            robot_colliders,
            moving_shapes,
            sensor,
            lumber: BTreeMap::new(),
            names,
            lumber_of: HashMap::new(),
            cell: cell.clone(),
            generation: 0,
            disturbances: 0,
            riding: BTreeMap::new(),
            placed: None,
            pending: None,
            ride_exact: HashMap::new(),
        }
    }

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

    fn insert_lumber(&mut self, piece: &ScenePiece, pose: &Isometry3<f64>, disturbs: bool) {
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

    /// Moves the robot's base (its carriage on a linear track); the links follow at the
    /// next drive or placement.
    pub fn set_robot_base(&mut self, base: nalgebra::Isometry3<f64>) {
        self.bodies_may_move();
        self.cell.robot_base = base;
    }

    /// Moves the robot's bodies to joint values `q` by the end of the next step.
    pub fn drive_robot(&mut self, q: &[f64]) {
        // The step moves the bodies from where they stand now.
        self.bodies_may_move();
        let poses = self.cell.robot.fk_all(q);
        for &(i, body) in &self.links {
            let pose = to_pose(&(self.cell.robot_base * poses[i]));
            self.world.bodies[body].set_next_kinematic_position(pose);
        }
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(q);
        self.world.bodies[self.tool].set_next_kinematic_position(to_pose(&tool));
    }

    /// A framing table under the wall when the cell's assembly surface is above the floor:
    /// a solid block from the floor to `top` over the cell-frame rectangle `min`..`max`.
    pub fn add_assembly_table(&mut self, min: [f64; 2], max: [f64; 2], top: f64) {
        self.changed(true);
        let floor = self.cell.floor.z;
        let height = top - floor;
        if height <= 0.0 {
            return;
        }
        let centre = Isometry3::translation(
            (min[0] + max[0]) / 2.0,
            (min[1] + max[1]) / 2.0,
            floor + height / 2.0,
        );
        let (_, c) = self.world.insert(
            RigidBodyBuilder::fixed().pose(to_pose(&centre)),
            ColliderBuilder::cuboid(
                ((max[0] - min[0]) / 2.0) as f32,
                ((max[1] - min[1]) / 2.0) as f32,
                (height / 2.0) as f32,
            )
            .collision_groups(groups(FIXED, LUMBER | ROBOT)),
        );
        self.names.insert(c, "assembly table".into());
    }

    /// Opens the jaws (`None`) or closes them on lumber of this thickness.
    pub fn set_jaws(&mut self, closed_on: Option<f64>) {
        self.changed(true);
        let open = self
            .cell
            .tool
            .gripper
            .as_ref()
            .and_then(|g| g.jaws())
            .map_or(0.1, |j| j.open_width);
        let width = closed_on.unwrap_or(open);
        for f in &self.fingers {
            if let Some(c) = self.world.colliders.get_mut(f.collider) {
                c.set_position_wrt_parent(to_pose(&f.offset(width)));
            }
        }
    }

    /// Runs the nailer out on its slide (`true`: where the tool file places it) or back.
    pub fn set_nailer(&mut self, out: bool) {
        if self.nailer.is_empty() || self.nailer_out == out {
            return;
        }
        self.changed(true);
        self.nailer_out = out;
        let slide = self.cell.tool.nailer_slide;
        for (c, origin) in &self.nailer {
            let pose = if out {
                *origin
            } else {
                retracted(origin, slide)
            };
            if let Some(c) = self.world.colliders.get_mut(*c) {
                c.set_position_wrt_parent(to_pose(&pose));
            }
        }
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

    /// One physics step.
    pub fn step(&mut self) {
        self.bodies_may_move();
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

    fn changed(&mut self, disturbs: bool) {
        self.bodies_may_move();
        self.generation += 1;
        if disturbs {
            self.disturbances += 1;
        }
    }

    /// Puts the robot's bodies (and the held piece, at `in_tool` in tool0) at joint values
    /// `q` at once, without a step: nothing is pushed and no velocity results. The bodies
    /// move when anything may see them (a step, a collision detection, a change to the
    /// world, the held piece's pose asked for): a robot moving through a quiet world is
    /// placed once per look, not once per tick. What is seen is the same.
    pub fn place_robot(&mut self, q: &[f64], held: Option<(&str, &Isometry3<f64>)>) {
        // A robot standing still (waiting for a piece) is where the last placement left it.
        let same = |p: &RobotPlacement| {
            p.q.as_slice() == q && p.held.as_ref().map(|(id, g)| (id.as_str(), g)) == held
        };
        if self
            .pending
            .as_ref()
            .or(self.placed.as_ref())
            .is_some_and(same)
        {
            return;
        }
        // Written over the waiting placement's buffers: no allocation per tick.
        let p = self.pending.get_or_insert_with(|| RobotPlacement {
            q: Vec::new(),
            held: None,
        });
        p.q.clear();
        p.q.extend_from_slice(q);
        match (held, &mut p.held) {
            (Some((id, g)), Some((was, in_tool))) => {
                if was != id {
                    was.clear();
                    was.push_str(id);
                }
                *in_tool = *g;
            }
            (held, slot) => *slot = held.map(|(id, g)| (id.to_string(), *g)),
        }
    }

    /// Before anything that may move the robot's bodies or look at them: they stand where
    /// `place_robot` was last asked to put them, and the next placement places them again.
    fn bodies_may_move(&mut self) {
        self.flush();
        self.placed = None;
    }

    /// Moves the robot's bodies where `place_robot` was last asked to put them.
    fn flush(&mut self) {
        let Some(placement) = self.pending.take() else {
            return;
        };
        let poses = self.cell.robot.fk_all(&placement.q);
        for &(i, body) in &self.links {
            let pose = to_pose(&(self.cell.robot_base * poses[i]));
            self.world.bodies[body].set_position(pose, false);
        }
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(&placement.q);
        self.world.bodies[self.tool].set_position(to_pose(&tool), false);
        if let Some((id, in_tool)) = &placement.held
            && let Some(b) = self.lumber.get(id)
        {
            self.world.bodies[b.body].set_position(to_pose(&(tool * in_tool)), false);
        }
        self.placed = Some(placement);
    }

    /// The held piece's pose while its placement waits (see `place_robot`), as `flush` will
    /// set it.
    fn pending_held(&self) -> Option<(&str, Isometry3<f64>)> {
        let placement = self.pending.as_ref()?;
        let (id, in_tool) = placement.held.as_ref()?;
        self.lumber.get(id)?;
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(&placement.q);
        Some((id.as_str(), to_iso(&to_pose(&(tool * in_tool)))))
    }

    /// Updates the contacts for where the bodies are now, without advancing time (no solver,
    /// nothing moves).
    pub fn detect(&mut self) {
        self.flush();
        self.world.detect_collisions(&self.belts, &());
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

    /// The probe's shape `i` (the robot's moving colliders, then the held piece) and its
    /// cell-frame pose.
    fn probe_shape(&self, probe: &Probe, i: usize) -> (ColliderHandle, Isometry3<f64>) {
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

    /// Where the robot's base stands (it moves with a carriage).
    pub fn robot_base(&self) -> Isometry3<f64> {
        self.cell.robot_base
    }

    /// The corners of the local bounding box of the probe's shape `i`, in the cell frame.
    fn shape_corners(&self, probe: &Probe, i: usize) -> [Vector3<f64>; 8] {
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

    /// Contacts of the robot, its tool and the piece `held` with anything else, deeper than
    /// `tolerance` (any depth between the arm or tool and lumber): (body, other body, depth),
    /// excluding the held piece against the tool.
    pub fn robot_contacts(&self, held: Option<&str>, tolerance: f64) -> Vec<(String, String, f64)> {
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
                let depth = -f64::from(contact.dist);
                // Any touch of the arm or tool on a piece counts: a graze knocks it over.
                // A held piece set down against its neighbours may touch them.
                let limit = if Some(c) != held_collider && self.lumber_of.contains_key(&other) {
                    0.0
                } else {
                    tolerance
                };
                if depth > limit {
                    found.push((self.name(c), self.name(other), depth));
                }
            }
        }
        found
    }

    pub fn name(&self, c: ColliderHandle) -> String {
        self.names.get(&c).cloned().unwrap_or_else(|| "?".into())
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

/// A box covering everything within `margin` of `shape` (its bounding box grown by the
/// margin, a coarse candidate filter; exact distances are measured afterwards) and the box's
/// centre in the shape's frame.
fn grown_box(shape: &dyn rapier3d::parry::shape::Shape, margin: f64) -> (Cuboid, Pose) {
    let aabb = shape.compute_local_aabb();
    let half = aabb.half_extents() + Vector::splat(margin as f32);
    (Cuboid::new(half), Pose::from_translation(aabb.center()))
}

impl Finger {
    /// The finger's pose in tool0 when the jaws stand `width` apart.
    fn offset(&self, width: f64) -> Isometry3<f64> {
        self.centre * Isometry3::translation(self.side * (width + FINGER) / 2.0, 0.0, 0.0)
    }
}

/// A rapier collider builder for a placed primitive (cylinders and capsules along local z).
pub fn collider(shape: &PlacedShape) -> ColliderBuilder {
    // rapier's cylinders run along y: turn them onto z.
    let y_to_z = Isometry3::from_parts(
        Translation3::identity(),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2),
    );
    let (builder, pose) = match shape.shape {
        Shape::Box { half_extents: h } => (
            ColliderBuilder::cuboid(h[0] as f32, h[1] as f32, h[2] as f32),
            shape.origin,
        ),
        Shape::Cylinder { radius, length } => (
            ColliderBuilder::cylinder(length as f32 / 2.0, radius as f32),
            shape.origin * y_to_z,
        ),
        Shape::Capsule { radius, length } => (
            ColliderBuilder::capsule_z(length as f32 / 2.0, radius as f32),
            shape.origin,
        ),
        Shape::Sphere { radius } => (ColliderBuilder::ball(radius as f32), shape.origin),
    };
    builder.position(to_pose(&pose))
}

/// A nailer part's pose in tool0 with the nailer `slide` back towards the flange (tool0 -z).
fn retracted(origin: &Isometry3<f64>, slide: f64) -> Isometry3<f64> {
    Isometry3::translation(0.0, 0.0, -slide) * origin
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 0.5 m piece standing on conveyor 1's deck, its centre on the deck's centre.
    fn piece_on_deck(cell: &Cell) -> (ScenePiece, Isometry3<f64>) {
        let size = [0.5, 0.1, 0.1];
        let pose = cell.conveyor1.pose * Isometry3::translation(0.0, 0.0, size[2] / 2.0);
        let piece = ScenePiece {
            id: "p".into(),
            name: "p".into(),
            ifc_type: "IfcMember".into(),
            wall: "W1".into(),
            slot: 0,
            size,
            material: "wood".into(),
            density: 450.0,
            mass: 450.0 * size.iter().product::<f64>(),
            spawn: pose,
            beyond_belt: None,
            target_robot: pose,
            target_cell: pose,
            on_edge: true,
            plies: Vec::new(),
        };
        (piece, pose)
    }

    /// A world with piece "p" on conveyor 1 and the belts running.
    fn piece_on_running_belt(cell: &Cell, dt: f64) -> Physics {
        let mut phys = Physics::new(cell, &cell.robot.home(), dt);
        let (piece, pose) = piece_on_deck(cell);
        phys.add_lumber(&piece, &pose);
        phys.set_belts(true, false);
        phys
    }

    #[test]
    fn a_riding_piece_moves_at_the_belt_speed_and_is_dynamic_again_when_the_belts_stop() {
        let cell = Cell::load("study-abb").expect("cell");
        let dt = 1.0 / 240.0;
        let mut phys = piece_on_running_belt(&cell, dt);
        for _ in 0..240 {
            phys.step();
        }
        let before = phys.lumber_pose("p").expect("piece");
        let velocity = cell.conveyor1.direction() * cell.conveyor1.speed;
        phys.start_ride("p", &velocity);
        let steps = 480;
        for _ in 0..steps {
            phys.step();
        }
        let after = phys.lumber_pose("p").expect("piece");
        let expected = velocity * (steps as f64 * dt);
        let moved = after.translation.vector - before.translation.vector;
        // The world is f32: each step rounds the position by up to about one unit in the last
        // place at the piece's distance from the origin.
        let rounding =
            steps as f64 * 2.0 * f64::from(f32::EPSILON) * after.translation.vector.amax();
        assert!(
            (moved - expected).norm() < rounding,
            "moved {moved:?}, the belt {expected:?}"
        );
        assert!(after.rotation.angle_to(&before.rotation) < 1e-6);
        let body = phys.lumber["p"].body;
        assert!(phys.world.bodies[body].is_kinematic());
        // Stopping the belts ends the ride: a dynamic body at rest.
        phys.set_belts(false, false);
        assert!(phys.world.bodies[body].is_dynamic());
        assert!(phys.lumber_speed("p").expect("piece").0 < 1e-9);
    }

    #[test]
    fn a_parked_rider_stays_put_without_the_solver_and_is_dynamic_when_the_belts_start() {
        let cell = Cell::load("study-abb").expect("cell");
        let dt = 1.0 / 240.0;
        let mut phys = piece_on_running_belt(&cell, dt);
        let velocity = cell.conveyor1.direction() * cell.conveyor1.speed;
        phys.start_ride("p", &velocity);
        for _ in 0..24 {
            phys.step();
            phys.advance_rides(dt);
        }
        phys.set_belts(false, true);
        let body = phys.lumber["p"].body;
        let parked_at = phys.lumber_pose("p").expect("piece");
        // Parked: kinematic, at rest, not counted as lumber the solver must watch.
        assert!(phys.world.bodies[body].is_kinematic());
        assert!(phys.lumber_calm(1e-9, 1e-9));
        for _ in 0..240 {
            phys.step();
            phys.advance_rides(dt);
        }
        assert_eq!(phys.lumber_pose("p").expect("piece"), parked_at);
        // The robot's clearance sees it as parked lumber.
        let clear = phys.clearance(&cell.robot.home(), None, 100.0, EVERY_TOUCH);
        assert!(clear.parked < 100.0 && clear.parked >= clear.loose);
        // Starting the belts leaves it as stopping them without parking does: dynamic, at rest.
        phys.set_belts(true, false);
        assert!(phys.world.bodies[body].is_dynamic());
        assert!(!phys.is_riding("p"));
        assert!(phys.lumber_speed("p").expect("piece").0 < 1e-9);
        assert_eq!(phys.lumber_pose("p").expect("piece"), parked_at);
    }

    #[test]
    fn unparking_makes_parked_lumber_dynamic_at_rest() {
        let cell = Cell::load("study-abb").expect("cell");
        let mut phys = piece_on_running_belt(&cell, 1.0 / 240.0);
        phys.start_ride("p", &(cell.conveyor1.direction() * cell.conveyor1.speed));
        phys.set_belts(false, true);
        let generation = phys.generation();
        phys.unpark();
        let body = phys.lumber["p"].body;
        assert!(phys.world.bodies[body].is_dynamic());
        assert!(!phys.is_riding("p"));
        assert!(
            phys.generation() > generation,
            "unparking changes the world"
        );
        assert_eq!(
            phys.clearance(&cell.robot.home(), None, 100.0, EVERY_TOUCH)
                .parked,
            100.0
        );
        // A standing belt carries nothing: no ride starts on it.
        phys.start_ride("p", &(cell.conveyor1.direction() * cell.conveyor1.speed));
        assert!(!phys.is_riding("p") && phys.world.bodies[body].is_dynamic());
    }

    #[test]
    fn advancing_a_ride_without_the_solver_moves_it_as_steps_do_and_clearance_sees_it_there() {
        let cell = Cell::load("study-abb").expect("cell");
        let dt = 1.0 / 240.0;
        let velocity = cell.conveyor1.direction() * cell.conveyor1.speed;
        let ride = |advance: bool| {
            let mut phys = Physics::new(&cell, &cell.robot.home(), dt);
            let (piece, pose) = piece_on_deck(&cell);
            phys.add_lumber(&piece, &pose);
            phys.set_belts(true, false);
            phys.start_ride("p", &velocity);
            for _ in 0..480 {
                if advance {
                    phys.advance_rides(dt);
                } else {
                    phys.step();
                }
            }
            phys
        };
        let stepped = ride(false).lumber_pose("p").expect("piece");
        let advanced_world = ride(true);
        let advanced = advanced_world.lumber_pose("p").expect("piece");
        let expected = (velocity * 480.0 * dt).norm();
        assert!(expected > 0.05, "the ride covers {expected} m");
        // Against the belt's travel: the advanced ride is off by the f32 rounding of its
        // start and end (not per step); the stepped one within rapier's per-step rounding.
        let start = piece_on_deck(&cell).1.translation.vector;
        let error = |pose: &Isometry3<f64>| {
            (pose.translation.vector - start - velocity * 480.0 * dt).norm()
        };
        let ulp = f64::from(f32::EPSILON) * advanced.translation.vector.amax();
        assert!(
            error(&advanced) < 4.0 * ulp,
            "advanced ride off by {}",
            error(&advanced)
        );
        assert!(
            error(&stepped) < 480.0 * 2.0 * ulp,
            "stepped ride off by {}",
            error(&stepped)
        );
        assert!((advanced_world.ride_speed() - cell.conveyor1.speed).abs() < 1e-6);
        // The rider counts as loose where it is now, not where the broad phase last saw it:
        // its distance to the robot at home equals that of a world stepped to the same place.
        let home = cell.robot.home();
        let measured = |phys: &Physics| phys.clearance(&home, None, 100.0, EVERY_TOUCH);
        let (a, b) = (measured(&ride(false)), measured(&advanced_world));
        // (within the stepped ride's rounding; the broad phase's stale place is the whole
        // ride, 0.1 m, away)
        assert!(
            (a.loose - b.loose).abs() < 1e-3,
            "{} vs {}",
            a.loose,
            b.loose
        );
        assert!(b.loose < 100.0);
    }

    /// The robot's bodies move when looked at (`place_robot` is lazy): the held piece is seen
    /// where the grip puts it on the tool at the last joints asked for, before and after the
    /// bodies move, and the tool body stands at those joints afterwards.
    #[test]
    fn a_placement_is_seen_before_the_bodies_move_where_they_then_move() {
        let cell = Cell::load("study-abb").expect("cell");
        let mut phys = piece_on_running_belt(&cell, 1.0 / 240.0);
        phys.attach("p");
        let in_tool = Isometry3::translation(0.01, -0.02, 0.2);
        let home = cell.robot.home();
        let near = |a: &Isometry3<f64>, b: &Isometry3<f64>| {
            (a.translation.vector - b.translation.vector).norm() < 1e-5
                && a.rotation.angle_to(&b.rotation) < 1e-5
        };
        let mut last = None;
        for k in 1..=5 {
            let q: Vec<f64> = home
                .iter()
                .enumerate()
                .map(|(j, v)| v + 0.01 * k as f64 * (j as f64 + 1.0))
                .collect();
            phys.place_robot(&q, Some(("p", &in_tool)));
            let seen = phys.lumber_pose("p").expect("piece");
            let tool = cell.robot_base * cell.robot.fk_tip(&q);
            assert!(near(&seen, &(tool * in_tool)), "k = {k}");
            assert_eq!(phys.lumber_poses_in_order()[0], ("p", seen));
            last = Some((tool, seen));
        }
        let (tool, seen) = last.expect("placed");
        phys.detect();
        assert_eq!(
            phys.lumber_pose("p"),
            Some(seen),
            "the body is where it was seen"
        );
        assert!(near(
            &to_iso(phys.world.bodies[phys.tool].position()),
            &tool
        ));
    }

    /// Every touch, at any depth.
    const EVERY_TOUCH: Watch = Watch::AllBut {
        bodies: &[],
        tolerance: 0.0,
    };

    /// How far the held piece is from a recorded touch when it lies `gap` from a clamped piece
    /// end to end (negative: pressed that deep into it), leaving out the pieces `ignored`.
    fn held_piece_to_record(gap: f64, ignored: &[String]) -> f64 {
        let cell = Cell::load("study-abb").expect("cell");
        let home = cell.robot.home();
        let mut phys = Physics::new(&cell, &home, 1.0 / 240.0);
        let (mut piece, _) = piece_on_deck(&cell);
        let in_tool = Isometry3::translation(0.0, 0.0, 0.3);
        let held_at = cell.robot_base * cell.robot.fk_tip(&home) * in_tool;
        phys.add_lumber(&piece, &held_at);
        piece.id = "w".into();
        let beside = held_at * Isometry3::translation(piece.size[0] + gap, 0.0, 0.0);
        phys.add_lumber(&piece, &beside);
        phys.attach("p");
        phys.clamp("w");
        phys.place_robot(&home, Some(("p", &in_tool)));
        phys.detect();
        let probe = phys.probe(&home, Some(("p", &in_tool)));
        let held = probe.held_shape().expect("the held piece is a shape");
        let watch = Watch::AllBut {
            bodies: ignored,
            tolerance: 0.001,
        };
        phys.shape_clearance(&probe, held, 0.1, watch).any
    }

    #[test]
    fn a_held_piece_is_a_recorded_touch_only_deeper_than_the_tolerance() {
        // Apart: the gap plus the depth that goes unrecorded.
        assert!((held_piece_to_record(0.003, &[]) - 0.004).abs() < 1e-5);
        // Pressed in less than the tolerance: not yet a recorded touch.
        assert!((held_piece_to_record(-0.0005, &[]) - 0.0005).abs() < 1e-5);
        // Deeper: recorded, by how much.
        assert!((held_piece_to_record(-0.002, &[]) + 0.001).abs() < 1e-5);
        // A piece the operation may touch is left out.
        assert!(held_piece_to_record(-0.002, &["piece w".to_string()]) > 0.05);
    }

    #[test]
    fn joint_levers_bound_how_far_every_corner_of_each_shape_moves() {
        for name in ["study-abb", "study-kuka"] {
            let cell = Cell::load(name).expect("cell");
            let phys = Physics::new(&cell, &cell.robot.home(), 1.0 / 240.0);
            let home = cell.robot.home();
            let at_home = phys.probe(&home, None);
            let slack = 0.10;
            let mut checked = 0;
            for i in 0..at_home.shape_count() {
                let corners = phys.shape_corners(&at_home, i);
                let levers = phys.levers(&at_home, i, slack);
                let mut farthest: f64 = 0.0;
                // Small moves of every joint together, both ways: each corner moves no
                // further than the bound while the bound stays under the slack.
                for k in 0..200 {
                    let dq: Vec<f64> = (0..home.len())
                        .map(|j| 0.004 * (((k * 7 + j * 3) % 11) as f64 - 5.0) / 5.0)
                        .collect();
                    let q: Vec<f64> = home.iter().zip(&dq).map(|(a, d)| a + d).collect();
                    let bound: f64 = dq.iter().zip(&levers).map(|(d, l)| d.abs() * l).sum();
                    if bound >= slack {
                        continue;
                    }
                    let moved = phys
                        .shape_corners(&phys.probe(&q, None), i)
                        .iter()
                        .zip(&corners)
                        .map(|(a, b)| (a - b).norm())
                        .fold(0.0, f64::max);
                    assert!(
                        moved <= bound + 1e-9,
                        "{name} shape {i}: moved {moved} > bound {bound}"
                    );
                    farthest = farthest.max(moved);
                    checked += 1;
                }
                // The moves move every shape (the bound is not checked on a standstill).
                assert!(farthest > 0.0, "{name} shape {i} never moved");
            }
            assert!(
                checked > 100 * at_home.shape_count(),
                "{name}: only {checked} moves within the slack"
            );
        }
    }
}
