//! What changed between two versions of a model: walls and elements added, removed, moved
//! or resized (matched by GlobalId, geometry compared within 0.1 mm), role and assembly-order
//! changes, and verdict changes when both simulations are at hand.

use crate::frame::plan::{Plan, Wall};
use crate::geom::OrientedBox;
use crate::ifc::{Model, Piece};
use crate::report::simulate::SimReport;
use serde::Serialize;
use std::collections::BTreeMap;

/// Geometry closer than this is the same, m.
pub const TOLERANCE: f64 = 1e-4;

/// One model version: its pieces, its plan and, when available, its simulation report.
pub struct Version<'a> {
    pub name: &'a str,
    pub model: &'a Model,
    pub plan: &'a Plan,
    pub report: Option<&'a SimReport>,
}

#[derive(Debug, Default, Serialize)]
pub struct ModelDiff {
    pub schema: &'static str,
    pub old: String,
    pub new: String,
    pub walls: Vec<WallChange>,
    pub elements: Vec<ElementChange>,
    pub roles: Vec<RoleChange>,
    pub assembly_order: Vec<OrderChange>,
    /// Verdict changes; None when either simulation is not in the cache.
    pub verdicts: Option<Vec<VerdictChange>>,
}

#[derive(Debug, Serialize)]
pub struct WallChange {
    /// The wall's name in the new model (the old one's when removed).
    pub wall: String,
    /// added | removed | changed
    pub change: &'static str,
    /// For changed walls: what changed (moved, resized, members).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub what: Vec<String>,
}

#[derive(Debug, Serialize)]
pub struct ElementChange {
    pub id: String,
    pub name: String,
    /// added | removed | moved | resized | moved and resized
    pub change: &'static str,
    /// How far the piece's farthest end moved, mm (moved pieces).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub moved_mm: Option<f64>,
    /// Old and new length, width, thickness, mm (resized pieces).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sizes_mm: Option<[[f64; 3]; 2]>,
}

#[derive(Debug, Serialize)]
pub struct RoleChange {
    pub id: String,
    pub old: String,
    pub new: String,
}

#[derive(Debug, Serialize)]
pub struct OrderChange {
    pub id: String,
    pub wall: String,
    /// Positions in the wall's assembly order (0 = first).
    pub old: usize,
    pub new: usize,
}

#[derive(Debug, Serialize)]
pub struct VerdictChange {
    /// A wall name, or an element id.
    pub subject: String,
    /// feeding | framing | nailing
    pub stage: &'static str,
    pub old: String,
    pub new: String,
}

fn r3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

/// The ends of the box along each axis, as unordered pairs (a box's axis signs are arbitrary).
fn ends(b: &OrientedBox) -> [[nalgebra::Vector3<f64>; 2]; 3] {
    let c = b.centre.coords;
    std::array::from_fn(|i| [c + b.axes[i] * b.half[i], c - b.axes[i] * b.half[i]])
}

/// How far the box moved: the largest displacement of an axis end, m.
fn displacement(old: &OrientedBox, new: &OrientedBox) -> f64 {
    let (a, b) = (ends(old), ends(new));
    (0..3)
        .map(|i| {
            let straight = (a[i][0] - b[i][0]).norm().max((a[i][1] - b[i][1]).norm());
            let swapped = (a[i][0] - b[i][1]).norm().max((a[i][1] - b[i][0]).norm());
            straight.min(swapped)
        })
        .fold((old.centre - new.centre).norm(), f64::max)
}

fn size_mm(b: &OrientedBox) -> [f64; 3] {
    b.half.map(|h| r3(2000.0 * h))
}

fn piece_name(p: &Piece) -> String {
    p.name.clone().unwrap_or_else(|| p.ifc_type.clone())
}

/// A wall's identity across versions: a panel of a split wall by its panel id (its whole wall's
/// identity and its number along the wall), else the IFC group that is the wall, else its key
/// piece.
fn wall_identity(w: &Wall) -> &str {
    match &w.panel {
        Some(p) if p.index > 0 => &p.panel_id,
        _ => w.group_global_id.as_deref().unwrap_or(&w.key),
    }
}

