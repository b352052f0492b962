//! The executor: runs one wall in its own rapier world. Lumber arrives on the conveyors in
//! assembly order; for every element the framing subroutine waits for the touch sensor,
//! approaches, grips, lifts, moves to above the framing target, places, releases and
//! retracts; then the nailing subroutine drives every nail. An element that cannot be framed
//! is taken off the belt with its reason recorded, and the run goes on.
//!
//! One file per subroutine: `feeding` (conveyors and the touch sensor), `framing` (grip, move,
//! place), `nailing`, `paths` (collision-free joint motion between poses) and `as_built`
//! (settling and measuring the result). This file holds the run itself, its clock and what it
//! records of contacts.

mod as_built;
mod carriage;
mod feeding;
mod framing;
mod nail_plan;
mod nailing;
mod paths;
mod slide_in;
mod stepping;

pub use nail_plan::NailPlan;

use super::SimOptions;
use super::motion::{JointMove, LinearMove};
use super::physics::Physics;
use super::reach::{check_step, solve};
use super::record::{
    ContactRecord, Op, Operation, RobotStep, StepFor, TouchAt, TouchRecord, WallRecord,
};
use crate::cell::{Cell, IkFailure};
use crate::world::{ScenePiece, SceneWall};
use nalgebra::{Isometry3, Point3, Translation3, Vector3};
use std::collections::{BTreeMap, BTreeSet, HashMap, VecDeque};

/// A contact shallower than this is a touch, not a collision (m).
const CONTACT_TOLERANCE: f64 = 0.001;
/// An assembly surface this far or less above the floor is the floor itself (m).
const SURFACE_ON_FLOOR: f64 = 0.005;
/// How far a framing table reaches beyond the wall laid on it (m).
const TABLE_BORDER: f64 = 0.05;

/// The gripped piece: its id, its pose in tool0, its box half sizes.
#[derive(Debug, Clone)]
pub(super) struct Held {
    id: String,
    in_tool: Isometry3<f64>,
    half: [f64; 3],
}

pub struct WallRun<'a> {
    /// The run's own copy of the cell: with a track, its `robot_base` follows the carriage.
    cell: Cell,
    options: &'a SimOptions,
    phys: Physics,
    wall_cell: Isometry3<f64>,
    pieces: Vec<&'a ScenePiece>,
    /// Each piece's size by id (the feeder looks them up every step), plies included.
    sizes: HashMap<String, [f64; 3]>,
    /// Plies riding in a pre-assembled member: the member's lead (their body) and the ply's
    /// own target (cell frame).
    plies: HashMap<String, (String, Isometry3<f64>)>,
    /// When the feeder looks at conveyor 1 next: (`belt_state`, time in s).
    feed_due: Option<((u64, usize), f64)>,
    /// When the transfer arm looks at conveyor 1's rail next (as `feed_due`).
    transfer_due: Option<((u64, usize), f64)>,
    t: f64,
    q: Vec<f64>,
    held: Option<Held>,
    /// The element and operation contacts are attributed to, and bodies it may touch.
    current: Option<(String, Op, Vec<String>)>,
    /// Robot/fixed pairs touching at the start (a base on its floor): never reported.
    resting: BTreeSet<(String, String)>,
    /// Per piece, operation and pair of bodies: the first time they touched, and where at
    /// the deepest.
    contacts: BTreeMap<(String, Op, String, String), (f64, TouchAt)>,
    /// Pieces not yet put on conveyor 1, in order.
    queue: VecDeque<&'a ScenePiece>,
    /// Pieces on the belts (spawned, not yet picked or removed).
    on_belts: BTreeSet<String>,
    /// Side by side: pieces the transfer has put on conveyor 2.
    transferred: BTreeSet<String>,
    placed: BTreeMap<String, Isometry3<f64>>,
    record: WallRecord,
    progress: &'a (dyn Fn(usize, usize) + Sync),
    /// Event-driven stepping's state (unused with fixed steps).
    events: stepping::Events,
    /// The bound on the wall's simulated time (s).
    time_limit: f64,
}

