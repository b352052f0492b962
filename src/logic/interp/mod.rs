//! The interpreter: semi-naive bottom-up evaluation, stratum by stratum, over
//! hash-indexed relations; optionally records provenance for explanations.

pub mod compile;
mod eval;
pub mod store;

use self::compile::{CAgg, CRule, CStep, Range};
use self::store::{Relation, hash_values};
use super::error::LogicError;
use super::front::Program;
use super::front::ast::{AggOp, BaseTy};
use super::value::Value;
use serde::Serialize;
use std::sync::Arc;

pub use self::eval::compare;

/// Evaluate a compiled expression (used by explanations).
pub(crate) fn eval_pub(e: &compile::CExpr, env: &[Value]) -> Result<Value, String> {
    eval::eval(e, env)
}

/// Where an input tuple came from, so explanations can point at it.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum Origin {
    /// A line of a facts file.
    File { file: String, line: u32 },
    /// An IFC entity `#id`.
    Entity(u64),
    /// A simulation event (its id or description).
    Event(String),
    /// Inserted by Rust code without a source.
    Rust,
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::File { file, line } => write!(f, "{file}:{line}"),
            Origin::Entity(id) => write!(f, "IFC #{id}"),
            Origin::Event(e) => write!(f, "event {e}"),
            Origin::Rust => f.write_str("inserted by the program"),
        }
    }
}

/// How a stored tuple was obtained.
#[derive(Clone, Debug)]
pub enum Prov {
    Input(Origin),
    /// Rule index and the (relation, tuple id) matched by each positive body atom, in plan order.
    Derived {
        rule: u32,
        body: Box<[(u32, u32)]>,
        height: u32,
    },
}

/// Bounds that stop runaway programs (e.g. `n(x+1) :- n(x).`).
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Total tuples over all relations.
    pub max_tuples: usize,
    /// Semi-naive iterations per stratum.
    pub max_iterations: usize,
    /// Body tuples visited over the whole run: the work of joins, which can be huge for
    /// few derived tuples (`r(1) :- a(x), a(y), a(z).`).
    pub max_steps: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_tuples: 50_000_000,
            max_iterations: 100_000,
            // About 3 minutes of joining on one core (10^7 visits/s measured); far above
            // any rule set framewright ships.
            max_steps: 2_000_000_000,
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    pub provenance: bool,
    pub limits: Limits,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct RunStats {
    pub iterations: usize,
    pub tuples: usize,
    /// Problems that did not stop the run (a `match` pattern that is not a
    /// regular expression), each once, sorted.
    pub warnings: Vec<String>,
}

pub struct Engine {
    pub(crate) program: Arc<Program>,
    pub(crate) rels: Vec<Relation>,
    pub(crate) prov: Option<Vec<Vec<Prov>>>,
    /// Compiled rules, per stratum.
    strata: Vec<Vec<CRule>>,
    options: Options,
    ran: bool,
    /// What `ord` handed out in this engine's run (explanations evaluate with the same).
    ords: std::cell::RefCell<super::ops::OrdTable>,
    /// Body tuples the run may still visit (`Limits::max_steps`).
    steps_left: std::cell::Cell<u64>,
}

/// Why an evaluation stopped before its end: a limit, reported as `LogicError::Limit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stop {
    Steps,
    Tuples,
}

type Cont<'k> = dyn FnMut(&mut Exec<'_>, &mut Vec<Value>) -> Result<(), String> + 'k;

pub(crate) struct Exec<'a> {
    rels: &'a [Relation],
    /// Per relation: (end of old tuples, end of tuples visible this iteration).
    lim: &'a [(u32, u32)],
    pub(crate) trail: Vec<(u32, u32)>,
    /// Body tuples this evaluation may still visit.
    budget: u64,
    /// Set when a limit stopped the evaluation (its error string is then only a marker).
    stop: Option<Stop>,
}

