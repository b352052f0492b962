//! What would make a failed place pass, computed and checked: for a place pose the arm cannot
//! take (beyond reach, past a joint limit), the smallest move of the wall along the robot's x
//! (the cell's `offset_x`) and along its y (`centre_y`) at which the place pose and the pose
//! the gripper descends from both solve, and each other shipped robot that, mounted where this
//! one is, takes both; for a pose beyond reach also the reach a robot would need, found as the
//! smallest scale of this arm (every length, joint limits kept) that takes both. Each move and
//! robot is checked as the executor plans a place (`frame::placement::reached_held_at`: exact
//! IK within the joint limits, the arm and tool above the floor, the piece held at its middle
//! or shifted along it as two grippers may hold it); collisions with the cell's fixtures and
//! with placed pieces are not re-run, and the text says so. The executor may also set a piece
//! down with the tool tilted, which the check does not try: a remedy is then sufficient, not
//! always the smallest. For a piece that came to rest off its target because its target lies
//! above what is beneath it, the move of its modelled position onto that surface (from the gap
//! the executor measured at the release), in the model's coordinates; the caller checks it by
//! simulating the wall again with the piece moved (`PieceMove`).

use super::location::{Located, rows};
use super::report::{WhyReport, walk};
use crate::cell::{Cell, Robot, robot_names};
use crate::frame::placement::reached_held_at;
use crate::frame::rows::{
    FramingTarget, FramingTargetWall, PieceSize, Row, SimIkFailed, WallAxes, WallOf, WallOffsetX,
};
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
    /// For a change of a piece's modelled position: the move, which the caller checks by
    /// simulating the wall again.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub piece_move: Option<PieceMove>,
}

/// How an unchecked piece move says so; `checked_by_simulation` replaces it.
const UNCHECKED_MOVE: &str =
    "; not checked: computed from the gap measured beneath it at the release";

impl Remedy {
    /// Marks a piece move checked by a new simulation of its wall in which the piece framed.
    pub fn checked_by_simulation(&mut self) {
        self.checked = true;
        self.text = self.text.replace(
            UNCHECKED_MOVE,
            "; checked by simulating the wall again with the piece moved: framed",
        );
    }
}

/// A piece moved in the model.
#[derive(Clone, Debug, Serialize, PartialEq)]
pub struct PieceMove {
    pub piece: String,
    /// The move in the model's coordinates (m).
    pub by: [f64; 3],
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

/// The remedies of a failed place in `cell`. None when the pose solves as modelled (the
/// failure then lies in what this check does not cover, and `none_found` says so).
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
        out.none_found.push(
            "none searched: the place pose passes the check remedies are verified by (IK, joint limits, floor, tool pointing down), so what refused it lies beyond that check: the executor's collision test of the arm and tool against the floor, the cell's fixtures and placed pieces, or its grip".into(),
        );
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
                piece_move: None,
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
                piece_move: None,
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
                piece_move: None,
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
        out.remedies.push(reach_remedy(cell, needed, reach, |c| {
            held(c, Vector3::zeros())
        }));
    }
    out
}

/// The arm scaled up at most this much (2.0: twice the reach) when looking for the reach a
/// pose beyond reach needs, in SCALE_STEP steps.
const SCALE_LIMIT: f64 = 2.0;
const SCALE_STEP: f64 = 0.01;

