//! What would make a failed place pass, computed and checked: for a place pose the arm cannot
//! take (beyond reach, past a joint limit), the smallest move of the wall along the robot's x
//! (the cell's `offset_x`) and along its y (`centre_y`) at which the place pose and the pose
//! the gripper descends from both solve, and each other shipped robot that, mounted where this
//! one is, takes both; for a pose beyond reach also the reach a robot would need. Each move and
//! robot is checked as the executor plans a place (`frame::placement::reached_held_at`: exact
//! IK within the joint limits, the arm and tool above the floor, the piece held at its middle
//! or shifted along it as two grippers may hold it); collisions with the cell's fixtures and
//! with placed pieces are not re-run, and the text says so. The executor may also set a piece
//! down with the tool tilted, which the check does not try: a remedy is then sufficient, not
//! always the smallest. For a piece that came to rest off its target because its target lies
//! above what is beneath it, the move of its modelled position onto that surface (from the gap
//! the executor measured at the release; not re-simulated, and said so).

use super::location::Located;
use super::report::{WhyReport, walk};
use crate::cell::{Cell, Robot, robot_names};
use crate::frame::placement::reached_held_at;
use crate::frame::rows::{FramingTarget, PieceSize, Row, SimIkFailed, WallOffsetX};
use crate::logic::provenance::Explanation;
use crate::logic::{Engine, LogicError};
use crate::sim::RELEASE_GAP;
use nalgebra::{Isometry3, Translation3, Vector3};
use serde::Serialize;

/// How far the wall is moved at most (m), and the step (m); along x it also stays within the
/// offsets the cell lays walls at (`auto_range`).
const SHIFT_LIMIT: f64 = 3.0;
const SHIFT_STEP: f64 = 0.01;

/// A piece released more than this above what lies beneath it (beyond the release gap) is
/// modelled off its support (m).
const OFF_SURFACE: f64 = 0.001;

/// The check a remedy was verified by, as the text says it.
const CHECKED_BY: &str = "checked by IK (place and approach poses, tool pointing down, joint limits, floor; collisions not re-run)";

/// One change that makes the failed pose pass.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct Remedy {
    /// What changes: `offset_x`, `centre_y` (the cell's `[assembly]` keys), `robot` (a shipped
    /// robot by name), `reach` (a robot's reach from its shoulder to its wrist centre).
    pub change: String,
    /// The new value: the key's value (m), the robot's rated reach (m), the reach needed (m).
    pub value: f64,
    pub unit: &'static str,
    /// Whether the change was verified by re-running the check (see `text`).
    pub checked: bool,
    /// The change in words, with how it was checked.
    pub text: String,
}

/// A place pose the arm could not take.
#[derive(Debug, Clone)]
pub struct FailedPlace {
    /// The piece's framing target (robot frame).
    pub target: Isometry3<f64>,
    /// Length, width, thickness (m).
    pub size: [f64; 3],
    /// The wall's offset along the robot's x in the run (m).
    pub offset_x: f64,
    /// For a pose beyond reach: the wrist centre's distance from the shoulder it would need,
    /// and the arm's reach (m).
    pub beyond: Option<(f64, f64)>,
}

/// The remedies, and what was searched without finding one (said so, not left out).
#[derive(Clone, Debug, Default, Serialize, PartialEq)]
pub struct Remedies {
    pub remedies: Vec<Remedy>,
    pub none_found: Vec<String>,
}

/// The remedies of a failed place in `cell`. Nothing when the pose solves as modelled (the
/// failure then lies in what this check does not cover).
pub fn remedies(cell: &Cell, failed: &FailedPlace) -> Remedies {
    let mut out = Remedies::default();
    // The grip shift (m from the piece's middle) at which the moved pose is taken.
    let held = |cell: &Cell, shift: Vector3<f64>| {
        reached_held_at(
            cell,
            &(Translation3::from(shift) * failed.target),
            &failed.size,
        )
    };
    if held(cell, Vector3::zeros()).is_some() {
        return out;
    }
    let grip = |s: f64| match s {
        0.0 => String::new(),
        s => format!(", held {:.2} m off its middle", s.abs()),
    };
    // The wall stays where the cell lays walls: clear of the robot's base, within its reach.
    let [near, far] = cell.assembly.auto_range;
    let within = |d: f64| (near - 1e-9..=far + 1e-9).contains(&(failed.offset_x + d));
    match smallest_shift(|d| within(d).then(|| held(cell, Vector3::x() * d))?) {
        Some((dx, s)) => {
            let value = mm(failed.offset_x + dx);
            out.remedies.push(Remedy {
                change: "offset_x".into(),
                value,
                unit: "m",
                checked: true,
                text: format!(
                    "lay the wall at offset_x = {value:.3} m ({dx:+.3} m along the robot's x, now {:.3} m{}); {CHECKED_BY}",
                    failed.offset_x,
                    grip(s)
                ),
            });
        }
        None => out.none_found.push(format!(
            "no offset_x within the cell's auto_range [{near:.3}, {far:.3}] m"
        )),
    }
    match smallest_shift(|d| held(cell, Vector3::y() * d)) {
        Some((dy, s)) => {
            let now = cell.assembly.centre_y;
            let value = mm(now + dy);
            out.remedies.push(Remedy {
                change: "centre_y".into(),
                value,
                unit: "m",
                checked: true,
                text: format!(
                    "centre the wall at centre_y = {value:.3} m ({dy:+.3} m along the robot's y, now {now:.3} m{}); {CHECKED_BY}",
                    grip(s)
                ),
            });
        }
        None => out
            .none_found
            .push(format!("no centre_y within ±{SHIFT_LIMIT:.1} m of now")),
    }
    for name in robot_names() {
        let Ok(mut robot) = Robot::load(name) else {
            continue;
        };
        if robot.name == cell.robot.name {
            continue;
        }
        robot.set_mount(cell.robot.mount);
        let mut other = cell.clone();
        other.robot = robot;
        if let Some(s) = held(&other, Vector3::zeros()) {
            let rated = other.robot.meta.reach.unwrap_or(f64::NAN);
            out.remedies.push(Remedy {
                change: "robot".into(),
                value: rated,
                unit: "m",
                checked: true,
                text: format!(
                    "the {} ({name}, rated reach {rated:.2} m) mounted where this one is{}; {CHECKED_BY}",
                    other.robot.meta.description.as_deref().unwrap_or(name),
                    grip(s)
                ),
            });
        }
    }
    if !out.remedies.iter().any(|r| r.change == "robot") {
        out.none_found
            .push("no other shipped robot takes it from this base".into());
    }
    if let Some((needed, reach)) = failed.beyond {
        out.remedies.push(Remedy {
            change: "reach".into(),
            value: mm(needed),
            unit: "m",
            checked: false,
            text: format!(
                "a robot whose wrist centre reaches {needed:.3} m from its shoulder (this one {reach:.3} m); not checked: computed from the IK's distance, joint limits and the floor not tried"
            ),
        });
    }
    out
}