impl Engine {
    pub fn new(program: Arc<Program>, options: Options) -> Engine {
        let mut rels: Vec<Relation> = program
            .relations
            .iter()
            .map(|r| Relation::new(r.arity()))
            .collect();
        let mut strata = Vec::new();
        for s in &program.strata {
            let mut in_stratum = vec![false; rels.len()];
            for &r in &s.relations {
                in_stratum[r] = true;
            }
            strata.push(
                s.rules
                    .iter()
                    .map(|&id| compile::compile_rule(&program, id, &mut rels, &in_stratum))
                    .collect(),
            );
        }
        let prov = options.provenance.then(|| vec![Vec::new(); rels.len()]);
        Engine {
            program,
            rels,
            prov,
            strata,
            options,
            ran: false,
            ords: Default::default(),
            steps_left: std::cell::Cell::new(options.limits.max_steps),
        }
    }

    pub fn program(&self) -> &Program {
        &self.program
    }

    /// Run `f` with this engine's `ord` table (explanations re-evaluate rule expressions).
    pub(crate) fn with_ords<R>(&self, f: impl FnOnce() -> R) -> R {
        super::ops::with_ords(&self.ords, f)
    }

    pub(crate) fn rel_id(&self, name: &str) -> Result<usize, LogicError> {
        self.program
            .rel_index
            .get(name)
            .copied()
            .ok_or_else(|| LogicError::Usage(format!("unknown relation `{name}`")))
    }

    /// Check a tuple against the relation's declared types.
    pub(crate) fn check_tuple(&self, rel: usize, tuple: &[Value]) -> Result<(), LogicError> {
        let d = &self.program.relations[rel];
        if d.arity() != tuple.len() {
            return Err(LogicError::Usage(format!(
                "relation `{}` has {} attributes, tuple has {}",
                d.name,
                d.arity(),
                tuple.len()
            )));
        }
        for (a, v) in d.attrs.iter().zip(tuple) {
            if a.ty != v.ty() {
                return Err(LogicError::Usage(format!(
                    "attribute `{}` of `{}` is a {}, got the {} {v}",
                    a.name,
                    d.name,
                    a.ty,
                    v.ty()
                )));
            }
        }
        Ok(())
    }

    /// Add an input tuple; returns false if it was already present.
    pub fn insert(
        &mut self,
        rel: &str,
        tuple: Vec<Value>,
        origin: Origin,
    ) -> Result<bool, LogicError> {
        let r = self.rel_id(rel)?;
        self.check_tuple(r, &tuple)?;
        if self.ran {
            return Err(LogicError::Usage(
                "facts must be inserted before `run`; create a new Engine to run again".into(),
            ));
        }
        match self.rels[r].insert(&tuple) {
            Some(_) => {
                if let Some(p) = &mut self.prov {
                    p[r].push(Prov::Input(origin));
                }
                Ok(true)
            }
            None => Ok(false),
        }
    }

    /// Evaluate every stratum to its fixpoint.
    pub fn run(&mut self) -> Result<RunStats, LogicError> {
        if self.ran {
            return Err(LogicError::Usage(
                "this engine has already run; create a new Engine".into(),
            ));
        }
        self.ran = true;
        let mut stats = RunStats::default();
        let strata = std::mem::take(&mut self.strata);
        let ords = std::mem::take(&mut self.ords);
        let result = super::ops::with_ords(&ords, || {
            let _ = super::ops::take_warnings();
            let result = (|| -> Result<(), LogicError> {
                for (si, rules) in strata.iter().enumerate() {
                    self.run_stratum(si, rules, &mut stats)?;
                }
                Ok(())
            })();
            stats.warnings = super::ops::take_warnings();
            result
        });
        self.ords = ords;
        self.strata = strata;
        result?;
        stats.tuples = self.rels.iter().map(Relation::len).sum();
        Ok(stats)
    }

