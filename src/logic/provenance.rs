//! Explanations: `explain` rebuilds the recorded minimal-height derivation of
//! a tuple as a tree; `explain_not` tells, for each rule that could derive a
//! missing tuple, the first body literal that fails and the closest candidates.

use super::error::LogicError;
use super::front::ast::{ExprKind, Literal};
use super::interp::compile::{CRule, CStep, Range};
use super::interp::{Engine, Exec, Origin, Prov, show};
use super::value::{BaseTy, Value};
use serde::Serialize;
use std::fmt::Write as _;

/// Largest tree `explain` builds (deeper parts are cut with a marker).
const MAX_NODES: usize = 2000;
/// Partial bindings followed by `explain_not` per rule.
const MAX_FRONTIER: usize = 1000;

#[derive(Clone, Debug, Serialize)]
pub struct Explanation {
    pub relation: String,
    pub tuple: Vec<Value>,
    pub how: How,
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum How {
    /// An input fact and where it came from.
    Input { origin: Origin },
    /// Derived by a rule from the premises.
    Rule {
        /// `label (file:line)` or `rule (file:line)`.
        rule: String,
        label: Option<String>,
        location: String,
        /// Height of this derivation (inputs have height 0).
        height: u32,
        premises: Vec<Premise>,
    },
    /// Cut to keep the tree small.
    Truncated,
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Premise {
    Tuple(Box<Explanation>),
    /// A negated atom that holds because no tuple matches.
    Absent {
        atom: String,
    },
    /// A comparison, string test, assignment or aggregate, with its values.
    Condition {
        text: String,
    },
}

#[derive(Clone, Debug, Serialize)]
pub struct WhyNot {
    pub relation: String,
    pub tuple: Vec<Value>,
    /// Set when no rule can derive the relation at all.
    pub reason: Option<String>,
    pub rules: Vec<RuleAttempt>,
}

#[derive(Clone, Debug, Serialize)]
pub struct RuleAttempt {
    pub rule: String,
    pub rule_text: String,
    pub failure: Failure,
}

#[derive(Clone, Debug, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Failure {
    /// The rule's head cannot produce this tuple.
    Head { detail: String },
    /// No tuple matches this body atom (shown with the known values).
    NoMatch {
        atom: String,
        candidates: Vec<Vec<Value>>,
        relation_size: usize,
    },
    /// A negated atom fails because this tuple exists.
    NegationHolds { atom: String, existing: Vec<Value> },
    /// A condition is false for every candidate binding.
    ConditionFalse { condition: String, example: String },
    /// Every literal matches: the tuple is derivable (the engine has not run?).
    Derivable,
}

impl Engine {
    fn crule(&self, id: usize) -> &CRule {
        self.compiled_rules()
            .find(|r| r.id == id)
            .expect("every rule is compiled")
    }

    /// The derivation tree of a stored tuple (needs `Options::provenance`).
    pub fn explain(&self, rel: &str, tuple: &[Value]) -> Result<Explanation, LogicError> {
        let r = self.rel_id(rel)?;
        self.check_tuple(r, tuple)?;
        if self.prov.is_none() {
            return Err(LogicError::Usage("explanations need provenance: create the Engine with `Options { provenance: true, .. }` (or pass --explain)".into()));
        }
        let Some(id) = self.rels[r].find(tuple) else {
            return Err(LogicError::Usage(format!(
                "{rel}({}) does not hold; ask why not with `explain not`",
                show_tuple(tuple)
            )));
        };
        let mut budget = MAX_NODES;
        Ok(self.with_ords(|| self.explain_id(r, id, &mut budget)))
    }

    fn explain_id(&self, r: usize, id: u32, budget: &mut usize) -> Explanation {
        let relation = self.program.relations[r].name.clone();
        let tuple = self.rels[r].tuple(id).to_vec();
        if *budget == 0 {
            return Explanation {
                relation,
                tuple,
                how: How::Truncated,
            };
        }
        *budget -= 1;
        let prov = &self.prov.as_ref().expect("provenance on")[r][id as usize];
        let how = match prov {
            Prov::Input(o) => How::Input { origin: o.clone() },
            Prov::Derived { rule, body, height } => {
                let rule = *rule as usize;
                let premises = self.replay(rule, body, budget);
                let pr = &self.program.rules[rule];
                How::Rule {
                    rule: self.program.rule_name(rule),
                    label: pr.label.clone(),
                    location: self.program.location(pr.span),
                    height: *height,
                    premises,
                }
            }
        };
        Explanation {
            relation,
            tuple,
            how,
        }
    }

