//! Text form of `why` and `why-not` for a terminal: a tree per verdict with
//! the widest supporting facts first (the premise resting on the most facts),
//! numbers shortened, a fact already shown printed once, and long runs of
//! input facts of one relation folded with a count. `--json` has everything.
//! By default `why` prints the answer first (`render_answer`): each failure's cause with its
//! numbers and what it led to, then the first cause's tree; `--verbose` prints every tree.

use super::report::{Verdict, WhyNotNode, WhyNotReport, WhyReport};
use super::words::{fact, origin_text};
pub use super::words::{fold_ids, short_value, shorten_numbers};
use crate::logic::provenance::{Explanation, How, Premise};
use std::collections::BTreeSet;
use std::fmt::Write as _;

/// Input facts of one relation shown under a node before the rest are folded.
const FOLD_AFTER: usize = 3;
/// Levels of a tree shown on a terminal; deeper facts are counted.
const MAX_DEPTH: usize = 6;
/// Levels of a cause's tree under the answer (the rest: `--verbose`).
const ANSWER_DEPTH: usize = 2;
/// Nail pairs listed in a consequence's line (all of them: `--json`).
const PAIRS_SHOWN: usize = 4;
/// Conditions longer than this (aggregates over boxes) are cut.
const MAX_CONDITION: usize = 160;

/// The element's line: id, name, type, entity, GlobalId, wall.
fn element_line(s: &mut String, r: &WhyReport) {
    let e = &r.element;
    let name = e.name.as_deref().unwrap_or("");
    let _ = writeln!(
        s,
        "{} '{name}' ({} #{}, GlobalId {}){}",
        e.id,
        e.ifc_type,
        e.entity,
        e.global_id,
        match (&r.wall_label, &r.wall) {
            (Some(label), _) => format!(", in {label}"),
            (None, Some(key)) => format!(", wall {key}"),
            (None, None) => ", in no wall".to_string(),
        }
    );
}

/// The answer first: statuses, each cause with its numbers and what it led to, findings, the
/// plan's verdicts; then the first cause's tree (the others: `--verbose`).
pub fn render_answer(reports: &[WhyReport]) -> String {
    let mut s = String::new();
    for (k, r) in reports.iter().enumerate() {
        if k > 0 {
            s.push('\n');
        }
        element_line(&mut s, r);
        let a = &r.answer;
        if r.verdicts.is_empty() {
            s.push_str("  no verdicts: the rules derived nothing about this piece\n");
            continue;
        }
        let statuses: Vec<String> = a
            .statuses
            .iter()
            .map(|st| match st.nails {
                Some((done, of)) => {
                    format!("{}: {} ({done} of {of} nails driven)", st.stage, st.status)
                }
                None => format!("{}: {}", st.stage, st.status),
            })
            .collect();
        if !statuses.is_empty() {
            let _ = writeln!(s, "{}", statuses.join("; "));
        }
        for c in &a.causes {
            s.push('\n');
            let what = match c.subjects.len() {
                0 => String::new(),
                1 => format!("nail {}: ", c.subjects[0]),
                n => format!("{n} nails ({}), the first: ", fold_ids(&c.subjects)),
            };
            let _ = writeln!(
                s,
                "{} failed ({}): {what}{}",
                c.stage, c.component, c.message
            );
            for l in &c.located {
                let _ = writeln!(s, "  where: {}", l.text());
            }
            let _ = writeln!(s, "  by {}", c.rule);
            for q in &c.consequences {
                let _ = writeln!(s, "  so {} {}: {}", q.count, q.kind, pairs(&q.ids));
            }
            for m in &c.remedies {
                let _ = writeln!(s, "  would pass: {}", m.text);
            }
            if !c.no_remedy.is_empty() {
                let _ = writeln!(s, "  no remedy: {}", c.no_remedy.join("; "));
            }
        }
        if !a.consequences.is_empty() || !a.findings.is_empty() {
            s.push('\n');
        }
        for q in &a.consequences {
            let _ = writeln!(s, "{} {}: {}", q.count, q.kind, pairs(&q.ids));
        }
        for f in &a.findings {
            let _ = writeln!(s, "{f}");
        }
        if !a.plan.is_empty() {
            let _ = writeln!(s, "plan: {}", a.plan.join("; "));
        }
        // The first cause's tree: the others are derived by rules shown in their `by` lines,
        // and every tree under the answer would push it past a screen.
        if let Some(first) = a.causes.first() {
            s.push_str("\nhow the first cause was derived:\n");
            render_verdict(&mut s, &r.verdicts[first.verdict], ANSWER_DEPTH);
        }
        if a.causes.len() > 1 {
            let _ = writeln!(
                s,
                "({} more causes' derivations: --verbose)",
                a.causes.len() - 1
            );
        }
    }
    s.push_str("\n(every verdict's derivation: --verbose; the whole trees: --json)\n");
    s
}

