//! Feeding: lumber onto conveyor 1 in assembly order, the belts, and the touch sensor that
//! stops them when a piece arrives.

use super::WallRun;
use crate::cell::Arrangement;
use crate::sim::record::BeltEvent;
use crate::world::ScenePiece;
use nalgebra::{Isometry3, Point3, Translation3, Vector3};
use std::collections::HashMap;

/// A piece this close to conveyor 1's stop rail is at the rail (m).
const TRANSFER_REACH: f64 = 0.005;
/// A piece on conveyor 1 rides it without the solver while nothing lies within this ahead of
/// it (m): 0.2 s of travel at the study's 0.05 m/s. The rest of the way it is a dynamic body
/// and meets what is ahead under the solver.
const RIDE_CLEARANCE: f64 = 0.01;

impl<'a> WallRun<'a> {
    /// Puts every piece whose spawn pose lies on conveyor 1 there; the rest wait in the queue.
    pub(super) fn load_belts(&mut self) {
        for p in self.pieces.clone() {
            // What the cell cannot carry or grip is never fed (`frame` says why).
            if self.carry_check(p).is_err() || self.grip_check(p).is_err() {
                continue;
            }
            if p.beyond_belt.is_none() && self.queue.is_empty() {
                self.phys.add_lumber(p, &p.spawn);
                self.on_belts.insert(p.id.clone());
            } else {
                self.queue.push_back(p);
            }
        }
    }

    /// Along conveyor 1 from its upstream end (m).
    fn belt1_position(&self, point: &Vector3<f64>) -> f64 {
        let c = &self.cell.conveyor1;
        (point - c.upstream_end().coords).dot(&c.direction())
    }

    /// The feeder: the next queued piece goes onto conveyor 1's upstream end once the belt
    /// there is clear by the lumber gap.
    pub(super) fn feed(&mut self) {
        self.update_rides();
        if self.cell.arrangement == Arrangement::SideBySide {
            self.transfer();
        }
        let Some(next) = self.queue.front().copied() else {
            return;
        };
        // After a look that found the belt short of clear, the next is due when it can be.
        let state = self.belt_state();
        if let Some((seen, due)) = self.feed_due
            && seen == state
            && self.t < due
        {
            return;
        }
        // How much of the belt's travel it takes up (its length end to end, its thickness
        // side by side).
        let direction = self.cell.conveyor1.direction();
        let local = next.spawn.rotation.inverse() * direction;
        let length: f64 = (0..3).map(|i| local[i].abs() * next.size[i]).sum();
        let shortfall = self
            .on_belts
            .iter()
            .filter_map(|id| {
                let pose = self.phys.lumber_pose(id)?;
                let centre = self.belt1_position(&pose.translation.vector);
                let half = piece_half_along(&pose, &direction, id, &self.sizes);
                Some(length + self.cell.lumber_gap - (centre - half))
            })
            .fold(f64::NEG_INFINITY, f64::max);
        if shortfall > 0.0 {
            self.feed_due = Some((state, self.due_after(shortfall)));
            return;
        }
        self.feed_due = None;
        // Its queue pose moved upstream-end first onto the belt.
        let at = self.belt1_position(&next.spawn.translation.vector);
        let shift = self.cell.conveyor1.direction() * (length / 2.0 - at);
        let pose = Isometry3::from_parts(
            Translation3::from(next.spawn.translation.vector + shift),
            next.spawn.rotation,
        );
        self.queue.pop_front();
        // With room ahead (the gap to the piece in front, the belt to its end) it rides from
        // the start, as `update_rides` would have it after its next look.
        let c1 = &self.cell.conveyor1;
        let room = self.cell.lumber_gap.min(c1.length - length);
        if self.phys.belts.running && room > RIDE_CLEARANCE {
            self.phys.add_riding(next, &pose, &(direction * c1.speed));
        } else {
            self.phys.add_lumber(next, &pose);
        }
        self.on_belts.insert(next.id.clone());
    }

    /// What the feeder's looks depend on besides the belt's travel: the world's change count
    /// and the lumber on the belts.
    fn belt_state(&self) -> (u64, usize) {
        (self.phys.generation(), self.on_belts.len())
    }

    /// The time a look that found conveyor 1 short of its mark by `shortfall` (m) is next due:
    /// nothing on it moves faster than its belt.
    fn due_after(&self, shortfall: f64) -> f64 {
        let speed = if self.phys.belts.running {
            self.cell.conveyor1.speed
        } else {
            0.0
        };
        if speed > 0.0 {
            self.t + shortfall / speed - self.options.dt
        } else {
            f64::INFINITY
        }
    }

