//! Feeding: lumber onto conveyor 1 in assembly order, the belts, and the touch sensor that
//! stops them when a piece arrives.

use super::WallRun;
use crate::sim::record::BeltEvent;
use crate::world::ScenePiece;
use nalgebra::{Isometry3, Translation3, Vector3};

impl<'a> WallRun<'a> {
    /// Puts every piece whose spawn pose lies on conveyor 1 there; the rest wait in the queue.
    pub(super) fn load_belts(&mut self) {
        for p in self.pieces.clone() {
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
        let Some(next) = self.queue.front().copied() else {
            return;
        };
        let length = next.size[0];
        let clear = self.on_belts.iter().all(|id| {
            let Some(pose) = self.phys.lumber_pose(id) else {
                return true;
            };
            let centre = self.belt1_position(&pose.translation.vector);
            let half = piece_half_along(&pose, &self.cell.conveyor1.direction(), id, &self.pieces);
            centre - half >= length + self.cell.lumber_gap
        });
        if !clear {
            return;
        }
        // Its queue pose moved upstream-end first onto the belt.
        let at = self.belt1_position(&next.spawn.translation.vector);
        let shift = self.cell.conveyor1.direction() * (length / 2.0 - at);
        let pose = Isometry3::from_parts(
            Translation3::from(next.spawn.translation.vector + shift),
            next.spawn.rotation,
        );
        self.queue.pop_front();
        self.phys.add_lumber(next, &pose);
        self.on_belts.insert(next.id.clone());
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
            self.phys.set_belts(false);
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
        self.phys.set_belts(true);
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
    pub(super) fn await_piece(&mut self, piece: &ScenePiece) -> Result<(), String> {
        let c1 = &self.cell.conveyor1;
        if c1.speed <= 0.0 || self.cell.conveyor2.speed <= 0.0 {
            return Err("a conveyor does not run (speed 0)".into());
        }
        if !self.on_belts.contains(&piece.id) && !self.queue.iter().any(|p| p.id == piece.id) {
            return Err("it is not on the conveyors".into());
        }
        // Everything still ahead of it on conveyor 1 plus both belts, at conveyor 1's speed.
        let ahead: f64 = self
            .pieces
            .iter()
            .filter(|p| self.on_belts.contains(&p.id) || self.queue.iter().any(|q| q.id == p.id))
            .take_while(|p| p.id != piece.id)
            .map(|p| p.size[0] + self.cell.lumber_gap)
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
                return Err(format!("{other} reached the sensor before it"));
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
                return Err(format!("it did not arrive within {limit:.0} s{where_}"));
            }
            self.step();
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

/// Half the extent of a piece along a direction.
fn piece_half_along(
    pose: &Isometry3<f64>,
    direction: &Vector3<f64>,
    id: &str,
    pieces: &[&ScenePiece],
) -> f64 {
    let Some(p) = pieces.iter().find(|p| p.id == id) else {
        return 0.0;
    };
    let local = pose.rotation.inverse() * direction;
    (0..3).map(|i| local[i].abs() * p.size[i] / 2.0).sum()
}
