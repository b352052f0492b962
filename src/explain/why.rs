//! `why` and `why-not` for one element: the rule base (and user rules) run
//! on the interpreter with provenance over the element's spatial container
//! only (walls never span containers, so the element's relations are the
//! same as over the whole model), then each verdict about the element is
//! explained down to its input facts: IFC entities, cell keys, simulation
//! events.

use super::answer::answer;
use super::report::Answer;
use super::report::walk;
pub use super::report::{ElementInfo, Sources, Verdict, WhyNotNode, WhyNotReport, WhyReport};
use crate::frame::containers::{containers_of, restrict_to_containers};
use crate::frame::panel::PanelOf;
use crate::frame::{Facts, RuleEngine};
use crate::ifc::{Model, Piece};
use crate::logic::provenance::{Explanation, How, parse_query};
use crate::logic::{Engine, LogicError, Options, Origin, Value};
use crate::user_rules::{UserRulesError, full_program};
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::sync::Arc;

/// Relations whose tuples about an element (first argument = its id) are its
/// verdicts, in the order they are shown: simulation outcomes (the reasons
/// first: a failed status is derived most directly from "not placed"),
/// user findings, built-in warnings, then what the plan decided.
pub const VERDICT_RELATIONS: &[&str] = &[
    "element_reason",
    "element_framing",
    "element_nailing",
    "violation",
    "warning",
    "frame_warning",
    "world_warning",
    "role",
    "wall_of",
    "assembly_rank",
    "framing_target",
    "framing_flat",
    "spawn_beyond_belt",
];

#[derive(Debug, thiserror::Error)]
pub enum WhyError {
    #[error(transparent)]
    Rules(#[from] UserRulesError),
    #[error(transparent)]
    Logic(#[from] LogicError),
    /// The ID names no piece of the model (the message lists the closest
    /// ids), or the query names no relation.
    #[error("{0}")]
    UnknownElement(String),
    /// The rule base failed to run (a `--rules-dir` that does not check, say).
    #[error("{0}")]
    Frame(String),
}

/// What to explain against: the model's facts (with cell and, when
/// simulated, the executor's facts), the rule base and user rule files.
pub struct Context<'a> {
    pub model: &'a Model,
    pub facts: &'a Facts,
    pub base: &'a RuleEngine,
    pub user_files: &'a [PathBuf],
    /// Bounds on the rule base's runs.
    pub limits: crate::frame::RuleLimits,
    /// The cell the element was simulated in: remedies are computed against it.
    pub cell: Option<&'a crate::cell::Cell>,
}

/// The pieces an ID names: a piece id, an IFC GlobalId (all pieces of a
/// many-piece product) or `#entity` (the product entity or the
/// representation item a piece comes from).
pub fn resolve_element<'m>(model: &'m Model, id: &str) -> Result<Vec<&'m Piece>, WhyError> {
    let id = id.trim();
    let pieces = model.pieces();
    let found: Vec<&Piece> = if let Some(n) = id.strip_prefix('#') {
        let n: u64 = n.parse().map_err(|_| {
            WhyError::UnknownElement(format!(
                "`{id}` is not an entity id: write `#` and the number, e.g. `#{}`",
                pieces.first().map_or(1, |p| p.entity)
            ))
        })?;
        let by_product: Vec<&Piece> = pieces.iter().filter(|p| p.entity == n).collect();
        if by_product.is_empty() {
            pieces.iter().filter(|p| p.item == n).collect()
        } else {
            by_product
        }
    } else {
        match pieces.iter().find(|p| p.id == id) {
            Some(p) => vec![p],
            None => pieces.iter().filter(|p| p.global_id == id).collect(),
        }
    };
    if found.is_empty() {
        return Err(WhyError::UnknownElement(unknown_element(model, id)));
    }
    Ok(found)
}

fn unknown_element(model: &Model, id: &str) -> String {
    let pieces = model.pieces();
    let closest: Vec<String> =
        if let Some(n) = id.strip_prefix('#').and_then(|n| n.parse::<u64>().ok()) {
            let mut by_distance: Vec<&Piece> = pieces.iter().collect();
            by_distance.sort_by_key(|p| (p.entity.abs_diff(n), p.entity));
            by_distance.dedup_by_key(|p| p.entity);
            by_distance
                .iter()
                .take(3)
                .map(|p| {
                    format!(
                        "#{} ({})",
                        p.entity,
                        p.name.as_deref().unwrap_or(&p.ifc_type)
                    )
                })
                .collect()
        } else {
            let shared = |p: &Piece| {
                p.id.chars()
                    .zip(id.chars())
                    .take_while(|(a, b)| a.eq_ignore_ascii_case(b))
                    .count()
            };
            let mut ranked: Vec<&Piece> = pieces.iter().collect();
            ranked.sort_by(|a, b| shared(b).cmp(&shared(a)).then_with(|| a.id.cmp(&b.id)));
            ranked
                .iter()
                .take(3)
                .map(|p| format!("{} (#{})", p.id, p.entity))
                .collect()
        };
    let nearby = if closest.is_empty() {
        "the model has no pieces".to_string()
    } else {
        format!("nearest: {}", closest.join(", "))
    };
    format!(
        "no piece of the model has the id `{id}` ({nearby}); an ID is a piece id, an IFC GlobalId or an entity `#id`; `framewright plan MODEL.ifc --json` lists every member with its id and entity"
    )
}

