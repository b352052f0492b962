//! Building the world of a cell: floor, conveyors, touch sensor and end stop, tool table, the
//! robot's links and tool as position-driven bodies, the assembly table.

use super::belts::{Belt, Belts};
use super::world::*;
use crate::cell::{Arrangement, Cell, PlacedShape, Shape};
use nalgebra::{Isometry3, Translation3, UnitQuaternion, Vector3};
use rapier3d::prelude::*;
use std::collections::{BTreeMap, HashMap};

impl Physics {
    /// The cell without lumber; the robot at `q`.
    pub fn new(cell: &Cell, q: &[f64], dt: f64) -> Physics {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, 0.0, -GRAVITY as f32);
        world.integration_parameters.dt = dt as f32;
        // rapier keeps a pair's contact points while the pair's relative pose drifts less than
        // 5 cm: far coarser than lumber set to 2 mm. A jack slid 38 mm along its bottom
        // plate kept a contact 12.6 mm apart that it had since passed into, then met the
        // plate all at once and turned. The solver pauses in a quiet world (event stepping),
        // so fresh contacts cost no measurable time (3-storey model: 25.6 s either way).
        world.integration_parameters.contact_recycling = false;
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
                now: c.speed as f32,
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
                                .friction(FINGER_FRICTION)
                                .friction_combine_rule(CoefficientCombineRule::Min)
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
pub(super) fn retracted(origin: &Isometry3<f64>, slide: f64) -> Isometry3<f64> {
    Isometry3::translation(0.0, 0.0, -slide) * origin
}
