//! The `plan` report (DESIGN §8): members with wall and role, walls with
//! frame, assembly order, precedence, nailing and framing targets.

use super::member::{MemberId, MemberShape};
use super::panels::{
    BreakRow, LimitsRow, PanelRow, SiteRow, break_rows, panel_rows, site_rows, text_line,
};
use super::{round_m, round_point};
use crate::frame::plan::Plan;
use crate::ifc::{LengthUnit, Model};
use rustc_hash::FxHashMap;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;

/// Borrows the model's and the plan's text: a 50,000-member report copies no name.
#[derive(Debug, Serialize)]
pub struct PlanReport<'a> {
    pub schema: String,
    pub length_unit: LengthUnit,
    pub members: Vec<PlannedMember<'a>>,
    pub walls: Vec<WallRow<'a>>,
    pub warnings: Vec<String>,
    /// The panel limits walls were split to (absent when the rules derive none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub panel_limits: Option<LimitsRow>,
    /// Walls reasoned and walls read from the cache (absent without a cache).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cache: Option<crate::cache::CacheCounts>,
    /// The roles against a hand-labelled truth file (`plan --truth`; absent otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub role_check: Option<&'a super::role_check::RoleCheck>,
}

/// A piece as the plan sees it: its wall and role; a horizontal member's axis from its
/// smaller-u end.
#[derive(Debug, Serialize)]
pub struct PlannedMember<'a> {
    #[serde(flatten)]
    pub member: MemberId<'a>,
    pub wall_id: Option<&'a str>,
    pub role: Option<&'a str>,
    #[serde(flatten)]
    pub shape: MemberShape,
    pub mass: f64,
}

#[derive(Debug, Serialize)]
pub struct WallRow<'a> {
    pub wall_id: &'a str,
    pub name: &'a str,
    pub group_global_id: Option<&'a str>,
    pub member_ids: &'a [String],
    /// 4×4 row-major; columns u, v, w, origin in world coordinates.
    pub frame_matrix: [[f64; 4]; 4],
    pub length: f64,
    pub height: f64,
    pub thickness: f64,
    pub role_counts: BTreeMap<&'a str, usize>,
    pub assembly_order: &'a [String],
    pub precedence: Vec<PrecedenceRow<'a>>,
    pub nailing_targets: Vec<NailRow<'a>>,
    pub framing_targets: Vec<FramingRow<'a>>,
    /// The wall split into panels the cell builds (one when it fits).
    pub panels: Vec<PanelRow<'a>>,
    pub panel_breaks: Vec<BreakRow<'a>>,
    /// Stretches of lapped plates (cap plates) across the panel joints, fixed on site.
    pub site_pieces: Vec<SiteRow<'a>>,
    /// The text report's line on the panels (split walls only).
    #[serde(skip)]
    pub panels_line: Option<String>,
}

#[derive(Debug, Serialize)]
pub struct PrecedenceRow<'a> {
    pub before: &'a str,
    pub after: &'a str,
    pub reason: &'a str,
}

#[derive(Debug, Serialize)]
pub struct NailRow<'a> {
    pub plate: &'a str,
    pub member: &'a str,
    pub kind: &'a str,
    pub u: f64,
    pub v: f64,
    pub w: f64,
    pub world: [f64; 3],
    pub direction_world: [f64; 3],
}

#[derive(Debug, Serialize)]
pub struct FramingRow<'a> {
    pub member: &'a str,
    /// Centre of mass in the robot base frame, metres.
    pub position: [f64; 3],
    /// Orientation in the robot base frame, quaternion w, x, y, z.
    pub orientation: [f64; 4],
}

fn unit(x: f64) -> f64 {
    let r = (x * 1e12).round() / 1e12;
    if r == 0.0 { 0.0 } else { r }
}

/// What the plan says of each piece of the model, by its index: wall, role, mass.
struct PieceLookup<'a> {
    wall_of: Vec<Option<&'a str>>,
    role: Vec<Option<&'a str>>,
    mass: Vec<f64>,
}

