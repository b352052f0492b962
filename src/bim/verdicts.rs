//! The per-piece verdicts of a simulation, in the shape the BIM writers need them:
//! framing and nailing status, the first reason (one line), the tightest reach margin.

use crate::frame::rows::{ElementFraming, ElementNailing, ElementReason, RowError, SimIkSolved};
use crate::sim::Simulation;
use std::collections::BTreeMap;

/// What the simulation says about one piece.
#[derive(Debug, Clone, PartialEq)]
pub struct ElementVerdict {
    pub framing: String,
    pub nailing: String,
    /// The first reason, one line; empty when the piece passed.
    pub reason: String,
    /// Smallest reach margin over the piece's solved poses, metres.
    pub reach_margin: Option<f64>,
}

/// Verdicts by piece id, for every piece the simulation ran; an error when a verdict tuple
/// does not match its relation's declaration.
pub fn element_verdicts(sim: &Simulation) -> Result<BTreeMap<String, ElementVerdict>, RowError> {
    let r = &sim.reasoned;
    let framing: BTreeMap<String, String> = r
        .rows::<ElementFraming>()?
        .into_iter()
        .map(|t| (t.p.to_string(), t.status.to_string()))
        .collect();
    let nailing: BTreeMap<String, String> = r
        .rows::<ElementNailing>()?
        .into_iter()
        .map(|t| (t.p.to_string(), t.status.to_string()))
        .collect();
    // Reasons sorted by stage (framing before nailing), then text: the first is the one shown.
    let mut reasons: BTreeMap<String, Vec<(bool, String)>> = BTreeMap::new();
    for t in r.rows::<ElementReason>()? {
        let line = format!("{}: {}", t.component, t.message);
        reasons
            .entry(t.p.to_string())
            .or_default()
            .push((t.stage != "framing", line));
    }
    let mut margins: BTreeMap<String, f64> = BTreeMap::new();
    for t in r.rows::<SimIkSolved>()? {
        let m = t.reach_margin;
        let e = margins.entry(t.p.to_string()).or_insert(m);
        *e = e.min(m);
    }
    let mut out = BTreeMap::new();
    for p in framing.keys().chain(nailing.keys()) {
        if out.contains_key(p) {
            continue;
        }
        let reason = reasons
            .get_mut(p)
            .and_then(|list| {
                list.sort();
                list.first().map(|(_, l)| l.clone())
            })
            .unwrap_or_default();
        out.insert(
            p.clone(),
            ElementVerdict {
                framing: framing.get(p).cloned().unwrap_or_default(),
                nailing: nailing.get(p).cloned().unwrap_or_default(),
                reason,
                reach_margin: margins.get(p).copied(),
            },
        );
    }
    Ok(out)
}
