//! The `plan` report (DESIGN §8): members with wall and role, walls with
//! frame, assembly order, precedence, nailing and framing targets.

use super::{round_m, round_point};
use crate::frame::plan::Plan;
use crate::ifc::{LengthUnit, Model};
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;

#[derive(Debug, Serialize)]
pub struct PlanReport {
    pub schema: String,
    pub length_unit: LengthUnit,
    pub members: Vec<MemberRow>,
    pub walls: Vec<WallRow>,
    pub warnings: Vec<String>,
    /// Walls reasoned and walls read from the cache (absent without a cache).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cache: Option<crate::cache::CacheCounts>,
}

#[derive(Debug, Serialize)]
pub struct MemberRow {
    pub id: String,
    pub entity: u64,
    pub global_id: String,
    pub piece: Option<usize>,
    pub name: Option<String>,
    pub ifc_type: String,
    pub wall_id: Option<String>,
    pub role: Option<String>,
    pub axis_start: [f64; 3],
    pub axis_end: [f64; 3],
    pub width: f64,
    pub thickness: f64,
    pub length: f64,
    pub mass: f64,
}

#[derive(Debug, Serialize)]
pub struct WallRow {
    pub wall_id: String,
    pub name: String,
    pub group_global_id: Option<String>,
    pub member_ids: Vec<String>,
    /// 4×4 row-major; columns u, v, w, origin in world coordinates.
    pub frame_matrix: [[f64; 4]; 4],
    pub length: f64,
    pub height: f64,
    pub thickness: f64,
    pub role_counts: BTreeMap<String, usize>,
    pub assembly_order: Vec<String>,
    pub precedence: Vec<PrecedenceRow>,
    pub nailing_targets: Vec<NailRow>,
    pub framing_targets: Vec<FramingRow>,
}

#[derive(Debug, Serialize)]
pub struct PrecedenceRow {
    pub before: String,
    pub after: String,
    pub reason: String,
}

#[derive(Debug, Serialize)]
pub struct NailRow {
    pub plate: String,
    pub member: String,
    pub kind: String,
    pub u: f64,
    pub v: f64,
    pub w: f64,
    pub world: [f64; 3],
    pub direction_world: [f64; 3],
}

#[derive(Debug, Serialize)]
pub struct FramingRow {
    pub member: String,
    /// Centre of mass in the robot base frame, metres.
    pub position: [f64; 3],
    /// Orientation in the robot base frame, quaternion w, x, y, z.
    pub orientation: [f64; 4],
}

fn unit(x: f64) -> f64 {
    let r = (x * 1e12).round() / 1e12;
    if r == 0.0 { 0.0 } else { r }
}

