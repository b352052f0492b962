//! Event-driven stepping. rapier's solver only matters while lumber can move on its own:
//! pieces on a running belt that do not merely ride it (see `start_ride`), settling after
//! they were fed, stopped or released, or pushed by the robot; riders advance at their belt's
//! speed without it. The rest of a run (the robot carrying a piece through free space, nailing a
//! clamped frame, waiting with nothing loose) advances time without the solver: the robot's
//! joints follow their motion profile tick by tick as before, the pose trace is sampled at
//! its rate, and the robot's contacts are found where a fixed-step run would find them.
//!
//! Contacts without the solver: the distance from each of the robot's shapes (links, tool
//! parts, the held piece) to a touch that would be recorded is measured at a pose; no point
//! of that shape comes closer than that until it has moved that far, so that shape is not
//! measured again until then. How far they have moved
//! is bounded without forward kinematics: per joint, |Δq| times the largest distance from its
//! axis to a corner of their bounding boxes (a rotation by θ moves a point at distance r at
//! most θ·r). Where they touch something, rapier's collision detection
//! runs (no time passes) and the contacts are recorded as a fixed-step run records them.
//! Touching loose lumber (within LOOSE_MARGIN) the solver steps: the robot may push it.

use super::{CONTACT_TOLERANCE, WallRun};
use crate::sim::Stepping;
use crate::sim::physics::Watch;
use crate::sim::record::Op;
use nalgebra::Isometry3;

/// Lumber slower than this is at rest (m/s, rad/s).
const CALM_LINEAR: f64 = 2e-4;
const CALM_ANGULAR: f64 = 2e-3;
/// Physics steps with all lumber at rest, after the last change to the world, before the
/// solver may pause (0.125 s at 240 Hz). A piece that can still move under gravity exceeds
/// CALM_LINEAR or CALM_ANGULAR within a step or two (one 240 Hz step of free fall is
/// 0.04 m/s), so a longer wait only holds back pieces that have settled: 60 steps gave the
/// same verdicts on TM1-TM3 (both study cells) and on every element of the 4,020-member
/// model, with 21 % more solver steps.
const CALM_STEPS: u32 = 30;
/// Within this of loose lumber the robot is stepped with the solver (m). Only a robot that
/// touches a piece can push it: in a quiet world all loose lumber is calm, so a piece the
/// robot merely comes near (the open jaws around a piece just let go, a gripper coming down
/// over a piece on the belt) stays where it lies until the robot is this close (twice TOUCH,
/// a margin for rounding). 20 mm (before) took 64 % more solver steps on the 4,020-member
/// model for the same statuses and as-built nail positions within 0.08 mm.
const LOOSE_MARGIN: f64 = 2.0 * TOUCH;
/// How far a clearance measurement looks (m): the robot moves this far less LOOSE_MARGIN
/// before the next one when nothing is near.
const CLEARANCE_REACH: f64 = 0.20;
/// Closer than this the robot may be touching something (m).
const TOUCH: f64 = 1e-4;
/// How deep the held piece may press into anything, and the robot into what is not lumber,
/// before the contact could be recorded (CONTACT_TOLERANCE deep): a measurement (parry's
/// penetration depth) and the recorded depth (rapier's contact manifold) may differ a little.
const UNRECORDED: f64 = CONTACT_TOLERANCE - 2.0 * TOUCH;

/// What event-driven stepping keeps between ticks.
#[derive(Debug, Clone)]
pub(super) struct Events {
    /// Consecutive solver steps with all lumber at rest since the world last changed.
    calm_steps: u32,
    /// The world's count of disturbances those steps were counted at.
    disturbances: u64,
    /// The previous tick's joint values: rapier reports a step's contacts for where the
    /// bodies stood when it began, one tick behind the joints it drives them to.
    prev_q: Vec<f64>,
    /// The last clearance measurement, while it holds.
    anchor: Option<Anchor>,
    /// `all_on_belts_ride`'s last answer and the (world change count, pieces on the belts)
    /// it was found at.
    all_ride: Option<((u64, usize), bool)>,
    /// `any_loose_lumber`'s last answer and the world change count it was found at.
    loose_lumber: Option<(u64, bool)>,
}

/// The last clearance measurements, while the world, the held piece, the robot's base and
/// the bodies left out stay as they were.
#[derive(Debug, Clone)]
struct Anchor {
    base: Isometry3<f64>,
    generation: u64,
    held: Option<String>,
    /// The bodies the robot may touch unrecorded then (`watched`): the measurements left
    /// them out.
    watched: Option<Vec<String>>,
    /// Per shape of the robot (`Physics::probe`), its last measurement.
    shapes: Vec<ShapeAnchor>,
}

