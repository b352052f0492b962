//! Running the engine: each stratum to its fixpoint (semi-naive), the rules
//! evaluated into new tuples with provenance, and the limits that stop a run.

use super::compile::CRule;
use super::eval;
use super::exec::{Exec, Stop};
use super::store::{Relation, hash_values};
use super::{Engine, Prov, RunStats, show};
use crate::logic::error::{EvalError, LogicError};
use crate::logic::ops;
use crate::logic::value::Value;

impl Engine {
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
        let result = ops::with_ords(&ords, || {
            let _ = ops::take_warnings();
            let result = (|| -> Result<(), LogicError> {
                for (si, rules) in strata.iter().enumerate() {
                    self.run_stratum(si, rules, &mut stats)?;
                }
                Ok(())
            })();
            stats.warnings = ops::take_warnings();
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
        result: Result<(), EvalError>,
        (si, iteration): (usize, usize),
        rule: &CRule,
        env: &[Value],
    ) -> Result<(), LogicError> {
        self.steps_left.set(ex.budget);
        match (result, ex.stop) {
            (Ok(()), _) => Ok(()),
            (Err(_), Some(stop)) => Err(self.stop_error(stop, si, rule.id, iteration)),
            (Err(EvalError(msg)), None) => Err(self.runtime_error(rule, env, msg)),
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
            let mut emit = |ex: &mut Exec<'_>, env: &mut Vec<Value>| -> Result<(), EvalError> {
                tuple.clear();
                for e in &rule.head {
                    tuple.push(eval::eval(e, env)?);
                }
                let h = hash_values(tuple.iter());
                let added = head.insert_hashed(&tuple, h).is_some();
                if added && others + head.len() > max_tuples {
                    ex.stop = Some(Stop::Tuples);
                    return Err(EvalError::default());
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
            let mut emit = |ex: &mut Exec<'_>, env: &mut Vec<Value>| -> Result<(), EvalError> {
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
                        return Err(EvalError::default());
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
