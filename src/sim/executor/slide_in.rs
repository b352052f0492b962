//! Slide-in: jaws that hold a piece by its side faces put a finger between it and a neighbour
//! it is to stand face to face with (a jack against its king stud). Such a piece is let go
//! beside its target, as far out as the open jaws need, and the open jaws' leading finger then
//! pushes it along the surface into face contact, low on its side so that it slides instead
//! of tipping over.

use super::framing::{CLEARANCE, FramingPlan, Miss};
use super::{WallRun, raise};
use crate::cell::{Gripper, IkFailure, Jaws};
use crate::sim::motion::LinearMove;
use crate::sim::physics::FINGER;
use crate::sim::reach::{continuous_line, touch};
use crate::sim::record::Op;
use crate::world::ScenePiece;
use nalgebra::{Isometry3, Matrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3};

/// Room between the open jaws' finger and the neighbour when the piece is let go, and between
/// the pushing finger and the piece before the push (m).
const SLIDE_CLEARANCE: f64 = 0.005;
/// How far the pushing finger leans back from the piece (rad, 3°): only the edge of its tip
/// touches the piece, low on its side. Upright, the finger's whole face (60 mm deep) met the
/// piece and the push could act anywhere up to 65 mm above the table, above the height that
/// tips a piece on edge (half its thickness over the friction coefficient: 19 mm / 0.6, about
/// 32 mm, for a 2x4): pushed pieces leaned, turned and stopped up to 16 mm off their targets.
const PUSH_TILT: f64 = 3.0 * std::f64::consts::PI / 180.0;
/// How far from a placed piece its end abuts a pushed piece is let go (m). Let go flush, the
/// piece's end slides along that piece's side and its leading corner meets that piece's end
/// edge-on with no gap either way: the contact could take the end as a wall across the push,
/// and a door jack pushed along its bottom plate's end pivoted on it and stopped turned 1°,
/// 4-5 mm off. The clearance stays in the as-built error (within the 2 mm tolerance).
const END_CLEARANCE: f64 = 0.001;
/// How far beyond a piece's end face another piece counts as abutting it (m).
const ABUT_PROBE: f64 = 5e-4;
/// The push's speed (m/s): slow, as lumber pushed along a table.
const PUSH_SPEED: f64 = 0.05;
/// Samples checked along each straight move of the push while planning.
const PUSH_SAMPLES: usize = 10;

/// A planned push: grip-TCP poses above its start, at its start (the leading finger just
/// short of the piece's far face), at its end (the piece at its target) and backed off, the
/// joints above the start, and the piece's final target.
pub(super) struct Push {
    pub(super) target: Isometry3<f64>,
    above: Isometry3<f64>,
    start: Isometry3<f64>,
    end: Isometry3<f64>,
    back: Isometry3<f64>,
    q_above: Vec<f64>,
}

impl<'a> WallRun<'a> {
    /// Where the plan's miss is a jaw finger meeting a placed piece at the place pose: the
    /// framing that lets the piece go beside its target (on the side away from that piece)
    /// and pushes it in. Err: the push's miss where a piece let go beside its target could
    /// not be pushed in, else the original miss.
    pub(super) fn plan_slide_in(
        &self,
        piece: &ScenePiece,
        miss: Miss,
    ) -> Result<FramingPlan, Miss> {
        let finger_on_piece = miss.op == Op::Place
            && matches!(&miss.failure, IkFailure::AllSolutionsCollide { pair }
                if pair[0].contains("finger") && pair[1].starts_with("piece "));
        let gripper = self.cell.tool.gripper.as_ref();
        let jaws = gripper.and_then(|g| g.jaws());
        let (true, Some(gripper), Some(jaws), true) =
            (finger_on_piece, gripper, jaws, piece.on_edge)
        else {
            return Err(miss);
        };
        // The jaws close across the piece's z: the finger stands on that side.
        let across = piece.target_cell.rotation * Vector3::z();
        if across.z.abs() > 0.1 {
            return Err(miss);
        }
        let across = Vector3::new(across.x, across.y, 0.0).normalize();
        // The open jaws stand this far out from the piece's faces, their finger plate beyond.
        let gap = FINGER + (jaws.open_width - piece.size[2]) / 2.0 + SLIDE_CLEARANCE;
        let clear_of_end = self.away_from_abutting_end(piece) * END_CLEARANCE;
        let mut push_miss = None;
        for towards in [across, -across] {
            let shift = -towards * gap + clear_of_end;
            let Ok(mut plan) = self.plan_framing(piece, &shift) else {
                continue;
            };
            let target = Translation3::from(-shift) * plan.target;
            match self.plan_push(piece, &plan, target, &towards, gap, (gripper, jaws)) {
                Ok(push) => {
                    plan.push = Some(push);
                    return Ok(plan);
                }
                Err(m) => {
                    push_miss.get_or_insert(m);
                }
            }
        }
        // Where the piece could be let go beside its target but not pushed in, the push's miss
        // says why; otherwise the first.
        Err(push_miss.unwrap_or(miss))
    }