    /// Re-run a rule's plan along the recorded body tuples to list its premises.
    fn replay(&self, rule_id: usize, body: &[(u32, u32)], budget: &mut usize) -> Vec<Premise> {
        let cr = self.crule(rule_id);
        let rule = &self.program.rules[rule_id];
        let steps = &cr.variants[0];
        let lim: Vec<(u32, u32)> = self
            .rels
            .iter()
            .map(|r| (r.len() as u32, r.len() as u32))
            .collect();
        let mut env = vec![Value::Number(0); cr.slot_names.len()];
        let mut premises = Vec::new();
        let mut scans = body.iter();
        for (k, step) in steps.iter().enumerate() {
            let lit = step_literal(rule, &rule.plan[k]);
            match step {
                CStep::Scan { binds, .. } => {
                    let Some(&(r, id)) = scans.next() else { break };
                    let t = self.rels[r as usize].tuple(id);
                    for &(c, s) in binds {
                        env[s as usize] = t[c].clone();
                    }
                    premises.push(Premise::Tuple(Box::new(
                        self.explain_id(r as usize, id, budget),
                    )));
                }
                CStep::Negate { .. } => premises.push(Premise::Absent {
                    atom: instantiate(lit, cr, &env, None),
                }),
                _ => {
                    // Re-evaluate to bind assigned variables; the recorded derivation passed it.
                    let mut ex = Exec::new(&self.rels, &lim);
                    let mut out = None;
                    let _ = ex.run(std::slice::from_ref(step), &mut env, &mut |_, e| {
                        out = Some(e.clone());
                        Ok(())
                    });
                    if let Some(e) = out {
                        env = e;
                    }
                    premises.push(Premise::Condition {
                        text: instantiate(lit, cr, &env, None),
                    });
                }
            }
        }
        premises
    }

    /// Why a tuple is not derived: per candidate rule, the first failing literal.
    pub fn explain_not(&self, rel: &str, tuple: &[Value]) -> Result<WhyNot, LogicError> {
        // Rule expressions are evaluated again: with the `ord` values of the run.
        self.with_ords(|| self.why_not(rel, tuple))
    }

    fn why_not(&self, rel: &str, tuple: &[Value]) -> Result<WhyNot, LogicError> {
        let r = self.rel_id(rel)?;
        self.check_tuple(r, tuple)?;
        if self.rels[r].find(tuple).is_some() {
            return Err(LogicError::Usage(format!(
                "{rel}({}) holds; ask how with `explain`",
                show_tuple(tuple)
            )));
        }
        let rules: Vec<usize> = (0..self.program.rules.len())
            .filter(|&i| self.program.rules[i].head.rel == rel)
            .collect();
        let decl = &self.program.relations[r];
        let reason = rules.is_empty().then(|| {
            if decl.input.is_some() {
                format!("no rule derives `{rel}`; it is read from input facts and this tuple is not among them")
            } else {
                format!("no rule or fact derives `{rel}`")
            }
        });
        let lim: Vec<(u32, u32)> = self
            .rels
            .iter()
            .map(|r| (r.len() as u32, r.len() as u32))
            .collect();
        let mut attempts = Vec::new();
        for id in rules {
            let failure = self.attempt(id, tuple, &lim);
            attempts.push(RuleAttempt {
                rule: self.program.rule_name(id),
                rule_text: self.program.rules[id].to_string(),
                failure,
            });
        }
        Ok(WhyNot {
            relation: rel.to_string(),
            tuple: tuple.to_vec(),
            reason,
            rules: attempts,
        })
    }