impl<'a> PieceLookup<'a> {
    /// One pass over each of the plan's maps (sorted by piece id, so looking every piece up
    /// in them would compare long ids over and over).
    fn new(model: &Model, plan: &'a Plan) -> Self {
        let index = model.piece_positions();
        let n = model.pieces().len();
        let by_piece = |map: &'a BTreeMap<String, String>| {
            let mut out = vec![None; n];
            for (id, value) in map {
                if let Some(&i) = index.get(id.as_str()) {
                    out[i] = Some(value.as_str());
                }
            }
            out
        };
        let mut mass = vec![0.0; n];
        for (id, kg) in &plan.masses {
            if let Some(&i) = index.get(id.as_str()) {
                mass[i] = *kg;
            }
        }
        PieceLookup {
            wall_of: by_piece(&plan.wall_of),
            role: by_piece(&plan.roles),
            mass,
        }
    }
}

impl<'a> PlanReport<'a> {
    pub fn new(model: &'a Model, plan: &'a Plan) -> PlanReport<'a> {
        use rayon::prelude::*;
        // World → wall coordinates, once per wall.
        let to_wall: FxHashMap<&str, nalgebra::Isometry3<f64>> = plan
            .walls
            .iter()
            .map(|w| (w.id.as_str(), w.frame.inverse()))
            .collect();
        let lookup = PieceLookup::new(model, plan);
        let members = model
            .pieces()
            .par_iter()
            .enumerate()
            .map(|(i, p)| {
                let wall_id = lookup.wall_of[i];
                let (mut start, mut end) = p.axis();
                // Horizontal members of a wall run from their smaller-u end.
                if let Some(to_wall) = wall_id.and_then(|w| to_wall.get(w)) {
                    let d = end - start;
                    if d.z.abs() <= d.xy().norm() && (to_wall * start).x > (to_wall * end).x {
                        std::mem::swap(&mut start, &mut end);
                    }
                }
                PlannedMember {
                    member: MemberId::of(p),
                    wall_id,
                    role: lookup.role[i],
                    shape: MemberShape::of(p, &start, &end),
                    mass: (lookup.mass[i] * 1e6).round() / 1e6,
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
                    let role = plan.roles.get(p).map_or("unclassified", String::as_str);
                    *role_counts.entry(role).or_insert(0) += 1;
                }
                WallRow {
                    wall_id: &w.id,
                    name: &w.name,
                    group_global_id: w.group_global_id.as_deref(),
                    member_ids: &w.members,
                    frame_matrix,
                    length: round_m(w.length),
                    height: round_m(w.height),
                    thickness: round_m(w.thickness),
                    role_counts,
                    assembly_order: &w.assembly_order,
                    precedence: w
                        .precedence
                        .iter()
                        .map(|(b, a, r)| PrecedenceRow {
                            before: b,
                            after: a,
                            reason: r,
                        })
                        .collect(),
                    nailing_targets: w
                        .nailing_targets
                        .iter()
                        .map(|n| NailRow {
                            plate: &n.plate,
                            member: &n.member,
                            kind: &n.kind,
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
                                member: p,
                                position: round_point(&nalgebra::Point3::from(
                                    pose.translation.vector,
                                )),
                                orientation: [unit(q.w), unit(q.i), unit(q.j), unit(q.k)],
                            }
                        })
                        .collect(),
                    panels: panel_rows(&w.panels),
                    panel_breaks: break_rows(&w.panels),
                    site_pieces: site_rows(&w.panels),
                    panels_line: text_line(&w.panels),
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
            panel_limits: plan.panel_limits.as_ref().map(LimitsRow::new),
            cache: None,
            role_check: None,
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
            panel_limits: self.panel_limits,
            cache: self.cache,
            role_check: self.role_check,
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
            if let Some(line) = w.panels_line.as_deref() {
                let _ = writeln!(out, "{line}");
            }
        }
        for warning in &self.warnings {
            let _ = writeln!(out, "warning: {warning}");
        }
        if let Some(check) = self.role_check {
            out.push_str(&check.to_text());
        }
        out
    }
}
