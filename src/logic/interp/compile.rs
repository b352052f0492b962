//! Turns checked rules into slot-addressed steps for the interpreter, with the
//! semi-naive variants of recursive rules.

use super::store::Relation;
use crate::logic::front::Program;
use crate::logic::front::ast::*;
use crate::logic::functors::{self, Functor};
use crate::logic::value::Value;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::sync::atomic::AtomicI64;

#[derive(Clone, Debug)]
pub enum CExpr {
    Slot(u32),
    Const(Value),
    Neg(BaseTy, Box<CExpr>),
    Bin(BinOp, BaseTy, Box<CExpr>, Box<CExpr>),
    /// The type is the result type for min/max, the argument type for to_string.
    Builtin(Builtin, BaseTy, Vec<CExpr>),
    Ext(&'static Functor, Vec<CExpr>),
    /// `autoinc()`: takes the next number of the engine's counter.
    Autoinc(Arc<AtomicI64>),
}

impl std::fmt::Debug for Functor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "@{}", self.sig.name)
    }
}

/// Which tuples of a relation a scan reads in semi-naive evaluation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Range {
    /// Everything known at the start of the iteration.
    Full,
    /// Known before the previous iteration.
    Old,
    /// New in the previous iteration.
    Delta,
}

#[derive(Clone, Debug)]
pub struct CAgg {
    pub op: AggOp,
    pub ty: BaseTy,
    pub target: Option<CExpr>,
    pub steps: Vec<CStep>,
}

#[derive(Clone, Debug)]
pub enum CStep {
    Scan {
        rel: usize,
        /// Index position on `rel` for the bound columns (None: no column bound).
        index: Option<usize>,
        key: Vec<CExpr>,
        /// `key` when it is only variables (the fast path).
        key_slots: Option<Vec<u32>>,
        /// Columns that later steps read, when some bound column is not read
        /// (or is `_`): tuples agreeing on them give the same results, so only
        /// the first is followed. Never set inside aggregates, where every match counts.
        project: Option<Vec<usize>>,
        binds: Vec<(usize, u32)>,
        checks: Vec<(usize, CExpr)>,
        range: Range,
        /// Position of the atom in the rule body (for provenance).
        lit: usize,
    },
    Negate {
        rel: usize,
        index: Option<usize>,
        key: Vec<CExpr>,
        /// All columns are bound: a set-membership test.
        all: bool,
    },
    Filter(CmpOp, BaseTy, CExpr, CExpr),
    StrTest {
        is_match: bool,
        negated: bool,
        a: CExpr,
        b: CExpr,
    },
    Assign(u32, CExpr),
    AggAssign(u32, Box<CAgg>),
    /// `other op agg` (or `agg op other` when `agg_left`).
    AggFilter {
        op: CmpOp,
        ty: BaseTy,
        other: CExpr,
        agg: Box<CAgg>,
        agg_left: bool,
    },
}

#[derive(Clone, Debug)]
pub struct CRule {
    /// Index in `Program::rules`.
    pub id: usize,
    pub head_rel: usize,
    pub head: Vec<CExpr>,
    pub slot_names: Vec<String>,
    /// One plan, or one per recursive atom for semi-naive evaluation.
    pub variants: Vec<Vec<CStep>>,
    pub recursive: bool,
}

struct Slots {
    names: Vec<String>,
    map: BTreeMap<String, u32>,
    /// The engine's `autoinc()` counter.
    counter: Arc<AtomicI64>,
}

impl Slots {
    fn get(&mut self, v: &str) -> u32 {
        if let Some(&s) = self.map.get(v) {
            return s;
        }
        let s = self.names.len() as u32;
        self.names.push(v.to_string());
        self.map.insert(v.to_string(), s);
        s
    }
}