/// The smallest move (m, by size, the negative side first on a tie) in SHIFT_STEP steps up to
/// SHIFT_LIMIT at which `held` gives a grip, with that grip.
fn smallest_shift(held: impl Fn(f64) -> Option<f64>) -> Option<(f64, f64)> {
    let steps = (SHIFT_LIMIT / SHIFT_STEP).round() as i64;
    (1..=steps)
        .flat_map(|k| [-k, k])
        .map(|k| k as f64 * SHIFT_STEP)
        .find_map(|d| Some((d, held(d)?)))
}

/// Rounded to whole millimetres.
fn mm(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}

/// Attaches remedies to each framing cause of `report` that rests on a place pose the IK
/// refused (`sim_ik_failed(p, "place", …)`), reading the target, size and wall offset from
/// the engine that explained it.
pub fn attach(engine: &Engine, cell: &Cell, report: &mut WhyReport) -> Result<(), LogicError> {
    // The first row of `R` whose key (`key` of the row) is `of`.
    fn row_of<R: Row>(
        engine: &Engine,
        of: &str,
        key: impl Fn(&R) -> &str,
    ) -> Result<Option<R>, LogicError> {
        if engine.program().relation(R::RELATION).is_none() {
            return Ok(None);
        }
        Ok(engine
            .relation(R::RELATION)?
            .iter()
            .filter_map(|t| R::read(t))
            .find(|r| key(r) == of))
    }
    for cause in report.answer.causes.iter_mut() {
        if let Some(r) = off_target_remedy(&cause.located) {
            cause.remedies.push(r);
        }
    }
    let piece = report.element.id.as_str();
    let (Some(target), Some(size)) = (
        row_of::<FramingTarget>(engine, piece, |r| r.p)?,
        row_of::<PieceSize>(engine, piece, |r| r.p)?,
    ) else {
        return Ok(());
    };
    let wall = report.wall.as_deref().unwrap_or_default();
    let offset_x = row_of::<WallOffsetX>(engine, wall, |r| r.w)?.map_or(f64::NAN, |r| r.x);
    for cause in report.answer.causes.iter_mut() {
        let Some(verdict) = report.verdicts.get(cause.verdict) else {
            continue;
        };
        let Some(failed) = place_failure(&verdict.explanation) else {
            continue;
        };
        let found = remedies(
            cell,
            &FailedPlace {
                target: target.pose,
                size: [size.length, size.width, size.thickness],
                offset_x,
                beyond: (failed.kind == "out_of_reach").then_some((failed.value, failed.limit)),
            },
        );
        cause.remedies = found.remedies;
        cause.no_remedy = found.none_found;
    }
    Ok(())
}

/// For a piece released above what lies beneath it (more than the executor's release gap):
/// the move of its modelled position that sets its target on that surface. Computed from the
/// gap the executor measured beneath it at the release (a shape cast straight down), not
/// checked by a new simulation.
fn off_target_remedy(located: &[Located]) -> Option<Remedy> {
    let (below, gap) = located.iter().find_map(|l| match l {
        Located::Release { below, gap } if !below.is_empty() => Some((below, *gap)),
        _ => None,
    })?;
    let excess = gap - RELEASE_GAP;
    if excess < OFF_SURFACE {
        return None;
    }
    Some(Remedy {
        change: "piece_position".to_string(),
        value: -mm(excess),
        unit: "m",
        checked: false,
        text: format!(
            "model it {:.1} mm nearer the surface beneath it as the wall lies ({below}): its framing target lies that far above it, so it drops when released; not checked: computed from the gap measured beneath it at the release",
            excess * 1000.0
        ),
    })
}

/// The refused place pose a tree rests on, if any.
fn place_failure(e: &Explanation) -> Option<SimIkFailed> {
    let mut found = None;
    walk(e, &mut |node| {
        if found.is_none() && node.relation == SimIkFailed::RELATION {
            found = SimIkFailed::read(&node.tuple).filter(|f| f.op == "place");
        }
    });
    found
}
