//! The answer `why` gives first, built from an element's verdicts: each failure's cause (the
//! rule's message, which carries the numbers, and the simulation facts it rests on), what the
//! cause led to folded into one line per kind ("6 nails not driven because it was not placed:
//! …"), the element's statuses and the plan's verdicts in a line. The derivation trees stay in
//! the report (`--verbose`, `--json`).

use super::report::{Answer, Cause, Consequence, Status, Verdict, WhyReport};
use super::words::{fact, origin_text};
use crate::logic::Value;
use crate::logic::provenance::{Explanation, How};
use std::collections::BTreeSet;

/// Simulation facts shown under a cause at most.
const EVIDENCE: usize = 3;

/// A nail's reason split into the nail it names and what it says of it.
struct NailReason<'a> {
    subject: String,
    cause: &'a str,
}

/// `nail PLATE -> MEMBER #k: cause` or `nail PLATE -> MEMBER #k cause`.
fn nail_reason(message: &str) -> Option<NailReason<'_>> {
    let rest = message.strip_prefix("nail ")?;
    let hash = rest.find(" #")?;
    let digits = rest[hash + 2..]
        .find(|c: char| !c.is_ascii_digit())
        .map_or(rest.len(), |i| hash + 2 + i);
    let subject = rest[..digits].to_string();
    let cause = rest[digits..].trim_start_matches(':').trim_start();
    Some(NailReason { subject, cause })
}

/// A message with each run of digits (and decimal points in it) as `#`: messages that differ
/// only in their numbers read alike.
fn numbers_aside(message: &str) -> String {
    let mut out = String::with_capacity(message.len());
    let mut in_number = false;
    for c in message.trim().chars() {
        let digit = c.is_ascii_digit() || (in_number && c == '.');
        if !digit {
            out.push(c);
        } else if !in_number {
            out.push('#');
        }
        in_number = digit;
    }
    out
}

/// A nail's cause with this element's id as "it" and the other piece's as "the other piece".
fn in_words(n: &NailReason, id: &str) -> String {
    let (pair, _) = n.subject.rsplit_once(" #").unwrap_or((&n.subject, ""));
    let (plate, member) = pair.split_once(" -> ").unwrap_or((pair, ""));
    let other = if plate == id { member } else { plate };
    let mut text = n.cause.replace(id, "it");
    if !other.is_empty() && other != id {
        text = text.replace(other, "the other piece");
    }
    text
}

fn sym(t: &[Value], i: usize) -> &str {
    t.get(i).and_then(Value::as_symbol).unwrap_or("")
}

fn rule_of(e: &Explanation) -> String {
    match &e.how {
        How::Rule { rule, .. } => rule.clone(),
        _ => String::new(),
    }
}

/// The simulation facts (inputs with a simulation origin) a tree rests on, first seen first.
fn evidence(e: &Explanation) -> Vec<String> {
    let (mut out, mut seen) = (Vec::new(), BTreeSet::new());
    super::report::walk(e, &mut |node| {
        if let How::Input { origin } = &node.how
            && matches!(origin, crate::logic::Origin::Event(_))
        {
            let line = format!(
                "{}  [{}]",
                fact(node),
                origin_text(&node.relation, &node.tuple, origin)
            );
            if seen.insert(line.clone()) {
                out.push(line);
            }
        }
    });
    out
}

/// The first tuple of `relation` in a tree.
fn find<'e>(e: &'e Explanation, relation: &str) -> Option<&'e Explanation> {
    let mut found = None;
    super::report::walk(e, &mut |node| {
        if found.is_none() && node.relation == relation {
            found = Some(node);
        }
    });
    found
}