impl<'a> WallRun<'a> {
    pub fn new(
        cell: &'a Cell,
        options: &'a SimOptions,
        wall: &SceneWall,
        pieces: Vec<&'a ScenePiece>,
        progress: &'a (dyn Fn(usize, usize) + Sync),
    ) -> WallRun<'a> {
        let q = cell.robot.home();
        let mut phys = Physics::new(cell, &q, options.dt);
        if cell.surface_height() > cell.floor.z + SURFACE_ON_FLOOR
            && let Some((min, max)) = footprint(&pieces)
        {
            phys.add_assembly_table(
                [min[0] - TABLE_BORDER, min[1] - TABLE_BORDER],
                [max[0] + TABLE_BORDER, max[1] + TABLE_BORDER],
                cell.surface_height(),
            );
        }
        WallRun {
            cell: cell.clone(),
            options,
            phys,
            wall_cell: cell.robot_base * wall.wall_to_robot,
            sizes: pieces
                .iter()
                .flat_map(|p| {
                    std::iter::once((p.id.clone(), p.size))
                        .chain(p.plies.iter().map(|ply| (ply.id.clone(), ply.size)))
                })
                .collect(),
            plies: pieces
                .iter()
                .flat_map(|p| {
                    p.plies
                        .iter()
                        .map(|ply| (ply.id.clone(), (p.id.clone(), ply.target_cell)))
                })
                .collect(),
            feed_due: None,
            transfer_due: None,
            pieces,
            t: 0.0,
            q: q.clone(),
            held: None,
            current: None,
            resting: BTreeSet::new(),
            contacts: BTreeMap::new(),
            queue: VecDeque::new(),
            on_belts: BTreeSet::new(),
            transferred: BTreeSet::new(),
            placed: BTreeMap::new(),
            record: WallRecord {
                wall: wall.id.clone(),
                ..WallRecord::default()
            },
            progress,
            events: stepping::Events::new(&q),
            time_limit: f64::INFINITY,
        }
    }

    /// Bounds the wall's simulated time: `run` stops with the time reached once it is past
    /// `seconds` (checked between pieces, before and after nailing).
    pub fn with_time_limit(mut self, seconds: f64) -> WallRun<'a> {
        self.time_limit = seconds;
        self
    }

    /// Runs the wall: framing of every element, then nailing. Err: the simulated time
    /// reached when the run went past its time limit.
    pub fn run(mut self, nails: &[NailPlan]) -> Result<WallRecord, f64> {
        self.record.program.push(RobotStep::Begin(StepFor::Start));
        let home = RobotStep::Carriage {
            s: self.cell.carriage(),
            q: self.q.clone(),
        };
        self.record.program.push(home);
        self.load_belts();
        self.phys.drive_robot(&self.q.clone());
        self.step();
        self.resting = self
            .phys
            .robot_contacts(None, CONTACT_TOLERANCE)
            .into_iter()
            .map(|(a, b, _)| (a, b))
            .collect();
        let total = self.pieces.len();
        let mut driven = vec![false; nails.len()];
        for (done, piece) in self.pieces.clone().into_iter().enumerate() {
            (self.progress)(done, total);
            self.check_time()?;
            // A piece laid over a nail's entry point (a cap plate on its top plate) would
            // shut the nailer out: the nails it covers are driven first, as a framing
            // station nails a plate before the next layer goes on.
            let mut covered: Vec<&NailPlan> = Vec::new();
            for (nail, done) in nails.iter().zip(driven.iter_mut()) {
                if !*done && self.both_placed(nail) && self.covers(piece, nail) {
                    *done = true;
                    covered.push(nail);
                }
            }
            if !covered.is_empty() {
                let start = self.t;
                self.nail_all(&covered);
                self.record.nailing_while_framing += self.t - start;
            }
            self.frame(piece);
        }
        self.record.framing_end = self.t;
        self.check_time()?;
        let rest: Vec<&NailPlan> = nails
            .iter()
            .zip(&driven)
            .filter(|(_, done)| !**done)
            .map(|(nail, _)| nail)
            .collect();
        self.nail_all(&rest);
        self.record.nailing_end = self.t;
        self.check_time()?;
        self.settle();
        self.measure(nails);
        self.record.trace.finish();
        (self.progress)(total, total);
        for ((piece, op, a, b), (t, at)) in std::mem::take(&mut self.contacts) {
            self.record.touches.push(TouchRecord {
                piece: piece.clone(),
                op,
                body_a: a.clone(),
                body_b: b.clone(),
                at,
            });
            self.record.contacts.push(ContactRecord {
                piece,
                op,
                t,
                body_a: a,
                body_b: b,
                depth: at.depth,
            });
        }

        Ok(self.record)
    }

    fn check_time(&self) -> Result<(), f64> {
        if self.t > self.time_limit {
            return Err(self.t);
        }
        Ok(())
    }
}