/// One shape's clearance measurement. Each shape is measured again only when it may have
/// used up its own clearance: a held piece sliding along what it is set against is measured
/// every tick, the arm's other shapes far from everything seldom.
#[derive(Debug, Clone)]
struct ShapeAnchor {
    /// The joints it was measured at, and per joint how far the shape's points move per unit
    /// of its motion at most (`Physics::levers`).
    q: Vec<f64>,
    levers: Vec<f64>,
    /// How far the shape may move before it could touch something or come within
    /// LOOSE_MARGIN of loose lumber (m).
    free: f64,
    /// When it was measured (s): riders have moved since.
    t: f64,
    /// Whether it touched something there.
    touching: bool,
}

impl ShapeAnchor {
    /// Some(touching) while the measurement holds at joints `q` and time `t`: it is not
    /// touching anything if it moved less than its clearance, and touches what it touched
    /// if nothing moved at all. None: measure again.
    fn holds(&self, q: &[f64], t: f64, ride_speed: f64) -> Option<bool> {
        // The shape and a rider may close the gap from both sides.
        let ridden = ride_speed * (t - self.t);
        let moved: f64 = self
            .q
            .iter()
            .zip(q)
            .zip(&self.levers)
            .map(|((from, to), lever)| (to - from).abs() * lever)
            .sum();
        if moved + ridden < self.free {
            Some(false)
        } else if moved + ridden == 0.0 && self.touching {
            Some(true)
        } else {
            None
        }
    }
}

impl Events {
    pub(super) fn new(q: &[f64]) -> Events {
        Events {
            calm_steps: 0,
            disturbances: u64::MAX,
            prev_q: q.to_vec(),
            anchor: None,
            all_ride: None,
            loose_lumber: None,
        }
    }
}

impl<'a> WallRun<'a> {
    /// Advances time by one step with the robot at `self.q`.
    pub(super) fn tick(&mut self) {
        if self.options.stepping == Stepping::Fixed {
            self.step();
            return;
        }
        if !self.world_quiet() {
            self.solver_tick();
            return;
        }
        let generation = self.phys.generation();
        let base = self.phys.robot_base();
        let held_id = self.held.as_ref().map(|h| h.id.as_str());
        let watched = watched(&self.current);
        if self.events.anchor.as_ref().is_some_and(|a| {
            a.generation != generation
                || a.held.as_deref() != held_id
                || a.base != base
                || a.watched.as_deref() != watched
        }) {
            self.events.anchor = None;
        }
        // Measured where the robot's bodies stand (the previous tick's joints).
        let at = &self.events.prev_q;
        let t = self.t + self.options.dt;
        let ride_speed = self.phys.ride_speed();
        let mut touching = false;
        // The shapes to measure again: all of them without a measurement that holds.
        let mut stale = None;
        if let Some(a) = &self.events.anchor {
            let mut expired = Vec::new();
            for (i, shape) in a.shapes.iter().enumerate() {
                match shape.holds(at, t, ride_speed) {
                    Some(touch) => touching |= touch,
                    None => expired.push(i),
                }
            }
            stale = Some(expired);
        }
        if stale.as_ref().is_none_or(|s| !s.is_empty()) {
            match self.measure_clearances(stale) {
                Some(touch) => touching |= touch,
                // Near loose lumber: the solver stepped.
                None => return,
            }
        }
        self.quiet_tick(touching);
    }

    /// Measures the robot's shapes `stale` (all of them: None) where its bodies stand (the
    /// previous tick's joints) and keeps the measurements. Some(whether one touches
    /// something); None: one is near loose lumber, and the solver stepped instead.
    fn measure_clearances(&mut self, stale: Option<Vec<usize>>) -> Option<bool> {
        let generation = self.phys.generation();
        let base = self.phys.robot_base();
        let held_id = self.held.as_ref().map(|h| h.id.as_str());
        let watched = watched(&self.current);
        let mut touching = false;
        let held = self.held.as_ref().map(|h| (h.id.as_str(), &h.in_tool));
        let at = self.events.prev_q.clone();
        let probe = self.phys.probe(&at, held);
        let stale = stale.unwrap_or_else(|| (0..probe.shape_count()).collect());
        let watch = match watched {
            Some(bodies) => Watch::AllBut {
                bodies,
                tolerance: UNRECORDED,
            },
            None => Watch::Nothing,
        };
        let mut measured = Vec::with_capacity(stale.len());
        for &i in &stale {
            let clear = self.phys.shape_clearance(&probe, i, CLEARANCE_REACH, watch);
            if clear.loose < LOOSE_MARGIN {
                // The robot may push loose lumber: the solver steps.
                self.events.anchor = None;
                if clear.parked < LOOSE_MARGIN {
                    // Parked lumber is dynamic again, as unparked.
                    self.phys.unpark();
                }
                self.solver_tick();
                return None;
            }
            measured.push((i, clear));
        }
        let anchor = self.events.anchor.get_or_insert_with(|| Anchor {
            base,
            generation,
            held: held_id.map(str::to_string),
            watched: watched.map(<[String]>::to_vec),
            shapes: Vec::new(),
        });
        for (i, clear) in measured {
            let free = clear.any.min(clear.loose - LOOSE_MARGIN);
            let shape = ShapeAnchor {
                levers: self.phys.levers(&probe, i, free.max(0.0)),
                q: at.clone(),
                free,
                t: self.t,
                touching: clear.any <= TOUCH,
            };
            touching |= shape.touching;
            if i < anchor.shapes.len() {
                anchor.shapes[i] = shape;
            } else {
                anchor.shapes.push(shape);
            }
        }
        Some(touching)
    }