pub fn compile_rule(
    prog: &Program,
    id: usize,
    rels: &mut [Relation],
    in_stratum: &[bool],
    counter: &Arc<AtomicI64>,
) -> CRule {
    let rule = &prog.rules[id];
    let mut slots = Slots {
        names: Vec::new(),
        map: BTreeMap::new(),
        counter: counter.clone(),
    };
    let steps = compile_steps(prog, &rule.body, &rule.plan, &mut slots, rels, Vec::new());

    let head: Vec<CExpr> = rule.head.args.iter().map(|e| expr(e, &mut slots)).collect();
    let mut steps = steps;
    // `autoinc()` is evaluated once per body match: only atoms that bind nothing read later
    // are reduced to their first tuple (Soufflé's existence checks).
    let counts_matches = head.iter().any(has_autoinc) || steps.iter().any(step_has_autoinc);
    set_projections(&mut steps, &head, rels, counts_matches);
    let head_rel = prog.rel_index[&rule.head.rel];
    let rec: Vec<usize> = steps
        .iter()
        .enumerate()
        .filter(|(_, s)| matches!(s, CStep::Scan { rel, .. } if in_stratum[*rel]))
        .map(|(i, _)| i)
        .collect();
    let variants = if rec.is_empty() {
        vec![steps]
    } else {
        rec.iter()
            .enumerate()
            .map(|(k, &delta_at)| {
                let mut v = steps.clone();
                for (k2, &at) in rec.iter().enumerate() {
                    if let CStep::Scan { range, .. } = &mut v[at] {
                        *range = match k2.cmp(&k) {
                            std::cmp::Ordering::Less => Range::Old,
                            std::cmp::Ordering::Equal => Range::Delta,
                            std::cmp::Ordering::Greater => Range::Full,
                        };
                    }
                }
                let _ = delta_at;
                v
            })
            .collect()
    };
    CRule {
        id,
        head_rel,
        head,
        slot_names: slots.names,
        variants,
        recursive: !rec.is_empty(),
    }
}

/// `bound`: variables bound before these steps (an aggregate's outer variables).
fn compile_steps(
    prog: &Program,
    body: &[Literal],
    plan: &[Step],
    slots: &mut Slots,
    rels: &mut [Relation],
    mut bound: Vec<String>,
) -> Vec<CStep> {
    let mut out = Vec::new();
    for step in plan {
        match step {
            Step::Scan(i) => {
                let Literal::Pos(a) = &body[*i] else {
                    unreachable!("scan of a non-atom")
                };
                let rel = prog.rel_index[&a.rel];
                let mut key_cols = Vec::new();
                let mut key = Vec::new();
                let mut binds = Vec::new();
                let mut checks = Vec::new();
                let mut newly: Vec<String> = Vec::new();
                for (c, e) in a.args.iter().enumerate() {
                    match &e.kind {
                        ExprKind::Wild => {}
                        ExprKind::Var(v) if !bound.contains(v) && !newly.contains(v) => {
                            binds.push((c, slots.get(v)));
                            newly.push(v.clone());
                        }
                        _ => {
                            let uses_new = check_vars(e).iter().any(|v| newly.contains(v));
                            if uses_new {
                                checks.push((c, expr(e, slots)));
                            } else {
                                key_cols.push(c);
                                key.push(expr(e, slots));
                            }
                        }
                    }
                }
                bound.extend(newly);
                let index = if key_cols.is_empty() {
                    None
                } else {
                    Some(rels[rel].ensure_index(&key_cols))
                };
                let key_slots = key
                    .iter()
                    .map(|e| match e {
                        CExpr::Slot(s) => Some(*s),
                        _ => None,
                    })
                    .collect::<Option<Vec<u32>>>();
                out.push(CStep::Scan {
                    rel,
                    index,
                    key_slots,
                    project: None,
                    key,
                    binds,
                    checks,
                    range: Range::Full,
                    lit: *i,
                });
            }
            Step::Negate(i) => {
                let Literal::Neg(a) = &body[*i] else {
                    unreachable!("negation of a non-atom")
                };
                let rel = prog.rel_index[&a.rel];
                let cols: Vec<usize> = (0..a.args.len())
                    .filter(|&c| !matches!(a.args[c].kind, ExprKind::Wild))
                    .collect();
                let key = cols.iter().map(|&c| expr(&a.args[c], slots)).collect();
                let all = cols.len() == a.args.len();
                let index = if all || cols.is_empty() {
                    None
                } else {
                    Some(rels[rel].ensure_index(&cols))
                };
                out.push(CStep::Negate {
                    rel,
                    index,
                    key,
                    all,
                });
            }
            Step::Filter(i) => match &body[*i] {
                Literal::Cmp(op, a, b, _) => {
                    let ty = a.ty.or(b.ty).unwrap_or(BaseTy::Number);
                    match (&a.kind, &b.kind) {
                        (ExprKind::Agg(g), _) => out.push(CStep::AggFilter {
                            op: *op,
                            ty,
                            other: expr(b, slots),
                            agg: Box::new(agg(prog, g, slots, rels, &bound)),
                            agg_left: true,
                        }),
                        (_, ExprKind::Agg(g)) => out.push(CStep::AggFilter {
                            op: *op,
                            ty,
                            other: expr(a, slots),
                            agg: Box::new(agg(prog, g, slots, rels, &bound)),
                            agg_left: false,
                        }),
                        _ => out.push(CStep::Filter(*op, ty, expr(a, slots), expr(b, slots))),
                    }
                }
                Literal::StrTest {
                    is_match,
                    negated,
                    args,
                    ..
                } => out.push(CStep::StrTest {
                    is_match: *is_match,
                    negated: *negated,
                    a: expr(&args[0], slots),
                    b: expr(&args[1], slots),
                }),
                _ => unreachable!("filter of an atom"),
            },
            Step::Assign {
                lit,
                var,
                var_on_left,
            } => {
                let Literal::Cmp(_, a, b, _) = &body[*lit] else {
                    unreachable!("assign from a non-comparison")
                };
                let e = if *var_on_left { b } else { a };
                let s = slots.get(var);
                bound.push(var.clone());
                match &e.kind {
                    ExprKind::Agg(g) => out.push(CStep::AggAssign(
                        s,
                        Box::new(agg(prog, g, slots, rels, &bound)),
                    )),
                    _ => out.push(CStep::Assign(s, expr(e, slots))),
                }
            }
        }
    }
    out
}

