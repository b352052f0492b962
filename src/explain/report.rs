//! What an explanation is: per element its verdicts with their derivation trees and what
//! they rest on, the answer first (causes with their numbers, consequences folded); per
//! tuple that does not hold, the rules that could derive it and the conditions that failed.

use crate::ifc::Piece;
use crate::logic::Value;
use crate::logic::provenance::{Explanation, How, Premise, WhyNot};
use serde::Serialize;

/// The element a report is about.
#[derive(Clone, Debug, Serialize)]
pub struct ElementInfo {
    pub id: String,
    pub entity: u64,
    pub item: u64,
    pub global_id: String,
    pub ifc_type: String,
    pub name: Option<String>,
}

impl ElementInfo {
    pub(super) fn of(p: &Piece) -> ElementInfo {
        ElementInfo {
            id: p.id.clone(),
            entity: p.entity,
            item: p.item,
            global_id: p.global_id.clone(),
            ifc_type: p.ifc_type.clone(),
            name: p.name.clone(),
        }
    }
}

/// What a derivation rests on.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Sources {
    /// Nodes of the tree (facts and derived tuples).
    pub facts: usize,
    /// Rules used, as `label (file:line)`, sorted.
    pub rules: Vec<String>,
    /// IFC entities of the model facts, sorted.
    pub ifc_entities: Vec<u64>,
    /// Keys of the cell facts (`cell_value`, `cell_choice`) used, sorted.
    pub cell_keys: Vec<String>,
    /// Simulation facts used.
    pub simulation_facts: usize,
    /// The tree was cut to keep it small (some sources may be missing).
    pub truncated: bool,
}

/// One verdict about the element and its derivation.
#[derive(Clone, Debug, Serialize)]
pub struct Verdict {
    pub relation: String,
    pub tuple: Vec<Value>,
    pub sources: Sources,
    pub explanation: Explanation,
}

/// `why` for one piece.
#[derive(Clone, Debug, Serialize)]
pub struct WhyReport {
    pub element: ElementInfo,
    /// The element's wall, when it is in one (the rules' name: its key piece).
    pub wall: Option<String>,
    /// The wall or panel as every command names it (`W1`, `W1-P2`; see `name_walls`).
    pub wall_id: Option<String>,
    /// `Wall 1 (W1)`, `Wall 1, panel 2 (W1-P2)`: as `simulate` prints it.
    pub wall_label: Option<String>,
    /// The answer first: causes with their numbers, consequences folded (`answer::answer`).
    pub answer: Answer,
    pub verdicts: Vec<Verdict>,
}

/// The answer for one element.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Answer {
    /// `framing: failed`, `nailing: failed (0 of 6 nails driven)`, …
    pub statuses: Vec<Status>,
    /// The failures' causes, framing first.
    pub causes: Vec<Cause>,
    /// Nails not driven because of another piece's failure (nailing reasons of the `Framing`
    /// component that no cause of this element explains), folded per kind.
    pub consequences: Vec<Consequence>,
    /// Findings of the rules (warnings, user rules' violations), one message each.
    pub findings: Vec<String>,
    /// What the plan decided, in words (`role bottom_plate`, `assembly rank 3`).
    pub plan: Vec<String>,
}

#[derive(Clone, Debug, Serialize)]
pub struct Status {
    pub stage: String,
    pub status: String,
    /// Nails driven and planned, for nailing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub nails: Option<(i64, i64)>,
}

/// One cause of a failure: the rule's message with its numbers, the facts it rests on.
#[derive(Clone, Debug, Serialize)]
pub struct Cause {
    pub stage: String,
    pub component: String,
    /// The rule's message; for nails folded together, the first one's, with `subjects`.
    pub message: String,
    /// The rule that derived it, `name (file:line)`.
    pub rule: String,
    /// The nails it is about (`PLATE -> MEMBER #k`), when it is about nails.
    pub subjects: Vec<String>,
    /// The simulation facts it rests on, as `fact  [origin]`.
    pub evidence: Vec<String>,
    /// What it led to, one entry per kind.
    pub consequences: Vec<Consequence>,
    /// The verdict (index into the report's `verdicts`) whose tree explains it.
    pub verdict: usize,
    /// Where it happened, with the numbers (`explain::location`).
    pub located: Vec<super::location::Located>,
    /// Changes that make it pass, each checked where it says so (`explain::remedy`).
    pub remedies: Vec<super::remedy::Remedy>,
    /// What was searched for a remedy without finding one.
    pub no_remedy: Vec<String>,
}

/// Verdicts that follow from a cause, folded.
#[derive(Clone, Debug, Serialize)]
pub struct Consequence {
    /// `nails not driven because it was not placed`.
    pub kind: String,
    pub count: usize,
    /// `PLATE -> MEMBER #k` of each.
    pub ids: Vec<String>,
}

/// Visits every derived node of a tree depth first, premises in order.
pub fn walk<'e>(e: &'e Explanation, f: &mut impl FnMut(&'e Explanation)) {
    f(e);
    if let How::Rule { premises, .. } = &e.how {
        for p in premises {
            if let Premise::Tuple(t) = p {
                walk(t, f);
            }
        }
    }
}

/// Why a tuple does not hold: per rule that could derive it, the first
/// failing condition; nested for failing atoms that are themselves derived.
#[derive(Clone, Debug, Serialize)]
pub struct WhyNotNode {
    pub why_not: WhyNot,
    /// Why-not of the fully known atoms that failed (derived relations only).
    pub because: Vec<WhyNotNode>,
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "answer", rename_all = "snake_case")]
pub enum WhyNotReport {
    /// The tuple holds after all: how.
    Holds {
        explanation: Explanation,
    },
    NotDerived {
        tree: WhyNotNode,
    },
}
