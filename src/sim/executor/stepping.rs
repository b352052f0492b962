//! Event-driven stepping. rapier's solver only matters while lumber can move on its own:
//! pieces settling after they were fed, stopped or released, pushed by the robot, or meeting
//! something on a belt. A piece that only rides a running belt (it touches nothing but the
//! belt and moves at its surface velocity) is advanced analytically, belt velocity × time,
//! until it comes within RIDE_MARGIN of anything else or of its belt's end (physics.rs,
//! `start_ride`); the solver takes over from there (the stop rail, the sensor's end stop). The rest of a run (the robot carrying a piece through free space, nailing a
//! clamped frame, waiting with nothing loose) advances time without the solver: the robot's
//! joints follow their motion profile tick by tick as before, the pose trace is sampled at
//! its rate, and the robot's contacts are found where a fixed-step run would find them.
//!
//! Contacts without the solver: the distances from the robot, its tool and the held piece to
//! everything else are measured at a pose; no point of them comes closer than that until
//! they have moved that far (measured at the corners of their bounding boxes), so nothing
//! more is measured until then. Where they touch something, rapier's collision detection
//! runs (no time passes) and the contacts are recorded as a fixed-step run records them.
//! Near loose lumber (within LOOSE_MARGIN) the solver steps: the robot may push it.

use super::WallRun;
use crate::sim::Stepping;

/// Lumber slower than this is at rest (m/s, rad/s).
const CALM_LINEAR: f64 = 2e-4;
const CALM_ANGULAR: f64 = 2e-3;
/// Physics steps with all lumber at rest or riding, after the last change to the world,
/// before the solver may pause (0.25 s at 240 Hz; 50 ms let a plate at the sensor freeze a
/// few micrometres off its fixed-step rest pose, enough to tip a place line near a
/// singularity onto another IK branch on TM3 with study-kuka).
const CALM_STEPS: u32 = 60;
/// Within this of loose lumber the robot is stepped with the solver (m).
const LOOSE_MARGIN: f64 = 0.02;
/// How far a clearance measurement looks (m): the robot moves this far less LOOSE_MARGIN
/// before the next one when nothing is near.
const CLEARANCE_REACH: f64 = 0.10;
/// Closer than this the robot may be touching something (m).
const TOUCH: f64 = 1e-4;
/// A riding piece is handed to the solver this far from anything else or its belt's end (m):
/// more than a time step's travel at the fastest belt (2 m/s × 1/240 s = 8.3 mm).
const RIDE_MARGIN: f64 = 0.02;
/// How far ahead a ride looks (m): a longer ride is measured again after this.
const RIDE_REACH: f64 = 1.0;

/// What event-driven stepping keeps between ticks.
#[derive(Debug, Clone)]
pub(super) struct Events {
    /// Consecutive solver steps with all lumber at rest or riding since the world last changed.
    calm_steps: u32,
    /// The world's change count those steps were counted at.
    generation: u64,
    /// The previous tick's joint values: rapier reports a step's contacts for where the
    /// bodies stood when it began, one tick behind the joints it drives them to.
    prev_q: Vec<f64>,
    /// The last clearance measurement, while it holds.
    anchor: Option<Anchor>,
    /// The robot's bodies stand at older joint values than `prev_q` (ticks without the
    /// solver do not place them; see `sync_world`).
    robot_stale: bool,
    /// During a ride, the feeder need not look again before this time (s).
    feed_due: f64,
}

#[derive(Debug, Clone)]
struct Anchor {
    /// The joints it was measured at and each joint's reach (`Physics::joint_reach`).
    q: Vec<f64>,
    reach: Vec<f64>,
    /// How far the robot may move, less the riders' travel, before something could be
    /// touched or loose lumber come within LOOSE_MARGIN (m).
    free: f64,
    /// When it was measured (s).
    t: f64,
    generation: u64,
    held: Option<String>,
}

impl Anchor {
    /// No point of the robot, its tool or the held piece has moved further than this (m).
    fn moved(&self, q: &[f64]) -> f64 {
        self.q
            .iter()
            .zip(q)
            .zip(&self.reach)
            .map(|((a, b), r)| (a - b).abs() * r)
            .sum()
    }
}

