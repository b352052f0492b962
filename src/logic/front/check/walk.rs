//! Walks over expressions and rule bodies: the variables they read, their
//! sub-expressions, and the relations a body depends on.

use super::super::ast::*;
use std::collections::BTreeMap;

/// Variables an expression reads (an aggregate reads only its injected variables).
pub fn expr_free_vars(e: &Expr) -> Vec<String> {
    match &e.kind {
        ExprKind::Agg(a) => a.injected.clone(),
        _ => {
            let mut out = expr_vars(e);
            walk_expr(e, &mut |x| {
                if let ExprKind::Agg(a) = &x.kind {
                    out.extend(a.injected.iter().cloned());
                }
            });
            out
        }
    }
}

/// Named variables of an expression, not looking inside aggregates.
pub fn expr_vars(e: &Expr) -> Vec<String> {
    let mut out = Vec::new();
    fn go(e: &Expr, out: &mut Vec<String>) {
        match &e.kind {
            ExprKind::Var(v) if !out.contains(v) => out.push(v.clone()),
            ExprKind::Neg(x) => go(x, out),
            ExprKind::Bin(_, a, b) => {
                go(a, out);
                go(b, out);
            }
            ExprKind::Builtin(_, args) | ExprKind::Ext(_, args) => {
                args.iter().for_each(|a| go(a, out))
            }
            _ => {}
        }
    }
    go(e, &mut out);
    out
}

/// Visit `e` and its sub-expressions (an aggregate's target, not its body).
pub fn walk_expr(e: &Expr, f: &mut dyn FnMut(&Expr)) {
    f(e);
    match &e.kind {
        ExprKind::Neg(x) => walk_expr(x, f),
        ExprKind::Bin(_, a, b) => {
            walk_expr(a, f);
            walk_expr(b, f);
        }
        ExprKind::Builtin(_, args) | ExprKind::Ext(_, args) => {
            args.iter().for_each(|a| walk_expr(a, f))
        }
        ExprKind::Agg(a) => {
            if let Some(t) = &a.target {
                walk_expr(t, f)
            }
        }
        _ => {}
    }
}

pub fn lit_exprs_mut(l: &mut Literal) -> Vec<&mut Expr> {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter_mut().collect(),
        Literal::Cmp(_, a, b, _) => vec![a, b],
        Literal::StrTest { args, .. } => args.iter_mut().collect(),
    }
}

pub(super) fn collect_deps(
    body: &[Literal],
    in_agg: bool,
    idx: &BTreeMap<String, usize>,
    out: &mut Vec<(usize, bool, Span)>,
) {
    for l in body {
        match l {
            Literal::Pos(a) => out.push((idx[&a.rel], in_agg, a.span)),
            Literal::Neg(a) => out.push((idx[&a.rel], true, a.span)),
            Literal::Cmp(_, x, y, _) => {
                for e in [x, y] {
                    if let ExprKind::Agg(g) = &e.kind {
                        collect_deps(&g.body, true, idx, out);
                    }
                }
            }
            Literal::StrTest { .. } => {}
        }
    }
}
