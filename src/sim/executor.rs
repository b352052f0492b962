//! The executor: runs one wall in its own rapier world. Lumber arrives on the conveyors in
//! assembly order; for every element the framing subroutine waits for the touch sensor,
//! approaches, grips, lifts, moves to above the framing target, places, releases and
//! retracts; then the nailing subroutine drives every nail. An element that cannot be framed
//! is taken off the belt with its reason recorded, and the run goes on.

use super::SimOptions;
use super::motion::{JointMove, LinearMove};
use super::physics::Physics;
use super::reach::{line, reach_margin, solve, touches};
use super::record::{
    BeltEvent, ContactRecord, IkRecord, NailOutcome, NailRecord, Operation, Placement, WallRecord,
    failure_columns,
};
use crate::cell::{Cell, IkFailure};
use crate::frame::plan::NailingTarget;
use crate::world::{ScenePiece, SceneWall};
use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};
use std::collections::{BTreeMap, BTreeSet, VecDeque};

/// A contact shallower than this is a touch, not a collision (m).
const CONTACT_TOLERANCE: f64 = 0.001;
/// Height above the pick and place poses the gripper approaches from (m).
const CLEARANCE: f64 = 0.25;
/// An assembly surface this far or less above the floor is the floor itself (m).
const SURFACE_ON_FLOOR: f64 = 0.005;
/// How far a framing table reaches beyond the wall laid on it (m).
const TABLE_BORDER: f64 = 0.05;
/// How far the arm, its tool and a held piece keep from everything on a move between poses
/// (m): a kinematic arm grazing a piece on the belt knocks it over.
const PATH_MARGIN: f64 = 0.005;
/// Travel over which the margin grows from nothing at a move's ends to PATH_MARGIN (m).
const MARGIN_TAPER: f64 = 0.05;
/// Largest travel of any point of the arm between two checked samples of a move (m).
const SWEEP_STEP: f64 = 0.02;
/// A piece is released this far above its target and drops into place (m).
const RELEASE_GAP: f64 = 0.001;
/// The nailer approaches along the nail line from this far back (m).
const NAIL_APPROACH: f64 = 0.10;
/// Where the straight line back along the nail is out of reach (a nail driven towards the
/// robot at the far edge of its reach), the nailer comes down to the nail from this far
/// above it instead (m)...
const NAIL_DESCENT: f64 = 0.10;
/// ...its nose this far off the face until the last stretch (m).
const NAIL_STANDOFF: f64 = 0.01;
/// Where the nailer fires: its nose this far off the plate's face (m).
const NOSE_GAP: f64 = 0.002;
const GRIP_TIME: f64 = 0.5;
const RELEASE_TIME: f64 = 0.3;
const FIRE_TIME: f64 = 0.2;
/// A piece more than this far from where the plan expected it when the jaws close is not
/// held (m).
const GRIP_TOLERANCE: f64 = 0.005;
/// Straight-line TCP speed and acceleration.
const LINE_SPEED: f64 = 0.25;
const LINE_ACCEL: f64 = 1.0;
/// How long placed pieces settle before their rest poses are measured (s).
const SETTLE_TIME: f64 = 1.0;
/// A piece that ran into the sensor's end stop settles this long before the robot plans its
/// grip (s).
const SENSOR_SETTLE: f64 = 0.5;
/// The longest the executor waits for a piece at the sensor to come to rest (s).
const MAX_SENSOR_SETTLE: f64 = 3.0;

/// One nail as the executor drives it.
#[derive(Debug, Clone)]
pub struct NailPlan {
    pub plate: String,
    pub member: String,
    pub k: i64,
    /// Wall coordinates of the target and the driving direction in the wall frame.
    pub uvw: [f64; 3],
    pub direction: Vector3<f64>,
}

impl NailPlan {
    /// The executor's nails of a wall from the plan's targets: numbered 1, 2, … along w per
    /// plate and member, in plate order then along the wall.
    pub fn from_targets(targets: &[NailingTarget], wall_frame: &Isometry3<f64>) -> Vec<NailPlan> {
        let mut sorted: Vec<&NailingTarget> = targets.iter().collect();
        sorted.sort_by(|a, b| {
            (&a.plate, &a.member)
                .cmp(&(&b.plate, &b.member))
                .then(a.w.total_cmp(&b.w))
        });
        let mut nails = Vec::new();
        let mut k = 0;
        let mut last: Option<(&str, &str)> = None;
        for t in sorted {
            let key = (t.plate.as_str(), t.member.as_str());
            k = if last == Some(key) { k + 1 } else { 1 };
            last = Some(key);
            nails.push(NailPlan {
                plate: t.plate.clone(),
                member: t.member.clone(),
                k,
                uvw: [t.u, t.v, t.w],
                direction: wall_frame.rotation.inverse() * t.direction,
            });
        }
        nails.sort_by(|a, b| {
            a.plate
                .cmp(&b.plate)
                .then(a.uvw[0].total_cmp(&b.uvw[0]))
                .then(a.k.cmp(&b.k))
        });
        nails
    }
}

/// The gripped piece: its id, its pose in tool0, its box half sizes.
#[derive(Debug, Clone)]
struct Held {
    id: String,
    in_tool: Isometry3<f64>,
    half: [f64; 3],
}