    fn run_stratum(
        &mut self,
        si: usize,
        rules: &[CRule],
        stats: &mut RunStats,
    ) -> Result<(), LogicError> {
        let members = self.program.strata[si].relations.clone();
        let mut lim: Vec<(u32, u32)> = self
            .rels
            .iter()
            .map(|r| (r.len() as u32, r.len() as u32))
            .collect();
        for &m in &members {
            lim[m].0 = 0;
        }
        let mut iteration = 0usize;
        loop {
            let mut produced: Vec<(usize, Relation, Vec<RecordedBody>)> = Vec::new();
            if !self.program.strata[si].recursive {
                // No rule of the stratum reads its relation: derive straight into it.
                let head = members[0];
                let mut target = std::mem::replace(&mut self.rels[head], Relation::new(0));
                let mut target_prov = self.prov.as_mut().map(|p| std::mem::take(&mut p[head]));
                let result = rules.iter().try_for_each(|rule| {
                    self.eval_rule_into(si, rule, &lim, &mut target, target_prov.as_mut())
                });
                self.rels[head] = target;
                if let (Some(p), Some(tp)) = (&mut self.prov, target_prov) {
                    p[head] = tp;
                }
                result?;
                stats.iterations += 1;
                return self.check_tuple_limit(si, rules, None, 0);
            }
            for rule in rules {
                if iteration > 0 && !rule.recursive {
                    continue;
                }
                let (pending, provs) = self.eval_rule(si, iteration, rule, &lim)?;
                if !pending.is_empty() {
                    produced.push((rule.id, pending, provs));
                }
            }
            let mut grew = false;
            let mut best: Option<(usize, usize)> = None;
            for (rule_id, pending, provs) in produced {
                let head = self.program.rel_index[&self.program.rules[rule_id].head.rel];
                let mut added = 0usize;
                for k in 0..pending.len() {
                    let t = pending.tuple(k as u32);
                    if self.rels[head].insert(t).is_some() {
                        added += 1;
                        if let (Some(p), Some((rule, body))) =
                            (&mut self.prov, provs.get(k).cloned())
                        {
                            let height = 1 + body
                                .iter()
                                .map(|&(r, id)| prov_height(&p[r as usize][id as usize]))
                                .max()
                                .unwrap_or(0);
                            p[head].push(Prov::Derived { rule, body, height });
                        }
                    }
                }
                if added > 0 {
                    grew = true;
                    if best.is_none_or(|(_, a)| added > a) {
                        best = Some((rule_id, added));
                    }
                }
            }
            self.check_tuple_limit(si, rules, best.map(|(r, _)| r), iteration)?;
            iteration += 1;
            stats.iterations += 1;
            if !grew || !self.program.strata[si].recursive {
                break;
            }
            if iteration >= self.options.limits.max_iterations {
                let rule = best.map(|(r, _)| r).unwrap_or(rules[0].id);
                return Err(LogicError::Limit {
                    message: format!(
                        "the stratum of {} still grows after {} iterations (limit); rule {} `{}` keeps adding tuples",
                        self.stratum_names(si),
                        iteration,
                        self.program.rule_name(rule),
                        self.program.rules[rule]
                    ),
                    hint: "a rule that computes new values from its own output (e.g. `n(x+1) :- n(x).`) never stops; bound it with a condition such as `x < 100`, or raise the limit (--max-iterations)".into(),
                });
            }
            for &m in &members {
                lim[m] = (lim[m].1, self.rels[m].len() as u32);
            }
        }
        Ok(())
    }

    /// Stop with a clear error once the relations hold more tuples than allowed.
    fn check_tuple_limit(
        &self,
        si: usize,
        rules: &[CRule],
        best: Option<usize>,
        iteration: usize,
    ) -> Result<(), LogicError> {
        let total: usize = self.rels.iter().map(Relation::len).sum();
        if total > self.options.limits.max_tuples {
            return Err(self.tuple_limit_error(si, best.unwrap_or(rules[0].id), iteration));
        }
        Ok(())
    }

    fn tuple_limit_error(&self, si: usize, rule: usize, iteration: usize) -> LogicError {
        LogicError::Limit {
                message: format!(
                    "more than {} tuples (limit) after {} iteration(s) of the stratum of {}; rule {} `{}` keeps adding tuples",
                    self.options.limits.max_tuples,
                    iteration + 1,
                    self.stratum_names(si),
                    self.program.rule_name(rule),
                    self.program.rules[rule]
                ),
                hint: "a rule that computes new values from its own output (e.g. `n(x+1) :- n(x).`) never stops; bound it with a condition such as `x < 100`, or raise the limit (--max-tuples)".into(),
        }
    }