    /// Pieces on conveyor 1 with nothing within RIDE_CLEARANCE ahead of them (the next piece
    /// or the belt's downstream end) ride it without the solver; the others are dynamic.
    fn update_rides(&mut self) {
        if !self.phys.belts.running {
            return; // stopping the belts ended every ride
        }
        let c1 = self.cell.conveyor1;
        // Looked at every so many ticks: between two looks a piece travels at most a fifth of
        // the clearance, so a ride always ends with most of it still ahead.
        let travel = c1.speed * self.options.dt;
        let every = ((RIDE_CLEARANCE / 5.0) / travel).floor().max(1.0) as u64;
        if !((self.t / self.options.dt).round() as u64).is_multiple_of(every) {
            return;
        }
        let direction = c1.direction();
        // (back, front, id) along conveyor 1 of every piece whose centre lies on it.
        let mut on_c1: Vec<(f64, f64, &String)> = Vec::new();
        for id in &self.on_belts {
            if self.transferred.contains(id) {
                continue;
            }
            let Some(pose) = self.phys.lumber_pose(id) else {
                continue;
            };
            let centre = self.belt1_position(&pose.translation.vector);
            let on_c2 = self
                .cell
                .conveyor2
                .covers(&Point3::from(pose.translation.vector));
            if on_c2 || !(0.0..=c1.length).contains(&centre) {
                continue;
            }
            let half = piece_half_along(&pose, &direction, id, &self.sizes);
            on_c1.push((centre - half, centre + half, id));
        }
        on_c1.sort_by(|a, b| a.1.total_cmp(&b.1).then_with(|| a.2.cmp(b.2)));
        let mut start = Vec::new();
        let mut end = Vec::new();
        for (i, (_, front, id)) in on_c1.iter().enumerate() {
            let ahead = on_c1.get(i + 1).map_or(c1.length, |next| next.0);
            if ahead - front > RIDE_CLEARANCE {
                start.push((*id).clone());
            } else {
                end.push((*id).clone());
            }
        }
        let velocity = direction * c1.speed;
        for id in start {
            self.phys.start_ride(&id, &velocity);
        }
        for id in end {
            self.phys.end_ride(&id);
        }
    }

    /// Side by side: the piece at conveyor 1's stop rail is lifted onto conveyor 2's centre
    /// line, long axis along the belt, once no other piece is on conveyor 2 (a transfer arm
    /// between the two belts; it does not change where the piece lies along conveyor 2).
    fn transfer(&mut self) {
        if !self.phys.belts.running {
            return;
        }
        let state = self.belt_state();
        if let Some((seen, due)) = self.transfer_due
            && seen == state
            && self.t < due
        {
            return;
        }
        let c1 = &self.cell.conveyor1;
        let c2 = &self.cell.conveyor2;
        let on_conveyor2 =
            |pose: &Isometry3<f64>| c2.covers(&Point3::from(pose.translation.vector));
        let mut at_rail = None;
        let mut shortfall = f64::INFINITY;
        for id in &self.on_belts {
            let Some(pose) = self.phys.lumber_pose(id) else {
                continue;
            };
            if self.transferred.contains(id) || on_conveyor2(&pose) {
                if self.transferred.contains(id) {
                    // Conveyor 2 is busy until that piece leaves the belts.
                    self.transfer_due = Some((state, f64::INFINITY));
                    return;
                }
                continue;
            }
            let half = piece_half_along(&pose, &c1.direction(), id, &self.sizes);
            let front = self.belt1_position(&pose.translation.vector) + half;
            shortfall = shortfall.min(c1.length - TRANSFER_REACH - front);
            if at_rail.is_none() && front >= c1.length - TRANSFER_REACH {
                at_rail = Some((id.clone(), pose));
            }
        }
        let Some((id, pose)) = at_rail else {
            self.transfer_due = Some((state, self.due_after(shortfall)));
            return;
        };
        let Some(piece) = self.pieces.iter().copied().find(|p| p.id == id) else {
            return;
        };
        // Onto conveyor 2's centre line at the same place along it, on its belt.
        let local = c2.pose.inverse() * Point3::from(pose.translation.vector);
        let lift = c2.pose.translation.z - c1.pose.translation.z;
        let centre = c2.pose * Point3::new(local.x, 0.0, local.z + lift);
        let upright =
            Isometry3::from_parts(Translation3::from(centre.coords), piece.spawn.rotation);
        self.phys.remove_lumber(&id);
        self.phys.add_lumber(piece, &upright);
        self.transferred.insert(id);
    }

