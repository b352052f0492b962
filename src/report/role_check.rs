//! How well the plan's roles agree with a hand-labelled truth file (`plan --truth FILE`): per
//! role the precision and recall, and every piece labelled otherwise. A truth file is JSON with
//! a `members` list, each with the piece's `id` (as `plan` prints it; for a single-piece product
//! its GlobalId) or its `global_id`, and its `role`; other fields are ignored, so the sidecars
//! `framewright synth` writes are truth files as they are.

use crate::frame::plan::Plan;
use crate::ifc::Model;
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// A truth file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum TruthError {
    #[error("{}: cannot read the truth file: {source}", path.display())]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{}: not a truth file: {message} (expected JSON {{\"members\": [{{\"id\": …, \"role\": …}}, …]}})", path.display())]
    Format { path: PathBuf, message: String },
}

#[derive(Deserialize)]
struct TruthFile {
    members: Vec<TruthMember>,
}

#[derive(Deserialize)]
struct TruthMember {
    id: Option<String>,
    global_id: Option<String>,
    role: String,
}

/// The labelled role of each piece, by piece id as the truth file gives it.
#[derive(Debug, Clone)]
pub struct Truth {
    pub path: PathBuf,
    pub roles: BTreeMap<String, String>,
}

impl Truth {
    pub fn read(path: &Path) -> Result<Truth, TruthError> {
        let text = std::fs::read(path).map_err(|source| TruthError::Read {
            path: path.to_path_buf(),
            source,
        })?;
        let format = |message: String| TruthError::Format {
            path: path.to_path_buf(),
            message,
        };
        let file: TruthFile = serde_json::from_slice(&text).map_err(|e| format(e.to_string()))?;
        let mut roles = BTreeMap::new();
        for (k, m) in file.members.into_iter().enumerate() {
            let Some(id) = m.id.or(m.global_id) else {
                return Err(format(format!(
                    "member {k} has neither `id` nor `global_id`"
                )));
            };
            if let Some(before) = roles.insert(id.clone(), m.role.clone())
                && before != m.role
            {
                return Err(format(format!(
                    "member {k}: `{id}` is labelled twice, {before} and {}",
                    m.role
                )));
            }
        }
        Ok(Truth {
            path: path.to_path_buf(),
            roles,
        })
    }
}

/// One role's figures over the labelled pieces of the model.
#[derive(Debug, Serialize, PartialEq)]
pub struct RoleRow {
    pub role: String,
    /// Labelled with this role.
    pub truth: usize,
    /// Given this role by the plan.
    pub found: usize,
    /// Both.
    pub correct: usize,
    /// correct / found (1 when nothing was found).
    pub precision: f64,
    /// correct / truth (1 when nothing is labelled).
    pub recall: f64,
}

/// A labelled piece the plan gives another role (`found` is "none" for a piece in no wall).
#[derive(Debug, Serialize, PartialEq)]
pub struct Mismatch {
    pub id: String,
    pub truth: String,
    pub found: String,
}

#[derive(Debug, Serialize)]
pub struct RoleCheck {
    pub truth_file: String,
    /// Labelled pieces found in the model, and how many of them the plan gives their role.
    pub labelled: usize,
    pub correct: usize,
    pub roles: Vec<RoleRow>,
    pub mismatches: Vec<Mismatch>,
    /// Labelled ids that name no piece of the model.
    pub not_in_model: Vec<String>,
}

impl RoleCheck {
    pub fn new(truth: &Truth, model: &Model, plan: &Plan) -> RoleCheck {
        // A truth file may name a piece by its id or, for single-piece products, its GlobalId.
        let mut by_label: BTreeMap<&str, &str> = BTreeMap::new();
        for p in model.pieces() {
            by_label.insert(p.id.as_str(), p.id.as_str());
            if p.piece.is_none() {
                by_label
                    .entry(p.global_id.as_str())
                    .or_insert(p.id.as_str());
            }
        }
        let mut pairs: Vec<(&str, &str, &str)> = Vec::new();
        let mut not_in_model = Vec::new();
        for (label, role) in &truth.roles {
            match by_label.get(label.as_str()) {
                Some(id) => {
                    let found = plan.roles.get(*id).map_or("none", String::as_str);
                    pairs.push((id, role, found));
                }
                None => not_in_model.push(label.clone()),
            }
        }
        let names: BTreeSet<&str> = pairs.iter().flat_map(|(_, t, f)| [*t, *f]).collect();
        let ratio = |n: usize, d: usize| if d == 0 { 1.0 } else { n as f64 / d as f64 };
        let roles = names
            .into_iter()
            .filter(|r| *r != "none")
            .map(|role| {
                let truth = pairs.iter().filter(|p| p.1 == role).count();
                let found = pairs.iter().filter(|p| p.2 == role).count();
                let correct = pairs.iter().filter(|p| p.1 == role && p.2 == role).count();
                RoleRow {
                    role: role.to_string(),
                    truth,
                    found,
                    correct,
                    precision: ratio(correct, found),
                    recall: ratio(correct, truth),
                }
            })
            .collect();
        let mismatches = pairs
            .iter()
            .filter(|p| p.1 != p.2)
            .map(|(id, truth, found)| Mismatch {
                id: id.to_string(),
                truth: truth.to_string(),
                found: found.to_string(),
            })
            .collect();
        RoleCheck {
            truth_file: truth.path.display().to_string(),
            labelled: pairs.len(),
            correct: pairs.iter().filter(|p| p.1 == p.2).count(),
            roles,
            mismatches,
            not_in_model,
        }
    }

    pub fn to_text(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "roles against {}: {} of {} labelled pieces right",
            self.truth_file, self.correct, self.labelled
        );
        let _ = writeln!(
            s,
            "  {:<14} {:>6} {:>6} {:>8} {:>10} {:>8}",
            "role", "truth", "found", "correct", "precision", "recall"
        );
        for r in &self.roles {
            let _ = writeln!(
                s,
                "  {:<14} {:>6} {:>6} {:>8} {:>9.1}% {:>7.1}%",
                r.role,
                r.truth,
                r.found,
                r.correct,
                r.precision * 100.0,
                r.recall * 100.0
            );
        }
        for m in &self.mismatches {
            let _ = writeln!(s, "  {}: labelled {}, plan says {}", m.id, m.truth, m.found);
        }
        if !self.not_in_model.is_empty() {
            let _ = writeln!(
                s,
                "  {} labelled ids name no piece of the model: {}",
                self.not_in_model.len(),
                self.not_in_model.join(", ")
            );
        }
        s
    }
}
