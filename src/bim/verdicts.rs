//! The per-piece verdicts of a simulation, in the shape the BIM writers need them:
//! framing and nailing status, the first reason (one line), the tightest reach margin.

use crate::logic::Value;
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

fn sym(v: &Value) -> String {
    v.as_symbol().unwrap_or_default().to_string()
}

/// Verdicts by piece id, for every piece the simulation ran.
pub fn element_verdicts(sim: &Simulation) -> BTreeMap<String, ElementVerdict> {
    let r = &sim.reasoned;
    let status = |relation: &str| -> BTreeMap<String, String> {
        r.get(relation)
            .iter()
            .map(|t| (sym(&t[0]), sym(&t[1])))
            .collect()
    };
    let framing = status("element_framing");
    let nailing = status("element_nailing");
    // Reasons sorted by stage (framing before nailing), then text: the first is the one shown.
    let mut reasons: BTreeMap<String, Vec<(bool, String)>> = BTreeMap::new();
    for t in r.get("element_reason") {
        let line = format!("{}: {}", sym(&t[2]), sym(&t[3]));
        reasons
            .entry(sym(&t[0]))
            .or_default()
            .push((sym(&t[1]) != "framing", line));
    }
    let mut margins: BTreeMap<String, f64> = BTreeMap::new();
    for t in r.get("sim_ik_solved") {
        if let Some(m) = t[2].as_float() {
            let e = margins.entry(sym(&t[0])).or_insert(m);
            *e = e.min(m);
        }
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
    out
}