    fn attempt(&self, rule_id: usize, tuple: &[Value], lim: &[(u32, u32)]) -> Failure {
        let cr = self.crule(rule_id);
        let rule = &self.program.rules[rule_id];
        let mut env = vec![Value::Number(0); cr.slot_names.len()];
        let mut bound = vec![false; cr.slot_names.len()];
        let mut deferred = Vec::new();
        // Unify the head with the tuple.
        for (i, (e, v)) in rule.head.args.iter().zip(tuple).enumerate() {
            match &e.kind {
                ExprKind::Var(name) => {
                    let s = cr
                        .slot_names
                        .iter()
                        .position(|n| n == name)
                        .expect("head variable has a slot");
                    if bound[s] && env[s] != *v {
                        return Failure::Head {
                            detail: format!(
                                "argument {} repeats `{name}` = {}, but the tuple has {}",
                                i + 1,
                                show(&env[s]),
                                show(v)
                            ),
                        };
                    }
                    env[s] = v.clone();
                    bound[s] = true;
                }
                _ => deferred.push(i),
            }
        }
        for &i in &deferred {
            let e = &cr.head[i];
            if let Ok(x) = eval_const(e, &env, &bound)
                && x != tuple[i]
            {
                return Failure::Head {
                    detail: format!(
                        "argument {} is always {} (`{}`), the tuple has {}",
                        i + 1,
                        show(&x),
                        rule.head.args[i],
                        show(&tuple[i])
                    ),
                };
            }
        }
        let steps = &cr.variants[0];
        let mut frontier = vec![env];
        for (k, step) in steps.iter().map(|s| with_range(s, Range::Full)).enumerate() {
            let mut next = Vec::new();
            let mut ex = Exec::new(&self.rels, lim);
            for env in &frontier {
                let mut e = env.clone();
                // Compiled steps assume their variables are free; keep only
                // results that agree with what the head already fixed.
                let _ = ex.run(std::slice::from_ref(&step), &mut e, &mut |_, e| {
                    let agrees = bound.iter().enumerate().all(|(s, b)| !*b || e[s] == env[s]);
                    if agrees && next.len() < MAX_FRONTIER {
                        next.push(e.clone());
                    }
                    Ok(())
                });
                if next.len() >= MAX_FRONTIER {
                    break;
                }
            }
            let lit = step_literal(rule, &rule.plan[k]);
            if next.is_empty() {
                let env = &frontier[0];
                return match &step {
                    CStep::Scan {
                        rel,
                        index,
                        key,
                        binds,
                        ..
                    } => {
                        let r = &self.rels[*rel];
                        let mut known: Vec<(usize, Value)> = Vec::new();
                        if let Some(ix) = index {
                            for (c, e) in r.indexes[*ix].cols.iter().zip(key) {
                                if let Ok(v) = super::interp::eval_pub(e, env) {
                                    known.push((*c, v));
                                }
                            }
                        }
                        for &(c, s) in binds {
                            if bound[s as usize] {
                                known.push((c, env[s as usize].clone()));
                            }
                        }
                        let mut scored: Vec<(usize, Vec<Value>)> = (0..r.len().min(200_000) as u32)
                            .map(|id| {
                                let t = r.tuple(id);
                                (
                                    known.iter().filter(|(c, v)| t[*c] == *v).count(),
                                    t.to_vec(),
                                )
                            })
                            .collect();
                        scored.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
                        Failure::NoMatch {
                            atom: instantiate(lit, cr, env, Some(&bound)),
                            candidates: scored.into_iter().take(3).map(|(_, t)| t).collect(),
                            relation_size: r.len(),
                        }
                    }
                    CStep::Negate {
                        rel,
                        index,
                        key,
                        all,
                    } => {
                        let keyv: Vec<Value> = key
                            .iter()
                            .filter_map(|e| super::interp::eval_pub(e, env).ok())
                            .collect();
                        let r = &self.rels[*rel];
                        let cols: Vec<usize> = if *all {
                            (0..r.arity).collect()
                        } else {
                            index
                                .map(|ix| r.indexes[ix].cols.clone())
                                .unwrap_or_default()
                        };
                        let existing = (0..r.len() as u32)
                            .map(|id| r.tuple(id).to_vec())
                            .find(|t| cols.iter().zip(&keyv).all(|(c, v)| t[*c] == *v))
                            .unwrap_or_default();
                        Failure::NegationHolds {
                            atom: instantiate(lit, cr, env, Some(&bound)),
                            existing,
                        }
                    }
                    _ => Failure::ConditionFalse {
                        condition: lit.to_string(),
                        example: instantiate(lit, cr, env, Some(&bound)),
                    },
                };
            }
            // Variables bound by this step.
            match &step {
                CStep::Scan { binds, .. } => {
                    binds.iter().for_each(|&(_, s)| bound[s as usize] = true)
                }
                CStep::Assign(s, _) | CStep::AggAssign(s, _) => bound[*s as usize] = true,
                _ => {}
            }
            frontier = next;
        }
        // Check head arguments computed from the body.
        let any = frontier.iter().any(|env| {
            deferred
                .iter()
                .all(|&i| super::interp::eval_pub(&cr.head[i], env).is_ok_and(|x| x == tuple[i]))
        });
        if any {
            Failure::Derivable
        } else {
            Failure::Head {
                detail: format!(
                    "the body matches but the computed head `{}` never equals the tuple",
                    rule.head
                ),
            }
        }
    }
}

fn with_range(s: &CStep, r: Range) -> CStep {
    let mut s = s.clone();
    if let CStep::Scan { range, .. } = &mut s {
        *range = r;
    }
    s
}

fn eval_const(
    e: &super::interp::compile::CExpr,
    env: &[Value],
    bound: &[bool],
) -> Result<Value, ()> {
    use super::interp::compile::CExpr;
    fn uses_unbound(e: &CExpr, bound: &[bool]) -> bool {
        match e {
            CExpr::Slot(s) => !bound[*s as usize],
            CExpr::Const(_) | CExpr::Autoinc(_) => false,
            CExpr::Neg(_, x) => uses_unbound(x, bound),
            CExpr::Bin(_, _, a, b) => uses_unbound(a, bound) || uses_unbound(b, bound),
            CExpr::Builtin(_, _, args) | CExpr::Ext(_, args) => {
                args.iter().any(|a| uses_unbound(a, bound))
            }
        }
    }
    if uses_unbound(e, bound) {
        return Err(());
    }
    super::interp::eval_pub(e, env).map_err(|_| ())
}

fn step_literal<'a>(
    rule: &'a super::front::ast::Rule,
    step: &super::front::ast::Step,
) -> &'a Literal {
    use super::front::ast::Step;
    let i = match step {
        Step::Scan(i) | Step::Negate(i) | Step::Filter(i) => *i,
        Step::Assign { lit, .. } => *lit,
    };
    &rule.body[i]
}

