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