/// Nails folded by pair, the first `PAIRS_SHOWN` pairs.
fn pairs(ids: &[String]) -> String {
    let all = fold_ids(ids);
    let groups: Vec<&str> = all.split("; ").collect();
    if groups.len() <= PAIRS_SHOWN {
        return all;
    }
    format!(
        "{}; and {} more pairs (--json lists them)",
        groups[..PAIRS_SHOWN].join("; "),
        groups.len() - PAIRS_SHOWN
    )
}

/// Every verdict's tree (`--verbose`).
pub fn render_why(reports: &[WhyReport]) -> String {
    let mut s = String::new();
    for (k, r) in reports.iter().enumerate() {
        if k > 0 {
            s.push('\n');
        }
        element_line(&mut s, r);
        if r.verdicts.is_empty() {
            s.push_str("  no verdicts: the rules derived nothing about this piece\n");
        }
        for v in &r.verdicts {
            s.push('\n');
            render_verdict(&mut s, v, MAX_DEPTH);
        }
    }
    s
}

fn render_verdict(s: &mut String, v: &Verdict, max_depth: usize) {
    // Each verdict's tree stands on its own: a fact repeats across verdicts.
    let mut shown = BTreeSet::new();
    render_node(s, &v.explanation, "", "", (0, max_depth), &mut shown);
    let src = &v.sources;
    let entities: Vec<String> = src.ifc_entities.iter().map(|n| format!("#{n}")).collect();
    let _ = writeln!(
        s,
        "  = {} facts, {} rules; IFC {}; cell keys: {}{}{}",
        src.facts,
        src.rules.len(),
        if entities.is_empty() {
            "none".to_string()
        } else {
            entities.join(" ")
        },
        if src.cell_keys.is_empty() {
            "none".to_string()
        } else {
            src.cell_keys.join(", ")
        },
        if src.simulation_facts > 0 {
            format!("; {} simulation facts", src.simulation_facts)
        } else {
            String::new()
        },
        if src.truncated {
            "; tree cut (see --json)"
        } else {
            ""
        }
    );
}

/// Number of nodes under (and including) `e`.
fn size(e: &Explanation) -> usize {
    match &e.how {
        How::Rule { premises, .. } => {
            1 + premises
                .iter()
                .map(|p| match p {
                    Premise::Tuple(t) => size(t),
                    _ => 0,
                })
                .sum::<usize>()
        }
        _ => 1,
    }
}

fn render_node(
    s: &mut String,
    e: &Explanation,
    first: &str,
    rest: &str,
    (depth, max_depth): (usize, usize),
    shown: &mut BTreeSet<String>,
) {
    let head = fact(e);
    match &e.how {
        How::Input { origin } => {
            let _ = writeln!(
                s,
                "{first}{head}  [{}]",
                origin_text(&e.relation, &e.tuple, origin)
            );
        }
        How::Truncated => {
            let _ = writeln!(s, "{first}{head}  [… cut, see --json]");
        }
        How::Rule { rule, premises, .. } => {
            if !shown.insert(head.clone()) {
                let _ = writeln!(s, "{first}{head}  [by {rule}, shown above]");
                return;
            }
            let _ = writeln!(s, "{first}{head}  [by {rule}]");
            if depth + 1 >= max_depth && !premises.is_empty() {
                let below = size(e) - 1;
                let _ = writeln!(
                    s,
                    "{rest}└─ … {below} more fact{} below (--json has the whole tree)",
                    if below == 1 { "" } else { "s" }
                );
                return;
            }
            let lines = children(premises);
            for (i, line) in lines.iter().enumerate() {
                let last = i + 1 == lines.len();
                let (f, r) = crate::logic::provenance::tree_branch(rest, last);
                match line {
                    Child::Node(t) => render_node(s, t, &f, &r, (depth + 1, max_depth), shown),
                    Child::Text(t) => {
                        let _ = writeln!(s, "{f}{t}");
                    }
                }
            }
        }
    }
}

enum Child<'a> {
    Node(&'a Explanation),
    Text(String),
}

