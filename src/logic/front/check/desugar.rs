//! Rewrites into the core language before typing: aggregates and expression
//! arguments lifted into fresh variables, `eqrel` declarations into rules.

use super::super::ast::*;
use super::checker::Checker;
use super::walk::{expr_vars, lit_exprs_mut};
use std::collections::BTreeSet;

impl Checker<'_> {
    /// Replaces expression arguments of positive atoms (in aggregate bodies too) by fresh
    /// variables `__argN`, adding `__argN = <expression>` to the same body: all of them when
    /// `every`, else those reading a variable that the same atom binds as a plain argument.
    /// Returns whether any was replaced.
    pub(super) fn lift_self_bound_args(&mut self, body: &mut Vec<Literal>, every: bool) -> bool {
        let mut changed = false;
        let mut added = Vec::new();
        for l in body.iter_mut() {
            for e in lit_exprs_mut(l) {
                if let ExprKind::Agg(a) = &mut e.kind {
                    changed |= self.lift_self_bound_args(&mut a.body, every);
                }
            }
            let Literal::Pos(atom) = l else {
                continue;
            };
            let plain: BTreeSet<String> = atom
                .args
                .iter()
                .filter_map(|e| match &e.kind {
                    ExprKind::Var(v) => Some(v.clone()),
                    _ => None,
                })
                .collect();
            for arg in &mut atom.args {
                if matches!(
                    arg.kind,
                    ExprKind::Var(_) | ExprKind::Wild | ExprKind::Agg(_)
                ) {
                    continue;
                }
                let vars = expr_vars(arg);
                if vars.is_empty() || !(every || vars.iter().any(|v| plain.contains(v))) {
                    continue;
                }
                let span = arg.span;
                let var = Expr {
                    kind: ExprKind::Var(format!("__arg{}", self.arg_counter)),
                    span,
                    ty: None,
                };
                self.arg_counter += 1;
                let expr = std::mem::replace(arg, var.clone());
                added.push(Literal::Cmp(CmpOp::Eq, var, expr, span));
                changed = true;
            }
        }
        body.extend(added);
        changed
    }

    pub(super) fn lift_in_body(&mut self, body: &mut [Literal]) {
        for l in body.iter_mut() {
            for e in lit_exprs_mut(l) {
                if let ExprKind::Agg(a) = &mut e.kind {
                    let mut inner = std::mem::take(&mut a.body);
                    self.lift_in_body(&mut inner);
                    let mut lifted = Vec::new();
                    for l2 in &mut inner {
                        for e2 in lit_exprs_mut(l2) {
                            self.lift_aggs(e2, &mut lifted);
                        }
                    }
                    inner.extend(lifted);
                    a.body = inner;
                }
            }
        }
    }

    /// Replace aggregates nested in `e` by fresh variables; keep a top-level
    /// `x = agg` / `agg = x` as it is (the planner treats it as an assignment).
    pub(super) fn lift_aggs(&mut self, e: &mut Expr, out: &mut Vec<Literal>) {
        match &mut e.kind {
            ExprKind::Agg(a) => {
                let mut inner = std::mem::take(&mut a.body);
                self.lift_in_body(&mut inner);
                let mut nested = Vec::new();
                for l in &mut inner {
                    for e2 in lit_exprs_mut(l) {
                        self.lift_aggs(e2, &mut nested);
                    }
                }
                inner.extend(nested);
                a.body = inner;
                let name = format!("__agg{}", self.agg_counter);
                self.agg_counter += 1;
                let span = e.span;
                let var = Expr {
                    kind: ExprKind::Var(name),
                    span,
                    ty: None,
                };
                let agg = std::mem::replace(e, var.clone());
                out.push(Literal::Cmp(CmpOp::Eq, var, agg, span));
            }
            ExprKind::Neg(x) => self.lift_aggs(x, out),
            ExprKind::Bin(_, a, b) => {
                self.lift_aggs(a, out);
                self.lift_aggs(b, out);
            }
            ExprKind::Builtin(_, args) | ExprKind::Ext(_, args) => {
                for a in args {
                    self.lift_aggs(a, out);
                }
            }
            _ => {}
        }
    }
}

/// The rules that make `rel` an equivalence relation:
/// `rel(x, x) :- rel(x, _).`, `rel(y, x) :- rel(x, y).`,
/// `rel(x, z) :- rel(x, y), rel(y, z).` (cited at the declaration).
pub(super) fn eqrel_rules(rel: &str, span: Span) -> Vec<Rule> {
    let v = |n: &str| Expr {
        kind: if n == "_" {
            ExprKind::Wild
        } else {
            ExprKind::Var(n.to_string())
        },
        span,
        ty: None,
    };
    let atom = |a: &str, b: &str| Atom {
        rel: rel.to_string(),
        args: vec![v(a), v(b)],
        span,
    };
    let rule = |head: Atom, body: Vec<Atom>, what: &str| Rule {
        head,
        body: body.into_iter().map(Literal::Pos).collect(),
        plan: Vec::new(),
        label: Some(format!("eqrel_{what}({rel})")),
        span,
    };
    vec![
        rule(atom("x", "x"), vec![atom("x", "_")], "reflexive"),
        rule(atom("y", "x"), vec![atom("x", "y")], "symmetric"),
        rule(
            atom("x", "z"),
            vec![atom("x", "y"), atom("y", "z")],
            "transitive",
        ),
    ]
}
