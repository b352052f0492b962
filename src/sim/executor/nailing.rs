//! Nailing: drive every nail of the plan whose plate and member were placed.

use super::as_built::nail_runs_into;
use super::nail_plan::NailPlan;
use super::{WallRun, failure_score, raise};
use crate::cell::Cell;
use crate::cell::IkFailure;
use crate::cell::tcp_poses::{nail_lines, nail_pose, nail_rolls, retreat};
use crate::sim::motion::LinearMove;
use crate::sim::reach::{continuous_line_where, touches};
use crate::sim::record::Op;
use crate::sim::record::{NailOutcome, NailRecord, RobotStep, StepFor, failure_columns};
use crate::world::ScenePiece;
use nalgebra::{Isometry3, Point3, Translation3, Vector3};
use rapier3d::parry::query::{Ray, RayCast};
use rapier3d::parry::shape::Cuboid;
use rapier3d::prelude::Vector;

/// The nailer approaches along the nail line from this far back (m).
pub(super) const NAIL_APPROACH: f64 = 0.10;
/// Where the straight line back along the nail is out of reach (a nail driven towards the
/// robot at the far edge of its reach), the nailer comes down to the nail from this far
/// above it instead (m)...
pub(super) const NAIL_DESCENT: f64 = 0.10;
/// ...its nose this far off the face until the last stretch (m).
pub(super) const NAIL_STANDOFF: f64 = 0.01;
/// Where the nailer fires: its nose this far off the plate's face (m).
pub(super) const NOSE_GAP: f64 = 0.002;

/// A piece this close to the line back out of a nail's entry point covers the nail (m)...
const COVER_CLEARANCE: f64 = 0.01;
/// ...along this much of the line: the nailer's nose and its straight approach (m).
const COVER_DEPTH: f64 = NAIL_APPROACH + 0.05;
/// How far the tool lifts straight up out of a tight spot before it tries the way to the next
/// nail again (m): well clear of lumber on edge on the table.
const LIFT_OUT: f64 = 0.25;

/// How many approach poses of one nail the executor tries to move to before giving up.
const MAX_PATH_TRIES: usize = 3;

/// How a nail is driven, once the arm is at the start of its approach: the firing pose, the
/// pose the straight approach starts from, and the line driven (cell frame) with its lean
/// off the planned one (rad).
struct ChosenNail {
    pose: Isometry3<f64>,
    back: Isometry3<f64>,
    line: Vector3<f64>,
    lean: f64,
}

