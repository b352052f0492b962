//! What the executor records while it runs a wall, and those records as the input facts of
//! `rules/sim.dl`.

use crate::cell::IkFailure;
use crate::frame::Facts;
use crate::logic::{Origin, Value};
use nalgebra::Isometry3;
use serde::Serialize;
use std::collections::BTreeMap;

/// What the executor does to a piece, in the words its records and the rules use. Declared in
/// the order of their names, so records sorted by operation sort as by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Op {
    /// Conveyor 1 brings the piece to the pick point.
    Feed,
    /// From the pick to above the place pose.
    Move,
    /// One nail driven.
    Nail,
    /// Grip and lift off the belt.
    Pick,
    /// Down to the framing target and release.
    Place,
    /// Back up from the placed piece.
    Retract,
}

impl Op {
    pub const ALL: [Op; 6] = [
        Op::Feed,
        Op::Move,
        Op::Nail,
        Op::Pick,
        Op::Place,
        Op::Retract,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Op::Feed => "feed",
            Op::Move => "move",
            Op::Nail => "nail",
            Op::Pick => "pick",
            Op::Place => "place",
            Op::Retract => "retract",
        }
    }

    /// The operation named `name`, if any.
    pub fn from_name(name: &str) -> Option<Op> {
        Op::ALL.into_iter().find(|op| op.name() == name)
    }
}

impl std::fmt::Display for Op {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One operation on an element.
#[derive(Debug, Clone, Serialize)]
pub struct Operation {
    pub piece: String,
    pub op: Op,
    pub start: f64,
    pub end: f64,
}

/// An IK answer for an operation's pose.
#[derive(Debug, Clone, Serialize)]
pub struct IkRecord {
    pub piece: String,
    pub op: Op,
    pub result: Result<f64, IkFailure>,
}

/// A contact of the robot, its tool or the held piece with something else.
#[derive(Debug, Clone, Serialize)]
pub struct ContactRecord {
    pub piece: String,
    pub op: Op,
    /// First time of the contact in this operation.
    pub t: f64,
    pub body_a: String,
    pub body_b: String,
    /// Deepest penetration seen in this operation, m.
    pub depth: f64,
}

/// Where two bodies met: the deepest point in the cell frame and the wall's frame (u along the
/// wall, v up it, w through it), each body's centre in the cell frame then, and how deep one
/// went into the other (m).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct TouchAt {
    pub point: [f64; 3],
    pub point_wall: [f64; 3],
    pub centre_a: [f64; 3],
    pub centre_b: [f64; 3],
    pub depth: f64,
}

/// Where a touch of two bodies happened while working on a piece: a contact during an
/// operation (at its deepest), or the collision that ruled out the pose an operation needed.
#[derive(Debug, Clone, Serialize)]
pub struct TouchRecord {
    pub piece: String,
    pub op: Op,
    pub body_a: String,
    pub body_b: String,
    pub at: TouchAt,
}

/// Where the piece's centre would have been at the pose an operation needed, for an operation
/// the arm could not take: cell frame and wall frame (m).
#[derive(Debug, Clone, Serialize)]
pub struct PoseRecord {
    pub piece: String,
    pub op: Op,
    pub centre: [f64; 3],
    pub centre_wall: [f64; 3],
}

/// What lay beneath a piece when the gripper let go of it, and how far below its underside
/// (m): a piece released above its support drops that far.
#[derive(Debug, Clone, Serialize)]
pub struct ReleaseRecord {
    pub piece: String,
    pub below: String,
    pub gap: f64,
}

/// A placed piece's rest pose against its target.
#[derive(Debug, Clone, Serialize)]
pub struct Placement {
    pub piece: String,
    pub position_error: f64,
    pub angle_error: f64,
}

/// A nail of the plan and what became of it.
#[derive(Debug, Clone, Serialize)]
pub struct NailRecord {
    pub plate: String,
    pub member: String,
    pub k: i64,
    /// Planned wall coordinates.
    pub planned: [f64; 3],
    pub outcome: NailOutcome,
}

