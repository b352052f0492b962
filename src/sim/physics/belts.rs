//! The conveyors' belts: fixed colliders whose contacts get a tangential velocity (rapier's way
//! of modelling a moving belt surface).

use rapier3d::prelude::*;

/// The belts: fixed colliders whose contacts get a tangential velocity (rapier's way of
/// modelling a moving belt surface).
pub struct Belts {
    pub(super) belts: Vec<Belt>,
    /// Both belts stop while the sensor holds a piece.
    pub running: bool,
}

/// One belt's slab, travel direction and speed; its slow end section, where it has one: (the
/// downstream end's distance along the travel direction from the origin, the section's length
/// and speed).
pub(super) struct Belt {
    pub(super) collider: ColliderHandle,
    pub(super) direction: Vector,
    pub(super) speed: f32,
    pub(super) creep: Option<(f32, f32, f32)>,
    /// The belt surface's speed now (m/s): one speed over its whole length (a belt is one
    /// band), set before each step by `Belts::slow_down`.
    pub(super) now: f32,
}

/// How fast a belt slows down for its slow section (m/s²). ESTIMATE: well below what tips a
/// piece on edge over (its centre of mass over its half thickness times g: a 2x6 on edge,
/// 70 mm up and 19 mm across, tips at about 2.7 m/s²); stopping at once from 2 m/s tipped
/// every piece on edge.
pub(super) const BELT_DECELERATION: f32 = 1.5;

impl Belts {
    /// Before a step of `dt` s: a belt with a slow section slows down (at BELT_DECELERATION)
    /// while any body it carries reaches within the braking distance from full speed of that
    /// section, and runs slow while one reaches into it, as a slow-down sensor ahead of an end
    /// stop switches a belt's drive; otherwise it runs at its speed. Slowing only the section's
    /// own surface would twist a piece spanning it.
    pub(super) fn slow_down(&mut self, world: &PhysicsWorld, dt: f32) {
        for belt in &mut self.belts {
            // A belt without a slow section keeps the speed it was built with.
            let Some((end, length, creep)) = belt.creep else {
                continue;
            };
            // From full speed down to the slow one, ending where the section starts.
            let braking = (belt.speed * belt.speed - creep * creep) / (2.0 * BELT_DECELERATION);
            let direction = belt.direction;
            // How far short of the section's start the nearest leading end lies (m).
            let short = world
                .narrow_phase
                .contact_pairs_with(belt.collider)
                .filter(|pair| pair.has_any_active_contact())
                .filter_map(|pair| {
                    let other = if pair.collider1 == belt.collider {
                        pair.collider2
                    } else {
                        pair.collider1
                    };
                    let aabb = world.colliders.get(other)?.compute_aabb();
                    // The box's furthest corner along the travel.
                    let front =
                        aabb.center().dot(direction) + aabb.half_extents().dot(direction.abs());
                    Some(end - front - length)
                })
                .fold(f32::INFINITY, f32::min);
            belt.now = if short <= 0.0 {
                // In the section: slow. A piece that lands there (pushed on from the side)
                // has not taken up the belt's speed yet.
                creep
            } else if short <= braking {
                (belt.now - BELT_DECELERATION * dt).max(creep)
            } else {
                belt.speed
            };
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
                for c in contacts.solver_contacts.iter_mut() {
                    c.tangent_velocity = belt.direction * (belt.now * sign);
                }
            }
            return;
        }
    }
}
