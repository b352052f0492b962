//! Framing: grip a piece at the sensor, carry it above its framing target, place and release it.

use super::paths::distance;
use super::{Held, WallRun, failure_score, raise};
use crate::cell::tcp_poses::{GRIP_SHIFT_STEP, two_gripper_reach, two_gripper_shifts};
use crate::cell::{Arrangement, Hold, IkFailure};
use crate::sim::RELEASE_GAP;
use crate::sim::motion::LinearMove;
use crate::sim::physics::GRAVITY;
use crate::sim::reach::{Touch, continuous_line, reach_margin, solve, touch};
use crate::sim::record::{
    IkRecord, Op, PoseRecord, Refusal, RefusalKind, ReleaseRecord, RobotStep, StepFor, TouchRecord,
};
use crate::world::ScenePiece;
use nalgebra::{Isometry3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// Height above the pick and place poses the gripper approaches from (m).
pub(super) const CLEARANCE: f64 = 0.25;
/// Samples checked along a straight descent while planning.
const LINE_SAMPLES: usize = 10;
/// A piece more than this far from where the plan expected it when the jaws close is not
/// held (m).
pub(super) const GRIP_TOLERANCE: f64 = 0.005;
/// A piece that ran into the sensor's end stop settles this long before the robot plans its
/// grip (s).
pub(super) const SENSOR_SETTLE: f64 = 0.5;
/// The longest the executor waits for a piece at the sensor to come to rest (s).
pub(super) const MAX_SENSOR_SETTLE: f64 = 3.0;

/// How far below a released piece the executor looks for what it will rest on (m).
const RELEASE_LOOK_DOWN: f64 = 1.0;

/// Why a framing could not be planned: the operation whose pose failed, how, and for a pose
/// ruled out by a collision, where the two bodies met.
pub(super) struct Miss {
    pub(super) op: Op,
    pub(super) failure: IkFailure,
    /// Boxed: a miss is passed around often, a touch rarely.
    touch: Option<Box<Touch>>,
}

impl Miss {
    pub(super) fn colliding(op: Op, t: Touch) -> Miss {
        Miss {
            op,
            failure: IkFailure::AllSolutionsCollide {
                pair: [t.body_a.clone(), t.body_b.clone()],
            },
            touch: Some(Box::new(t)),
        }
    }
}

impl From<(Op, IkFailure)> for Miss {
    fn from((op, failure): (Op, IkFailure)) -> Miss {
        Miss {
            op,
            failure,
            touch: None,
        }
    }
}

/// A planned framing: the grip and the joint values of its four poses.
pub(super) struct FramingPlan {
    pick: Isometry3<f64>,
    place: Isometry3<f64>,
    q_above_pick: Vec<f64>,
    q_above_place: Vec<f64>,
    pick_margin: f64,
    place_margin: f64,
    /// The piece's body pose the pick was planned on.
    pick_body: Isometry3<f64>,
    /// The target orientation actually used (a box has four equivalent ones), where the piece
    /// is let go (beside its target, for a piece slid into place after).
    pub(super) target: Isometry3<f64>,
    /// Where the carriage stands (on a track) to pick and to place.
    carriage_pick: f64,
    pub(super) carriage_place: f64,
    /// After the release: the push that slides the piece into face contact with its
    /// neighbour (`slide_in.rs`).
    pub(super) push: Option<super::slide_in::Push>,
}

impl<'a> WallRun<'a> {
    pub(super) fn frame(&mut self, piece: &'a ScenePiece) {
        self.record
            .program
            .push(RobotStep::Begin(StepFor::Piece(piece.id.clone())));
        // Lumber the cell cannot handle never goes on the belts (`load_belts` leaves it
        // out): its verdict names why, not what the belts would have done to it (a 60 mm
        // block on edge topples at the end stop; a 58 m plate falls off the belts' ends).
        if let Err(why) = self.carry_check(piece) {
            self.record.not_fed.push((piece.id.clone(), why));
            return;
        }
        if let Err(why) = self.grip_check(piece) {
            self.record.grip_failed.push((piece.id.clone(), why));
            return;
        }
        let start = self.begin(&piece.id, Op::Feed, &[]);
        self.record.program.push(RobotStep::AwaitPart);
        let fed = self.await_piece(piece);
        self.end(&piece.id, Op::Feed, start);
        if let Err(why) = fed {
            self.record.not_fed.push((
                piece.id.clone(),
                Refusal::new(RefusalKind::NotFed, why.to_string()),
            ));
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
        self.record.program.push(RobotStep::Dwell(waited));
        if let Some(pose) = self.phys.lumber_pose(&piece.id)
            && piece.on_edge
            && (pose.rotation * Vector3::y()).z.abs() < 0.9
        {
            self.record.grip_failed.push((
                piece.id.clone(),
                Refusal::new(
                    RefusalKind::Toppled,
                    "it toppled over at the end stop of conveyor 2 (it lies on its wide face); the gripper takes lumber standing on edge",
                ),
            ));
            self.take_off(&piece.id);
            return;
        }
        let plan = match self
            .plan_framing(piece, &Vector3::zeros())
            .or_else(|miss| self.plan_slide_in(piece, miss))
        {
            Ok(plan) => plan,
            Err(miss) => {
                self.record_miss(piece, miss);
                self.take_off(&piece.id);
                return;
            }
        };
        for (op, margin) in [(Op::Pick, plan.pick_margin), (Op::Place, plan.place_margin)] {
            self.record.ik.push(IkRecord {
                piece: piece.id.clone(),
                op,
                result: Ok(margin),
            });
        }
        let grip = *self.cell.tool.tcp("grip").expect("cells have a grip TCP");
        let id = piece.id.as_str();

        // Pick: approach above, descend, close the jaws, lift.
        let start = self.begin(id, Op::Pick, &[]);
        // The approach must not touch the piece either; the descent and grip may.
        if let Some(current) = &mut self.current {
            current.2.clear();
        }
        if let Err(failure) = self
            .move_carriage(plan.carriage_pick, &grip, &[])
            .and_then(|()| {
                self.move_to(
                    &plan.q_above_pick.clone(),
                    &grip,
                    &[],
                    self.transfer_speed(),
                )
            })
        {
            self.record_line_failure(piece, Op::Pick, failure);
            self.end(id, Op::Pick, start);
            self.take_off(id);
            return;
        }
        if let Some(current) = &mut self.current {
            current.2.push(format!("piece {id}"));
        }
        let above_pick = raise(&plan.pick, CLEARANCE);
        let ok = self
            .run_line(
                &LinearMove::new(
                    above_pick,
                    plan.pick,
                    self.approach_speed(),
                    self.cell.motion.line_accel,
                ),
                &grip,
            )
            .map_err(|f| self.record_line_failure(piece, Op::Pick, f))
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
                    self.approach_speed(),
                    self.cell.motion.line_accel,
                ),
                &grip,
            );
            self.end(id, Op::Pick, start);
            self.record.grip_failed.push((
                id.to_string(),
                Refusal::new(
                    RefusalKind::Slipped,
                    format!(
                        "the piece was {:.0} mm from where the jaws closed on it",
                        offset * 1000.0
                    ),
                ),
            ));
            self.take_off(id);
            return;
        }
        // Hold the piece where it lies, then close the jaws on it: finger plates jumping shut
        // on a free piece would knock it over.
        self.phys.attach(id);
        self.phys.set_jaws(Some(piece.size[2]));
        self.record.program.push(RobotStep::Grip);
        self.dwell(self.cell.motion.grip_dwell);
        self.held = Some(Held {
            id: id.to_string(),
            in_tool: tool.inverse() * body,
            half: piece.size.map(|v| v / 2.0),
        });
        let ok = ok
            && self
                .run_line(
                    &LinearMove::new(
                        plan.pick,
                        above_pick,
                        self.approach_speed(),
                        self.cell.motion.line_accel,
                    ),
                    &grip,
                )
                .map_err(|f| self.record_line_failure(piece, Op::Pick, f))
                .is_ok();
        self.on_belts.remove(id);
        self.start_belts(id);
        self.end(id, Op::Pick, start);

        // Move above the target: the carriage to its place position, then the arm.
        let start = self.begin(id, Op::Move, &[]);
        let carried = if ok {
            self.move_carriage(plan.carriage_place, &grip, &[])
        } else {
            Ok(())
        };
        // The place pose from how the piece actually sits in the gripper.
        let (place, q_above_place) = match &self.held {
            Some(h) => {
                let place = plan.target * h.in_tool.inverse() * grip;
                match solve(
                    &self.cell,
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
        if ok
            && let Err(failure) = carried
                .and_then(|()| self.move_to(&q_above_place, &grip, &[], self.transfer_speed()))
            && self
                .above_from_abeam(&place, &grip, &q_above_place)
                .is_err()
        {
            // No way to the target with the piece: the arm lets go where it is and the piece
            // is taken out of the cell.
            self.record_line_failure(piece, Op::Place, failure);
            self.phys.set_jaws(None);
            self.record.program.push(RobotStep::Release);
            self.phys.detach(id);
            self.held = None;
            self.end(id, Op::Move, start);
            self.take_off(id);
            return;
        }
        self.end(id, Op::Move, start);

        // Place: descend, open, release, retract.
        let start = self.begin(id, Op::Place, &[]);
        let above_place = raise(&place, CLEARANCE);
        let release = raise(&place, RELEASE_GAP);
        let ok = ok
            && self
                .run_line(
                    &LinearMove::new(
                        above_place,
                        release,
                        self.approach_speed(),
                        self.cell.motion.line_accel,
                    ),
                    &grip,
                )
                .map_err(|f| self.record_line_failure(piece, Op::Place, f))
                .is_ok();
        if ok {
            self.record_grip(piece, &grip);
            self.record_release(id);
        }
        self.phys.set_jaws(None);
        self.phys.detach(id);
        self.held = None;
        self.record.program.push(RobotStep::Release);
        self.dwell(self.cell.motion.release_dwell);
        self.end(id, Op::Place, start);
        let start = self.begin(id, Op::Retract, &[]);
        let _ = self.run_line(
            &LinearMove::new(
                release,
                above_place,
                self.approach_speed(),
                self.cell.motion.line_accel,
            ),
            &grip,
        );
        self.end(id, Op::Retract, start);
        let (ok, target) = match &plan.push {
            Some(push) if ok => (self.slide_in(piece, push), push.target),
            _ => (ok, plan.target),
        };
        if ok {
            // Settled on the fixture: from now on the fixture holds it.
            self.phys.clamp(id);
            self.placed.insert(id.to_string(), target);
            // A pre-assembled member's other plies are in place with it.
            for ply in &piece.plies {
                self.placed.insert(ply.id.clone(), ply.target_cell);
            }
        }
    }

    /// On a track, where the way above the place pose is blocked from where the carriage
    /// stands: the carriage abeam of the place pose instead (the arm reaches down over the
    /// work rather than across it), and the arm above the pose from there. Err where that
    /// is the same position or no clear way either.
    fn above_from_abeam(
        &mut self,
        place: &Isometry3<f64>,
        grip: &Isometry3<f64>,
        seed: &[f64],
    ) -> Result<(), IkFailure> {
        let Some(track) = self.cell.track else {
            return Err(IkFailure::InvalidPose);
        };
        let above = raise(place, CLEARANCE);
        let s = self.carriage_for(
            track.abeam(&Point3::from(place.translation.vector)),
            &[(*place, *grip), (above, *grip)],
        )?;
        if (s - self.cell.carriage()).abs() < 1e-9 {
            return Err(IkFailure::InvalidPose);
        }
        let (q_above, _) =
            continuous_line(&self.cell_at(s), seed, &above, place, grip, LINE_SAMPLES)?;
        self.move_carriage(s, grip, &[])?;
        self.move_to(&q_above, grip, &[], self.transfer_speed())
    }

    /// What lies beneath the piece the gripper is about to let go of, and how far down.
    fn record_release(&mut self, id: &str) {
        let (below, gap) = self
            .phys
            .below(id, RELEASE_LOOK_DOWN)
            .unwrap_or((String::new(), 0.0));
        self.record.releases.push(ReleaseRecord {
            piece: id.to_string(),
            below,
            gap,
        });
    }

    /// Where the grip TCP holds `piece` at its release: metres along the piece from its
    /// target's centre, positive towards its upper end (a piece running up the wall) or its
    /// larger-u end, as `plan` orders a member's axis.
    fn record_grip(&mut self, piece: &ScenePiece, grip: &Isometry3<f64>) {
        let tcp = self.cell.robot_base * self.cell.robot.fk_tip(&self.q) * grip;
        let to_wall = self.wall_cell.inverse();
        let point = (to_wall * tcp).translation.vector;
        let target = to_wall * piece.target_cell;
        let mut axis = target.rotation * Vector3::x();
        let up_the_wall = axis.y.abs() > (axis.x * axis.x + axis.z * axis.z).sqrt();
        if (up_the_wall && axis.y < 0.0) || (!up_the_wall && axis.x < 0.0) {
            axis = -axis;
        }
        let offset = (point - target.translation.vector).dot(&axis);
        self.record.grips.push((piece.id.clone(), offset));
    }

    /// A straight move of a framing that failed on the way: recorded against the piece, so
    /// that it is not placed without a reason.
    pub(super) fn record_line_failure(&mut self, piece: &ScenePiece, op: Op, failure: IkFailure) {
        self.record_miss(piece, Miss::from((op, failure)));
    }

    /// A pose the arm could not take: the failure, where the piece would have been, and
    /// where the collision that ruled it out lay.
    fn record_miss(&mut self, piece: &ScenePiece, miss: Miss) {
        let centre = match miss.op {
            Op::Pick => self.phys.lumber_pose(&piece.id).unwrap_or(piece.spawn),
            _ => piece.target_cell,
        }
        .translation
        .vector;
        let in_wall = self.wall_cell.inverse() * Point3::from(centre);
        self.record.poses.push(PoseRecord {
            piece: piece.id.clone(),
            op: miss.op,
            centre: centre.into(),
            centre_wall: in_wall.coords.into(),
        });
        if let Some(t) = miss.touch.map(|t| *t) {
            let at = self.in_wall(t.at);
            self.record.touches.push(TouchRecord {
                piece: piece.id.clone(),
                op: miss.op,
                body_a: t.body_a,
                body_b: t.body_b,
                at,
            });
        }
        self.record.ik.push(IkRecord {
            piece: piece.id.clone(),
            op: miss.op,
            result: Err(miss.failure),
        });
    }

    /// Whether the conveyors can carry the piece: no longer than conveyor 2, nor than
    /// conveyor 1's deck is wide (side by side) or its belt long (end to end).
    pub(super) fn carry_check(&self, piece: &ScenePiece) -> Result<(), Refusal> {
        let length = piece.size[0];
        let c2 = self.cell.conveyor2.length;
        let (c1, extent) = match self.cell.arrangement {
            Arrangement::SideBySide => (self.cell.conveyor1.width, "wide"),
            Arrangement::EndToEnd => (self.cell.conveyor1.length, "long"),
        };
        let too_long = |message: String| Refusal::new(RefusalKind::TooLongForConveyors, message);
        if length > c2 + 1e-9 {
            return Err(too_long(format!(
                "the conveyors cannot carry it: it is {length:.2} m long, conveyor 2 is {c2:.2} m long"
            )));
        }
        if length > c1 + 1e-9 {
            return Err(too_long(format!(
                "the conveyors cannot carry it: it is {length:.2} m long, conveyor 1 is {c1:.2} m {extent}"
            )));
        }
        Ok(())
    }

    /// Whether the gripper can take the piece: jaws across its thickness or pads on its top
    /// face, both grippers on it or one rated to hold it alone.
    pub(super) fn grip_check(&self, piece: &ScenePiece) -> Result<(), Refusal> {
        let Some(g) = &self.cell.tool.gripper else {
            return Err(Refusal::new(
                RefusalKind::NoGripper,
                format!("the tool {} has no gripper", self.cell.tool.name),
            ));
        };
        let [length, _, thickness] = piece.size;
        match &g.holds {
            Hold::Sides(jaws) => {
                if thickness > jaws.open_width || thickness < jaws.closed_width {
                    return Err(Refusal::new(
                        RefusalKind::OutsideJawRange,
                        format!(
                            "its thickness {:.0} mm is outside the jaws' range {:.0}..{:.0} mm",
                            thickness * 1000.0,
                            jaws.closed_width * 1000.0,
                            jaws.open_width * 1000.0
                        ),
                    ));
                }
            }
            Hold::Top(pads) => {
                // On edge its top face is as wide as it is thick; fed flat (rules/world.dl:
                // feeds_flat, every piece not on edge at its target), as it is wide.
                let face = if piece.on_edge {
                    thickness
                } else {
                    piece.size[1]
                };
                if face < pads.pad_width {
                    return Err(Refusal::new(
                        RefusalKind::NarrowerThanPads,
                        format!(
                            "its top face is {:.0} mm wide, narrower than the pads ({:.0} mm)",
                            face * 1000.0,
                            pads.pad_width * 1000.0
                        ),
                    ));
                }
                if piece.mass > pads.max_mass {
                    return Err(Refusal::new(
                        RefusalKind::TooHeavyForGripper,
                        format!(
                            "it weighs {:.1} kg: the pads hold at most {:.1} kg",
                            piece.mass, pads.max_mass
                        ),
                    ));
                }
            }
        }
        if length < g.spacing {
            let Some(one) = g.one_gripper else {
                return Err(Refusal::new(
                    RefusalKind::ShorterThanGripperSpacing,
                    format!(
                        "it is {:.0} mm long, shorter than the gripper spacing {:.0} mm: only one gripper would hold it, and the tool {} rates none to hold a piece alone",
                        length * 1000.0,
                        g.spacing * 1000.0,
                        self.cell.tool.name
                    ),
                ));
            };
            if length < one.min_length {
                return Err(Refusal::new(
                    RefusalKind::TooShortForOneGripper,
                    format!(
                        "it is {:.0} mm long: one gripper holds pieces of {:.0} mm or more square",
                        length * 1000.0,
                        one.min_length * 1000.0
                    ),
                ));
            }
            if piece.mass > one.max_mass {
                return Err(Refusal::new(
                    RefusalKind::TooHeavyForOneGripper,
                    format!(
                        "it is {:.0} mm long (shorter than the gripper spacing {:.0} mm) and weighs {:.1} kg: one gripper holds at most {:.1} kg",
                        length * 1000.0,
                        g.spacing * 1000.0,
                        piece.mass,
                        one.max_mass
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Chooses the grip (which way round the tool holds the piece) and the target orientation
    /// (a box fits its target four ways) whose pick and place poses the arm reaches, preferring
    /// a tool pointing down, poses clear of other bodies and short joint travel. Err: the
    /// operation and failure of the closest miss. `aside` (m, cell frame) moves the target
    /// (where a piece is let go beside its target to be slid in).
    pub(super) fn plan_framing(
        &self,
        piece: &ScenePiece,
        aside: &Vector3<f64>,
    ) -> Result<FramingPlan, Miss> {
        let grip = *self.cell.tool.tcp("grip").expect("cells have a grip TCP");
        let body = self.phys.lumber_pose(&piece.id).unwrap_or(piece.spawn);
        let along = self.cell.conveyor2.direction();
        let mut best: Option<(f64, FramingPlan)> = None;
        let mut miss: Option<(f64, Miss)> = None;
        let mut note_miss = |m: Miss| {
            // A grip whose pick fails got less far than one whose place fails: report the
            // place miss when there is one (a long plate's middle may lie beyond reach on the
            // belt, but that is not why it cannot be framed).
            let score = failure_score(&m.failure) + if m.op == Op::Pick { 100.0 } else { 0.0 };
            if miss.as_ref().is_none_or(|best| score < best.0) {
                miss = Some((score, m));
            }
        };
        // The study grips at the centre of mass; where the arm cannot pick or place a piece
        // gripped there (a long plate whose middle lies far up the belt), the grip moves
        // towards the leading end, the nearest to the centre that works.
        for (shift, flip, fallback) in grip_shifts(piece, self.cell.tool.gripper.as_ref()) {
            if fallback && best.is_some() {
                break;
            }
            let pick = grip_pose(&body, piece, &along, shift, flip);
            let in_body = body.inverse() * pick;
            for symmetry in box_symmetries() {
                let target = Translation3::from(*aside) * piece.target_cell * symmetry;
                let place = target * in_body;
                let down = -(place.rotation * Vector3::z()).z;
                if down < 0.5 && piece.on_edge {
                    continue;
                }
                let attempt = (|| {
                    // Where the carriage stands (on a track): nearest the current position
                    // for the pick, nearest the pick position for the place.
                    let carriage_pick = self
                        .carriage_for(
                            self.cell.carriage(),
                            &[(pick, grip), (raise(&pick, CLEARANCE), grip)],
                        )
                        .map_err(|f| (Op::Pick, f))?;
                    let carriage_place = self
                        .carriage_for(
                            carriage_pick,
                            &[(place, grip), (raise(&place, CLEARANCE), grip)],
                        )
                        .map_err(|f| (Op::Place, f))?;
                    let at_pick = self.cell_at(carriage_pick);
                    let at_place = self.cell_at(carriage_place);
                    // The pick and place poses themselves first: when one is out of the arm's
                    // range, that (not its approach above) is the miss to report.
                    solve(&at_pick, &pick, &grip, &self.q).map_err(|f| (Op::Pick, f))?;
                    solve(&at_place, &place, &grip, &self.q).map_err(|f| (Op::Place, f))?;
                    // Descents on a branch that exists all the way down.
                    let (q_above_pick, q_pick) = continuous_line(
                        &at_pick,
                        &self.q,
                        &raise(&pick, CLEARANCE),
                        &pick,
                        &grip,
                        LINE_SAMPLES,
                    )
                    .map_err(|f| (Op::Pick, f))?;
                    let (q_above_place, q_place) = continuous_line(
                        &at_place,
                        &q_above_pick,
                        &raise(&place, CLEARANCE),
                        &place,
                        &grip,
                        LINE_SAMPLES,
                    )
                    .map_err(|f| (Op::Place, f))?;
                    // A reachable pose that collides: the closest kind of miss, named by the
                    // pose it is at (a short piece's front gripper may meet the end stop at
                    // the pick).
                    let held_in_tool = grip * in_body.inverse();
                    let half = piece.size.map(|v| v / 2.0);
                    let held = Some((piece.id.as_str(), &held_in_tool, half));
                    // Holding the piece at its target (the jaws closed on it), then letting
                    // it go (the jaws open: a finger may meet a piece placed beside it).
                    let at_target =
                        touch(&self.phys, &at_place, &q_place, held, &[], 0.0).or_else(|| {
                            touch(&self.phys, &at_place, &q_place, None, &[&piece.id], 0.0)
                        });
                    if let Some(t) = at_target {
                        return Err(Miss::colliding(Op::Place, t));
                    }
                    if let Some(t) = touch(&self.phys, &at_pick, &q_pick, None, &[&piece.id], 0.0) {
                        return Err(Miss::colliding(Op::Pick, t));
                    }
                    Ok::<_, Miss>(FramingPlan {
                        pick_body: body,
                        pick_margin: reach_margin(&at_pick, &pick, &grip),
                        place_margin: reach_margin(&at_place, &place, &grip),
                        pick,
                        place,
                        q_above_pick,
                        q_above_place,
                        target,
                        carriage_pick,
                        carriage_place,
                        push: None,
                    })
                })();
                match attempt {
                    Err(m) => note_miss(m),
                    Ok(plan) => {
                        // Joint travel (rad) and carriage travel (m) alike count as travel.
                        let travel = distance(&self.q, &plan.q_above_pick)
                            + distance(&plan.q_above_pick, &plan.q_above_place)
                            + (plan.carriage_pick - self.cell.carriage()).abs()
                            + (plan.carriage_place - plan.carriage_pick).abs();
                        let score = (1.0 - down) * 100.0 + travel;
                        if best.as_ref().is_none_or(|b| score < b.0) {
                            best = Some((score, plan));
                        }
                    }
                }
            }
        }
        match (best, miss) {
            (Some((_, plan)), _) => Ok(plan),
            (None, Some((_, m))) => Err(m),
            (None, None) => Err(Miss::from((Op::Place, IkFailure::InvalidPose))),
        }
    }
}

/// Where along a piece the grip TCP may hold it, nearest the study's grip first: (shift from
/// the piece's middle towards its leading end, m; tool turned end for end; a fallback, tried
/// only while no grip before it planned). Two grippers hold a piece at its centre of mass, or
/// moved towards either end in steps while both stay on it; one barely longer than the spacing
/// falls back on one gripper over its centre of mass. A piece shorter than the spacing is held
/// by one gripper (the TCP half the spacing off the piece's middle, either way): over its
/// centre of mass, or off it in steps while the jaws stay on the piece and the moment of its
/// weight stays within the gripper's rating.
fn grip_shifts(
    piece: &ScenePiece,
    gripper: Option<&crate::cell::Gripper>,
) -> Vec<(f64, bool, bool)> {
    let length = piece.size[0];
    let spacing = gripper.map_or(0.0, |g| g.spacing);
    let one = gripper.and_then(|g| g.one_gripper);
    let mut shifts = Vec::new();
    match one {
        Some(one) if length < spacing => {
            let furthest = ((length - one.min_length) / 2.0)
                .min(one.max_moment / (piece.mass.max(1e-9) * GRAVITY));
            let offsets = (0..)
                .map(|k| k as f64 * GRIP_SHIFT_STEP)
                .take_while(|d| *d <= furthest + 1e-9);
            for d in offsets {
                for side in [spacing / 2.0, -spacing / 2.0] {
                    for along in if d > 0.0 { vec![d, -d] } else { vec![0.0] } {
                        for flip in [false, true] {
                            shifts.push((side + along, flip, d > 0.0));
                        }
                    }
                }
            }
        }
        _ => {
            let furthest = two_gripper_reach(length, spacing);
            for s in two_gripper_shifts(length, spacing) {
                shifts.push((s, false, s > 0.0));
                shifts.push((s, true, false));
            }
            // A piece barely longer than the spacing puts a jaw at its very end, where it may
            // meet the end stop at the pick: one gripper over its centre of mass, where the
            // tool rates it, is the fallback.
            if let Some(one) = one
                && furthest < GRIP_SHIFT_STEP
                && piece.mass <= one.max_mass
            {
                for side in [spacing / 2.0, -spacing / 2.0] {
                    for flip in [false, true] {
                        shifts.push((side, flip, true));
                    }
                }
            }
        }
    }
    shifts
}

/// The grip TCP on a piece lying on conveyor 2: on its top face, `shift` from its middle
/// towards its leading end, z down, y along the piece (reversed when `flip`), x across it (the
/// jaws close along x).
fn grip_pose(
    body: &Isometry3<f64>,
    piece: &ScenePiece,
    along_belt: &Vector3<f64>,
    shift: f64,
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
    let point = body.translation.vector + long * shift + up * (height / 2.0);
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
pub(super) fn box_symmetries() -> [Isometry3<f64>; 4] {
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