    /// The error for a limit that stopped rule `rule` in the middle of an iteration.
    fn stop_error(&self, stop: Stop, si: usize, rule: usize, iteration: usize) -> LogicError {
        match stop {
            Stop::Tuples => self.tuple_limit_error(si, rule, iteration),
            Stop::Steps => LogicError::Limit {
                message: format!(
                    "more than {} body tuples visited (limit) in iteration {} of the stratum of {}; rule {} `{}` was joining",
                    self.options.limits.max_steps,
                    iteration + 1,
                    self.stratum_names(si),
                    self.program.rule_name(rule),
                    self.program.rules[rule]
                ),
                hint: "joining relations without shared variables (e.g. `r(1) :- a(x), a(y), a(z).`) visits the product of their sizes; join on shared variables, or raise the limit (--max-steps)".into(),
            },
        }
    }

    /// An `Exec` over the current relations with the run's remaining step budget.
    fn exec<'e>(&'e self, lim: &'e [(u32, u32)]) -> Exec<'e> {
        Exec {
            rels: &self.rels,
            lim,
            trail: Vec::new(),
            budget: self.steps_left.get(),
            stop: None,
        }
    }

    /// Turn an evaluation's failure into the error to report, and keep its step count.
    fn finish(
        &self,
        ex: &Exec<'_>,
        result: Result<(), String>,
        (si, iteration): (usize, usize),
        rule: &CRule,
        env: &[Value],
    ) -> Result<(), LogicError> {
        self.steps_left.set(ex.budget);
        match (result, ex.stop) {
            (Ok(()), _) => Ok(()),
            (Err(_), Some(stop)) => Err(self.stop_error(stop, si, rule.id, iteration)),
            (Err(msg), None) => Err(self.runtime_error(rule, env, msg)),
        }
    }

    /// Evaluate a rule of a non-recursive stratum, inserting into its (taken out) head relation.
    fn eval_rule_into(
        &self,
        si: usize,
        rule: &CRule,
        lim: &[(u32, u32)],
        head: &mut Relation,
        mut prov: Option<&mut Vec<Prov>>,
    ) -> Result<(), LogicError> {
        let mut env = vec![Value::Number(0); rule.slot_names.len()];
        let mut ex = self.exec(lim);
        let mut tuple = Vec::with_capacity(head.arity);
        let all_prov = self.prov.as_ref();
        // The head relation is taken out of `rels` while it fills.
        let others: usize = self.rels.iter().map(Relation::len).sum();
        let max_tuples = self.options.limits.max_tuples;
        for steps in &rule.variants {
            let mut emit = |ex: &mut Exec<'_>, env: &mut Vec<Value>| -> Result<(), String> {
                tuple.clear();
                for e in &rule.head {
                    tuple.push(eval::eval(e, env)?);
                }
                let h = hash_values(tuple.iter());
                let added = head.insert_hashed(&tuple, h).is_some();
                if added && others + head.len() > max_tuples {
                    ex.stop = Some(Stop::Tuples);
                    return Err(String::new());
                }
                if added && let (Some(p), Some(all)) = (prov.as_deref_mut(), all_prov) {
                    let height = 1 + ex
                        .trail
                        .iter()
                        .map(|&(r, id)| prov_height(&all[r as usize][id as usize]))
                        .max()
                        .unwrap_or(0);
                    p.push(Prov::Derived {
                        rule: rule.id as u32,
                        body: ex.trail.clone().into_boxed_slice(),
                        height,
                    });
                }
                Ok(())
            };
            let result = ex.run(steps, &mut env, &mut emit);
            self.finish(&ex, result, (si, 0), rule, &env)?;
        }
        Ok(())
    }

    fn stratum_names(&self, si: usize) -> String {
        let names: Vec<String> = self.program.strata[si]
            .relations
            .iter()
            .map(|&r| format!("`{}`", self.program.relations[r].name))
            .collect();
        names.join(", ")
    }

    /// All head tuples a rule derives this iteration that are not yet stored.
    #[allow(clippy::type_complexity)]
    fn eval_rule(
        &self,
        si: usize,
        iteration: usize,
        rule: &CRule,
        lim: &[(u32, u32)],
    ) -> Result<(Relation, Vec<RecordedBody>), LogicError> {
        // New tuples are collected in a set of their own: a join can derive the
        // same tuple millions of times within one iteration.
        let head_rel = &self.rels[rule.head_rel];
        let mut pending = Relation::new(head_rel.arity);
        let mut provs: Vec<RecordedBody> = Vec::new();
        let want_prov = self.prov.is_some();
        let mut env = vec![Value::Number(0); rule.slot_names.len()];
        let mut ex = self.exec(lim);
        let mut tuple = Vec::with_capacity(head_rel.arity);
        let stored: usize = self.rels.iter().map(Relation::len).sum();
        let max_tuples = self.options.limits.max_tuples;
        for steps in &rule.variants {
            let mut emit = |ex: &mut Exec<'_>, env: &mut Vec<Value>| -> Result<(), String> {
                tuple.clear();
                for e in &rule.head {
                    tuple.push(eval::eval(e, env)?);
                }
                let h = hash_values(tuple.iter());
                if head_rel.find_hashed(&tuple, h).is_none()
                    && pending.insert_hashed(&tuple, h).is_some()
                {
                    // New tuples of this rule alone already pass the limit: stop now
                    // rather than after the iteration (its pending set could exhaust memory).
                    if stored + pending.len() > max_tuples {
                        ex.stop = Some(Stop::Tuples);
                        return Err(String::new());
                    }
                    if want_prov {
                        provs.push((rule.id as u32, ex.trail.clone().into_boxed_slice()));
                    }
                }
                Ok(())
            };
            let result = ex.run(steps, &mut env, &mut emit);
            self.finish(&ex, result, (si, iteration), rule, &env)?;
        }
        Ok((pending, provs))
    }

    fn runtime_error(&self, rule: &CRule, env: &[Value], message: String) -> LogicError {
        let bindings: Vec<String> = rule
            .slot_names
            .iter()
            .zip(env)
            .filter(|(n, _)| !n.starts_with("__"))
            .map(|(n, v)| format!("{n} = {}", show_short(v)))
            .collect();
        LogicError::Runtime {
            rule: self.program.rule_name(rule.id),
            rule_text: self.program.rules[rule.id].to_string(),
            bindings: if bindings.is_empty() {
                "no variables".into()
            } else {
                bindings.join(", ")
            },
            message,
        }
    }

    /// The tuples of a relation, sorted.
    pub fn relation(&self, name: &str) -> Result<Vec<Vec<Value>>, LogicError> {
        Ok(self.rels[self.rel_id(name)?].sorted())
    }

    /// Whether the relation holds the tuple.
    pub fn contains(&self, name: &str, tuple: &[Value]) -> Result<bool, LogicError> {
        Ok(self.rels[self.rel_id(name)?].find(tuple).is_some())
    }

    pub(crate) fn compiled_rules(&self) -> impl Iterator<Item = &CRule> {
        self.strata.iter().flatten()
    }

    pub fn len(&self, name: &str) -> Result<usize, LogicError> {
        Ok(self.rels[self.rel_id(name)?].len())
    }
}