/// The walls (keys, as in `wall_of`) of the pieces an ID names, from the
/// rule base run over their containers only.
pub fn element_walls(ctx: &Context<'_>, id: &str) -> Result<Vec<String>, WhyError> {
    Ok(element_walls_split(ctx, id)?.0)
}

/// `element_walls`, and whether the rules split any of them into panels (`wall_split`).
pub fn element_walls_split(ctx: &Context<'_>, id: &str) -> Result<(Vec<String>, bool), WhyError> {
    let pieces = resolve_element(ctx.model, id)?;
    let ids: BTreeSet<&str> = pieces.iter().map(|p| p.id.as_str()).collect();
    let facts = restrict_to_containers(ctx.facts, &containers_of(ctx.facts, &ids));
    let reasoned = crate::frame::Ask::new(ctx.base)
        .within(ctx.limits)
        .over(&facts)
        .map_err(|e| WhyError::Frame(e.to_string()))?;
    let walls: BTreeSet<String> = reasoned
        .get("wall_of")
        .iter()
        .filter(|t| t[0].as_symbol().is_some_and(|p| ids.contains(p)))
        .filter_map(|t| t[1].as_symbol().map(str::to_string))
        .collect();
    let split = reasoned
        .get("wall_split")
        .iter()
        .any(|t| t[0].as_symbol().is_some_and(|w| walls.contains(w)));
    Ok((walls.into_iter().collect(), split))
}

/// Runs the base (+ user rules) with provenance over `facts`.
pub fn explaining_engine(
    facts: &Facts,
    base: &RuleEngine,
    user_files: &[PathBuf],
) -> Result<Engine, WhyError> {
    let program = Arc::new(full_program(base, user_files)?);
    let mut engine = Engine::new(
        program,
        Options {
            provenance: true,
            ..Options::default()
        },
    );
    facts.insert_into(&mut engine)?;
    engine.run()?;
    Ok(engine)
}

/// Explains every verdict about each piece the ID names.
pub fn why(ctx: &Context<'_>, id: &str) -> Result<Vec<WhyReport>, WhyError> {
    let pieces = resolve_element(ctx.model, id)?;
    let ids: BTreeSet<&str> = pieces.iter().map(|p| p.id.as_str()).collect();
    let facts = restrict_to_containers(ctx.facts, &containers_of(ctx.facts, &ids));
    let engine = explaining_engine(&facts, ctx.base, ctx.user_files)?;
    let mut reports = Vec::new();
    for p in pieces {
        let mut report = why_piece(&engine, p)?;
        super::location::attach(&engine, &mut report)?;
        if let Some(cell) = ctx.cell {
            super::remedy::attach(&engine, cell, &mut report)?;
        }
        reports.push(report);
    }
    Ok(reports)
}

/// The verdicts about one piece in an engine that has run with provenance.
pub fn why_piece(engine: &Engine, piece: &Piece) -> Result<WhyReport, WhyError> {
    let mut verdicts = Vec::new();
    let mut wall = None;
    for rel in VERDICT_RELATIONS {
        if engine.program().relation(rel).is_none() {
            continue;
        }
        for tuple in engine.relation(rel)? {
            if tuple.first().and_then(Value::as_symbol) != Some(piece.id.as_str()) {
                continue;
            }
            if *rel == "wall_of" {
                wall = tuple.get(1).and_then(Value::as_symbol).map(str::to_string);
            }
            let explanation = engine.explain(rel, &tuple)?;
            verdicts.push(Verdict {
                relation: rel.to_string(),
                sources: sources_of(&explanation),
                tuple,
                explanation,
            });
        }
    }
    let mut report = WhyReport {
        element: ElementInfo::of(piece),
        wall,
        wall_id: None,
        wall_label: None,
        answer: Answer::default(),
        verdicts,
    };
    report.answer = answer(&report);
    Ok(report)
}

/// Names each report's wall as the plan of the whole model does (`panels_by_piece` of it):
/// the rules know a wall by its key piece, the user by `W1` or `W1-P2`.
pub fn name_walls(reports: &mut [WhyReport], names: &BTreeMap<String, PanelOf>) {
    for r in reports {
        if let Some(of) = names.get(&r.element.id) {
            r.wall_id = Some(of.unit_id().to_string());
            r.wall_label = Some(of.label());
        }
    }
}