pub fn diff(old: &Version, new: &Version) -> ModelDiff {
    let mut d = ModelDiff {
        schema: "framewright.diff/1",
        old: old.name.to_string(),
        new: new.name.to_string(),
        ..ModelDiff::default()
    };
    diff_walls(old.plan, new.plan, &mut d);
    diff_elements(old.model, new.model, &mut d);
    for (id, role) in &new.plan.roles {
        if let Some(before) = old.plan.roles.get(id)
            && before != role
        {
            d.roles.push(RoleChange {
                id: id.clone(),
                old: before.clone(),
                new: role.clone(),
            });
        }
    }
    diff_order(old.plan, new.plan, &mut d);
    if let (Some(a), Some(b)) = (old.report, new.report) {
        d.verdicts = Some(diff_verdicts(a, b));
    }
    d
}

fn diff_walls(old: &Plan, new: &Plan, d: &mut ModelDiff) {
    let before: BTreeMap<&str, &Wall> = old.walls.iter().map(|w| (wall_identity(w), w)).collect();
    let after: BTreeMap<&str, &Wall> = new.walls.iter().map(|w| (wall_identity(w), w)).collect();
    for w in &new.walls {
        let Some(o) = before.get(wall_identity(w)) else {
            d.walls.push(WallChange {
                wall: w.name.clone(),
                change: "added",
                what: Vec::new(),
            });
            continue;
        };
        let mut what = Vec::new();
        let moved = (o.frame.translation.vector - w.frame.translation.vector).norm();
        let turned = (o.frame.rotation.inverse() * w.frame.rotation).angle();
        if moved > TOLERANCE || turned * w.length.max(o.length) > TOLERANCE {
            what.push(format!("moved {:.1} mm", moved * 1000.0));
        }
        let sizes = [
            (o.length, w.length),
            (o.height, w.height),
            (o.thickness, w.thickness),
        ];
        if sizes.iter().any(|(a, b)| (a - b).abs() > TOLERANCE) {
            what.push(format!(
                "resized {:.0} x {:.0} mm -> {:.0} x {:.0} mm",
                o.length * 1000.0,
                o.height * 1000.0,
                w.length * 1000.0,
                w.height * 1000.0
            ));
        }
        let added = w.members.iter().filter(|m| !o.members.contains(m)).count();
        let removed = o.members.iter().filter(|m| !w.members.contains(m)).count();
        if added + removed > 0 {
            what.push(format!("members +{added} -{removed}"));
        }
        if !what.is_empty() {
            d.walls.push(WallChange {
                wall: w.name.clone(),
                change: "changed",
                what,
            });
        }
    }
    for w in &old.walls {
        if !after.contains_key(wall_identity(w)) {
            d.walls.push(WallChange {
                wall: w.name.clone(),
                change: "removed",
                what: Vec::new(),
            });
        }
    }
}

fn diff_elements(old: &Model, new: &Model, d: &mut ModelDiff) {
    let before: BTreeMap<&str, &Piece> = old.pieces.iter().map(|p| (p.id.as_str(), p)).collect();
    let after: BTreeMap<&str, &Piece> = new.pieces.iter().map(|p| (p.id.as_str(), p)).collect();
    for (id, p) in &after {
        let Some(o) = before.get(id) else {
            d.elements.push(ElementChange {
                id: id.to_string(),
                name: piece_name(p),
                change: "added",
                moved_mm: None,
                sizes_mm: None,
            });
            continue;
        };
        let resized = (0..3).any(|i| (o.obox.half[i] - p.obox.half[i]).abs() * 2.0 > TOLERANCE);
        // A resized piece's ends move too; the centre says whether it also moved.
        let moved_by = if resized {
            (o.obox.centre - p.obox.centre).norm()
        } else {
            displacement(&o.obox, &p.obox)
        };
        let moved = moved_by > TOLERANCE;
        let change = match (moved, resized) {
            (false, false) => continue,
            (true, false) => "moved",
            (false, true) => "resized",
            (true, true) => "moved and resized",
        };
        d.elements.push(ElementChange {
            id: id.to_string(),
            name: piece_name(p),
            change,
            moved_mm: moved.then(|| r3(moved_by * 1000.0)),
            sizes_mm: resized.then(|| [size_mm(&o.obox), size_mm(&p.obox)]),
        });
    }
    for (id, p) in &before {
        if !after.contains_key(id) {
            d.elements.push(ElementChange {
                id: id.to_string(),
                name: piece_name(p),
                change: "removed",
                moved_mm: None,
                sizes_mm: None,
            });
        }
    }
}