fn check_vars(e: &Expr) -> Vec<String> {
    crate::logic::front::check::expr_vars(e)
}

fn agg(
    prog: &Program,
    g: &Aggregate,
    slots: &mut Slots,
    rels: &mut [Relation],
    bound: &[String],
) -> CAgg {
    let steps = compile_steps(prog, &g.body, &g.plan, slots, rels, bound.to_vec());
    CAgg {
        op: g.op,
        ty: g
            .target
            .as_ref()
            .and_then(|t| t.ty)
            .unwrap_or(BaseTy::Number),
        target: g.target.as_ref().map(|t| expr(t, slots)),
        steps,
    }
}

fn expr(e: &Expr, slots: &mut Slots) -> CExpr {
    let ty = e.ty.unwrap_or(BaseTy::Number);
    match &e.kind {
        ExprKind::Var(v) => CExpr::Slot(slots.get(v)),
        ExprKind::Wild => unreachable!("wildcards are handled by the scan"),
        ExprKind::Int(i) => CExpr::Const(match ty {
            BaseTy::Unsigned => Value::Unsigned(*i as u64),
            BaseTy::Float => Value::float(*i as f64),
            _ => Value::Number(*i as i64),
        }),
        ExprKind::Float(f) => CExpr::Const(Value::float(*f)),
        ExprKind::Str(s) => CExpr::Const(Value::sym(s)),
        ExprKind::Neg(x) => CExpr::Neg(ty, Box::new(expr(x, slots))),
        ExprKind::Bin(op, a, b) => {
            CExpr::Bin(*op, ty, Box::new(expr(a, slots)), Box::new(expr(b, slots)))
        }
        ExprKind::Builtin(Builtin::Autoinc, _) => CExpr::Autoinc(slots.counter.clone()),
        ExprKind::Builtin(b, args) => {
            let t = if *b == Builtin::ToString {
                args[0].ty.unwrap_or(BaseTy::Number)
            } else {
                ty
            };
            CExpr::Builtin(*b, t, args.iter().map(|a| expr(a, slots)).collect())
        }
        ExprKind::Ext(name, args) => CExpr::Ext(
            functors::lookup(name).expect("checked functor"),
            args.iter().map(|a| expr(a, slots)).collect(),
        ),
        ExprKind::Agg(_) => unreachable!("aggregates are lifted into their own literals"),
    }
}