#[derive(Debug, Clone, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum NailOutcome {
    Fired {
        t: f64,
        /// The planned point carried by the as-built plate, in wall coordinates.
        as_built: [f64; 3],
        position_error: f64,
        member_inside: bool,
        /// The line the nail was driven along (wall frame, unit vector) and its lean off the
        /// planned line (rad; 0 when driven square).
        driven: [f64; 3],
        lean: f64,
    },
    Skipped {
        kind: String,
        what: String,
        value: f64,
        limit: f64,
        message: String,
    },
}

/// Why a piece was never fed or never held: what kind of limit it met (for counting causes,
/// e.g. in a bid) and the one-line message with the numbers (the verdict's reason).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Refusal {
    pub kind: RefusalKind,
    pub message: String,
}

/// The limits a piece can meet before the arm moves it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RefusalKind {
    /// Longer than a conveyor carries.
    TooLongForConveyors,
    /// The belts did not bring it to the sensor.
    NotFed,
    /// The tool has no gripper.
    NoGripper,
    /// Thicker or thinner than the jaws open and close.
    OutsideJawRange,
    /// Its top face is narrower than the pads of a gripper holding the top face.
    NarrowerThanPads,
    /// Heavier than the grippers together are rated to hold.
    TooHeavyForGripper,
    /// Shorter than the distance between the two grippers (and the tool rates no gripper to
    /// hold a piece alone).
    ShorterThanGripperSpacing,
    /// Held by one gripper: shorter than its jaws hold square.
    TooShortForOneGripper,
    /// Held by one gripper: heavier than it is rated for, or no grip point within its moment.
    TooHeavyForOneGripper,
    /// It toppled onto its wide face at the end stop.
    Toppled,
    /// It was not where the jaws closed on it.
    Slipped,
}

impl Refusal {
    pub fn new(kind: RefusalKind, message: impl Into<String>) -> Refusal {
        Refusal {
            kind,
            message: message.into(),
        }
    }
}

/// A belt starting or stopping.
#[derive(Debug, Clone, Serialize)]
pub struct BeltEvent {
    pub t: f64,
    pub belt: &'static str,
    pub event: &'static str,
    pub piece: String,
}

/// Everything recorded for one wall.
#[derive(Debug, Clone, Default, Serialize)]
pub struct WallRecord {
    pub wall: String,
    pub operations: Vec<Operation>,
    pub ik: Vec<IkRecord>,
    pub contacts: Vec<ContactRecord>,
    /// Where the contacts and the collisions that ruled out a pose happened.
    pub touches: Vec<TouchRecord>,
    /// Where the pieces would have been at the poses the arm could not take.
    pub poses: Vec<PoseRecord>,
    /// What lay beneath each released piece.
    pub releases: Vec<ReleaseRecord>,
    pub placements: Vec<Placement>,
    pub fed: Vec<(String, f64)>,
    /// Pieces the belts did not bring to the sensor, and why.
    pub not_fed: Vec<(String, Refusal)>,
    /// Pieces the gripper could not take (or lost), and why.
    pub grip_failed: Vec<(String, Refusal)>,
    pub nails: Vec<NailRecord>,
    pub belt_events: Vec<BeltEvent>,
    /// Where the grip TCP held each placed piece: metres along the piece from its centre,
    /// positive towards its upper end (a vertical piece) or its larger-u end (the rest), as
    /// `plan` orders a member's axis.
    pub grips: Vec<(String, f64)>,
    /// When the last piece's framing ended (s).
    pub framing_end: f64,
    /// When the run ended (s).
    pub nailing_end: f64,
    /// Seconds of nailing done before `framing_end`: nails driven before a later piece
    /// covered them.
    pub nailing_while_framing: f64,
    /// Physics steps taken.
    pub steps: u64,
    /// The robot's and the lumber's poses over time, for animations.
    #[serde(skip)]
    pub trace: PoseTrace,
    /// What the robot did, step by step, as a controller runs it (`program` writes it out).
    #[serde(skip)]
    pub program: Vec<RobotStep>,
}