/// Builds the answer from a report's verdicts.
pub fn answer(report: &WhyReport) -> Answer {
    let id = report.element.id.as_str();
    let mut out = Answer::default();
    // Causes keyed by (stage, component, rule, message but its numbers): nails failing alike
    // fold into one; a nail failing otherwise under the same rule is a cause of its own.
    let mut causes: Vec<Cause> = Vec::new();
    // Nails not driven because a piece was not framed, by kind.
    let mut skipped: Vec<Consequence> = Vec::new();
    for (i, v) in report.verdicts.iter().enumerate() {
        let t = &v.tuple;
        match v.relation.as_str() {
            "element_reason" => {
                let (stage, component, message) = (sym(t, 1), sym(t, 2), sym(t, 3));
                let rule = rule_of(&v.explanation);
                let nail = nail_reason(message);
                if let Some(n) = &nail
                    && stage == "nailing"
                    && component == "Framing"
                {
                    let kind = format!("nails not driven because {}", in_words(n, id));
                    match skipped.iter_mut().find(|c| c.kind == kind) {
                        Some(c) => {
                            c.count += 1;
                            c.ids.push(n.subject.clone());
                        }
                        None => skipped.push(Consequence {
                            kind,
                            count: 1,
                            ids: vec![n.subject.clone()],
                        }),
                    }
                    continue;
                }
                let same = causes.iter_mut().find(|c| {
                    nail.as_ref()
                        .is_some_and(|n| numbers_aside(&c.message) == numbers_aside(n.cause))
                        && !c.subjects.is_empty()
                        && c.stage == stage
                        && c.component == component
                        && c.rule == rule
                });
                match (same, nail) {
                    (Some(c), Some(n)) => c.subjects.push(n.subject),
                    (_, nail) => causes.push(cause(v, i, stage, component, message, rule, nail)),
                }
            }
            "element_framing" | "element_nailing" => {
                let nails = find(&v.explanation, "element_nail_count").map(|c| {
                    let n = |k: usize| c.tuple.get(k).and_then(Value::as_number).unwrap_or(0);
                    (n(2), n(1))
                });
                out.statuses.push(Status {
                    stage: v.relation.trim_start_matches("element_").to_string(),
                    status: sym(t, 1).to_string(),
                    nails: nails.filter(|_| v.relation == "element_nailing"),
                });
            }
            "role" => out.plan.push(format!("role {}", sym(t, 1))),
            "assembly_rank" => out.plan.push(format!(
                "assembly rank {}",
                t.get(1).map_or(String::new(), |r| r.to_string())
            )),
            "violation" | "warning" | "frame_warning" | "world_warning" => {
                let message = t.iter().rev().find_map(Value::as_symbol).unwrap_or("");
                out.findings.push(format!(
                    "{} ({}): {message}",
                    v.relation,
                    rule_of(&v.explanation)
                ));
            }
            _ => {}
        }
    }
    // What this element's own framing failure led to goes under that cause; what another
    // piece's failure led to stands apart.
    for consequence in skipped {
        let own = consequence.kind.contains(" it ");
        match causes.iter_mut().find(|c| c.stage == "framing") {
            Some(c) if own => c.consequences.push(consequence),
            _ => out.consequences.push(consequence),
        }
    }
    // Framing causes first: a piece not placed explains its nails.
    causes.sort_by_key(|c| c.stage != "framing");
    out.causes = causes;
    out
}

fn cause(
    v: &Verdict,
    index: usize,
    stage: &str,
    component: &str,
    message: &str,
    rule: String,
    nail: Option<NailReason>,
) -> Cause {
    let mut lines = evidence(&v.explanation);
    lines.truncate(EVIDENCE);
    Cause {
        stage: stage.to_string(),
        component: component.to_string(),
        message: nail
            .as_ref()
            .map_or(message, |n| n.cause)
            .trim()
            .to_string(),
        rule,
        subjects: nail.map(|n| n.subject).into_iter().collect(),
        evidence: lines,
        consequences: Vec::new(),
        verdict: index,
        located: Vec::new(),
        remedies: Vec::new(),
        no_remedy: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_differing_in_their_numbers_read_alike() {
        assert_eq!(
            numbers_aside("beyond reach: 3.477 m, reaches 2.377 m (1100 mm too far)"),
            numbers_aside("beyond reach: 3.5 m, reaches 2.377 m (1123 mm too far)")
        );
        assert_ne!(
            numbers_aside("every solution collides: link_5 with floor"),
            numbers_aside("every solution collides: tool gripper_2_jaws finger with piece A/7")
        );
    }

    #[test]
    fn nail_reasons_split_into_the_nail_and_its_cause() {
        let n = nail_reason("nail A/0 -> B/1 #12: A/0 was not placed").unwrap();
        assert_eq!(
            (n.subject.as_str(), n.cause),
            ("A/0 -> B/1 #12", "A/0 was not placed")
        );
        let n = nail_reason("nail A -> B #3 beyond reach: the wrist centre would be 3 m").unwrap();
        assert_eq!(
            (n.subject.as_str(), n.cause),
            ("A -> B #3", "beyond reach: the wrist centre would be 3 m")
        );
        assert!(nail_reason("place pose: every solution collides").is_none());
    }

    #[test]
    fn a_nail_cause_names_the_element_it_and_its_partner_the_other_piece() {
        let n = nail_reason("nail P -> M #1: P and M were not placed").unwrap();
        assert_eq!(in_words(&n, "M"), "the other piece and it were not placed");
        let n = nail_reason("nail P -> M #1: P was not placed").unwrap();
        assert_eq!(in_words(&n, "P"), "it was not placed");
        assert_eq!(in_words(&n, "M"), "the other piece was not placed");
    }
}
