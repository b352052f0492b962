//! Nailing: drive every nail of the plan whose plate and member were placed.

use super::{WallRun, failure_score};
use crate::cell::IkFailure;
use crate::cell::tcp_poses::{nail_pose, nail_rolls, retreat};
use crate::frame::plan::NailingTarget;
use crate::sim::motion::LinearMove;
use crate::sim::reach::{line, solve, touches};
use crate::sim::record::{NailOutcome, NailRecord, failure_columns};
use nalgebra::{Isometry3, Point3, Translation3, Vector3};

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

/// A nail's firing pose, the pose its straight approach starts from, the joints there and
/// the carriage position.
type ChosenNail = (Isometry3<f64>, Isometry3<f64>, Vec<f64>, f64);

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

impl<'a> WallRun<'a> {
    pub(super) fn nail_all(&mut self, nails: &[NailPlan]) {
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
            let mut chosen: Option<ChosenNail> = None;
            let mut miss: Option<(f64, IkFailure)> = None;
            // The nailer's roll turns its flange towards the base (on a track: the base
            // abeam of the nail).
            let base = match &self.cell.track {
                Some(t) => Point3::from(t.base_at(t.abeam(&point)).translation.vector),
                None => Point3::from(self.cell.robot_base.translation.vector),
            };
            let rolls = nail_rolls(&point, &direction, &base);
            let candidates = rolls.into_iter().flat_map(|roll| {
                // The nose stops just short of the face: pressed against the work, the
                // position-driven tool would shove the loose frame across the floor.
                let pose = retreat(&nail_pose(&point, &direction, roll), NOSE_GAP);
                nail_approaches(pose).map(move |back| (pose, back))
            });
            for (pose, back) in candidates {
                let attempt = self
                    .carriage_for(self.cell.carriage(), &[(back, nail_tcp), (pose, nail_tcp)])
                    .and_then(|s| {
                        let at = self.cell_at(s);
                        let qa = solve(&at, &back, &nail_tcp, &self.q)?;
                        let q_nail = line(&at, &qa, &back, &pose, &nail_tcp, 4)?;
                        let ignore = [nail.plate.as_str(), nail.member.as_str()];
                        match touches(&self.phys, &at, &q_nail, None, &ignore, 0.0)
                            .or_else(|| touches(&self.phys, &at, &qa, None, &ignore, 0.0))
                        {
                            Some((a, b)) => Err(IkFailure::AllSolutionsCollide { pair: [a, b] }),
                            None => Ok((qa, s)),
                        }
                    });
                match attempt {
                    Ok((q_back, s)) => {
                        chosen = Some((pose, back, q_back, s));
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
            let Some((pose, back, q_back, carriage)) = chosen else {
                let failure = miss.map_or(IkFailure::InvalidPose, |m| m.1);
                let (kind, what, value, limit) = failure_columns(&failure);
                self.skip_nail(nail, kind, &what, value, limit, failure.to_string());
                continue;
            };
            let plate = nail.plate.clone();
            let start = self.begin(&plate, "nail", &[nail.member.as_str()]);
            if let Err(failure) = self
                .move_carriage(carriage, &nail_tcp, &[])
                .and_then(|()| self.move_to(&q_back, &nail_tcp, &[], self.nailing_speed()))
            {
                self.end(&plate, "nail", start);
                let (kind, what, value, limit) = failure_columns(&failure);
                self.skip_nail(nail, kind, &what, value, limit, failure.to_string());
                continue;
            }
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
                self.phys.nail(&nail.plate, &nail.member);
                self.wait(self.cell.motion.fire_dwell);
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