/// Mark scans whose bound columns are partly unused afterwards (see `CStep::Scan::project`).
fn set_projections(steps: &mut [CStep], head: &[CExpr], rels: &[Relation], counts_matches: bool) {
    for i in 0..steps.len() {
        let mut used = Vec::new();
        for s in &steps[i + 1..] {
            step_reads(s, &mut used);
        }
        head.iter().for_each(|e| expr_reads(e, &mut used));
        if let CStep::Scan {
            rel,
            key,
            binds,
            checks,
            project,
            ..
        } = &mut steps[i]
        {
            let wild = rels[*rel].arity - key.len() - binds.len() - checks.len();
            let live: Vec<usize> = binds
                .iter()
                .filter(|(_, s)| used.contains(s))
                .map(|(c, _)| *c)
                .collect();
            if (wild > 0 || live.len() < binds.len()) && (!counts_matches || live.is_empty()) {
                *project = Some(live);
            }
        }
    }
}

fn step_reads(s: &CStep, out: &mut Vec<u32>) {
    match s {
        CStep::Scan { key, checks, .. } => {
            key.iter().for_each(|e| expr_reads(e, out));
            checks.iter().for_each(|(_, e)| expr_reads(e, out));
        }
        CStep::Negate { key, .. } => key.iter().for_each(|e| expr_reads(e, out)),
        CStep::Filter(_, _, a, b) | CStep::StrTest { a, b, .. } => {
            expr_reads(a, out);
            expr_reads(b, out);
        }
        CStep::Assign(_, e) => expr_reads(e, out),
        CStep::AggAssign(_, g) => agg_reads(g, out),
        CStep::AggFilter { other, agg, .. } => {
            expr_reads(other, out);
            agg_reads(agg, out);
        }
    }
}

fn agg_reads(g: &CAgg, out: &mut Vec<u32>) {
    g.steps.iter().for_each(|s| step_reads(s, out));
    if let Some(t) = &g.target {
        expr_reads(t, out);
    }
}

fn expr_reads(e: &CExpr, out: &mut Vec<u32>) {
    match e {
        CExpr::Slot(s) => out.push(*s),
        CExpr::Const(_) | CExpr::Autoinc(_) => {}
        CExpr::Neg(_, x) => expr_reads(x, out),
        CExpr::Bin(_, _, a, b) => {
            expr_reads(a, out);
            expr_reads(b, out);
        }
        CExpr::Builtin(_, _, args) | CExpr::Ext(_, args) => {
            args.iter().for_each(|a| expr_reads(a, out))
        }
    }
}

fn has_autoinc(e: &CExpr) -> bool {
    match e {
        CExpr::Autoinc(_) => true,
        CExpr::Slot(_) | CExpr::Const(_) => false,
        CExpr::Neg(_, x) => has_autoinc(x),
        CExpr::Bin(_, _, a, b) => has_autoinc(a) || has_autoinc(b),
        CExpr::Builtin(_, _, args) | CExpr::Ext(_, args) => args.iter().any(has_autoinc),
    }
}

fn step_has_autoinc(s: &CStep) -> bool {
    match s {
        CStep::Scan { key, checks, .. } => {
            key.iter().any(has_autoinc) || checks.iter().any(|(_, e)| has_autoinc(e))
        }
        CStep::Negate { key, .. } => key.iter().any(has_autoinc),
        CStep::Filter(_, _, a, b) | CStep::StrTest { a, b, .. } => has_autoinc(a) || has_autoinc(b),
        CStep::Assign(_, e) => has_autoinc(e),
        CStep::AggAssign(_, g) => agg_has_autoinc(g),
        CStep::AggFilter { other, agg, .. } => has_autoinc(other) || agg_has_autoinc(agg),
    }
}

fn agg_has_autoinc(g: &CAgg) -> bool {
    g.steps.iter().any(step_has_autoinc) || g.target.as_ref().is_some_and(has_autoinc)
}
