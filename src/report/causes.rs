//! Root causes of a wall's failures, each with the failures it brought about.
//!
//! A simulation reports every failed element and nail; most of them follow from a few
//! faults (a plate out of reach is not placed, so every nail into it is skipped). This module
//! folds the report of one wall into those faults.
//!
//! API (kept small and stable; other exporters reuse it):
//! - [`root_causes`]`(report, wall_id) -> Vec<RootCause>` for one wall of a [`SimReport`]
//!   (`wall_id` as the plan names the simulated wall, or a whole wall's id for all its panels; an unknown wall gives an empty list).
//! - [`RootCause`]: `piece` (element id at fault), `stage` (`framing` | `nailing`),
//!   `component` (Robot, Gripper, Conveyor, Nailer), `message` (one line, with numbers) and
//!   `consequences`.
//! - [`Consequence`]: `piece` (the element that suffered) and `message` (one line).
//!
//! Rules, in this order:
//! 1. Every element whose framing failed is a cause (its first framing reason is the
//!    message). Its consequences are the nails skipped because it was not placed; a nail
//!    whose plate and member were both not placed counts for the first of them in element
//!    order only, so every consequence is said once.
//! 2. The nails of one plate that failed for the same component and the same outcome
//!    (beyond reach, colliding, off target, missing the member) are one cause; the message is
//!    the first nail's reason prefixed with how many nails share it, and the consequences
//!    are those nails.
//! 3. Any other nailing reason (the arm touched something while nailing) is a cause with no
//!    consequences.
//!
//! The order is deterministic: framing causes in element (spawn) order, then nailing causes
//! in nailing-target order, then the rest in element order.

use super::simulate::{ElementRow, NailRow, SimReport};
use serde::Serialize;
use std::collections::BTreeMap;

/// A fault the simulation found, with what followed from it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RootCause {
    /// The element at fault (a piece id).
    pub piece: String,
    /// `framing` or `nailing`.
    pub stage: &'static str,
    /// The component at fault, as in the results table.
    pub component: String,
    /// One line saying what went wrong, with its numbers.
    pub message: String,
    pub consequences: Vec<Consequence>,
}

/// A failure that follows from a root cause.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Consequence {
    /// The element that suffered it.
    pub piece: String,
    pub message: String,
}

/// Failed nails sharing a plate, a component and an outcome, with their reasons.
type NailGroup<'a> = (String, String, String, Vec<(&'a NailRow, String)>);

/// The root causes of one wall's failures (see the module doc for the rules and order).
pub fn root_causes(report: &SimReport, wall_id: &str) -> Vec<RootCause> {
    let elements: Vec<&ElementRow> = report
        .elements
        .iter()
        .filter(|e| e.wall_id == wall_id || e.panel_id == wall_id)
        .collect();
    let nails: Vec<&NailRow> = report
        .nailing_validation
        .targets
        .iter()
        .filter(|n| n.wall_id == wall_id || n.panel_id == wall_id)
        .collect();
    let order: BTreeMap<&str, usize> = elements
        .iter()
        .enumerate()
        .map(|(i, e)| (e.id.as_str(), i))
        .collect();
    let not_placed = |id: &str| {
        elements
            .iter()
            .any(|e| e.id == id && e.framing.status != "framed")
    };

    // 1. Elements not framed, with the nails skipped because of them.
    let mut causes: Vec<RootCause> = elements
        .iter()
        .filter(|e| e.framing.status != "framed")
        .map(|e| {
            let (component, message) = e.framing.reasons.first().map_or_else(
                || ("Framing".to_string(), "was not placed".to_string()),
                |r| (r.component.clone(), r.message.clone()),
            );
            RootCause {
                piece: e.id.clone(),
                stage: "framing",
                component,
                message,
                consequences: Vec::new(),
            }
        })
        .collect();
    for n in nails.iter().filter(|n| n.status == "skipped: not_framed") {
        let culprit = [n.plate.as_str(), n.member.as_str()]
            .into_iter()
            .filter(|p| not_placed(p))
            .min_by_key(|p| order.get(p).copied().unwrap_or(usize::MAX));
        if let Some(cause) = culprit.and_then(|p| causes.iter_mut().find(|c| c.piece == p)) {
            let other = if n.plate == cause.piece {
                &n.member
            } else {
                &n.plate
            };
            cause.consequences.push(Consequence {
                piece: other.clone(),
                message: format!(
                    "nail {} -> {} #{} not driven: {} was not placed",
                    n.plate, n.member, n.k, cause.piece
                ),
            });
        }
    }

    // 2. Nails that failed on their own, grouped by plate, component and outcome.
    let reason_of = |n: &NailRow| {
        let prefix = format!("nail {} -> {} #{}", n.plate, n.member, n.k);
        elements
            .iter()
            .filter(|e| e.id == n.plate || e.id == n.member)
            .flat_map(|e| e.nailing.reasons.iter())
            .find(|r| {
                r.message
                    .strip_prefix(&prefix)
                    .is_some_and(|rest| rest.starts_with([' ', ':']))
            })
            .cloned()
    };
    // (plate, component, outcome) and the nails with their reasons.
    let mut groups: Vec<NailGroup> = Vec::new();
    for n in nails.iter().filter(|n| n.status != "skipped: not_framed") {
        let Some(reason) = reason_of(n) else {
            continue;
        };
        let outcome = if n.status == "fired" {
            // Landing off target and missing the member are different faults.
            reason.message.contains("does not run into").to_string()
        } else {
            n.status.clone()
        };
        let key = (n.plate.clone(), reason.component.clone(), outcome);
        match groups
            .iter_mut()
            .find(|g| (&g.0, &g.1, &g.2) == (&key.0, &key.1, &key.2))
        {
            Some(g) => g.3.push((n, reason.message)),
            None => groups.push((key.0, key.1, key.2, vec![(n, reason.message)])),
        }
    }
    for (plate, component, _, members) in groups {
        let first = &members[0].1;
        // One nail alone is the cause itself; several share a cause and are its consequences.
        let (message, consequences) = if members.len() == 1 {
            (first.clone(), Vec::new())
        } else {
            (
                format!(
                    "{} nails of {plate} fail like this one: {first}",
                    members.len()
                ),
                members
                    .iter()
                    .map(|(n, m)| Consequence {
                        piece: n.member.clone(),
                        message: m.clone(),
                    })
                    .collect(),
            )
        };
        causes.push(RootCause {
            piece: plate,
            stage: "nailing",
            component,
            message,
            consequences,
        });
    }

    // 3. Nailing reasons about no nail (the arm touched something while nailing).
    for e in &elements {
        for r in e
            .nailing
            .reasons
            .iter()
            .filter(|r| !r.message.starts_with("nail "))
        {
            causes.push(RootCause {
                piece: e.id.clone(),
                stage: "nailing",
                component: r.component.clone(),
                message: r.message.clone(),
                consequences: Vec::new(),
            });
        }
    }
    causes
}