/// The literal with its variables replaced by their current values.
/// With `bound`, variables not yet bound keep their names.
fn instantiate(lit: &Literal, cr: &CRule, env: &[Value], bound: Option<&[bool]>) -> String {
    let value_of = |name: &str| {
        cr.slot_names
            .iter()
            .position(|n| n == name)
            .filter(|&s| bound.is_none_or(|b| b[s]))
            .map(|s| show(&env[s]))
    };
    let text = lit.to_string();
    let mut vars: Vec<(String, String)> = Vec::new();
    for n in &cr.slot_names {
        if let Some(v) = value_of(n) {
            vars.push((n.clone(), v));
        }
    }
    // Replace whole-word variable names (not a functor's or a relation's name before `(`).
    super::tokens::map_tokens(&text, |kind, word, next| {
        if kind != super::tokens::Kind::Ident || next == Some('(') {
            return None;
        }
        vars.iter().find(|(n, _)| n == word).map(|(_, v)| v.clone())
    })
}

fn show_tuple(t: &[Value]) -> String {
    t.iter().map(show).collect::<Vec<_>>().join(", ")
}

impl Explanation {
    /// A text tree, one line per node.
    pub fn render(&self) -> String {
        let mut s = String::new();
        self.render_into(&mut s, "", "");
        s
    }

    fn render_into(&self, s: &mut String, first: &str, rest: &str) {
        let head = format!("{}({})", self.relation, show_tuple(&self.tuple));
        match &self.how {
            How::Input { origin } => {
                let _ = writeln!(s, "{first}{head}  [input: {origin}]");
            }
            How::Truncated => {
                let _ = writeln!(s, "{first}{head}  [... explanation cut]");
            }
            How::Rule { rule, premises, .. } => {
                let _ = writeln!(s, "{first}{head}  [by {rule}]");
                for (i, p) in premises.iter().enumerate() {
                    let last = i + 1 == premises.len();
                    let (f, r) = tree_branch(rest, last);
                    match p {
                        Premise::Tuple(e) => e.render_into(s, &f, &r),
                        Premise::Absent { atom } => {
                            let _ = writeln!(s, "{f}{atom}  [no such tuple]");
                        }
                        Premise::Condition { text } => {
                            let _ = writeln!(s, "{f}{text}  [holds]");
                        }
                    }
                }
            }
        }
    }
}