    pub(super) fn watch_sensor(&mut self) {
        if !self.phys.belts.running {
            return;
        }
        let held = self.held.as_ref().map(|h| h.id.clone());
        let arrived: Vec<String> = self
            .phys
            .at_sensor()
            .into_iter()
            .filter(|id| Some(id) != held.as_ref() && self.on_belts.contains(id))
            .collect();
        if let Some(id) = arrived.first() {
            // Event-driven runs park the riders: they touch nothing, the solver need not hold them.
            let park = self.options.stepping == crate::sim::Stepping::Events;
            self.phys.set_belts(false, park);
            for belt in ["conveyor1", "conveyor2"] {
                self.record.belt_events.push(BeltEvent {
                    t: self.t,
                    belt,
                    event: "stop",
                    piece: id.clone(),
                });
            }
        }
    }

    pub(super) fn start_belts(&mut self, piece: &str) {
        if self.phys.belts.running {
            return;
        }
        self.phys.set_belts(true, false);
        for belt in ["conveyor1", "conveyor2"] {
            self.record.belt_events.push(BeltEvent {
                t: self.t,
                belt,
                event: "start",
                piece: piece.to_string(),
            });
        }
    }

    /// Waits until `piece` touches the sensor. Err: why it did not arrive.
    pub(super) fn await_piece(&mut self, piece: &ScenePiece) -> Result<(), NotFed> {
        let c1 = &self.cell.conveyor1;
        if c1.speed <= 0.0 || self.cell.conveyor2.speed <= 0.0 {
            return Err(NotFed::BeltsStopped);
        }
        if !self.on_belts.contains(&piece.id) && !self.queue.iter().any(|p| p.id == piece.id) {
            return Err(NotFed::NotOnBelts);
        }
        // Everything still ahead of it on conveyor 1 plus both belts, at conveyor 1's speed.
        let ahead: f64 = self
            .pieces
            .iter()
            .filter(|p| self.on_belts.contains(&p.id) || self.queue.iter().any(|q| q.id == p.id))
            .take_while(|p| p.id != piece.id)
            .map(|p| p.size.iter().copied().fold(0.0, f64::max) + self.cell.lumber_gap)
            .sum();
        let limit = 60.0
            + 1.5 * (ahead + piece.size[0] + c1.length + self.cell.conveyor2.length) / c1.speed;
        let start = self.t;
        self.start_belts(&piece.id);
        loop {
            let at = self.phys.at_sensor();
            if at.contains(&piece.id) && !self.phys.belts.running {
                return Ok(());
            }
            let other = at
                .iter()
                .find(|id| **id != piece.id && self.on_belts.contains(*id));
            if let (Some(other), false) = (other, self.phys.belts.running) {
                return Err(NotFed::Overtaken {
                    other: other.clone(),
                });
            }
            if self.t - start > limit {
                let where_ = self
                    .phys
                    .lumber_pose(&piece.id)
                    .map(|p| {
                        let v = p.translation.vector;
                        format!(" (it is at x {:.3}, y {:.3}, z {:.3} m)", v.x, v.y, v.z)
                    })
                    .unwrap_or_default();
                return Err(NotFed::TimedOut { limit, where_ });
            }
            self.tick();
        }
    }

    /// An operator takes a piece that cannot be framed off the belt.
    pub(super) fn take_off(&mut self, id: &str) {
        self.phys.remove_lumber(id);
        self.on_belts.remove(id);
        self.queue.retain(|p| p.id != id);
        self.start_belts(id);
    }
}

/// Why a piece did not arrive at the touch sensor (`await_piece`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(super) enum NotFed {
    #[error("a conveyor does not run (speed 0)")]
    BeltsStopped,
    #[error("it is not on the conveyors")]
    NotOnBelts,
    #[error("{other} reached the sensor before it")]
    Overtaken { other: String },
    /// `where_`: where the piece is, as ` (it is at x …, y …, z … m)`, or empty.
    #[error("it did not arrive within {limit:.0} s{where_}")]
    TimedOut { limit: f64, where_: String },
}

/// Half the extent of a piece along a direction.
fn piece_half_along(
    pose: &Isometry3<f64>,
    direction: &Vector3<f64>,
    id: &str,
    sizes: &HashMap<String, [f64; 3]>,
) -> f64 {
    let Some(size) = sizes.get(id) else {
        return 0.0;
    };
    let local = pose.rotation.inverse() * direction;
    (0..3).map(|i| local[i].abs() * size[i] / 2.0).sum()
}