    /// Whether nothing in the world moves unless the robot pushes it, or rides a belt: the
    /// lumber on running belts all rides (a rider moves at its belt's speed, without
    /// contacts), and every other piece at rest for CALM_STEPS solver steps since the last
    /// change.
    fn world_quiet(&mut self) -> bool {
        if self.phys.belts.running && !self.all_on_belts_ride() {
            return false;
        }
        if !self.any_loose_lumber() {
            // Nothing can move on its own (every piece held, clamped, riding or parked):
            // after a change there is nothing to settle.
            self.events.disturbances = self.phys.disturbances();
            self.events.calm_steps = CALM_STEPS;
            return true;
        }
        self.events.disturbances == self.phys.disturbances() && self.events.calm_steps >= CALM_STEPS
    }

    /// Whether some piece is a dynamic body. A piece changes kind only with a change to the
    /// world: the answer holds while the world's change count stays.
    fn any_loose_lumber(&mut self) -> bool {
        let generation = self.phys.generation();
        if let Some((seen, answer)) = self.events.loose_lumber
            && seen == generation
        {
            return answer;
        }
        let answer = self.phys.any_dynamic_lumber();
        self.events.loose_lumber = Some((generation, answer));
        answer
    }

    /// Whether every piece on the belts rides them. Rides start and end, and pieces come onto
    /// and leave the belts, only with a change to the world: the answer holds while the
    /// world's change count and the count of pieces on the belts stay.
    fn all_on_belts_ride(&mut self) -> bool {
        let state = (self.phys.generation(), self.on_belts.len());
        if let Some((seen, answer)) = self.events.all_ride
            && seen == state
        {
            return answer;
        }
        let answer = self.on_belts.iter().all(|id| self.phys.is_riding(id));
        self.events.all_ride = Some((state, answer));
        answer
    }

    /// A step with the solver (the robot's bodies stand where the last tick left them).
    fn solver_tick(&mut self) {
        let disturbances = self.phys.disturbances();
        self.step();
        self.events.prev_q.clone_from(&self.q);
        if self.phys.disturbances() != disturbances || self.events.disturbances != disturbances {
            self.events.disturbances = self.phys.disturbances();
            self.events.calm_steps = 0;
        }
        if self.phys.lumber_calm(CALM_LINEAR, CALM_ANGULAR) {
            self.events.calm_steps = self.events.calm_steps.saturating_add(1);
        } else {
            self.events.calm_steps = 0;
        }
    }

    /// A step without the solver: time, the trace, the feeder and, where the robot touches
    /// something, its contacts. The robot's bodies end the tick where a fixed step leaves
    /// them (at `self.q`), for whatever the executor does next (grip, release, measure).
    fn quiet_tick(&mut self, touching: bool) {
        let held_ref = self.held.as_ref().map(|h| (h.id.as_str(), &h.in_tool));
        let watched = watched(&self.current).is_some();
        if touching && watched {
            self.phys.place_robot(&self.events.prev_q, held_ref);
            self.phys.detect();
        }
        self.phys.place_robot(&self.q, held_ref);
        self.phys.advance_rides(self.options.dt);
        self.t += self.options.dt;
        self.sample_trace();
        if touching && watched {
            self.watch_contacts();
        }
        let generation = self.phys.generation();
        self.feed();
        if self.phys.generation() != generation {
            self.events.anchor = None;
        }
        self.events.prev_q.clone_from(&self.q);
    }

    /// A trace sample, if one is due.
    pub(super) fn sample_trace(&mut self) {
        if !self.record.trace.due(self.t) {
            return;
        }
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(&self.q);
        let lumber = self.phys.lumber_poses_in_order();
        self.record.trace.sample(self.t, &self.q, tool, &lumber);
    }
}
/// The bodies (`piece <id>` names) whose touches the current operation does not record, if it
/// records any: contacts are recorded in operations other than waiting for a piece (as
/// `step`). A clearance measurement leaves out those that cannot move: touching them changes
/// nothing until the operation changes.
fn watched(current: &Option<(String, Op, Vec<String>)>) -> Option<&[String]> {
    match current {
        Some((_, op, allowed)) if *op != Op::Feed => Some(allowed),
        _ => None,
    }
}