impl Events {
    pub(super) fn new(q: &[f64]) -> Events {
        Events {
            calm_steps: 0,
            generation: u64::MAX,
            prev_q: q.to_vec(),
            anchor: None,
            robot_stale: false,
            feed_due: f64::NEG_INFINITY,
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
        let dt = self.options.dt;
        if !self.phys.riding() {
            self.phys
                .start_ride(CALM_LINEAR, CALM_ANGULAR, RIDE_REACH, RIDE_MARGIN);
        }
        if self.phys.ride_left() < dt {
            self.solver_tick();
            return;
        }
        let generation = self.phys.generation();
        let ride_speed = self.phys.ride_speed();
        let within = self.events.anchor.as_ref().is_some_and(|a| {
            a.generation == generation
                && a.held.as_deref() == self.held.as_ref().map(|h| h.id.as_str())
                && a.moved(&self.events.prev_q) + ride_speed * (self.t + dt - a.t) < a.free
        });
        if within {
            self.quiet_tick(false);
            return;
        }
        let at = self.events.prev_q.clone();
        let held = self.held.clone();
        let held_ref = held.as_ref().map(|h| (h.id.as_str(), &h.in_tool));
        let touching;
        {
            // The riders' bodies stand where the ride began: a distance measured to them is
            // short of the truth by at most their travel since (the drift). Past half the
            // measurement's reach they are placed where the belts have carried them.
            if ride_speed * self.phys.ride_elapsed() > CLEARANCE_REACH / 2.0 {
                self.phys.end_ride();
                self.phys
                    .start_ride(CALM_LINEAR, CALM_ANGULAR, RIDE_REACH, RIDE_MARGIN);
                if self.phys.ride_left() < dt {
                    self.events.anchor = None;
                    self.solver_tick();
                    return;
                }
            }
            let drift = self.phys.ride_speed() * self.phys.ride_elapsed();
            let mut clear = self.phys.clearance(&at, held_ref, CLEARANCE_REACH);
            clear.any -= drift;
            clear.loose -= drift;
            if clear.loose < LOOSE_MARGIN {
                self.events.anchor = None;
                self.solver_tick();
                return;
            }
            touching = clear.any <= TOUCH;
            self.events.anchor = Some(Anchor {
                reach: self.phys.joint_reach(&at, held_ref),
                q: at,
                free: clear.any.min(clear.loose - LOOSE_MARGIN),
                t: self.t,
                generation,
                held: held_ref.map(|h| h.0.to_string()),
            });
        }
        self.quiet_tick(touching);
    }

    /// Whether nothing in the world moves unless the robot pushes it or a belt carries it:
    /// every piece at rest or riding a belt for CALM_STEPS solver steps since the last change.
    fn world_quiet(&self) -> bool {
        self.events.generation == self.phys.generation() && self.events.calm_steps >= CALM_STEPS
    }

    /// A step with the solver (the robot's bodies stand where the last tick left them).
    fn solver_tick(&mut self) {
        if self.events.robot_stale {
            let prev = self.events.prev_q.clone();
            self.place_robot_at(&prev);
        }
        // The solver moves loose lumber: a clearance measured before holds no longer, nor
        // when the conveyor-1 belt clears.
        self.events.anchor = None;
        self.events.feed_due = f64::NEG_INFINITY;
        let generation = self.phys.generation();
        self.step();
        self.events.prev_q.clone_from(&self.q);
        if self.phys.generation() != generation || self.events.generation != generation {
            self.events.generation = self.phys.generation();
            self.events.calm_steps = 0;
        }
        if self.phys.lumber_steady(CALM_LINEAR, CALM_ANGULAR) {
            self.events.calm_steps = self.events.calm_steps.saturating_add(1);
        } else {
            self.events.calm_steps = 0;
        }
    }

    /// The robot's bodies (and the held piece) at joint values `q`, at once.
    fn place_robot_at(&mut self, q: &[f64]) {
        let held = self.held.clone();
        let held_ref = held.as_ref().map(|h| (h.id.as_str(), &h.in_tool));
        self.phys.place_robot(q, held_ref);
        self.events.robot_stale = false;
    }

    /// The robot's base moved (its carriage on a track) while its joints held: a clearance
    /// measured from joint travel alone no longer holds, and the bodies must be placed anew.
    pub(super) fn base_moved(&mut self) {
        self.events.anchor = None;
        self.events.robot_stale = true;
    }

    /// Brings the world up to the run's clock after ticks without the solver: the robot's
    /// bodies at `self.q`, riders where the belts have carried them. The executor calls it
    /// when a motion ends, before it plans, grips, releases or measures.
    pub(super) fn sync_world(&mut self) {
        if self.options.stepping == Stepping::Fixed {
            return;
        }
        if self.events.robot_stale {
            let q = self.q.clone();
            self.place_robot_at(&q);
        }
        self.phys.end_ride();
    }

    /// A step without the solver: time, the riders, the trace, the feeder and, where the
    /// robot touches something, its contacts. The robot's bodies are placed only when
    /// something looks at them (`sync_world`, a trace sample, a solver step).
    fn quiet_tick(&mut self, touching: bool) {
        // Contacts are recorded in operations other than waiting for a piece (as `step`).
        let watched = matches!(&self.current, Some((_, op, _)) if *op != "feed");
        if touching && watched {
            let prev = self.events.prev_q.clone();
            self.place_robot_at(&prev);
            self.phys.detect();
        }
        self.events.robot_stale = true;
        self.t += self.options.dt;
        self.phys.ride_on(self.options.dt);
        self.sample_trace();
        if touching && watched {
            self.watch_contacts();
        }
        // During a ride the feeder's answer changes only when the conveyor-1 belt clears,
        // at a time the riders' speeds give (a change to the world ends the ride).
        if !self.phys.riding() || self.t >= self.events.feed_due {
            let generation = self.phys.generation();
            self.feed();
            if self.phys.generation() != generation {
                self.events.anchor = None;
            } else if self.phys.riding() {
                self.events.feed_due = self.t + self.time_to_clear();
            }
        }
        self.events.prev_q.clone_from(&self.q);
    }

    /// A trace sample, if one is due (as `step` takes it).
    fn sample_trace(&mut self) {
        if !self.record.trace.due(self.t) {
            return;
        }
        if self.events.robot_stale && self.held.is_some() {
            let q = self.q.clone();
            self.place_robot_at(&q);
        }
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(&self.q);
        let lumber = self.phys.lumber_poses();
        self.record.trace.sample(self.t, &self.q, tool, lumber);
    }
}