// ---- time and physics ----
impl<'a> WallRun<'a> {
    /// The programmed speeds (the cell's `[motion]`) scaled by the run's speed fraction.
    pub(super) fn transfer_speed(&self) -> f64 {
        self.cell.motion.transfer_speed * self.options.speed
    }
    pub(super) fn nailing_speed(&self) -> f64 {
        self.cell.motion.nailing_speed * self.options.speed
    }
    pub(super) fn approach_speed(&self) -> f64 {
        self.cell.motion.approach_speed * self.options.speed
    }
    pub(super) fn nail_approach_speed(&self) -> f64 {
        self.cell.motion.nail_approach_speed * self.options.speed
    }

    /// One physics step (see `tick` for the step the run takes): the robot follows `q`, a held piece follows the tool, the feeder and
    /// the sensor act, contacts are recorded.
    fn step(&mut self) {
        self.phys.drive_robot(&self.q);
        if let Some(h) = &self.held {
            let tool = self.cell.robot_base * self.cell.robot.fk_tip(&self.q);
            self.phys.carry(&h.id, &(tool * h.in_tool));
        }
        self.phys.step();
        self.t += self.options.dt;
        self.record.steps += 1;
        self.sample_trace();
        self.feed();
        self.watch_sensor();
        self.watch_contacts();
    }

    /// A wait of the robot's program (a dwell at the grip, release or firing, a settle at
    /// the sensor): recorded as a step of the program, then run.
    fn dwell(&mut self, seconds: f64) {
        self.record.program.push(RobotStep::Dwell(seconds));
        self.wait(seconds);
    }

    /// The name of the tool's TCP `tcp` (as the tool file names it).
    fn tcp_name(&self, tcp: &Isometry3<f64>) -> String {
        self.cell
            .tool
            .tcps
            .iter()
            .find(|(_, t)| *t == tcp)
            .map_or_else(|| "tool0".to_string(), |(name, _)| name.clone())
    }

    fn wait(&mut self, seconds: f64) {
        let steps = (seconds / self.options.dt).ceil().max(1.0) as u64;
        for _ in 0..steps {
            self.tick();
        }
    }

    /// Runs a joint move at `speed` (the fraction it was planned with), recorded as a step
    /// of the program with the TCP `tcp` active.
    fn run_joint(&mut self, mv: &JointMove, speed: f64, tcp: &Isometry3<f64>) {
        let steps = (mv.profile.duration / self.options.dt).ceil().max(1.0) as u64;
        for k in 1..=steps {
            self.q = mv.at(k as f64 * self.options.dt);
            self.tick();
        }
        self.q = mv.to.clone();
        let tcp = self.tcp_name(tcp);
        self.record.program.push(RobotStep::Joint {
            q: self.q.clone(),
            speed,
            duration: mv.profile.duration,
            tcp,
        });
    }

    /// Follows a straight TCP line; stops (returning the failure) if IK fails on the way.
    /// The stretch run is recorded as a step of the program, ending where the arm stopped.
    fn run_line(&mut self, mv: &LinearMove, tcp: &Isometry3<f64>) -> Result<(), IkFailure> {
        let steps = (mv.profile.duration / self.options.dt).ceil().max(1.0) as u64;
        let mut reached = None;
        let mut outcome = Ok(());
        for k in 1..=steps {
            let pose = mv.pose_at(k as f64 * self.options.dt);
            let next = solve(&self.cell, &pose, tcp, &self.q).and_then(|next| {
                check_step(&self.cell, &self.q, &next, k as f64 / steps as f64).map(|()| next)
            });
            match next {
                Ok(next) => {
                    self.q = next;
                    reached = Some(pose);
                    self.tick();
                }
                Err(failure) => {
                    outcome = Err(failure);
                    break;
                }
            }
        }
        if let Some(pose) = reached {
            let tcp_name = self.tcp_name(tcp);
            self.record.program.push(RobotStep::Line {
                pose,
                q: self.q.clone(),
                tcp: tcp_name,
                speed: mv.speed,
            });
        }
        outcome
    }