/// One step of the robot's work as the executor ran it: the motions it validated, with the
/// joints reached at each, and the tool's signals and waits between them.
#[derive(Debug, Clone, PartialEq)]
pub enum RobotStep {
    /// The steps up to the next `Begin` serve this piece, nail or the run's start.
    Begin(StepFor),
    /// A joint move (straight in joint space) to `q`, at a fraction of the joints' speed and
    /// acceleration limits, taking `duration` s, with the TCP `tcp` of the tool active.
    Joint {
        q: Vec<f64>,
        speed: f64,
        duration: f64,
        tcp: String,
    },
    /// A straight TCP move ending at `pose` (the TCP in the cell frame) with the joints at
    /// `q`, at `speed` m/s along the line.
    Line {
        pose: Isometry3<f64>,
        q: Vec<f64>,
        tcp: String,
        speed: f64,
    },
    /// The track's carriage moves to `s` (m from its home) with the arm's joints held at `q`.
    Carriage { s: f64, q: Vec<f64> },
    /// The jaws close on the piece.
    Grip,
    /// The jaws open.
    Release,
    /// The nailer fires.
    Fire,
    /// The nailer runs out on its slide (`out`) or back, taking `seconds`.
    NailerSlide { out: bool, seconds: f64 },
    /// The robot waits for the touch sensor to report a piece.
    AwaitPart,
    /// The robot waits this long (s).
    Dwell(f64),
}

/// What a stretch of robot steps serves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum StepFor {
    /// The run's start: the arm at its home pose.
    Start,
    /// Feeding, picking and placing a piece.
    Piece(String),
    /// Driving nail `k` through `plate` into `member`.
    Nail {
        plate: String,
        member: String,
        k: i64,
    },
}

/// How often the executor samples poses for the trace (s): 20 Hz.
pub const TRACE_PERIOD: f64 = 0.05;
/// A lumber pose that moved less than this since its last key is at rest (m, rad).
const REST_MOVE: f64 = 1e-5;

/// Poses sampled every [`TRACE_PERIOD`] of simulated time: the robot's joint values and its
/// tool pose as the executor computes them (cell frame), and per lumber piece the keys of its
/// body pose (a piece at rest is kept as its first and last pose only).
#[derive(Debug, Clone, Default)]
pub struct PoseTrace {
    pub times: Vec<f64>,
    pub joints: Vec<Vec<f64>>,
    /// tool0 in the cell frame.
    pub tool: Vec<Isometry3<f64>>,
    /// Piece id → its keys (time, body pose in the cell frame); the piece exists from its
    /// first key to `gone` (or the end).
    pub lumber: BTreeMap<String, LumberTrack>,
}

#[derive(Debug, Clone, Default)]
pub struct LumberTrack {
    pub keys: Vec<(f64, Isometry3<f64>)>,
    /// When the piece left the world (taken off the belt), if it did.
    pub gone: Option<f64>,
    /// The last sample seen while at rest, not yet a key.
    held: Option<(f64, Isometry3<f64>)>,
}

impl PoseTrace {
    /// Whether a sample is due at simulated time `t`.
    pub fn due(&self, t: f64) -> bool {
        self.times
            .last()
            .is_none_or(|last| t >= last + TRACE_PERIOD - 1e-9)
    }

