//! Where a cause happened, with its numbers, from the facts the executor recorded
//! (`rules/sim.dl`): for a pose the arm could not take, where the piece would have been; for
//! two bodies that touched (a contact during an operation, or the collision that ruled out a
//! pose), the deepest point, each body's centre and the depth; for a piece that came to rest
//! off its target, what lay beneath it when the gripper let go and how far below; for a nail,
//! the point it aims at. Points are
//! given in the cell frame (x, y, z) and the wall frame (u along the wall, v up it, w through
//! it), metres.

use super::report::{WhyReport, walk};
use crate::frame::rows::{
    Row, SimContact, SimIkFailed, SimNail, SimPlaced, SimPose, SimReleased, SimTouch,
    SimTouchCentres,
};
use crate::logic::provenance::Explanation;
use crate::logic::{Engine, LogicError};
use serde::Serialize;

/// One place a cause happened.
#[derive(Clone, Debug, Serialize, PartialEq)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Located {
    /// The piece's centre at the pose `op` needed.
    Pose {
        op: String,
        cell: [f64; 3],
        wall: [f64; 3],
    },
    /// Two bodies met: the deepest point, each body's centre (cell frame), the depth (m).
    Touch {
        op: String,
        body_a: String,
        body_b: String,
        depth: f64,
        cell: [f64; 3],
        wall: [f64; 3],
        centre_a: [f64; 3],
        centre_b: [f64; 3],
    },
    /// When released: the first body beneath the piece and the gap down to it (m).
    Release { below: String, gap: f64 },
    /// A nailing target (wall frame).
    Nail {
        plate: String,
        member: String,
        k: i64,
        wall: [f64; 3],
    },
}

impl Located {
    /// One line with the numbers.
    pub fn text(&self) -> String {
        match self {
            Located::Pose { op, cell, wall } => format!(
                "the {op} pose puts its centre at {} m in the cell, {} m in the wall",
                xyz(cell),
                uvw(wall)
            ),
            Located::Touch {
                body_a,
                body_b,
                depth,
                cell,
                wall,
                centre_a,
                centre_b,
                ..
            } => format!(
                "{body_a} (centre {}) into {body_b} (centre {}) {:.1} mm deep at {} m in the cell, {} m in the wall",
                xyz(centre_a),
                xyz(centre_b),
                depth * 1000.0,
                xyz(cell),
                uvw(wall)
            ),
            Located::Nail {
                plate,
                member,
                k,
                wall,
            } => format!(
                "nail {plate} -> {member} #{k} aims at {} m in the wall",
                uvw(wall)
            ),
            Located::Release { below, .. } if below.is_empty() => {
                "released with nothing beneath it within a metre".to_string()
            }
            Located::Release { below, gap } => format!(
                "released {:.1} mm above the first body beneath it ({below}) and dropped onto it",
                gap * 1000.0
            ),
        }
    }
}

fn xyz(p: &[f64; 3]) -> String {
    format!("(x {:.3}, y {:.3}, z {:.3})", p[0], p[1], p[2])
}

fn uvw(p: &[f64; 3]) -> String {
    format!("(u {:.3}, v {:.3}, w {:.3})", p[0], p[1], p[2])
}

/// The rows of `R` in the engine (none when the program does not declare it).
pub(super) fn rows<R: Row>(engine: &Engine) -> Result<Vec<R>, LogicError> {
    if engine.program().relation(R::RELATION).is_none() {
        return Ok(Vec::new());
    }
    Ok(engine
        .relation(R::RELATION)?
        .iter()
        .filter_map(|t| R::read(t))
        .collect())
}

/// The facts of a run where causes happened.
struct Recorded {
    poses: Vec<SimPose>,
    touches: Vec<SimTouch>,
    centres: Vec<SimTouchCentres>,
    releases: Vec<SimReleased>,
}

impl Recorded {
    fn touch(&self, p: &str, op: &str, a: &str, b: &str) -> Option<Located> {
        let t = self
            .touches
            .iter()
            .find(|t| t.p == p && t.op == op && t.body_a == a && t.body_b == b)?;
        let c = self
            .centres
            .iter()
            .find(|c| c.p == p && c.op == op && c.body_a == a && c.body_b == b)?;
        Some(Located::Touch {
            op: op.to_string(),
            body_a: a.to_string(),
            body_b: b.to_string(),
            depth: t.depth,
            cell: [t.x, t.y, t.z],
            wall: [t.u, t.v, t.w],
            centre_a: [c.ax, c.ay, c.az],
            centre_b: [c.bx, c.by, c.bz],
        })
    }

    /// Where each simulation fact of a tree happened, first seen first.
    fn of_tree(&self, e: &Explanation) -> Vec<Located> {
        let mut out: Vec<Located> = Vec::new();
        walk(e, &mut |node| {
            let found: Vec<Located> = if let Some(f) =
                SimIkFailed::read(&node.tuple).filter(|_| node.relation == SimIkFailed::RELATION)
            {
                let pose = self.poses.iter().find(|p| p.p == f.p && p.op == f.op);
                let pose = pose.map(|p| Located::Pose {
                    op: p.op.to_string(),
                    cell: [p.x, p.y, p.z],
                    wall: [p.u, p.v, p.w],
                });
                let pair = f.what.split_once(" / ");
                let touch = pair.and_then(|(a, b)| self.touch(f.p, f.op, a, b));
                pose.into_iter().chain(touch).collect()
            } else if let Some(c) =
                SimContact::read(&node.tuple).filter(|_| node.relation == SimContact::RELATION)
            {
                self.touch(c.p, c.op, c.body_a, c.body_b)
                    .into_iter()
                    .collect()
            } else if let Some(p) =
                SimPlaced::read(&node.tuple).filter(|_| node.relation == SimPlaced::RELATION)
            {
                self.releases
                    .iter()
                    .filter(|r| r.p == p.p)
                    .map(|r| Located::Release {
                        below: r.below.to_string(),
                        gap: r.gap,
                    })
                    .collect()
            } else if let Some(n) =
                SimNail::read(&node.tuple).filter(|_| node.relation == SimNail::RELATION)
            {
                vec![Located::Nail {
                    plate: n.plate.to_string(),
                    member: n.member.to_string(),
                    k: n.k,
                    wall: [n.u, n.v, n.w],
                }]
            } else {
                Vec::new()
            };
            for l in found {
                if !out.contains(&l) {
                    out.push(l);
                }
            }
        });
        out
    }
}

/// Attaches to each cause of `report` where it happened, read from the engine that explained
/// it.
pub fn attach(engine: &Engine, report: &mut WhyReport) -> Result<(), LogicError> {
    let recorded = Recorded {
        poses: rows(engine)?,
        touches: rows(engine)?,
        centres: rows(engine)?,
        releases: rows(engine)?,
    };
    for cause in report.answer.causes.iter_mut() {
        if let Some(verdict) = report.verdicts.get(cause.verdict) {
            cause.located = recorded.of_tree(&verdict.explanation);
        }
    }
    Ok(())
}