    /// The unit direction along `piece` away from the placed piece one of its ends abuts at
    /// its target (probed just beyond the end face, over its width and thickness); zero
    /// where neither end or both ends abut.
    fn away_from_abutting_end(&self, piece: &ScenePiece) -> Vector3<f64> {
        let target = piece.target_cell;
        let half = piece.size.map(|v| v / 2.0);
        let inside_placed = |p: &Point3<f64>| {
            self.placed.iter().any(|(id, pose)| {
                let Some(size) = self.sizes.get(id) else {
                    return false;
                };
                let local = pose.inverse() * p;
                (0..3).all(|i| local[i].abs() < size[i] / 2.0)
            })
        };
        let abuts = |side: f64| {
            let x = side * (half[0] + ABUT_PROBE);
            [-0.8, 0.0, 0.8].iter().any(|&fy| {
                [-0.8, 0.0, 0.8].iter().any(|&fz| {
                    inside_placed(&(target * Point3::new(x, fy * half[1], fz * half[2])))
                })
            })
        };
        let axis = target.rotation * Vector3::x();
        match (abuts(1.0), abuts(-1.0)) {
            (true, false) => -axis,
            (false, true) => axis,
            _ => Vector3::zeros(),
        }
    }

    /// The push from where `plan` lets the piece go to `target`, `towards` the neighbour:
    /// the tool pointing down, its jaw axis along the push with the nailer (slid back) leading
    /// over the pieces (or, where that fails, trailing), the leading finger's tip just above
    /// the surface. Err: the first miss, where no grip-TCP position along the piece gives
    /// moves the arm reaches clear of everything but the piece.
    fn plan_push(
        &self,
        piece: &ScenePiece,
        plan: &FramingPlan,
        target: Isometry3<f64>,
        towards: &Vector3<f64>,
        gap: f64,
        (gripper, jaws): (&Gripper, &Jaws),
    ) -> Result<Push, Miss> {
        let grip = *self.cell.tool.tcp("grip").expect("cells have a grip TCP");
        let let_go = plan.target;
        let half = piece.size.map(|v| v / 2.0);
        let rotation = let_go.rotation;
        let below: f64 = (0..3)
            .map(|i| (rotation * Vector3::ith(i, 1.0)).z.abs() * half[i])
            .sum();
        let bottom = let_go.translation.z - below;
        let down = -Vector3::z();
        let facing = |x: Vector3<f64>| {
            UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(
                Matrix3::from_columns(&[x, down.cross(&x), down]),
            ))
        };
        let along = rotation * Vector3::x();
        let far_face = let_go.translation.vector - towards * half[2];
        let reach = jaws.open_width / 2.0 + FINGER;
        // Both grippers push a piece as long as their spacing; a shorter one is pushed by one
        // gripper's finger at its middle, so it does not turn.
        let offsets = if piece.size[0] >= gripper.spacing || gripper.count < 2 {
            vec![0.0]
        } else {
            vec![gripper.spacing / 2.0, -gripper.spacing / 2.0]
        };
        // Leaning back lowers the trailing finger (the jaws' opening and two fingers behind
        // the tip edge): its tip stays SLIDE_CLEARANCE above the table, the pushing tip edge
        // that much higher (15 mm for the study's jaws, well below the 32 mm that tips a 2x4).
        let lean = UnitQuaternion::from_axis_angle(
            &nalgebra::Unit::new_normalize(down.cross(towards)),
            PUSH_TILT,
        );
        let tip_height = SLIDE_CLEARANCE + (jaws.open_width + 2.0 * FINGER) * PUSH_TILT.sin();
        let cell = self.cell_at(plan.carriage_place);
        let mut miss = None;
        // The tool's x (the nailer's side) towards the neighbour, then away from it.
        let ways = [facing(*towards), facing(-towards)];
        for (tool, offset) in ways
            .into_iter()
            .flat_map(|tool| offsets.iter().map(move |o| (tool, *o)))
        {
            let mut point = far_face - towards * (SLIDE_CLEARANCE + reach) + along * offset;
            point.z = bottom + jaws.jaw_depth + tip_height;
            let upright = Isometry3::from_parts(Translation3::from(point), tool);
            // Leaning back about the leading finger's tip edge, which stays where it was.
            let tip = point + towards * reach + down * jaws.jaw_depth;
            let start = Translation3::from(tip) * lean * Translation3::from(-tip) * upright;
            let end = Translation3::from(towards * (gap + SLIDE_CLEARANCE)) * start;
            let back = Translation3::from(-towards * SLIDE_CLEARANCE) * end;
            let above = raise(&start, CLEARANCE);
            let lines = (|| {
                let (q_above, q_start) =
                    continuous_line(&cell, &self.q, &above, &start, &grip, PUSH_SAMPLES)?;
                let (_, q_end) =
                    continuous_line(&cell, &q_start, &start, &end, &grip, PUSH_SAMPLES)?;
                let (_, q_back) = continuous_line(&cell, &q_end, &end, &back, &grip, 2)?;
                continuous_line(&cell, &q_back, &back, &raise(&back, CLEARANCE), &grip, 4)?;
                Ok::<_, IkFailure>((q_above, q_start, q_end))
            })();
            let (q_above, q_start, q_end) = match lines {
                Ok(lines) => lines,
                Err(failure) => {
                    miss.get_or_insert(Miss::from((Op::Place, failure)));
                    continue;
                }
            };
            // The piece is not there yet: only what else the tool would meet counts.
            if let Some(t) = [&q_start, &q_end]
                .iter()
                .find_map(|q| touch(&self.phys, &cell, q, None, &[&piece.id], 0.0))
            {
                miss.get_or_insert(Miss::colliding(Op::Place, t));
                continue;
            }
            return Ok(Push {
                target,
                above,
                start,
                end,
                back,
                q_above,
            });
        }
        Err(miss.unwrap_or_else(|| Miss::from((Op::Place, IkFailure::InvalidPose))))
    }

    /// Runs a planned push after the piece was let go beside its target. Whether the piece
    /// was pushed in (a failure on the way is recorded against it).
    pub(super) fn slide_in(&mut self, piece: &ScenePiece, push: &Push) -> bool {
        let grip = *self.cell.tool.tcp("grip").expect("cells have a grip TCP");
        let id = piece.id.as_str();
        let start = self.begin(id, Op::Place, &[]);
        let (speed, accel) = (self.approach_speed(), self.cell.motion.line_accel);
        let lift = raise(&push.back, CLEARANCE);
        let moved = self
            .move_to(&push.q_above, &grip, &[], self.transfer_speed())
            .and_then(|()| {
                self.run_line(
                    &LinearMove::new(push.above, push.start, speed, accel),
                    &grip,
                )
            })
            .and_then(|()| {
                self.run_line(
                    &LinearMove::new(push.start, push.end, PUSH_SPEED.min(speed), accel),
                    &grip,
                )
            })
            .and_then(|()| {
                self.run_line(&LinearMove::new(push.end, push.back, speed, accel), &grip)
            })
            .and_then(|()| self.run_line(&LinearMove::new(push.back, lift, speed, accel), &grip));
        self.end(id, Op::Place, start);
        match moved {
            Ok(()) => true,
            Err(failure) => {
                self.record_line_failure(piece, Op::Place, failure);
                false
            }
        }
    }
}