    /// Records one sample: joint values, tool0 and every lumber body present, in id order.
    pub fn sample(
        &mut self,
        t: f64,
        q: &[f64],
        tool: Isometry3<f64>,
        lumber: &[(&str, Isometry3<f64>)],
    ) {
        debug_assert!(lumber.windows(2).all(|w| w[0].0 < w[1].0), "in id order");
        self.times.push(t);
        self.joints.push(q.to_vec());
        self.tool.push(tool);
        // Tracks and present pieces are both in id order: one walk pairs them, finds the
        // pieces gone and the new ones, without a lookup per piece.
        let mut present = lumber.iter().peekable();
        let mut new = Vec::new();
        for (id, track) in &mut self.lumber {
            while let Some(&(p, pose)) = present.next_if(|(p, _)| *p < id.as_str()) {
                new.push((p, pose));
            }
            match present.next_if(|(p, _)| *p == id.as_str()) {
                Some(&(_, pose)) => track.observe(t, pose),
                None if track.gone.is_none() => {
                    track.flush();
                    track.gone = Some(t);
                }
                None => {}
            }
        }
        new.extend(present.copied());
        for (id, pose) in new {
            self.lumber
                .entry(id.to_string())
                .or_default()
                .observe(t, pose);
        }
    }

    /// Ends the trace: the last rest pose of every piece becomes a key.
    pub fn finish(&mut self) {
        for track in self.lumber.values_mut() {
            track.flush();
        }
    }
}

impl LumberTrack {
    /// A sample of the piece at `t`: a key where it moved since the last one, else the rest
    /// pose held back until it moves or the trace ends.
    fn observe(&mut self, t: f64, pose: Isometry3<f64>) {
        let Some(&(_, last)) = self.keys.last() else {
            self.keys.push((t, pose));
            return;
        };
        let moved = (pose.translation.vector - last.translation.vector).norm() > REST_MOVE
            || pose.rotation.angle_to(&last.rotation) > REST_MOVE;
        if moved {
            self.flush();
            self.keys.push((t, pose));
        } else {
            self.held = Some((t, pose));
        }
    }

    fn flush(&mut self) {
        if let Some(key) = self.held.take() {
            self.keys.push(key);
        }
    }
}

/// The `what`, value and limit columns of an IK failure.
pub fn failure_columns(f: &IkFailure) -> (&'static str, String, f64, f64) {
    match f {
        IkFailure::OutOfReach {
            distance, reach, ..
        } => ("out_of_reach", String::new(), *distance, *reach),
        IkFailure::JointLimit {
            joint,
            value,
            limit,
            ..
        } => ("joint_limit", joint.clone(), *value, *limit),
        IkFailure::WristSingularity { margin, required } => {
            ("wrist_singularity", String::new(), *margin, *required)
        }
        IkFailure::AllSolutionsCollide { pair } => (
            "all_solutions_collide",
            format!("{} / {}", pair[0], pair[1]),
            0.0,
            0.0,
        ),
        IkFailure::NoExactSolution {
            position_error,
            rotation_error,
        } => (
            "no_exact_solution",
            String::new(),
            *position_error,
            *rotation_error,
        ),
        IkFailure::BranchJump { joint, jump, at } => ("branch_jump", joint.clone(), *jump, *at),
        IkFailure::PathBlocked { pair } => (
            "path_blocked",
            format!("{} / {}", pair[0], pair[1]),
            0.0,
            0.0,
        ),
        IkFailure::InvalidPose => ("invalid_pose", String::new(), 0.0, 0.0),
    }
}

impl WallRecord {
    /// Seconds spent framing: the run up to `framing_end` less the nailing done on the way.
    pub fn framing_time(&self) -> f64 {
        self.framing_end - self.nailing_while_framing
    }

    /// Seconds spent nailing, during framing and after it.
    pub fn nailing_time(&self) -> f64 {
        self.nailing_end - self.framing_time()
    }