/// Rules, IFC entities, cell keys and simulation facts a tree rests on.
pub fn sources_of(e: &Explanation) -> Sources {
    let mut rules = BTreeSet::new();
    let mut entities = BTreeSet::new();
    let mut keys = BTreeSet::new();
    let mut s = Sources::default();
    walk(e, &mut |node| {
        s.facts += 1;
        match &node.how {
            How::Rule { rule, .. } => {
                rules.insert(rule.clone());
            }
            How::Input { origin } => {
                if node.relation.starts_with("cell_")
                    && let Some(k) = node.tuple.first().and_then(Value::as_symbol)
                {
                    keys.insert(k.to_string());
                }
                if node.relation.starts_with("sim_") {
                    s.simulation_facts += 1;
                }
                if let Origin::Entity(n) = origin {
                    entities.insert(*n);
                }
            }
            How::Truncated => s.truncated = true,
        }
    });
    s.rules = rules.into_iter().collect();
    s.ifc_entities = entities.into_iter().collect();
    s.cell_keys = keys.into_iter().collect();
    s
}

/// How deep `why-not` follows failing atoms into the rules that derive them.
const WHY_NOT_DEPTH: usize = 3;
/// At most this many why-not answers in one report.
const WHY_NOT_NODES: usize = 24;

/// `why-not` for a tuple written `rel(a, b, ...)`; `#entity` arguments are
/// replaced by the piece id of that entity.
pub fn why_not(ctx: &Context<'_>, query: &str) -> Result<WhyNotReport, WhyError> {
    let program = full_program(ctx.base, ctx.user_files)?;
    let query = substitute_entities(ctx.model, query)?;
    let name = query.split('(').next().unwrap_or("").trim();
    if program.relation(name).is_none() {
        let names = program.relations.iter().map(|r| r.name.as_str());
        let hint = match crate::logic::front::diag::closest(name, names) {
            Some(c) => format!("did you mean `{c}`? "),
            None => String::new(),
        };
        return Err(WhyError::UnknownElement(format!(
            "unknown relation `{name}` in `{query}`; {hint}`framewright rules relations` lists the built-in relations"
        )));
    }
    let (rel, tuple) = parse_query(&program, &query)?;
    let ids: BTreeSet<&str> = tuple.iter().filter_map(Value::as_symbol).collect();
    let containers = containers_of(ctx.facts, &ids);
    let facts = if containers.is_empty() {
        ctx.facts.clone()
    } else {
        restrict_to_containers(ctx.facts, &containers)
    };
    let engine = explaining_engine(&facts, ctx.base, ctx.user_files)?;
    if engine.contains(&rel, &tuple)? {
        return Ok(WhyNotReport::Holds {
            explanation: engine.explain(&rel, &tuple)?,
        });
    }
    let mut seen = BTreeSet::new();
    let mut budget = WHY_NOT_NODES;
    Ok(WhyNotReport::NotDerived {
        tree: why_not_node(&engine, &rel, &tuple, 0, &mut seen, &mut budget)?,
    })
}

fn why_not_node(
    engine: &Engine,
    rel: &str,
    tuple: &[Value],
    depth: usize,
    seen: &mut BTreeSet<String>,
    budget: &mut usize,
) -> Result<WhyNotNode, WhyError> {
    *budget = budget.saturating_sub(1);
    seen.insert(format!("{rel}{tuple:?}"));
    let why_not = engine.explain_not(rel, tuple)?;
    let mut because = Vec::new();
    if depth + 1 < WHY_NOT_DEPTH {
        for attempt in &why_not.rules {
            let crate::logic::provenance::Failure::NoMatch { atom, .. } = &attempt.failure else {
                continue;
            };
            // Only atoms with every argument known parse as a tuple.
            let Ok((r, t)) = parse_query(engine.program(), atom) else {
                continue;
            };
            let derived = engine
                .program()
                .relation(&r)
                .is_some_and(|d| d.input.is_none());
            if !derived || *budget == 0 || seen.contains(&format!("{r}{t:?}")) {
                continue;
            }
            if engine.contains(&r, &t)? {
                continue;
            }
            because.push(why_not_node(engine, &r, &t, depth + 1, seen, budget)?);
        }
    }
    Ok(WhyNotNode { why_not, because })
}

/// Replaces `#123` arguments by the quoted id of the piece of that entity.
fn substitute_entities(model: &Model, query: &str) -> Result<String, WhyError> {
    let mut out = String::new();
    let mut rest = query;
    let mut in_str = false;
    while let Some(c) = rest.chars().next() {
        if c == '"' {
            in_str = !in_str;
        }
        if c == '#' && !in_str {
            let digits: String = rest[1..].chars().take_while(char::is_ascii_digit).collect();
            if !digits.is_empty() {
                let token = format!("#{digits}");
                let pieces = resolve_element(model, &token)?;
                if pieces.len() > 1 {
                    let ids: Vec<&str> = pieces.iter().map(|p| p.id.as_str()).collect();
                    return Err(WhyError::UnknownElement(format!(
                        "{token} holds {} pieces ({}); name one of them by its piece id",
                        pieces.len(),
                        ids.join(", ")
                    )));
                }
                out.push_str(&format!("{:?}", pieces[0].id));
                rest = &rest[token.len()..];
                continue;
            }
        }
        out.push(c);
        rest = &rest[c.len_utf8()..];
    }
    Ok(out)
}