/// Projections of the tuples a scan has followed (see `CStep::Scan::project`).
pub(crate) struct Seen<'c> {
    cols: &'c [usize],
    set: std::collections::HashSet<Vec<Value>, std::hash::BuildHasherDefault<store::FastHasher>>,
}

impl<'c> Seen<'c> {
    fn new(cols: &'c [usize]) -> Self {
        Seen {
            cols,
            set: Default::default(),
        }
    }
    /// Whether no earlier tuple had the same projection.
    fn first(&mut self, t: &[Value]) -> bool {
        self.set
            .insert(self.cols.iter().map(|&c| t[c].clone()).collect())
    }
}

/// Rule index and the body tuples of one derivation.
type RecordedBody = (u32, Box<[(u32, u32)]>);

fn prov_height(p: &Prov) -> u32 {
    match p {
        Prov::Input(_) => 0,
        Prov::Derived { height, .. } => *height,
    }
}

/// `show`, cut to a readable length (a runaway `cat` can bind a megabyte).
fn show_short(v: &Value) -> String {
    const MAX_CHARS: usize = 200;
    let s = show(v);
    match s.char_indices().nth(MAX_CHARS) {
        Some((cut, _)) => format!("{}… ({} bytes)", &s[..cut], s.len()),
        None => s,
    }
}

pub(crate) fn show(v: &Value) -> String {
    match v {
        Value::Symbol(s) => format!("{:?}", &**s),
        other => other.to_string(),
    }
}