impl<'a> WallRun<'a> {
    /// Drives `nails` in their order; a nail whose plate or member was not placed is skipped.
    pub(super) fn nail_all(&mut self, nails: &[&NailPlan]) {
        if nails.is_empty() {
            return;
        }
        let nail_tcp = *self.cell.tool.tcp("nail").expect("cells have a nail TCP");
        self.slide_nailer(true);
        for &nail in nails {
            self.record.program.push(RobotStep::Begin(StepFor::Nail {
                plate: nail.plate.clone(),
                member: nail.member.clone(),
                k: nail.k,
            }));
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
            let plate = nail.plate.clone();
            let (
                start,
                ChosenNail {
                    pose,
                    back,
                    line,
                    lean,
                },
            ) = match self.approach_nail(nail, &nail_tcp) {
                Ok(chosen) => chosen,
                Err((start, failure)) => {
                    if let Some(start) = start {
                        self.end(&plate, Op::Nail, start);
                    }
                    let (kind, what, value, limit) = failure_columns(&failure);
                    self.skip_nail(nail, kind, &what, value, limit, failure.to_string());
                    continue;
                }
            };
            let reached = self
                .run_line(
                    &LinearMove::new(
                        back,
                        pose,
                        self.nail_approach_speed(),
                        self.cell.motion.line_accel,
                    ),
                    &nail_tcp,
                )
                .is_ok();
            let fired_at = self.t;
            if reached {
                let plate = self.body(&nail.plate).to_string();
                let member = self.body(&nail.member).to_string();
                if plate != member {
                    self.phys.nail(&plate, &member);
                }
                self.record.program.push(RobotStep::Fire);
                self.dwell(self.cell.motion.fire_dwell);
            }
            let _ = self.run_line(
                &LinearMove::new(
                    pose,
                    back,
                    self.nail_approach_speed(),
                    self.cell.motion.line_accel,
                ),
                &nail_tcp,
            );
            self.end(&plate, Op::Nail, start);
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
                        driven: (self.wall_cell.rotation.inverse() * line).into(),
                        lean,
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
        self.slide_nailer(false);
    }

    /// Runs the nailer out on its slide before a run of nails and back after it, where the
    /// tool has a slide; the slide moves in the gripper's time.
    fn slide_nailer(&mut self, out: bool) {
        if self.cell.tool.nailer_slide <= 0.0 {
            return;
        }
        let seconds = self.cell.motion.grip_dwell;
        self.phys.set_nailer(out);
        self.record
            .program
            .push(RobotStep::NailerSlide { out, seconds });
        self.wait(seconds);
    }

    /// Chooses how to drive `nail` (square first, then leaning; every roll and approach) and
    /// moves the arm to the start of its approach: when the nail operation began (at the
    /// first move towards it), and the chosen pose or the most telling miss.
    fn approach_nail(
        &mut self,
        nail: &NailPlan,
        nail_tcp: &Isometry3<f64>,
    ) -> Result<(f64, ChosenNail), (Option<f64>, IkFailure)> {
        let nail_tcp = *nail_tcp;
        let point = self.wall_cell * Point3::from(Vector3::from(nail.uvw));
        let direction = self.wall_cell.rotation * nail.direction;
        let mut miss: Option<(f64, IkFailure)> = None;
        // When the nail operation began (the first move towards it).
        let mut start: Option<f64> = None;
        let mut path_tries = 0;
        // The nailer's roll turns its flange towards the base (on a track: the base
        // abeam of the nail).
        let base = match &self.cell.track {
            Some(t) => Point3::from(t.base_at(t.abeam(&point)).translation.vector),
            None => Point3::from(self.cell.robot_base.translation.vector),
        };
        // Square first; then leaning as far as the tool allows, each lean only where
        // the nail still runs through the plate into the member as planned.
        let lines: Vec<(Vector3<f64>, f64)> = nail_lines(&direction, self.cell.tool.max_nail_lean)
            .into_iter()
            .filter(|(line, lean)| *lean == 0.0 || self.runs_into_as_planned(nail, &point, line))
            .collect();
        let candidates = lines.iter().flat_map(|&(driven, lean)| {
            nail_rolls(&point, &driven, &base)
                .into_iter()
                .flat_map(move |roll| {
                    // The nose stops just short of the face: pressed against the work, the
                    // position-driven tool would shove the loose frame across the floor.
                    let pose = retreat(&nail_pose(&point, &driven, roll), NOSE_GAP);
                    nail_approaches(pose).map(move |back| (pose, back, driven, lean))
                })
        });
        // On a track the carriage stays where it is while that reaches; where the way from
        // there is blocked, it stands abeam of the nail instead (over the work, the arm
        // reaches down rather than across the frame).
        let abeam = self.cell.track.map(|t| t.abeam(&point));
        let tries =
            candidates.flat_map(|c| std::iter::once((c, None)).chain(abeam.map(|a| (c, Some(a)))));
        let mut blocked = false;
        let mut lifted = false;
        for ((pose, back, driven, lean), from) in tries {
            if from.is_some() && !blocked {
                // The way from where the carriage stands was not tried or not blocked.
                continue;
            }
            let attempt = self
                .carriage_for(
                    from.unwrap_or(self.cell.carriage()),
                    &[(back, nail_tcp), (pose, nail_tcp)],
                )
                .and_then(|s| {
                    let at = self.cell_at(s);
                    self.clear_nail_branch(&at, nail, (&back, &pose), &nail_tcp)
                        .map(|qa| (qa, s))
                });
            blocked = false;
            match attempt {
                Ok((_, s)) if from.is_some() && (s - self.cell.carriage()).abs() < 1e-9 => {
                    // Abeam leads back to where the carriage stands: blocked as before.
                    continue;
                }
                Ok((q_back, s)) => {
                    // Go to the approach pose; where no way leads there, try the next
                    // pose (a few at most: each costs the planner's budget).
                    let begun = *start.get_or_insert_with(|| {
                        self.begin(&nail.plate, Op::Nail, &[nail.member.as_str()])
                    });
                    let mut way = self.move_to_approach(s, &q_back, &nail_tcp);
                    if way.is_err() && !lifted {
                        // Blocked from a tight spot (the nose down among the pieces after
                        // the last nail): once per nail, lift straight out and try again.
                        lifted = true;
                        if self.lift_out(&nail_tcp).is_ok() {
                            way = self.move_to_approach(s, &q_back, &nail_tcp);
                        }
                    }
                    if let Err(f) = way {
                        // Reachable and clear, only the way there is blocked: the most
                        // telling miss.
                        miss = Some((-2.0, f));
                        blocked = true;
                        path_tries += 1;
                        if path_tries == MAX_PATH_TRIES {
                            break;
                        }
                        continue;
                    }
                    return Ok((
                        begun,
                        ChosenNail {
                            pose,
                            back,
                            line: driven,
                            lean,
                        },
                    ));
                }
                Err(f) => {
                    let score = failure_score(&f);
                    if miss.as_ref().is_none_or(|m| score < m.0) {
                        miss = Some((score, f));
                    }
                }
            }
        }
        Err((start, miss.map_or(IkFailure::InvalidPose, |m| m.1)))
    }

    /// The carriage to `s` and the arm to a nail's approach joints `q_back`.
    fn move_to_approach(
        &mut self,
        s: f64,
        q_back: &[f64],
        tcp: &Isometry3<f64>,
    ) -> Result<(), IkFailure> {
        self.move_carriage(s, tcp, &[])?;
        self.move_to(q_back, tcp, &[], self.nailing_speed())
    }

    /// Lifts the tool straight up by LIFT_OUT from where it is, at the nailer's approach speed.
    fn lift_out(&mut self, tcp: &Isometry3<f64>) -> Result<(), IkFailure> {
        let here = self.cell.robot_base * self.cell.robot.fk_tip(&self.q) * tcp;
        self.run_line(
            &LinearMove::new(
                here,
                raise(&here, LIFT_OUT),
                self.nail_approach_speed(),
                self.cell.motion.line_accel,
            ),
            tcp,
        )
    }

    /// The joints at `back` of the first IK solution there (nearest the arm's joints first)
    /// whose straight line to `fire` exists without a jump and touches nothing at either
    /// end: firing, the nose may touch the plate and the member; at `back` nothing may.
    fn clear_nail_branch(
        &self,
        at: &Cell,
        nail: &NailPlan,
        (back, fire): (&Isometry3<f64>, &Isometry3<f64>),
        tcp: &Isometry3<f64>,
    ) -> Result<Vec<f64>, IkFailure> {
        let ignore = [self.body(&nail.plate), self.body(&nail.member)];
        // A solution that got there but collides is the more telling miss.
        let collides = |q_back: &[f64], q_fire: &[f64]| {
            touches(&self.phys, at, q_fire, None, &ignore, 0.0)
                .or_else(|| touches(&self.phys, at, q_back, None, &[], 0.0))
                .map(|(a, b)| IkFailure::AllSolutionsCollide { pair: [a, b] })
        };
        continuous_line_where(at, &self.q, (back, fire), tcp, 4, collides).map(|(q_back, _)| q_back)
    }

    /// Whether the nail's plate and member are both in place.
    pub(super) fn both_placed(&self, nail: &NailPlan) -> bool {
        self.placed.contains_key(&nail.plate) && self.placed.contains_key(&nail.member)
    }

    /// Whether `piece`, once at its framing target, lies over `nail`'s entry point: within
    /// `COVER_CLEARANCE` of the line back out of the face along which the nailer drives it.
    pub(super) fn covers(&self, piece: &ScenePiece, nail: &NailPlan) -> bool {
        let entry = self.wall_cell * Point3::from(Vector3::from(nail.uvw));
        let out = -(self.wall_cell.rotation * nail.direction);
        let to_piece = piece.target_cell.inverse();
        let half = piece.size.map(|s| s / 2.0 + COVER_CLEARANCE);
        segment_meets_box(
            &(to_piece * entry),
            &(to_piece.rotation * out * COVER_DEPTH),
            &half,
        )
    }

    /// Whether a nail entering at `point` along `line` (cell frame) runs through its plate into
    /// its member where both were placed.
    fn runs_into_as_planned(
        &self,
        nail: &NailPlan,
        point: &Point3<f64>,
        line: &Vector3<f64>,
    ) -> bool {
        let piece = |id: &str| Some((self.placed.get(id)?, self.sizes.get(id)?));
        match (piece(&nail.plate), piece(&nail.member)) {
            (Some(plate), Some(member)) => nail_runs_into(point, line, plate, member),
            _ => false,
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
}

/// Where the nailer starts its straight approach to a nail pose, in the order tried: back
/// along the nail line, then (for a nail not driven steeply down or up) straight above the
/// nail, just off the face.
fn nail_approaches(pose: Isometry3<f64>) -> impl Iterator<Item = Isometry3<f64>> {
    let along = retreat(&pose, NAIL_APPROACH);
    let drive = pose.rotation * Vector3::z();
    let from_above = (drive.z.abs() < 0.75f64.sqrt()).then(|| {
        // Straight up (not square to a leaning nail, which would swing the nose over the face).
        let lift = Vector3::z() * NAIL_DESCENT;
        let off = retreat(&pose, NAIL_STANDOFF);
        Isometry3::from_parts(
            Translation3::from(off.translation.vector + lift),
            pose.rotation,
        )
    });
    std::iter::once(along).chain(from_above)
}

/// Whether the segment from `start` along `run` meets the axis-aligned box of half sizes
/// `half` about the origin (parry's ray cast against a solid cuboid, the ray's time 0..1).
fn segment_meets_box(start: &Point3<f64>, run: &Vector3<f64>, half: &[f64; 3]) -> bool {
    let v = |x: f64, y: f64, z: f64| Vector::new(x as f32, y as f32, z as f32);
    let cuboid = Cuboid::new(v(half[0], half[1], half[2]));
    let ray = Ray::new(v(start.x, start.y, start.z), v(run.x, run.y, run.z));
    cuboid.intersects_local_ray(&ray, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_segment_meets_a_box_it_passes_through_and_misses_one_beside_it() {
        let half = [1.0, 0.5, 0.25];
        let up = Vector3::new(0.0, 0.0, 1.0);
        // From below the box straight up through it.
        assert!(segment_meets_box(&Point3::new(0.5, 0.0, -1.0), &up, &half));
        // Ends short of its underside.
        assert!(!segment_meets_box(
            &Point3::new(0.5, 0.0, -1.0),
            &(up * 0.7),
            &half
        ));
        // Runs beside it.
        assert!(!segment_meets_box(
            &Point3::new(1.1, 0.0, -1.0),
            &(up * 3.0),
            &half
        ));
        // Starts on its face, going away: touches at the start.
        assert!(segment_meets_box(&Point3::new(0.0, 0.0, 0.25), &up, &half));
        // Diagonal through a corner region it misses.
        assert!(!segment_meets_box(
            &Point3::new(2.0, 0.0, 0.0),
            &Vector3::new(-0.9, 0.0, 0.9),
            &half
        ));
    }
}