impl PlanReport {
    pub fn new(model: &Model, plan: &Plan) -> PlanReport {
        use rayon::prelude::*;
        let frames: BTreeMap<&str, &nalgebra::Isometry3<f64>> = plan
            .walls
            .iter()
            .map(|w| (w.id.as_str(), &w.frame))
            .collect();
        let members = model
            .pieces()
            .par_iter()
            .map(|p| {
                let wall_id = plan.wall_of.get(&p.id).cloned();
                let (mut start, mut end) = p.axis();
                // Horizontal members of a wall run from their smaller-u end.
                if let Some(frame) = wall_id.as_deref().and_then(|w| frames.get(w)) {
                    let d = end - start;
                    if d.z.abs() <= d.xy().norm()
                        && (frame.inverse() * start).x > (frame.inverse() * end).x
                    {
                        std::mem::swap(&mut start, &mut end);
                    }
                }
                MemberRow {
                    id: p.id.clone(),
                    entity: p.entity,
                    global_id: p.global_id.clone(),
                    piece: p.piece,
                    name: p.name.clone(),
                    ifc_type: p.ifc_type.clone(),
                    role: plan.roles.get(&p.id).cloned(),
                    wall_id,
                    axis_start: round_point(&start),
                    axis_end: round_point(&end),
                    width: round_m(p.obox.width()),
                    thickness: round_m(p.obox.thickness()),
                    length: round_m(p.obox.length()),
                    mass: (plan.masses.get(&p.id).copied().unwrap_or(0.0) * 1e6).round() / 1e6,
                }
            })
            .collect();
        let walls = plan
            .walls
            .par_iter()
            .map(|w| {
                let m = w.frame.to_homogeneous();
                let frame_matrix = [0, 1, 2, 3].map(|i| {
                    [0, 1, 2, 3].map(|j| {
                        if j == 3 {
                            round_m(m[(i, j)])
                        } else {
                            unit(m[(i, j)])
                        }
                    })
                });
                let mut role_counts = BTreeMap::new();
                for p in &w.members {
                    *role_counts
                        .entry(
                            plan.roles
                                .get(p)
                                .cloned()
                                .unwrap_or_else(|| "unclassified".into()),
                        )
                        .or_insert(0) += 1;
                }
                WallRow {
                    wall_id: w.id.clone(),
                    name: w.name.clone(),
                    group_global_id: w.group_global_id.clone(),
                    member_ids: w.members.clone(),
                    frame_matrix,
                    length: round_m(w.length),
                    height: round_m(w.height),
                    thickness: round_m(w.thickness),
                    role_counts,
                    assembly_order: w.assembly_order.clone(),
                    precedence: w
                        .precedence
                        .iter()
                        .map(|(b, a, r)| PrecedenceRow {
                            before: b.clone(),
                            after: a.clone(),
                            reason: r.clone(),
                        })
                        .collect(),
                    nailing_targets: w
                        .nailing_targets
                        .iter()
                        .map(|n| NailRow {
                            plate: n.plate.clone(),
                            member: n.member.clone(),
                            kind: n.kind.clone(),
                            u: round_m(n.u),
                            v: round_m(n.v),
                            w: round_m(n.w),
                            world: round_point(&n.world),
                            direction_world: [
                                unit(n.direction.x),
                                unit(n.direction.y),
                                unit(n.direction.z),
                            ],
                        })
                        .collect(),
                    framing_targets: w
                        .framing_targets
                        .iter()
                        .map(|(p, pose)| {
                            let q = pose.rotation.quaternion();
                            FramingRow {
                                member: p.clone(),
                                position: round_point(&nalgebra::Point3::from(
                                    pose.translation.vector,
                                )),
                                orientation: [unit(q.w), unit(q.i), unit(q.j), unit(q.k)],
                            }
                        })
                        .collect(),
                }
            })
            .collect();
        let mut warnings: Vec<String> = model.warnings.iter().map(|w| w.message.clone()).collect();
        warnings.extend(plan.warnings.iter().cloned());
        PlanReport {
            schema: model.schema.name().into(),
            length_unit: model.length_unit.clone(),
            members,
            walls,
            warnings,
            cache: None,
        }
    }

    pub fn write_json(&self, out: &mut impl std::io::Write) -> std::io::Result<()> {
        use super::pretty_json::{Array, write_pretty};
        // The members and walls are rendered in parallel into the rest of the report.
        let skeleton = PlanReport {
            schema: self.schema.clone(),
            length_unit: self.length_unit.clone(),
            members: Vec::new(),
            walls: Vec::new(),
            warnings: self.warnings.clone(),
            cache: self.cache,
        };
        let members = Array {
            key: "members",
            items: &self.members,
        };
        let walls = Array {
            key: "walls",
            items: &self.walls,
        };
        write_pretty(out, &skeleton, (members, walls))
    }

    /// One line per wall: name, size, counts by role; then warnings.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        let in_walls = self.members.iter().filter(|m| m.wall_id.is_some()).count();
        let _ = writeln!(
            out,
            "{} walls, {} of {} pieces in walls",
            self.walls.len(),
            in_walls,
            self.members.len()
        );
        for w in &self.walls {
            let roles: Vec<String> = w
                .role_counts
                .iter()
                .map(|(r, n)| format!("{n} {r}"))
                .collect();
            let _ = writeln!(
                out,
                "{:<24} {:>6.3} x {:>5.3} x {:.3} m  {:>3} pieces  {:>3} nails  {}",
                format!("{} ({})", w.name, w.wall_id),
                w.length,
                w.height,
                w.thickness,
                w.member_ids.len(),
                w.nailing_targets.len(),
                roles.join(", ")
            );
        }
        for warning in &self.warnings {
            let _ = writeln!(out, "warning: {warning}");
        }
        out
    }
}