/// A planned framing: the grip and the joint values of its four poses.
struct FramingPlan {
    pick: Isometry3<f64>,
    place: Isometry3<f64>,
    q_above_pick: Vec<f64>,
    q_above_place: Vec<f64>,
    pick_margin: f64,
    place_margin: f64,
    /// The piece's body pose the pick was planned on.
    pick_body: Isometry3<f64>,
    /// The target orientation actually used (a box has four equivalent ones).
    target: Isometry3<f64>,
}

pub struct WallRun<'a> {
    cell: &'a Cell,
    options: &'a SimOptions,
    phys: Physics,
    wall_cell: Isometry3<f64>,
    pieces: Vec<&'a ScenePiece>,
    t: f64,
    q: Vec<f64>,
    held: Option<Held>,
    /// The element and operation contacts are attributed to, and bodies it may touch.
    current: Option<(String, &'static str, Vec<String>)>,
    /// Robot/fixed pairs touching at the start (a base on its floor): never reported.
    resting: BTreeSet<(String, String)>,
    contacts: BTreeMap<(String, &'static str, String, String), (f64, f64)>,
    /// Pieces not yet put on conveyor 1, in order.
    queue: VecDeque<&'a ScenePiece>,
    /// Pieces on the belts (spawned, not yet picked or removed).
    on_belts: BTreeSet<String>,
    placed: BTreeMap<String, Isometry3<f64>>,
    record: WallRecord,
    progress: &'a (dyn Fn(usize, usize) + Sync),
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
        if cell.assembly.surface_z > cell.floor.z + SURFACE_ON_FLOOR
            && let Some((min, max)) = footprint(&pieces)
        {
            phys.add_assembly_table(
                [min[0] - TABLE_BORDER, min[1] - TABLE_BORDER],
                [max[0] + TABLE_BORDER, max[1] + TABLE_BORDER],
                cell.assembly.surface_z,
            );
        }
        WallRun {
            cell,
            options,
            phys,
            wall_cell: cell.robot_base * wall.wall_to_robot,
            pieces,
            t: 0.0,
            q,
            held: None,
            current: None,
            resting: BTreeSet::new(),
            contacts: BTreeMap::new(),
            queue: VecDeque::new(),
            on_belts: BTreeSet::new(),
            placed: BTreeMap::new(),
            record: WallRecord {
                wall: wall.id.clone(),
                ..WallRecord::default()
            },
            progress,
        }
    }

    /// Runs the wall: framing of every element, then nailing.
    pub fn run(mut self, nails: &[NailPlan]) -> WallRecord {
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
        for (done, piece) in self.pieces.clone().into_iter().enumerate() {
            (self.progress)(done, total);
            self.frame(piece);
        }
        self.record.framing_end = self.t;
        self.nail_all(nails);
        self.record.nailing_end = self.t;
        self.settle();
        self.measure(nails);
        (self.progress)(total, total);
        self.record.contacts = std::mem::take(&mut self.contacts)
            .into_iter()
            .map(|((piece, op, a, b), (t, depth))| ContactRecord {
                piece,
                op,
                t,
                body_a: a,
                body_b: b,
                depth,
            })
            .collect();
        self.record
    }

    // ---- time and physics ----

    /// One physics step: the robot follows `q`, a held piece follows the tool, the feeder and
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
        self.feed();
        self.watch_sensor();
        self.watch_contacts();
    }

    fn wait(&mut self, seconds: f64) {
        let steps = (seconds / self.options.dt).ceil().max(1.0) as u64;
        for _ in 0..steps {
            self.step();
        }
    }

    fn run_joint(&mut self, mv: &JointMove) {
        let steps = (mv.profile.duration / self.options.dt).ceil().max(1.0) as u64;
        for k in 1..=steps {
            self.q = mv.at(k as f64 * self.options.dt);
            self.step();
        }
        self.q = mv.to.clone();
    }

    /// Follows a straight TCP line; stops (returning the failure) if IK fails on the way.
    fn run_line(&mut self, mv: &LinearMove, tcp: &Isometry3<f64>) -> Result<(), IkFailure> {
        let steps = (mv.profile.duration / self.options.dt).ceil().max(1.0) as u64;
        for k in 1..=steps {
            let pose = mv.pose_at(k as f64 * self.options.dt);
            self.q = solve(self.cell, &pose, tcp, &self.q)?;
            self.step();
        }
        Ok(())
    }

    /// A collision-checked joint move from the current joints to `to`: straight in joint
    /// space if that is clear, else over the highest of a few raised waypoints that are; if
    /// none is clear, straight (the contacts are then recorded as they happen).
    fn move_to(&mut self, to: &[f64], tcp: &Isometry3<f64>, ignore: &[&str]) {
        let from = self.q.clone();
        let path = self.clear_path(&from, to, tcp, ignore);
        for q in path.windows(2) {
            let mv = JointMove::new(&self.cell.robot, &q[0], &q[1], self.options.speed);
            self.run_joint(&mv);
        }
    }

    fn clear_path(
        &self,
        from: &[f64],
        to: &[f64],
        tcp: &Isometry3<f64>,
        ignore: &[&str],
    ) -> Vec<Vec<f64>> {
        let direct = vec![from.to_vec(), to.to_vec()];
        if self.path_clear(&direct, ignore) {
            return direct;
        }
        // An arc about the robot's base that keeps the tool's orientation turning evenly
        // (a held piece stays level) and rises over the middle.
        for bump in [0.3, 0.7] {
            if let Some(path) = self.arc(from, to, tcp, bump)
                && self.path_clear(&path, ignore)
            {
                return path;
            }
        }
        let up = |q: &[f64], h: f64| -> Option<Vec<f64>> {
            let pose = self.cell.robot_base * self.cell.robot.fk_tip(q) * tcp;
            let raised = Isometry3::from_parts(
                Translation3::from(pose.translation.vector + Vector3::new(0.0, 0.0, h)),
                pose.rotation,
            );
            solve(self.cell, &raised, tcp, q).ok()
        };
        // Raised waypoints over both ends, then the same through the robot's home pose (a
        // transit pose that turns the wrist high above the work).
        let home = self.cell.robot.home();
        for h in [0.4, 0.8] {
            let (Some(a), Some(b)) = (up(from, h), up(to, h)) else {
                continue;
            };
            for path in [
                vec![from.to_vec(), a.clone(), b.clone(), to.to_vec()],
                vec![from.to_vec(), a, home.clone(), b, to.to_vec()],
            ] {
                if self.path_clear(&path, ignore) {
                    return path;
                }
            }
        }
        direct
    }

    /// Joint waypoints along a TCP arc about the base from the pose at `from` to the pose at
    /// `to`: radius, angle and height interpolated, the height raised by `bump` mid-way.
    fn arc(
        &self,
        from: &[f64],
        to: &[f64],
        tcp: &Isometry3<f64>,
        bump: f64,
    ) -> Option<Vec<Vec<f64>>> {
        let base = self.cell.robot_base;
        let a = base * self.cell.robot.fk_tip(from) * tcp;
        let b = base * self.cell.robot.fk_tip(to) * tcp;
        let local = |p: &Isometry3<f64>| base.inverse() * Point3::from(p.translation.vector);
        let (pa, pb) = (local(&a), local(&b));
        let (ra, rb) = (pa.xy().coords.norm(), pb.xy().coords.norm());
        let ta = pa.y.atan2(pa.x);
        let mut tb = pb.y.atan2(pb.x);
        while tb - ta > std::f64::consts::PI {
            tb -= 2.0 * std::f64::consts::PI;
        }
        while ta - tb > std::f64::consts::PI {
            tb += 2.0 * std::f64::consts::PI;
        }
        const SAMPLES: usize = 12;
        let mut path = vec![from.to_vec()];
        let mut q = from.to_vec();
        for k in 1..SAMPLES {
            let s = k as f64 / SAMPLES as f64;
            let (r, th) = (ra + (rb - ra) * s, ta + (tb - ta) * s);
            let z = pa.z + (pb.z - pa.z) * s + bump * (std::f64::consts::PI * s).sin();
            let yaw = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), (tb - ta) * s);
            let rotation = base.rotation * yaw * (base.rotation.inverse() * a.rotation);
            let point = base * Point3::new(r * th.cos(), r * th.sin(), z);
            let pose = Isometry3::from_parts(Translation3::from(point.coords), rotation);
            q = solve(self.cell, &pose, tcp, &q).ok()?;
            path.push(q.clone());
        }
        path.push(to.to_vec());
        Some(path)
    }

    /// Whether the arm sweeps along `path` (straight in joint space between waypoints) at
    /// least PATH_MARGIN clear of everything away from its two ends: checked at samples no
    /// further apart than SWEEP_STEP for the fastest-moving point of the arm, its tool and a
    /// held piece.
    fn path_clear(&self, path: &[Vec<f64>], ignore: &[&str]) -> bool {
        let held = self
            .held
            .as_ref()
            .map(|h| (h.id.as_str(), &h.in_tool, h.half));
        let lengths: Vec<f64> = path
            .windows(2)
            .map(|leg| self.sweep_length(&leg[0], &leg[1]))
            .collect();
        let total: f64 = lengths.iter().sum();
        let mut travelled = 0.0;
        for (leg, length) in path.windows(2).zip(&lengths) {
            let samples = (length / SWEEP_STEP).ceil().max(1.0) as usize;
            for k in 0..=samples {
                let s = k as f64 / samples as f64;
                // The margin grows from nothing at the two ends (poses already checked, which
                // may lie close to what they work on) to PATH_MARGIN after MARGIN_TAPER.
                let from_end = (travelled + s * length).min(total - travelled - s * length);
                let margin = PATH_MARGIN * (from_end / MARGIN_TAPER).clamp(0.0, 1.0);
                let q = lerp(&leg[0], &leg[1], s);
                if touches(&self.phys, self.cell, &q, held, ignore, margin).is_some() {
                    return false;
                }
            }
            travelled += length;
        }
        true
    }

    /// How far the fastest-moving of the arm's key points travels on the joint-space line
    /// from `a` to `b` (m), measured over a few sub-steps: link origins, tool part centres and
    /// the ends of a held piece.
    fn sweep_length(&self, a: &[f64], b: &[f64]) -> f64 {
        const SUB_STEPS: usize = 8;
        let points = |q: &[f64]| -> Vec<Vector3<f64>> {
            let base = self.cell.robot_base;
            let tool = base * self.cell.robot.fk_tip(q);
            let mut pts: Vec<Vector3<f64>> = self
                .cell
                .robot
                .fk_all(q)
                .iter()
                .map(|p| (base * p).translation.vector)
                .collect();
            pts.extend(
                self.cell
                    .tool
                    .parts
                    .iter()
                    .map(|p| (tool * p.shape.origin).translation.vector),
            );
            if let Some(h) = &self.held {
                for end in [-h.half[0], h.half[0]] {
                    pts.push((tool * h.in_tool * Point3::new(end, 0.0, 0.0)).coords);
                }
            }
            pts
        };
        let mut before = points(a);
        let mut total = 0.0;
        for k in 1..=SUB_STEPS {
            let now = points(&lerp(a, b, k as f64 / SUB_STEPS as f64));
            total += before
                .iter()
                .zip(&now)
                .map(|(p, n)| (n - p).norm())
                .fold(0.0, f64::max);
            before = now;
        }
        total
    }

    fn begin(&mut self, piece: &str, op: &'static str, may_touch: &[&str]) -> f64 {
        let mut allowed: Vec<String> = may_touch.iter().map(|p| format!("piece {p}")).collect();
        allowed.push(format!("piece {piece}"));
        self.current = Some((piece.to_string(), op, allowed));
        self.t
    }

    fn end(&mut self, piece: &str, op: &'static str, start: f64) {
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
        if *op == "feed" {
            return;
        }
        let held = self.held.as_ref().map(|h| h.id.as_str());
        for (a, b, depth) in self.phys.robot_contacts(held, CONTACT_TOLERANCE) {
            if allowed.contains(&b) || self.resting.contains(&(a.clone(), b.clone())) {
                continue;
            }
            let entry = self
                .contacts
                .entry((piece.clone(), op, a, b))
                .or_insert((self.t, depth));
            entry.1 = entry.1.max(depth);
        }
    }

    // ---- conveyors ----

    /// Puts every piece whose spawn pose lies on conveyor 1 there; the rest wait in the queue.
    fn load_belts(&mut self) {
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
    fn feed(&mut self) {
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

    fn watch_sensor(&mut self) {
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

    fn start_belts(&mut self, piece: &str) {
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
    fn await_piece(&mut self, piece: &ScenePiece) -> Result<(), String> {
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
    fn take_off(&mut self, id: &str) {
        self.phys.remove_lumber(id);
        self.on_belts.remove(id);
        self.queue.retain(|p| p.id != id);
        self.start_belts(id);
    }

    // ---- framing ----

    fn frame(&mut self, piece: &'a ScenePiece) {
        let start = self.begin(&piece.id, "feed", &[]);
        let fed = self.await_piece(piece);
        self.end(&piece.id, "feed", start);
        if let Err(why) = fed {
            self.record.not_fed.push((piece.id.clone(), why));
            self.take_off(&piece.id);
            return;
        }
        self.record.fed.push((piece.id.clone(), self.t));
        // Let the piece come to rest against the end stop before planning the grip.
        self.wait(SENSOR_SETTLE);
        let mut waited = SENSOR_SETTLE;
        while waited < MAX_SENSOR_SETTLE
            && self
                .phys
                .lumber_speed(&piece.id)
                .is_some_and(|(v, w)| v > 1e-3 || w > 1e-2)
        {
            self.wait(0.1);
            waited += 0.1;
        }
        if let Some(pose) = self.phys.lumber_pose(&piece.id)
            && piece.on_edge
            && (pose.rotation * Vector3::y()).z.abs() < 0.9
        {
            self.record.grip_failed.push((
                piece.id.clone(),
                "it toppled over at the end stop of conveyor 2 (it lies on its wide face); the gripper takes lumber standing on edge".into(),
            ));
            self.take_off(&piece.id);
            return;
        }
        if let Err(why) = self.grip_check(piece) {
            self.record.grip_failed.push((piece.id.clone(), why));
            self.take_off(&piece.id);
            return;
        }
        let plan = match self.plan_framing(piece) {
            Ok(plan) => plan,
            Err((op, failure)) => {
                self.record.ik.push(IkRecord {
                    piece: piece.id.clone(),
                    op,
                    result: Err(failure),
                });
                self.take_off(&piece.id);
                return;
            }
        };
        for (op, margin) in [("pick", plan.pick_margin), ("place", plan.place_margin)] {
            self.record.ik.push(IkRecord {
                piece: piece.id.clone(),
                op,
                result: Ok(margin),
            });
        }
        let grip = *self.cell.tool.tcp("grip").expect("cells have a grip TCP");
        let id = piece.id.as_str();

        // Pick: approach above, descend, close the jaws, lift.
        let start = self.begin(id, "pick", &[]);
        // The approach must not touch the piece either; the descent and grip may.
        if let Some(current) = &mut self.current {
            current.2.clear();
        }
        self.move_to(&plan.q_above_pick.clone(), &grip, &[]);
        if let Some(current) = &mut self.current {
            current.2.push(format!("piece {id}"));
        }
        let above_pick = raise(&plan.pick, CLEARANCE);
        let ok = self
            .run_line(
                &LinearMove::new(above_pick, plan.pick, LINE_SPEED, LINE_ACCEL),
                &grip,
            )
            .is_ok();
        let tool = self.cell.robot_base * self.cell.robot.fk_tip(&self.q);
        let body = self.phys.lumber_pose(id).unwrap_or(piece.spawn);
        // The jaws close where the plan expected the piece; if it is not there (it moved after
        // the plan), the grip fails.
        let expected = plan.pick * grip.inverse();
        let offset = (body.translation.vector
            - (tool * expected.inverse() * plan.pick_body)
                .translation
                .vector)
            .norm();
        if ok && offset > GRIP_TOLERANCE {
            self.phys.set_jaws(None);
            let _ = self.run_line(
                &LinearMove::new(
                    plan.pick,
                    raise(&plan.pick, CLEARANCE),
                    LINE_SPEED,
                    LINE_ACCEL,
                ),
                &grip,
            );
            self.end(id, "pick", start);
            self.record.grip_failed.push((
                id.to_string(),
                format!(
                    "the piece was {:.0} mm from where the jaws closed on it",
                    offset * 1000.0
                ),
            ));
            self.take_off(id);
            return;
        }
        // Hold the piece where it lies, then close the jaws on it: finger plates jumping shut
        // on a free piece would knock it over.
        self.phys.attach(id);
        self.phys.set_jaws(Some(piece.size[2]));
        self.wait(GRIP_TIME);
        self.held = Some(Held {
            id: id.to_string(),
            in_tool: tool.inverse() * body,
            half: piece.size.map(|v| v / 2.0),
        });
        let ok = ok
            && self
                .run_line(
                    &LinearMove::new(plan.pick, above_pick, LINE_SPEED, LINE_ACCEL),
                    &grip,
                )
                .is_ok();
        self.on_belts.remove(id);
        self.start_belts(id);
        self.end(id, "pick", start);

        // The place pose from how the piece actually sits in the gripper.
        let (place, q_above_place) = match &self.held {
            Some(h) => {
                let place = plan.target * h.in_tool.inverse() * grip;
                match solve(
                    self.cell,
                    &raise(&place, CLEARANCE),
                    &grip,
                    &plan.q_above_place,
                ) {
                    Ok(q) => (place, q),
                    Err(_) => (plan.place, plan.q_above_place.clone()),
                }
            }
            None => (plan.place, plan.q_above_place.clone()),
        };

        // Move above the target.
        let start = self.begin(id, "move", &[]);
        if ok {
            self.move_to(&q_above_place, &grip, &[]);
        }
        self.end(id, "move", start);

        // Place: descend, open, release, retract.
        let start = self.begin(id, "place", &[]);
        let above_place = raise(&place, CLEARANCE);
        let release = raise(&place, RELEASE_GAP);
        let ok = ok
            && self
                .run_line(
                    &LinearMove::new(above_place, release, LINE_SPEED, LINE_ACCEL),
                    &grip,
                )
                .is_ok();
        self.phys.set_jaws(None);
        self.phys.detach(id);
        self.held = None;
        self.wait(RELEASE_TIME);
        self.end(id, "place", start);
        let start = self.begin(id, "retract", &[]);
        let _ = self.run_line(
            &LinearMove::new(release, above_place, LINE_SPEED, LINE_ACCEL),
            &grip,
        );
        self.end(id, "retract", start);
        if ok {
            // Settled on the fixture: from now on the fixture holds it.
            self.phys.clamp(id);
            self.placed.insert(id.to_string(), plan.target);
        }
    }

    /// Whether the gripper can take the piece: jaws across its thickness, both grippers on it.
    fn grip_check(&self, piece: &ScenePiece) -> Result<(), String> {
        let Some(g) = &self.cell.tool.gripper else {
            return Err(format!("the tool {} has no gripper", self.cell.tool.name));
        };
        let [length, _, thickness] = piece.size;
        if thickness > g.open_width || thickness < g.closed_width {
            return Err(format!(
                "its thickness {:.0} mm is outside the jaws' range {:.0}..{:.0} mm",
                thickness * 1000.0,
                g.closed_width * 1000.0,
                g.open_width * 1000.0
            ));
        }
        if length < g.spacing {
            return Err(format!(
                "it is {:.0} mm long, shorter than the gripper spacing {:.0} mm: only one gripper would hold it",
                length * 1000.0,
                g.spacing * 1000.0
            ));
        }
        Ok(())
    }

    /// Chooses the grip (which way round the tool holds the piece) and the target orientation
    /// (a box fits its target four ways) whose pick and place poses the arm reaches, preferring
    /// a tool pointing down, poses clear of other bodies and short joint travel. Err: the
    /// operation and failure of the closest miss.
    fn plan_framing(&self, piece: &ScenePiece) -> Result<FramingPlan, (&'static str, IkFailure)> {
        let grip = *self.cell.tool.tcp("grip").expect("cells have a grip TCP");
        let body = self.phys.lumber_pose(&piece.id).unwrap_or(piece.spawn);
        let along = self.cell.conveyor2.direction();
        let mut best: Option<(f64, FramingPlan)> = None;
        let mut miss: Option<(f64, &'static str, IkFailure)> = None;
        let mut note_miss = |op, f: IkFailure| {
            let score = failure_score(&f);
            if miss.as_ref().is_none_or(|m| score < m.0) {
                miss = Some((score, op, f));
            }
        };
        for flip in [false, true] {
            let pick = grip_pose(&body, piece, &along, self.cell.pick.offset, flip);
            let in_body = body.inverse() * pick;
            for symmetry in box_symmetries() {
                let target = piece.target_cell * symmetry;
                let place = target * in_body;
                let down = -(place.rotation * Vector3::z()).z;
                if down < 0.5 && piece.on_edge {
                    continue;
                }
                let attempt = (|| {
                    // The pick and place poses themselves first: when one is out of the arm's
                    // range, that (not its approach above) is the miss to report.
                    solve(self.cell, &pick, &grip, &self.q).map_err(|f| ("pick", f))?;
                    solve(self.cell, &place, &grip, &self.q).map_err(|f| ("place", f))?;
                    let q_above_pick = solve(self.cell, &raise(&pick, CLEARANCE), &grip, &self.q)
                        .map_err(|f| ("pick", f))?;
                    let q_pick = line(
                        self.cell,
                        &q_above_pick,
                        &raise(&pick, CLEARANCE),
                        &pick,
                        &grip,
                        5,
                    )
                    .map_err(|f| ("pick", f))?;
                    let q_above_place =
                        solve(self.cell, &raise(&place, CLEARANCE), &grip, &q_above_pick)
                            .map_err(|f| ("place", f))?;
                    let q_place = line(
                        self.cell,
                        &q_above_place,
                        &raise(&place, CLEARANCE),
                        &place,
                        &grip,
                        5,
                    )
                    .map_err(|f| ("place", f))?;
                    Ok::<_, (&'static str, IkFailure)>((
                        q_above_pick,
                        q_pick,
                        q_above_place,
                        q_place,
                    ))
                })();
                match attempt {
                    Err((op, f)) => note_miss(op, f),
                    Ok((q_above_pick, q_pick, q_above_place, q_place)) => {
                        let held_in_tool = grip * in_body.inverse();
                        let half = piece.size.map(|v| v / 2.0);
                        let held = Some((piece.id.as_str(), &held_in_tool, half));
                        let blocked = touches(&self.phys, self.cell, &q_place, held, &[], 0.0)
                            .or_else(|| {
                                touches(&self.phys, self.cell, &q_pick, None, &[&piece.id], 0.0)
                            });
                        if let Some((a, b)) = blocked {
                            // A reachable pose that collides: the closest kind of miss.
                            note_miss("place", IkFailure::AllSolutionsCollide { pair: [a, b] });
                            continue;
                        }
                        let travel = distance(&self.q, &q_above_pick)
                            + distance(&q_above_pick, &q_above_place);
                        let score = (1.0 - down) * 100.0 + travel;
                        if best.as_ref().is_none_or(|b| score < b.0) {
                            best = Some((
                                score,
                                FramingPlan {
                                    pick_body: body,
                                    pick_margin: reach_margin(self.cell, &pick, &grip),
                                    place_margin: reach_margin(self.cell, &place, &grip),
                                    pick,
                                    place,
                                    q_above_pick,
                                    q_above_place,
                                    target,
                                },
                            ));
                        }
                    }
                }
            }
        }
        match (best, miss) {
            (Some((_, plan)), _) => Ok(plan),
            (None, Some((_, op, f))) => Err((op, f)),
            (None, None) => Err(("place", IkFailure::InvalidPose)),
        }
    }

    // ---- nailing ----

    fn nail_all(&mut self, nails: &[NailPlan]) {
        let nail_tcp = *self.cell.tool.tcp("nail").expect("cells have a nail TCP");
        for nail in nails {
            let missing: Vec<&str> = [nail.plate.as_str(), nail.member.as_str()]
                .into_iter()
                .filter(|p| !self.placed.contains_key(*p))
                .collect();
            if !missing.is_empty() {
                self.skip_nail(
                    nail,
                    "not_framed",
                    "",
                    0.0,
                    0.0,
                    match missing.as_slice() {
                        [one] => format!("{one} was not placed"),
                        _ => format!("{} were not placed", missing.join(" and ")),
                    },
                );
                continue;
            }
            let point = self.wall_cell * Point3::from(Vector3::from(nail.uvw));
            let direction = self.wall_cell.rotation * nail.direction;
            let mut chosen: Option<(Isometry3<f64>, Isometry3<f64>, Vec<f64>)> = None;
            let mut miss: Option<(f64, IkFailure)> = None;
            let candidates = nail_rolls().into_iter().flat_map(|roll| {
                // The nose stops just short of the face: pressed against the work, the
                // position-driven tool would shove the loose frame across the floor.
                let pose = retreat(&nail_pose(&point, &direction, roll), NOSE_GAP);
                nail_approaches(pose).map(move |back| (pose, back))
            });
            for (pose, back) in candidates {
                let attempt = solve(self.cell, &back, &nail_tcp, &self.q).and_then(|qa| {
                    let q_nail = line(self.cell, &qa, &back, &pose, &nail_tcp, 4)?;
                    let ignore = [nail.plate.as_str(), nail.member.as_str()];
                    match touches(&self.phys, self.cell, &q_nail, None, &ignore, 0.0)
                        .or_else(|| touches(&self.phys, self.cell, &qa, None, &ignore, 0.0))
                    {
                        Some((a, b)) => Err(IkFailure::AllSolutionsCollide { pair: [a, b] }),
                        None => Ok(qa),
                    }
                });
                match attempt {
                    Ok(q_back) => {
                        chosen = Some((pose, back, q_back));
                        break;
                    }
                    Err(f) => {
                        let score = failure_score(&f);
                        if miss.as_ref().is_none_or(|m| score < m.0) {
                            miss = Some((score, f));
                        }
                    }
                }
            }
            let Some((pose, back, q_back)) = chosen else {
                let failure = miss.map_or(IkFailure::InvalidPose, |m| m.1);
                let (kind, what, value, limit) = failure_columns(&failure);
                self.skip_nail(nail, kind, &what, value, limit, failure.to_string());
                continue;
            };
            let plate = nail.plate.clone();
            let start = self.begin(&plate, "nail", &[nail.member.as_str()]);
            self.move_to(&q_back, &nail_tcp, &[]);
            let reached = self
                .run_line(
                    &LinearMove::new(back, pose, LINE_SPEED, LINE_ACCEL),
                    &nail_tcp,
                )
                .is_ok();
            let fired_at = self.t;
            if reached {
                self.phys.nail(&nail.plate, &nail.member);
                self.wait(FIRE_TIME);
            }
            let _ = self.run_line(
                &LinearMove::new(pose, back, LINE_SPEED, LINE_ACCEL),
                &nail_tcp,
            );
            self.end(&plate, "nail", start);
            if reached {
                self.record.nails.push(NailRecord {
                    plate: nail.plate.clone(),
                    member: nail.member.clone(),
                    k: nail.k,
                    planned: nail.uvw,
                    outcome: NailOutcome::Fired {
                        t: fired_at,
                        as_built: nail.uvw,
                        position_error: f64::NAN,
                        member_inside: false,
                    },
                });
            } else {
                self.skip_nail(
                    nail,
                    "no_exact_solution",
                    "",
                    0.0,
                    0.0,
                    "the nailer lost the straight line to the nail".into(),
                );
            }
        }
    }

    fn skip_nail(
        &mut self,
        nail: &NailPlan,
        kind: &str,
        what: &str,
        value: f64,
        limit: f64,
        message: String,
    ) {
        self.record.nails.push(NailRecord {
            plate: nail.plate.clone(),
            member: nail.member.clone(),
            k: nail.k,
            planned: nail.uvw,
            outcome: NailOutcome::Skipped {
                kind: kind.to_string(),
                what: what.to_string(),
                value,
                limit,
                message,
            },
        });
    }

    // ---- as built ----

    fn settle(&mut self) {
        let home = self.cell.robot.home();
        let tcp = *self.cell.tool.tcp("grip").expect("cells have a grip TCP");
        self.move_to(&home, &tcp, &[]);
        self.wait(SETTLE_TIME);
    }

    /// Rest poses against targets, and every fired nail's as-built point and member check.
    fn measure(&mut self, nails: &[NailPlan]) {
        let poses = self.phys.lumber_poses();
        let mut delta: BTreeMap<String, Isometry3<f64>> = BTreeMap::new();
        for (id, target) in &self.placed {
            let Some(actual) = poses.get(id) else {
                continue;
            };
            let position_error = (actual.translation.vector - target.translation.vector).norm();
            let angle_error = box_symmetries()
                .into_iter()
                .map(|s| (target * s).rotation.angle_to(&actual.rotation))
                .fold(f64::INFINITY, f64::min);
            self.record.placements.push(Placement {
                piece: id.clone(),
                position_error,
                angle_error,
            });
            let best = box_symmetries()
                .into_iter()
                .min_by(|a, b| {
                    let ea = (target * a).rotation.angle_to(&actual.rotation);
                    let eb = (target * b).rotation.angle_to(&actual.rotation);
                    ea.total_cmp(&eb)
                })
                .unwrap_or_else(Isometry3::identity);
            delta.insert(id.clone(), actual * (target * best).inverse());
        }
        let sizes: BTreeMap<&str, [f64; 3]> = self
            .pieces
            .iter()
            .map(|p| (p.id.as_str(), p.size))
            .collect();
        let wall_inv = self.wall_cell.inverse();
        for record in &mut self.record.nails {
            let NailOutcome::Fired {
                as_built,
                position_error,
                member_inside,
                ..
            } = &mut record.outcome
            else {
                continue;
            };
            let Some(nail) = nails
                .iter()
                .find(|n| n.plate == record.plate && n.member == record.member && n.k == record.k)
            else {
                continue;
            };
            let (Some(plate_delta), Some(member_pose), Some(plate_size)) = (
                delta.get(&record.plate),
                poses.get(&record.member),
                sizes.get(record.plate.as_str()),
            ) else {
                continue;
            };
            let planned = self.wall_cell * Point3::from(Vector3::from(nail.uvw));
            let built = plate_delta * planned;
            *position_error = (built - planned).norm();
            let b = wall_inv * built;
            *as_built = [b.x, b.y, b.z];
            // A point past the plate, along the as-built nail line, must lie in the member.
            let direction = plate_delta.rotation * (self.wall_cell.rotation * nail.direction);
            let plate_pose = poses
                .get(&record.plate)
                .copied()
                .unwrap_or_else(Isometry3::identity);
            let local_dir = plate_pose.rotation.inverse() * direction;
            let depth: f64 = (0..3).map(|i| local_dir[i].abs() * plate_size[i]).sum();
            let tip = built + direction * (depth + 0.02);
            let member_size = sizes
                .get(record.member.as_str())
                .copied()
                .unwrap_or([0.0; 3]);
            let local = member_pose.inverse() * tip;
            *member_inside = (0..3).all(|i| local[i].abs() <= member_size[i] / 2.0 + 5e-4);
        }
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

/// The pose `h` higher (cell z).
fn raise(pose: &Isometry3<f64>, h: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(pose.translation.vector + Vector3::new(0.0, 0.0, h)),
        pose.rotation,
    )
}

/// The pose moved back `d` against its z axis (the tool's approach direction).
fn retreat(pose: &Isometry3<f64>, d: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(pose.translation.vector - pose.rotation * Vector3::z() * d),
        pose.rotation,
    )
}

/// The grip TCP on a piece lying on conveyor 2: on its top face, `offset` back from its
/// leading end (or at its middle if it is shorter), z down, y along the piece (reversed when
/// `flip`), x across it (the jaws close along x).
fn grip_pose(
    body: &Isometry3<f64>,
    piece: &ScenePiece,
    along_belt: &Vector3<f64>,
    offset: f64,
    flip: bool,
) -> Isometry3<f64> {
    let axes: [Vector3<f64>; 3] = std::array::from_fn(|i| body.rotation * Vector3::ith(i, 1.0));
    let long = if axes[0].dot(along_belt) >= 0.0 {
        axes[0]
    } else {
        -axes[0]
    };
    // The up axis: whichever of the section's axes is closest to vertical.
    let (up_axis, height) = if axes[1].z.abs() >= axes[2].z.abs() {
        (axes[1], piece.size[1])
    } else {
        (axes[2], piece.size[2])
    };
    let up = if up_axis.z >= 0.0 { up_axis } else { -up_axis };
    let length = piece.size[0];
    let from_centre = (length / 2.0 - offset).max(0.0);
    let point = body.translation.vector + long * from_centre + up * (height / 2.0);
    let z = -up;
    let y = if flip { -long } else { long };
    let x = y.cross(&z);
    let rotation = Rotation3::from_basis_unchecked(&[x, y, z]);
    Isometry3::from_parts(
        Translation3::from(point),
        UnitQuaternion::from_rotation_matrix(&rotation),
    )
}

/// The four rotations that map a box onto itself (identity and half turns about its axes).
fn box_symmetries() -> [Isometry3<f64>; 4] {
    let half_turn = |axis: Vector3<f64>| {
        Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(
                &nalgebra::Unit::new_normalize(axis),
                std::f64::consts::PI,
            ),
        )
    };
    [
        Isometry3::identity(),
        half_turn(Vector3::x()),
        half_turn(Vector3::y()),
        half_turn(Vector3::z()),
    ]
}

/// Roll angles about the nail line tried in turn (0: the flange above the nose).
fn nail_rolls() -> [f64; 6] {
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    [0.0, FRAC_PI_4, -FRAC_PI_4, FRAC_PI_2, -FRAC_PI_2, PI]
}

/// Where the nailer starts its straight approach to a nail pose, in the order tried: back
/// along the nail line, then (for a nail not driven vertically) from above, just off the face.
fn nail_approaches(pose: Isometry3<f64>) -> impl Iterator<Item = Isometry3<f64>> {
    let along = retreat(&pose, NAIL_APPROACH);
    let drive = pose.rotation * Vector3::z();
    let up = Vector3::z() - drive * drive.z;
    let from_above = (up.norm() > 0.5).then(|| {
        let lift = up.normalize() * NAIL_DESCENT;
        let off = retreat(&pose, NAIL_STANDOFF);
        Isometry3::from_parts(
            Translation3::from(off.translation.vector + lift),
            pose.rotation,
        )
    });
    std::iter::once(along).chain(from_above)
}

/// The nail TCP at `point` driving along `direction`, its x axis turned `roll` from up.
fn nail_pose(point: &Point3<f64>, direction: &Vector3<f64>, roll: f64) -> Isometry3<f64> {
    let z = direction.normalize();
    let mut x = Vector3::z() - z * z.z;
    if x.norm() < 1e-6 {
        x = Vector3::x() - z * z.x;
    }
    let x =
        UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(z), roll) * x.normalize();
    let y = z.cross(&x);
    let rotation = Rotation3::from_basis_unchecked(&[x, y, z]);
    Isometry3::from_parts(
        Translation3::from(point.coords),
        UnitQuaternion::from_rotation_matrix(&rotation),
    )
}

/// How bad an IK failure is, to report the closest miss: metres or radians beyond the limit.
fn failure_score(f: &IkFailure) -> f64 {
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

fn lerp(a: &[f64], b: &[f64], s: f64) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + (y - x) * s).collect()
}

fn distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).abs()).sum()
}