    /// The records as facts of `rules/sim.dl`, each tuple's origin naming the event.
    pub fn facts(&self) -> Facts {
        let mut facts = Facts::default();
        let s = Value::sym;
        let f = Value::float;
        let event = |what: &str| Origin::Event(format!("{} {what}", self.wall));
        for o in &self.operations {
            facts.add(
                "sim_operation",
                vec![s(&o.piece), s(o.op.name()), f(o.start), f(o.end)],
                event(&format!("{} of {} at t = {:.3} s", o.op, o.piece, o.start)),
            );
        }
        for r in &self.ik {
            let origin = event(&format!("IK for {} of {}", r.op, r.piece));
            match &r.result {
                Ok(margin) => facts.add(
                    "sim_ik_solved",
                    vec![s(&r.piece), s(r.op.name()), f(*margin)],
                    origin,
                ),
                Err(failure) => {
                    let (kind, what, value, limit) = failure_columns(failure);
                    facts.add(
                        "sim_ik_failed",
                        vec![
                            s(&r.piece),
                            s(r.op.name()),
                            s(kind),
                            s(&what),
                            f(value),
                            f(limit),
                            s(&failure.to_string()),
                        ],
                        origin,
                    );
                }
            }
        }
        for c in &self.contacts {
            facts.add(
                "sim_contact",
                vec![
                    s(&c.piece),
                    s(c.op.name()),
                    f(c.t),
                    s(&c.body_a),
                    s(&c.body_b),
                    f(c.depth),
                ],
                event(&format!(
                    "contact {} / {} at t = {:.3} s",
                    c.body_a, c.body_b, c.t
                )),
            );
        }
        for r in &self.touches {
            let origin = || {
                event(&format!(
                    "{} of {}: {} / {}",
                    r.op, r.piece, r.body_a, r.body_b
                ))
            };
            let (at, [u, v, w]) = (&r.at, r.at.point_wall);
            let [x, y, z] = at.point;
            facts.add(
                "sim_touch",
                vec![
                    s(&r.piece),
                    s(r.op.name()),
                    s(&r.body_a),
                    s(&r.body_b),
                    f(at.depth),
                    f(x),
                    f(y),
                    f(z),
                    f(u),
                    f(v),
                    f(w),
                ],
                origin(),
            );
            let ([ax, ay, az], [bx, by, bz]) = (at.centre_a, at.centre_b);
            facts.add(
                "sim_touch_centres",
                vec![
                    s(&r.piece),
                    s(r.op.name()),
                    s(&r.body_a),
                    s(&r.body_b),
                    f(ax),
                    f(ay),
                    f(az),
                    f(bx),
                    f(by),
                    f(bz),
                ],
                origin(),
            );
        }
        for p in &self.poses {
            let ([x, y, z], [u, v, w]) = (p.centre, p.centre_wall);
            facts.add(
                "sim_pose",
                vec![
                    s(&p.piece),
                    s(p.op.name()),
                    f(x),
                    f(y),
                    f(z),
                    f(u),
                    f(v),
                    f(w),
                ],
                event(&format!("{} pose of {}", p.op, p.piece)),
            );
        }
        for r in &self.releases {
            facts.add(
                "sim_released",
                vec![s(&r.piece), s(&r.below), f(r.gap)],
                event(&format!("release of {}", r.piece)),
            );
        }
        for p in &self.placements {
            facts.add(
                "sim_placed",
                vec![s(&p.piece), f(p.position_error), f(p.angle_error)],
                event(&format!("rest pose of {}", p.piece)),
            );
        }
        for (p, t) in &self.fed {
            facts.add(
                "sim_fed",
                vec![s(p), f(*t)],
                event(&format!("{p} at the sensor")),
            );
        }
        for (p, why) in &self.not_fed {
            facts.add(
                "sim_not_fed",
                vec![s(p), s(&why.message)],
                event(&format!("{p} not fed")),
            );
        }
        for (p, why) in &self.grip_failed {
            facts.add(
                "sim_grip_failed",
                vec![s(p), s(&why.message)],
                event(&format!("grip of {p}")),
            );
        }
        for n in &self.nails {
            let key = || vec![s(&n.plate), s(&n.member), Value::Number(n.k)];
            let origin = || event(&format!("nail {} -> {} #{}", n.plate, n.member, n.k));
            let mut planned = key();
            planned.extend(n.planned.map(f));
            facts.add("sim_nail", planned, origin());
            match &n.outcome {
                NailOutcome::Fired {
                    t,
                    as_built,
                    position_error,
                    member_inside,
                    lean,
                    ..
                } => {
                    let mut fired = key();
                    fired.extend([
                        f(*t),
                        f(*position_error),
                        Value::Number(i64::from(*member_inside)),
                    ]);
                    facts.add("sim_nail_fired", fired, origin());
                    let mut leaning = key();
                    leaning.push(f(*lean));
                    facts.add("sim_nail_lean", leaning, origin());
                    let mut built = key();
                    built.extend(as_built.map(f));
                    facts.add("sim_nail_as_built", built, origin());
                }
                NailOutcome::Skipped {
                    kind,
                    what,
                    value,
                    limit,
                    message,
                } => {
                    let mut skipped = key();
                    skipped.extend([s(kind), s(what), f(*value), f(*limit), s(message)]);
                    facts.add("sim_nail_skipped", skipped, origin());
                }
            }
        }
        facts.add(
            "sim_wall",
            vec![
                s(&self.wall),
                f(0.0),
                f(self.framing_time()),
                f(self.nailing_end),
            ],
            event("run"),
        );
        for b in &self.belt_events {
            facts.add(
                "sim_belt_event",
                vec![s(&self.wall), f(b.t), s(b.belt), s(b.event), s(&b.piece)],
                event(&format!("{} {} at t = {:.3} s", b.belt, b.event, b.t)),
            );
        }
        facts
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operations_order_as_their_names_and_read_back_by_name() {
        let mut by_name = Op::ALL;
        by_name.sort_by_key(|op| op.name());
        assert_eq!(by_name, Op::ALL, "declared in the order of their names");
        let mut by_ord = Op::ALL;
        by_ord.sort();
        assert_eq!(by_ord, Op::ALL);
        for op in Op::ALL {
            assert_eq!(Op::from_name(op.name()), Some(op));
            assert_eq!(serde_json::to_string(&op).unwrap(), format!("\"{op}\""));
        }
        assert_eq!(Op::from_name("weld"), None);
    }

    #[test]
    fn a_sample_pairs_pieces_with_their_tracks_and_notes_new_and_gone_ones() {
        let at = |x: f64| Isometry3::translation(x, 0.0, 0.0);
        let mut trace = PoseTrace::default();
        trace.sample(0.0, &[0.0], at(0.0), &[("b", at(1.0)), ("d", at(2.0))]);
        // "a" and "c" appear before and between the tracked ids, "b" moves, "d" is gone.
        trace.sample(
            0.05,
            &[0.0],
            at(0.0),
            &[("a", at(3.0)), ("b", at(1.5)), ("c", at(4.0))],
        );
        // "b" rests, "c" leaves.
        trace.sample(0.1, &[0.0], at(0.0), &[("a", at(3.0)), ("b", at(1.5))]);
        trace.finish();
        let keys = |id: &str| -> Vec<(f64, f64)> {
            trace.lumber[id]
                .keys
                .iter()
                .map(|(t, p)| (*t, p.translation.x))
                .collect()
        };
        assert_eq!(keys("a"), vec![(0.05, 3.0), (0.1, 3.0)]);
        assert_eq!(keys("b"), vec![(0.0, 1.0), (0.05, 1.5), (0.1, 1.5)]);
        assert_eq!(keys("c"), vec![(0.05, 4.0)]);
        assert_eq!(keys("d"), vec![(0.0, 2.0)]);
        let gone = |id: &str| trace.lumber[id].gone;
        assert_eq!(
            [gone("a"), gone("b"), gone("c"), gone("d")],
            [None, None, Some(0.1), Some(0.05)]
        );
    }
}