impl<'a> Exec<'a> {
    pub(crate) fn new(rels: &'a [Relation], lim: &'a [(u32, u32)]) -> Self {
        Exec {
            rels,
            lim,
            trail: Vec::new(),
            budget: u64::MAX,
            stop: None,
        }
    }

    pub(crate) fn run(
        &mut self,
        steps: &[CStep],
        env: &mut Vec<Value>,
        k: &mut Cont<'_>,
    ) -> Result<(), String> {
        let Some((step, rest)) = steps.split_first() else {
            return k(self, env);
        };
        match step {
            CStep::Scan {
                rel,
                index,
                key,
                key_slots,
                project,
                binds,
                checks,
                range,
                ..
            } => {
                let mut seen = project.as_deref().map(Seen::new);
                let r: &'a Relation = &self.rels[*rel];
                let (old, end) = self.lim[*rel];
                let (lo, hi) = match range {
                    Range::Full => (0, end),
                    Range::Old => (0, old),
                    Range::Delta => (old, end),
                };
                if lo >= hi {
                    return Ok(());
                }
                match index {
                    None => {
                        for id in lo..hi {
                            self.visit(*rel, r, id, binds, checks, &mut seen, rest, env, k)?;
                        }
                    }
                    Some(ix) if key_slots.is_some() => {
                        // Common case: the key is made of bound variables; no allocation.
                        let slots = key_slots.as_deref().unwrap_or_default();
                        let index = &r.indexes[*ix];
                        let ids = index.get(hash_values(slots.iter().map(|&s| &env[s as usize])));
                        let start = ids.partition_point(|&i| i < lo);
                        for &id in &ids[start..] {
                            if id >= hi {
                                break;
                            }
                            let t = r.tuple(id);
                            if index
                                .cols
                                .iter()
                                .zip(slots)
                                .all(|(&c, &s)| t[c] == env[s as usize])
                            {
                                self.visit(*rel, r, id, binds, checks, &mut seen, rest, env, k)?;
                            }
                        }
                    }
                    Some(ix) => {
                        let keyv: Vec<Value> = key
                            .iter()
                            .map(|e| eval::eval(e, env))
                            .collect::<Result<_, _>>()?;
                        let index = &r.indexes[*ix];
                        let ids = index.get(hash_values(keyv.iter()));
                        let start = ids.partition_point(|&i| i < lo);
                        for &id in &ids[start..] {
                            if id >= hi {
                                break;
                            }
                            let t = r.tuple(id);
                            if index.cols.iter().zip(&keyv).all(|(&c, v)| &t[c] == v) {
                                self.visit(*rel, r, id, binds, checks, &mut seen, rest, env, k)?;
                            }
                        }
                    }
                }
                Ok(())
            }
            CStep::Negate {
                rel,
                index,
                key,
                all,
            } => {
                let r = &self.rels[*rel];
                let keyv: Vec<Value> = key
                    .iter()
                    .map(|e| eval::eval(e, env))
                    .collect::<Result<_, _>>()?;
                let exists = if *all {
                    r.find(&keyv).is_some()
                } else {
                    match index {
                        None => !r.is_empty(),
                        Some(ix) => {
                            let index = &r.indexes[*ix];
                            index.get(hash_values(keyv.iter())).iter().any(|&id| {
                                let t = r.tuple(id);
                                index.cols.iter().zip(&keyv).all(|(&c, v)| &t[c] == v)
                            })
                        }
                    }
                };
                if exists {
                    Ok(())
                } else {
                    self.run(rest, env, k)
                }
            }
            CStep::Filter(op, _, a, b) => {
                if compare(*op, &eval::eval(a, env)?, &eval::eval(b, env)?) {
                    self.run(rest, env, k)
                } else {
                    Ok(())
                }
            }
            CStep::StrTest {
                is_match,
                negated,
                a,
                b,
            } => {
                let (x, y) = (eval::eval(a, env)?, eval::eval(b, env)?);
                let (x, y) = (x.as_symbol().unwrap_or(""), y.as_symbol().unwrap_or(""));
                let holds = if *is_match {
                    super::ops::regex_match(x, y)?
                } else {
                    super::ops::contains(x, y)
                };
                if holds != *negated {
                    self.run(rest, env, k)
                } else {
                    Ok(())
                }
            }
            CStep::Assign(slot, e) => {
                env[*slot as usize] = eval::eval(e, env)?;
                self.run(rest, env, k)
            }
            CStep::AggAssign(slot, agg) => match self.aggregate(agg, env)? {
                Some(v) => {
                    env[*slot as usize] = v;
                    self.run(rest, env, k)
                }
                None => Ok(()),
            },
            CStep::AggFilter {
                op,
                other,
                agg,
                agg_left,
                ..
            } => {
                let Some(v) = self.aggregate(agg, env)? else {
                    return Ok(());
                };
                let o = eval::eval(other, env)?;
                let holds = if *agg_left {
                    compare(*op, &v, &o)
                } else {
                    compare(*op, &o, &v)
                };
                if holds {
                    self.run(rest, env, k)
                } else {
                    Ok(())
                }
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn visit(
        &mut self,
        rel: usize,
        r: &Relation,
        id: u32,
        binds: &[(usize, u32)],
        checks: &[(usize, compile::CExpr)],
        seen: &mut Option<Seen<'_>>,
        rest: &[CStep],
        env: &mut Vec<Value>,
        k: &mut Cont<'_>,
    ) -> Result<(), String> {
        if self.budget == 0 {
            self.stop = Some(Stop::Steps);
            return Err(String::new());
        }
        self.budget -= 1;
        let t = r.tuple(id);
        for &(c, s) in binds {
            env[s as usize] = t[c].clone();
        }
        for (c, e) in checks {
            if eval::eval(e, env)? != t[*c] {
                return Ok(());
            }
        }
        if let Some(seen) = seen
            && !seen.first(t)
        {
            return Ok(());
        }
        self.trail.push((rel as u32, id));
        let res = self.run(rest, env, k);
        self.trail.pop();
        res
    }

    /// Value of an aggregate for the current bindings (None: min/max/mean of nothing).
    pub(crate) fn aggregate(
        &mut self,
        agg: &CAgg,
        env: &mut Vec<Value>,
    ) -> Result<Option<Value>, String> {
        let mut count: i64 = 0;
        let mut acc: Option<Value> = None;
        let mut fsum = 0.0f64;
        let trail_len = self.trail.len();
        {
            let mut k = |_: &mut Exec<'_>, env: &mut Vec<Value>| -> Result<(), String> {
                count += 1;
                if let Some(t) = &agg.target {
                    let v = eval::eval(t, env)?;
                    match agg.op {
                        AggOp::Mean => fsum += numeric_f64(&v),
                        AggOp::Sum => {
                            acc = Some(match (acc.take(), v) {
                                (None, v) => v,
                                (Some(Value::Number(a)), Value::Number(b)) => {
                                    Value::Number(a.wrapping_add(b))
                                }
                                (Some(Value::Unsigned(a)), Value::Unsigned(b)) => {
                                    Value::Unsigned(a.wrapping_add(b))
                                }
                                (Some(Value::Float(a)), Value::Float(b)) => Value::float(a.0 + b.0),
                                (Some(a), _) => a,
                            })
                        }
                        AggOp::Min | AggOp::Max => {
                            let better = match &acc {
                                None => true,
                                // Total order (floats too), so the result does not depend on visiting order.
                                Some(a) => {
                                    (agg.op == AggOp::Min && v < *a)
                                        || (agg.op == AggOp::Max && v > *a)
                                }
                            };
                            if better {
                                acc = Some(v);
                            }
                        }
                        AggOp::Count => {}
                    }
                }
                Ok(())
            };
            self.run(&agg.steps, env, &mut k)?;
        }
        self.trail.truncate(trail_len);
        Ok(match agg.op {
            AggOp::Count => Some(Value::Number(count)),
            AggOp::Sum => Some(acc.unwrap_or(match agg.ty {
                BaseTy::Unsigned => Value::Unsigned(0),
                BaseTy::Float => Value::float(0.0),
                _ => Value::Number(0),
            })),
            AggOp::Min | AggOp::Max => acc,
            AggOp::Mean => (count > 0).then(|| Value::float(fsum / count as f64)),
        })
    }
}

fn numeric_f64(v: &Value) -> f64 {
    match v {
        Value::Number(n) => *n as f64,
        Value::Unsigned(n) => *n as f64,
        Value::Float(f) => f.0,
        _ => 0.0,
    }
}
