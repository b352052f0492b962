//! Witnesses of `min`/`max` aggregates, as Soufflé grounds them: a variable that only the
//! aggregate's body binds but that the rule uses outside it (`Tallest(s, n) :- n = max h :
//! { Student(s, h) }.`) is bound by a copy of the body in the rule, with the aggregated
//! variable replaced by the aggregate's result. Every body match attaining the extreme is a
//! witness, so ties give one tuple each. (`count`, `sum` and `mean` have no witnesses: the
//! planner reports the witness problem.)

use super::super::ast::*;
use super::checker::Checker;
use super::walk::{expr_vars, rename_expr, rename_lit};
use std::collections::BTreeSet;

impl Checker<'_> {
    /// Rewrite the rule's top-level `min`/`max` aggregates that have witnesses (aggregates are
    /// already lifted into `x = agg` or `x op agg` literals of the body).
    pub(super) fn ground_witnesses(&mut self, rule: &mut Rule) {
        let head_vars: BTreeSet<String> = rule.head.args.iter().flat_map(expr_vars).collect();
        let mut i = 0;
        while i < rule.body.len() {
            self.ground_witnesses_of(rule, i, &head_vars);
            i += 1;
        }
    }

    fn ground_witnesses_of(&mut self, rule: &mut Rule, i: usize, head_vars: &BTreeSet<String>) {
        let Literal::Cmp(op, a, b, span) = &rule.body[i] else {
            return;
        };
        let (op, span) = (*op, *span);
        let (agg, other, agg_left) = match (&a.kind, &b.kind) {
            (ExprKind::Agg(g), _) => (g.as_ref().clone(), b.clone(), true),
            (_, ExprKind::Agg(g)) => (g.as_ref().clone(), a.clone(), false),
            _ => return,
        };
        if !matches!(agg.op, AggOp::Min | AggOp::Max) {
            return;
        }
        let Some(target) = agg.target.clone() else {
            return;
        };
        // Variables the rule uses outside this aggregate (not inside other aggregates).
        let mut outside: BTreeSet<String> = head_vars.clone();
        outside.extend(expr_vars(&other));
        for (j, l) in rule.body.iter().enumerate() {
            if j != i {
                outside.extend(shallow_vars(l));
            }
        }
        let grounded_outside = grounded(
            rule.body
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, l)| l),
        );
        let grounded_inside = grounded(agg.body.iter());
        let target_vars: BTreeSet<String> = expr_vars(&target).into_iter().collect();
        let inner: BTreeSet<String> = agg.body.iter().flat_map(shallow_vars).collect();
        let witnesses: BTreeSet<String> = inner
            .iter()
            .filter(|v| {
                outside.contains(*v)
                    && !grounded_outside.contains(*v)
                    && grounded_inside.contains(*v)
                    && !target_vars.contains(*v)
            })
            .cloned()
            .collect();
        if witnesses.is_empty() {
            return;
        }
        // The aggregate's result, in a variable the copied body can read.
        let result = match &other.kind {
            ExprKind::Var(r) if op == CmpOp::Eq => r.clone(),
            _ => {
                let r = format!("__agg{}", self.agg_counter);
                self.agg_counter += 1;
                let var = Expr {
                    kind: ExprKind::Var(r.clone()),
                    span,
                    ty: None,
                };
                rule.body[i] = if agg_left {
                    Literal::Cmp(op, var.clone(), other.clone(), span)
                } else {
                    Literal::Cmp(op, other.clone(), var.clone(), span)
                };
                rule.body
                    .push(Literal::Cmp(CmpOp::Eq, var, agg_expr(&agg, span), span));
                r
            }
        };
        // Inside the aggregate the witnesses become local variables.
        let n = self.agg_counter;
        self.agg_counter += 1;
        let mut inner_agg = agg.clone();
        for l in &mut inner_agg.body {
            rename_lit(l, &mut |v| {
                witnesses
                    .contains(v)
                    .then(|| ExprKind::Var(format!("__wit{n}_{v}")))
            });
        }
        let at = rule
            .body
            .iter()
            .position(
                |l| matches!(l, Literal::Cmp(_, x, y, _) if is_this(x, &agg) || is_this(y, &agg)),
            )
            .unwrap_or(i);
        if let Literal::Cmp(_, x, y, _) = &mut rule.body[at] {
            for e in [x, y] {
                if is_this(e, &agg) {
                    *e = agg_expr(&inner_agg, span);
                }
            }
        }
        // The copy binds the witnesses; its other variables stay local to it.
        let keep: BTreeSet<String> = outside.iter().cloned().collect();
        let mut rename_local = |v: &str| {
            if target_vars.contains(v) && matches!(target.kind, ExprKind::Var(_)) {
                Some(ExprKind::Var(result.clone()))
            } else if keep.contains(v) {
                None
            } else {
                Some(ExprKind::Var(format!("__wit{n}_{v}")))
            }
        };
        let mut copy: Vec<Literal> = agg.body.clone();
        for l in &mut copy {
            rename_lit(l, &mut rename_local);
        }
        if !matches!(target.kind, ExprKind::Var(_)) {
            let mut t = target.clone();
            rename_expr(&mut t, &mut rename_local);
            let r = Expr {
                kind: ExprKind::Var(result.clone()),
                span,
                ty: None,
            };
            copy.push(Literal::Cmp(CmpOp::Eq, t, r, span));
        }
        rule.body.extend(copy);
    }
}

fn agg_expr(g: &Aggregate, span: Span) -> Expr {
    Expr {
        kind: ExprKind::Agg(Box::new(g.clone())),
        span,
        ty: None,
    }
}

fn is_this(e: &Expr, g: &Aggregate) -> bool {
    matches!(&e.kind, ExprKind::Agg(x) if x.as_ref() == g)
}

/// Variables of a literal outside its aggregates.
fn shallow_vars(l: &Literal) -> BTreeSet<String> {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().flat_map(expr_vars).collect(),
        Literal::Cmp(_, a, b, _) => expr_vars(a).into_iter().chain(expr_vars(b)).collect(),
        Literal::StrTest { args, .. } => args.iter().flat_map(expr_vars).collect(),
    }
}

/// The variables the literals ground: plain arguments of positive atoms, and `x = e` once
/// `e`'s variables are grounded (an aggregate counts as a value).
fn grounded<'l>(lits: impl Iterator<Item = &'l Literal> + Clone) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    loop {
        let before = out.len();
        for l in lits.clone() {
            match l {
                Literal::Pos(a) => {
                    for e in &a.args {
                        if let ExprKind::Var(v) = &e.kind {
                            out.insert(v.clone());
                        }
                    }
                }
                Literal::Cmp(CmpOp::Eq, x, y, _) => {
                    for (v, e) in [(x, y), (y, x)] {
                        if let ExprKind::Var(v) = &v.kind {
                            if expr_vars(e).iter().all(|w| out.contains(w)) {
                                out.insert(v.clone());
                            }
                        }
                    }
                }
                _ => {}
            }
        }
        if out.len() == before {
            return out;
        }
    }
}
