//! The linear track's carriage: where it stands for each pick, place and nail, and how it
//! moves there. Without a track every position is the one fixed base and nothing moves.

use super::WallRun;
use super::paths::{PATH_MARGIN, SWEEP_STEP};
use crate::cell::{Cell, IkFailure};
use crate::sim::reach::touches;
use nalgebra::Isometry3;
use std::borrow::Cow;

/// A carriage position counts as comfortable when every pose of the group lies this far
/// inside the arm's reach (m); the nearest comfortable position is taken, else the one
/// with the most to spare.
const CARRIAGE_MARGIN: f64 = 0.15;
/// Where no position is comfortable, a farther one is taken only for this much more margin (m).
const MARGIN_WORTH_MOVING: f64 = 0.005;

impl<'a> WallRun<'a> {
    /// The cell with the carriage at `s` (the run's own cell when it stands there already).
    pub(super) fn cell_at(&self, s: f64) -> Cow<'_, Cell> {
        if self.cell.track.is_none() || (s - self.cell.carriage()).abs() < 1e-9 {
            Cow::Borrowed(&self.cell)
        } else {
            let mut cell = self.cell.clone();
            cell.set_carriage(s);
            Cow::Owned(cell)
        }
    }

    /// Where the carriage stands to reach a group of TCP poses (cell frame, each with its
    /// TCP) from one position: the position nearest `from` that reaches all of them
    /// with CARRIAGE_MARGIN to spare, else the one that reaches them with the most to spare.
    /// Err: the closest miss, when no position reaches them all.
    pub(super) fn carriage_for(
        &self,
        from: f64,
        poses: &[(Isometry3<f64>, Isometry3<f64>)],
    ) -> Result<f64, IkFailure> {
        let Some(track) = self.cell.track else {
            return Ok(0.0);
        };
        let robot = &self.cell.robot;
        let mut best: Option<(f64, f64)> = None;
        let mut miss: Option<(f64, IkFailure)> = None;
        for s in track.positions_from(from) {
            let base_inv = track.base_at(s).inverse();
            let mut margin = f64::INFINITY;
            let mut failed = None;
            for (pose, tcp) in poses {
                let local = base_inv * pose;
                match robot.ik(&local, tcp, &self.q) {
                    Ok(_) => {
                        let m = robot.reach_margin(&local, tcp).unwrap_or(0.0);
                        margin = margin.min(m);
                    }
                    Err(f) => {
                        failed = Some(f);
                        break;
                    }
                }
            }
            match failed {
                Some(f) => {
                    let score = super::failure_score(&f);
                    if miss.as_ref().is_none_or(|m| score < m.0) {
                        miss = Some((score, f));
                    }
                }
                None if margin >= CARRIAGE_MARGIN => return Ok(s),
                None => {
                    // Positions come nearest first: a farther one must be worth its travel
                    // (equal margins abeam of the work differ only by rounding).
                    if best.is_none_or(|b| margin > b.1 + MARGIN_WORTH_MOVING) {
                        best = Some((s, margin));
                    }
                }
            }
        }
        match (best, miss) {
            (Some((s, _)), _) => Ok(s),
            (None, Some((_, f))) => Err(f),
            (None, None) => Err(IkFailure::InvalidPose),
        }
    }

    /// Moves the carriage to `s` with the arm's joints held (a gripped piece rides along).
    /// Where the arm, its tool or the piece would touch something on the way, the arm goes to
    /// its home pose first; Err (the blocking pair) if the way is not clear even then.
    pub(super) fn move_carriage(
        &mut self,
        s: f64,
        tcp: &Isometry3<f64>,
        ignore: &[&str],
    ) -> Result<(), IkFailure> {
        let Some(track) = self.cell.track else {
            return Ok(());
        };
        let from = self.cell.carriage();
        let to = track.clamp(s);
        if (to - from).abs() < 1e-9 {
            return Ok(());
        }
        if self.carriage_contact(from, to, ignore).is_some() {
            let home = self.cell.robot.home();
            self.move_to(&home, tcp, ignore, self.transfer_speed())?;
            if let Some(pair) = self.carriage_contact(from, to, ignore) {
                return Err(IkFailure::PathBlocked {
                    pair: [pair.0, pair.1],
                });
            }
        }
        let distance = to - from;
        let scale = self.options.speed;
        let mut profile = track;
        profile.speed *= scale;
        profile.accel *= scale;
        let duration = profile.travel_time(distance);
        let steps = (duration / self.options.dt).ceil().max(1.0) as u64;
        for k in 1..=steps {
            let t = (k as f64 * self.options.dt).min(duration);
            let base = track.base_at(from + profile.covered(distance, t));
            self.cell.robot_base = base;
            self.phys.set_robot_base(base);
            self.tick();
        }
        let base = track.base_at(to);
        self.cell.robot_base = base;
        self.phys.set_robot_base(base);
        self.record
            .program
            .push(crate::sim::record::RobotStep::Carriage {
                s: to,
                q: self.q.clone(),
            });
        Ok(())
    }

    /// The first pair of bodies the arm (at its current joints), its tool or a held piece
    /// would touch while the carriage runs from `from` to `to`.
    fn carriage_contact(&self, from: f64, to: f64, ignore: &[&str]) -> Option<(String, String)> {
        let held = self
            .held
            .as_ref()
            .map(|h| (h.id.as_str(), &h.in_tool, h.half));
        let samples = ((to - from).abs() / SWEEP_STEP).ceil().max(1.0) as usize;
        let mut cell = self.cell.clone();
        (0..=samples).find_map(|k| {
            let s = from + (to - from) * k as f64 / samples as f64;
            cell.set_carriage(s);
            // The ends are poses the arm works at (close to its work); on the way it keeps
            // the path margin.
            let margin = if k == 0 || k == samples {
                0.0
            } else {
                PATH_MARGIN
            };
            touches(&self.phys, &cell, &self.q, held, ignore, margin)
        })
    }
}