/// The reach that takes a pose `needed` m from the shoulder (the arm reaching `reach`): the
/// smallest scale of this arm, from needed / reach up in SCALE_STEP steps, at which `held`
/// takes the place and approach poses (every length of the arm scaled, joint limits kept).
/// Unchecked, with the distance the IK gave, when no scale up to SCALE_LIMIT does.
fn reach_remedy(
    cell: &Cell,
    needed: f64,
    reach: f64,
    held: impl Fn(&Cell) -> Option<f64>,
) -> Remedy {
    let from = (needed / reach / SCALE_STEP).ceil() as i64;
    let to = (SCALE_LIMIT / SCALE_STEP).round() as i64;
    let found = (from.max(1)..=to).find_map(|n| {
        let k = n as f64 * SCALE_STEP;
        let mut scaled = cell.clone();
        scaled.robot = cell.robot.scaled(k);
        held(&scaled).map(|_| k)
    });
    match found {
        Some(k) => {
            let value = mm(reach * k);
            Remedy {
                change: "reach".into(),
                value,
                unit: "m",
                checked: true,
                piece_move: None,
                text: format!(
                    "a robot whose wrist centre reaches {value:.3} m from its shoulder (this one {reach:.3} m; the pose needs {needed:.3} m): this arm scaled ×{k:.2}, mounted where it is, takes the pose; {CHECKED_BY}"
                ),
            }
        }
        None => Remedy {
            change: "reach".into(),
            value: mm(needed),
            unit: "m",
            checked: false,
            piece_move: None,
            text: format!(
                "a robot whose wrist centre reaches {needed:.3} m from its shoulder (this one {reach:.3} m); not checked: this arm scaled up to ×{SCALE_LIMIT:.1} does not take the pose (joint limits, the floor), so another arm's shape is needed"
            ),
        },
    }
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
    let piece = report.element.id.as_str();
    let down = cell_down_in_model(engine, cell, piece)?;
    for cause in report.answer.causes.iter_mut() {
        if let Some(r) = off_target_remedy(&cause.located, piece, down) {
            cause.remedies.push(r);
        }
    }
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

/// The cell's down (−z) in the model's coordinates for the wall of `piece`, as the wall is laid
/// (`framing_target_wall` in the robot frame, `wall_axes` in the model), when both are known.
fn cell_down_in_model(
    engine: &Engine,
    cell: &Cell,
    piece: &str,
) -> Result<Option<Vector3<f64>>, LogicError> {
    let Some(wall) = row_of::<WallOf>(engine, piece, |r| r.p)?.map(|r| r.w) else {
        return Ok(None);
    };
    let (Some(laid), Some(axes)) = (
        row_of::<FramingTargetWall>(engine, wall, |r| r.w)?,
        row_of::<WallAxes>(engine, wall, |r| r.w)?,
    ) else {
        return Ok(None);
    };
    let in_wall = (cell.robot_base * laid.wall_to_robot)
        .rotation
        .inverse_transform_vector(&-Vector3::z());
    Ok(Some(
        axes.u * in_wall.x + axes.v * in_wall.y + axes.n * in_wall.z,
    ))
}

/// The first row of `R` whose key (`key` of the row) is `of`.
fn row_of<R: Row>(
    engine: &Engine,
    of: &str,
    key: impl Fn(&R) -> &str,
) -> Result<Option<R>, LogicError> {
    Ok(rows::<R>(engine)?.into_iter().find(|r| key(r) == of))
}

/// For a piece released above what lies beneath it (more than the executor's release gap):
/// the move of its modelled position that sets its target on that surface, along the cell's
/// down as the wall is laid (`down`, model coordinates). Computed from the gap the executor
/// measured beneath it at the release (a shape cast straight down); unchecked until the caller
/// simulates the wall with the piece moved.
fn off_target_remedy(
    located: &[Located],
    piece: &str,
    down: Option<Vector3<f64>>,
) -> Option<Remedy> {
    let (below, gap) = located.iter().find_map(|l| match l {
        Located::Release { below, gap } if !below.is_empty() => Some((below, *gap)),
        _ => None,
    })?;
    let excess = gap - RELEASE_GAP;
    if excess < OFF_SURFACE {
        return None;
    }
    let by = down.map(|d| d * mm(excess));
    let model_move = by.map_or_else(String::new, |b| {
        format!(
            ", i.e. by ({:.3}, {:.3}, {:.3}) m in the model",
            b.x + 0.0,
            b.y + 0.0,
            b.z + 0.0
        )
    });
    Some(Remedy {
        change: "piece_position".to_string(),
        value: -mm(excess),
        unit: "m",
        checked: false,
        text: format!(
            "model it {:.1} mm nearer the surface beneath it as the wall lies ({below}){model_move}: its framing target lies that far above it, so it drops when released{UNCHECKED_MOVE}",
            excess * 1000.0
        ),
        piece_move: by.map(|b| PieceMove {
            piece: piece.to_string(),
            by: [b.x, b.y, b.z].map(|v| mm(v) + 0.0),
        }),
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
