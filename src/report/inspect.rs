//! The `inspect` report: what the reader found in a model.

use super::member::{MemberId, MemberShape};
use crate::ifc::{LengthUnit, Model, Warning};
use serde::Serialize;
use std::collections::BTreeMap;
use std::fmt::Write;

/// Borrows its text from the model, so a large report costs no second copy.
#[derive(Debug, Serialize)]
pub struct InspectReport<'m> {
    pub schema: &'static str,
    pub schema_identifier: &'m str,
    pub length_unit: &'m LengthUnit,
    pub originating_system: &'m str,
    pub entity_count: usize,
    pub members: Vec<ReadMember<'m>>,
    pub warnings: &'m [Warning],
}

/// A piece as the reader found it.
#[derive(Debug, Serialize)]
pub struct ReadMember<'m> {
    #[serde(flatten)]
    pub member: MemberId<'m>,
    pub predefined_type: Option<&'m str>,
    pub parent_global_id: Option<&'m str>,
    pub material: Option<&'m str>,
    #[serde(flatten)]
    pub shape: MemberShape,
    pub volume: f64,
}

impl<'m> InspectReport<'m> {
    pub fn new(model: &'m Model) -> Self {
        let members = model
            .pieces()
            .iter()
            .map(|p| {
                let (start, end) = p.axis();
                ReadMember {
                    member: MemberId::of(p),
                    predefined_type: p.predefined_type.as_deref(),
                    parent_global_id: p
                        .parent
                        .and_then(|id| model.groups.get(&id))
                        .map(|g| g.global_id.as_str()),
                    material: p.material.as_deref(),
                    shape: MemberShape::of(p, &start, &end),
                    volume: (p.obox.volume() * 1e12).round() / 1e12,
                }
            })
            .collect();
        InspectReport {
            schema: model.schema.name(),
            schema_identifier: &model.schema_identifier,
            length_unit: &model.length_unit,
            originating_system: &model.header().originating_system,
            entity_count: model.entity_count(),
            members,
            warnings: &model.warnings,
        }
    }

    /// Streams pretty JSON (no second copy of a large report in memory).
    pub fn write_json(&self, out: &mut impl std::io::Write) -> std::io::Result<()> {
        serde_json::to_writer_pretty(&mut *out, self)?;
        out.write_all(b"\n")
    }

    /// A short summary for a terminal.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        let _ = writeln!(
            out,
            "schema       {} ({})",
            self.schema, self.schema_identifier
        );
        let _ = writeln!(
            out,
            "length unit  {} ({} m)",
            self.length_unit.name, self.length_unit.metres_per_unit
        );
        let _ = writeln!(
            out,
            "written by   {}",
            if self.originating_system.is_empty() {
                "-"
            } else {
                &self.originating_system
            }
        );
        let _ = writeln!(out, "entities     {}", self.entity_count);
        let mut by_type: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
        let mut products = std::collections::BTreeSet::new();
        for m in &self.members {
            let slot = by_type.entry(m.member.ifc_type).or_default();
            slot.1 += 1;
            if products.insert(m.member.entity) {
                slot.0 += 1;
            }
        }
        let _ = writeln!(
            out,
            "pieces       {} in {} products",
            self.members.len(),
            products.len()
        );
        for (ifc_type, (count, pieces)) in &by_type {
            let _ = writeln!(
                out,
                "  {ifc_type:<28} {count:>6} products {pieces:>7} pieces"
            );
        }
        if self.warnings.is_empty() {
            let _ = writeln!(out, "warnings     none");
        } else {
            let _ = writeln!(out, "warnings     {}", self.warnings.len());
            for w in self.warnings.iter().take(20) {
                let _ = writeln!(out, "  - {}", w.message);
            }
            if self.warnings.len() > 20 {
                let _ = writeln!(
                    out,
                    "  … and {} more (see --json)",
                    self.warnings.len() - 20
                );
            }
        }
        out
    }
}
