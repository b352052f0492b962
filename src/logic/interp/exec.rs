//! Executing a compiled rule body: scans, negations, filters, assignments and
//! aggregates, one binding at a time, within a step budget.

use super::compile::{self, CAgg, CStep, Range};
use super::eval::{self, compare};
use super::store::{self, Relation, hash_values};
use crate::logic::error::EvalError;
use crate::logic::front::ast::{AggOp, BaseTy};
use crate::logic::ops;
use crate::logic::value::Value;

/// Why an evaluation stopped before its end: a limit, reported as `LogicError::Limit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Stop {
    Steps,
    Tuples,
}

type Cont<'k> = dyn FnMut(&mut Exec<'_>, &mut Vec<Value>) -> Result<(), EvalError> + 'k;

pub(crate) struct Exec<'a> {
    pub(super) rels: &'a [Relation],
    /// Per relation: (end of old tuples, end of tuples visible this iteration).
    pub(super) lim: &'a [(u32, u32)],
    pub(crate) trail: Vec<(u32, u32)>,
    /// Body tuples this evaluation may still visit.
    pub(super) budget: u64,
    /// Set when a limit stopped the evaluation (its error is then only a marker).
    pub(super) stop: Option<Stop>,
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
    ) -> Result<(), EvalError> {
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
                // An invalid pattern makes `match` and `!match` both false.
                let holds = if *is_match {
                    ops::match_test(x, y, *negated)
                } else {
                    ops::contains(x, y) != *negated
                };
                if holds {
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
    ) -> Result<(), EvalError> {
        if self.budget == 0 {
            self.stop = Some(Stop::Steps);
            return Err(EvalError::default());
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
    ) -> Result<Option<Value>, EvalError> {
        let mut count: i64 = 0;
        let mut acc: Option<Value> = None;
        let mut fsum = 0.0f64;
        let trail_len = self.trail.len();
        {
            let mut k = |_: &mut Exec<'_>, env: &mut Vec<Value>| -> Result<(), EvalError> {
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