impl WhyNot {
    pub fn render(&self) -> String {
        let mut s = format!(
            "{}({}) is not derived.\n",
            self.relation,
            show_tuple(&self.tuple)
        );
        if let Some(r) = &self.reason {
            let _ = writeln!(s, "  {r}");
        }
        for a in &self.rules {
            let _ = writeln!(s, "- {}: {}", a.rule, a.rule_text);
            let _ = match &a.failure {
                Failure::Head { detail } => writeln!(s, "    head does not fit: {detail}"),
                Failure::NoMatch {
                    atom,
                    candidates,
                    relation_size,
                } => {
                    let _ = writeln!(s, "    no match for {atom}");
                    if candidates.is_empty() {
                        writeln!(s, "    (the relation is empty)")
                    } else {
                        let _ = writeln!(s, "    closest of {relation_size} tuple(s):");
                        for c in candidates {
                            let _ = writeln!(s, "      ({})", show_tuple(c));
                        }
                        Ok(())
                    }
                }
                Failure::NegationHolds { atom, existing } => writeln!(
                    s,
                    "    negation fails: {} exists ({})",
                    atom.trim_start_matches('!'),
                    show_tuple(existing)
                ),
                Failure::ConditionFalse { condition, example } => {
                    writeln!(s, "    condition `{condition}` is false, e.g. {example}")
                }
                Failure::Derivable => writeln!(
                    s,
                    "    every literal matches: the tuple is derivable (has the program run?)"
                ),
            };
        }
        s
    }
}

/// Parse `rel(a, b, "c d")` into a relation name and typed values.
pub fn parse_query(
    program: &super::Program,
    text: &str,
) -> Result<(String, Vec<Value>), LogicError> {
    let bad = |m: &str| {
        LogicError::Usage(format!(
            "cannot read the tuple `{text}`: {m}; write it as rel(1, \"a\", 2.5)"
        ))
    };
    let t = text.trim();
    let open = t.find('(').ok_or_else(|| bad("missing `(`"))?;
    let name = t[..open].trim();
    let inner = t[open + 1..]
        .strip_suffix(')')
        .ok_or_else(|| bad("missing `)` at the end"))?;
    let decl = program
        .relation(name)
        .ok_or_else(|| LogicError::Usage(format!("unknown relation `{name}`")))?;
    let mut fields = Vec::new();
    let mut cur = String::new();
    let (mut in_str, mut depth) = (false, 0);
    for c in inner.chars() {
        match c {
            '"' => {
                in_str = !in_str;
                cur.push(c)
            }
            '[' if !in_str => {
                depth += 1;
                cur.push(c)
            }
            ']' if !in_str => {
                depth -= 1;
                cur.push(c)
            }
            ',' if !in_str && depth == 0 => fields.push(std::mem::take(&mut cur)),
            _ => cur.push(c),
        }
    }
    if !cur.trim().is_empty() || !fields.is_empty() {
        fields.push(cur);
    }
    if fields.len() != decl.arity() {
        return Err(bad(&format!(
            "`{name}` has {} attribute(s), found {}",
            decl.arity(),
            fields.len()
        )));
    }
    let mut vals = Vec::new();
    for (f, a) in fields.iter().zip(&decl.attrs) {
        let f = f.trim();
        let f = if a.ty == BaseTy::Symbol {
            f.strip_prefix('"')
                .and_then(|x| x.strip_suffix('"'))
                .unwrap_or(f)
        } else {
            f
        };
        vals.push(Value::parse(a.ty, f).map_err(|m| bad(&m.to_string()))?);
    }
    Ok((name.to_string(), vals))
}

/// The prefixes of a tree child under `rest`: its own line and the lines below it.
pub fn tree_branch(rest: &str, last: bool) -> (String, String) {
    let (first, below) = if last {
        ("└─ ", "   ")
    } else {
        ("├─ ", "│  ")
    };
    (format!("{rest}{first}"), format!("{rest}{below}"))
}