/// Premises ordered widest first (most supporting facts; ties in rule
/// order), then the conditions; input facts of a relation beyond
/// `FOLD_AFTER` folded into one line.
fn children(premises: &[Premise]) -> Vec<Child<'_>> {
    let mut tuples: Vec<&Explanation> = premises
        .iter()
        .filter_map(|p| match p {
            Premise::Tuple(t) => Some(&**t),
            _ => None,
        })
        .collect();
    tuples.sort_by_key(|t| std::cmp::Reverse(size(t)));
    let mut out = Vec::new();
    let mut inputs_shown: Vec<(&str, usize)> = Vec::new();
    let mut folded: Vec<(&str, usize)> = Vec::new();
    for t in tuples {
        if matches!(t.how, How::Input { .. }) {
            let n = match inputs_shown.iter_mut().find(|(r, _)| *r == t.relation) {
                Some((_, n)) => {
                    *n += 1;
                    *n
                }
                None => {
                    inputs_shown.push((&t.relation, 1));
                    1
                }
            };
            if n > FOLD_AFTER {
                match folded.iter_mut().find(|(r, _)| *r == t.relation) {
                    Some((_, k)) => *k += 1,
                    None => folded.push((&t.relation, 1)),
                }
                continue;
            }
        }
        out.push(Child::Node(t));
    }
    for (rel, k) in folded {
        out.push(Child::Text(format!("… and {k} more {rel} facts")));
    }
    for p in premises {
        match p {
            Premise::Absent { atom } => out.push(Child::Text(format!(
                "{}  [no such fact]",
                cut(&shorten_numbers(atom))
            ))),
            Premise::Condition { text } => out.push(Child::Text(format!(
                "{}  [holds]",
                cut(&shorten_numbers(text))
            ))),
            Premise::Tuple(_) => {}
        }
    }
    out
}

fn cut(text: &str) -> String {
    match text.char_indices().nth(MAX_CONDITION) {
        Some((i, _)) => format!("{} …", &text[..i]),
        None => text.to_string(),
    }
}

pub fn render_why_not(query: &str, report: &WhyNotReport) -> String {
    let mut s = String::new();
    match report {
        WhyNotReport::Holds { explanation } => {
            let _ = writeln!(s, "{query} holds:");
            let mut shown = BTreeSet::new();
            render_node(&mut s, explanation, "", "", (0, MAX_DEPTH), &mut shown);
        }
        WhyNotReport::NotDerived { tree } => render_why_not_node(&mut s, tree, ""),
    }
    s
}

fn render_why_not_node(s: &mut String, node: &WhyNotNode, indent: &str) {
    use crate::logic::provenance::Failure;
    let w = &node.why_not;
    let args: Vec<String> = w.tuple.iter().map(short_value).collect();
    let _ = writeln!(
        s,
        "{indent}{}({}) is not derived.",
        w.relation,
        args.join(", ")
    );
    if let Some(r) = &w.reason {
        let _ = writeln!(s, "{indent}  {r}");
    }
    let mut head_misfits = 0;
    for a in &w.rules {
        let text = match &a.failure {
            Failure::Head { .. } => {
                head_misfits += 1;
                continue;
            }
            Failure::NoMatch {
                atom,
                candidates,
                relation_size,
            } => {
                let mut t = format!(
                    "no {} fact matches {}",
                    relation_of(atom),
                    shorten_numbers(atom)
                );
                if candidates.is_empty() {
                    t.push_str(" (the relation is empty)");
                } else {
                    let _ = write!(t, "; closest of {relation_size}:");
                    for c in candidates {
                        let vals: Vec<String> = c.iter().map(short_value).collect();
                        let _ = write!(t, "\n{indent}      ({})", vals.join(", "));
                    }
                }
                t
            }
            Failure::NegationHolds { atom, existing } => {
                let vals: Vec<String> = existing.iter().map(short_value).collect();
                format!(
                    "{} fails: the fact exists ({})",
                    shorten_numbers(atom),
                    vals.join(", ")
                )
            }
            Failure::ConditionFalse { condition, example } => format!(
                "condition `{condition}` is false, e.g. {}",
                cut(&shorten_numbers(example))
            ),
            Failure::Derivable => {
                "every condition holds: the tuple is derivable (the rules have not run?)".into()
            }
        };
        let _ = writeln!(s, "{indent}- {}: {}", a.rule, a.rule_text);
        let _ = writeln!(s, "{indent}    {text}");
    }
    if head_misfits > 0 {
        let _ = writeln!(
            s,
            "{indent}- and {head_misfits} rule{} whose head cannot give this tuple",
            if head_misfits == 1 { "" } else { "s" }
        );
    }
    let deeper = format!("{indent}    ");
    for b in &node.because {
        let _ = writeln!(s, "{indent}  because:");
        render_why_not_node(s, b, &deeper);
    }
}

/// `rel` of an atom written `rel(...)` or `!rel(...)`.
fn relation_of(atom: &str) -> &str {
    let a = atom.trim_start_matches('!');
    a.split('(').next().unwrap_or(a)
}