fn diff_order(old: &Plan, new: &Plan, d: &mut ModelDiff) {
    let rank = |plan: &Plan| -> BTreeMap<String, (usize, String)> {
        plan.walls
            .iter()
            .flat_map(|w| {
                w.assembly_order
                    .iter()
                    .enumerate()
                    .map(|(i, id)| (id.clone(), (i, w.name.clone())))
            })
            .collect()
    };
    let (before, after) = (rank(old), rank(new));
    for (id, (new_rank, wall)) in &after {
        if let Some((old_rank, _)) = before.get(id)
            && old_rank != new_rank
        {
            d.assembly_order.push(OrderChange {
                id: id.clone(),
                wall: wall.clone(),
                old: *old_rank,
                new: *new_rank,
            });
        }
    }
}

fn diff_verdicts(old: &SimReport, new: &SimReport) -> Vec<VerdictChange> {
    let mut changes = Vec::new();
    let mut push = |subject: &str, stage, a: &str, b: &str| {
        if a != b {
            changes.push(VerdictChange {
                subject: subject.to_string(),
                stage,
                old: a.to_string(),
                new: b.to_string(),
            });
        }
    };
    for w in &new.walls {
        if let Some(o) = old.walls.iter().find(|o| o.name == w.name) {
            push(&w.name, "feeding", &o.material_feeding, &w.material_feeding);
            push(&w.name, "framing", &o.framing.status, &w.framing.status);
            push(&w.name, "nailing", &o.nailing.status, &w.nailing.status);
        }
    }
    for e in &new.elements {
        if let Some(o) = old.elements.iter().find(|o| o.id == e.id) {
            push(&e.id, "framing", &o.framing.status, &e.framing.status);
            push(&e.id, "nailing", &o.nailing.status, &e.nailing.status);
        }
    }
    changes
}

impl ModelDiff {
    pub fn is_empty(&self) -> bool {
        self.walls.is_empty()
            && self.elements.is_empty()
            && self.roles.is_empty()
            && self.assembly_order.is_empty()
            && self.verdicts.as_ref().is_none_or(Vec::is_empty)
    }

    /// One line per change.
    pub fn to_text(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let _ = writeln!(s, "{} -> {}", self.old, self.new);
        for w in &self.walls {
            let _ = writeln!(s, "wall {}: {} {}", w.wall, w.change, w.what.join(", "));
        }
        for e in &self.elements {
            let mut line = format!("element {} ({}): {}", e.id, e.name, e.change);
            if let Some(mm) = e.moved_mm {
                let _ = write!(line, " {mm:.1} mm");
            }
            if let Some([a, b]) = e.sizes_mm {
                let _ = write!(
                    line,
                    " {:.1} x {:.1} x {:.1} mm -> {:.1} x {:.1} x {:.1} mm",
                    a[0], a[1], a[2], b[0], b[1], b[2]
                );
            }
            let _ = writeln!(s, "{}", line.trim_end());
        }
        for r in &self.roles {
            let _ = writeln!(s, "role {}: {} -> {}", r.id, r.old, r.new);
        }
        for o in &self.assembly_order {
            let _ = writeln!(
                s,
                "assembly order {} in {}: {} -> {}",
                o.id, o.wall, o.old, o.new
            );
        }
        match &self.verdicts {
            Some(v) => {
                for c in v {
                    let _ = writeln!(
                        s,
                        "verdict {} {}: {} -> {}",
                        c.subject, c.stage, c.old, c.new
                    );
                }
            }
            None => {
                let _ = writeln!(
                    s,
                    "verdicts: not compared (simulate both models with the same cache and cell first)"
                );
            }
        }
        if self.is_empty() {
            let _ = writeln!(s, "no changes");
        }
        s.trim_end().to_string() + "\n"
    }
}