    /// The physics body a piece rides in: its own, or its pre-assembled member's.
    fn body<'s>(&'s self, id: &'s str) -> &'s str {
        self.plies.get(id).map_or(id, |(lead, _)| lead.as_str())
    }

    fn begin(&mut self, piece: &str, op: Op, may_touch: &[&str]) -> f64 {
        let mut allowed: Vec<String> = may_touch
            .iter()
            .map(|p| format!("piece {}", self.body(p)))
            .collect();
        allowed.push(format!("piece {}", self.body(piece)));
        self.current = Some((piece.to_string(), op, allowed));
        self.t
    }

    fn end(&mut self, piece: &str, op: Op, start: f64) {
        self.record.operations.push(Operation {
            piece: piece.to_string(),
            op,
            start,
            end: self.t,
        });
        self.current = None;
    }

    fn watch_contacts(&mut self) {
        let Some((piece, op, allowed)) = &self.current else {
            return;
        };
        // While the robot waits for a piece it stands still: what it touches does not change
        // (a contact it is still in is recorded by the next operation).
        if *op == Op::Feed {
            return;
        }
        let held = self.held.as_ref().map(|h| h.id.as_str());
        for (a, b, at) in self.phys.robot_contacts(held, CONTACT_TOLERANCE) {
            if allowed.contains(&b) || self.resting.contains(&(a.clone(), b.clone())) {
                continue;
            }
            let at = self.in_wall(at);
            let entry = self
                .contacts
                .entry((piece.clone(), *op, a, b))
                .or_insert((self.t, at));
            if at.depth > entry.1.depth {
                entry.1 = at;
            }
        }
    }

    /// A touch with its point also in the wall's frame.
    pub(super) fn in_wall(&self, mut at: TouchAt) -> TouchAt {
        let p = self.wall_cell.inverse() * Point3::from(at.point);
        at.point_wall = [p.x, p.y, p.z];
        at
    }
}

/// The pose `h` higher (cell z).
pub(super) fn raise(pose: &Isometry3<f64>, h: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(pose.translation.vector + Vector3::new(0.0, 0.0, h)),
        pose.rotation,
    )
}

/// How bad an IK failure is, to report the closest miss: metres or radians beyond the limit.
pub(super) fn failure_score(f: &IkFailure) -> f64 {
    match f {
        IkFailure::OutOfReach {
            distance,
            reach,
            min_reach,
        } => (distance - reach).max(min_reach - distance).max(0.0),
        IkFailure::JointLimit { excess, .. } => excess.abs(),
        IkFailure::WristSingularity { margin, required } => (required - margin).max(0.0),
        // Reachable but colliding: the most telling miss.
        IkFailure::AllSolutionsCollide { .. } => -1.0,
        _ => 10.0,
    }
}

/// The cell-frame x/y rectangle the pieces cover at their framing targets.
fn footprint(pieces: &[&ScenePiece]) -> Option<([f64; 2], [f64; 2])> {
    let mut corners = pieces.iter().flat_map(|p| {
        let [l, w, t] = p.size.map(|v| v / 2.0);
        [-1.0, 1.0].into_iter().flat_map(move |a| {
            [-1.0, 1.0].into_iter().flat_map(move |b| {
                [-1.0, 1.0]
                    .into_iter()
                    .map(move |c| p.target_cell * Point3::new(a * l, b * w, c * t))
            })
        })
    });
    let first = corners.next()?;
    let (mut min, mut max) = ([first.x, first.y], [first.x, first.y]);
    for c in corners {
        min = [min[0].min(c.x), min[1].min(c.y)];
        max = [max[0].max(c.x), max[1].max(c.y)];
    }
    Some((min, max))
}
