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

/// Visit every expression of a literal, aggregate bodies and targets included (pre-order).
pub fn visit_lit_deep(l: &mut Literal, f: &mut dyn FnMut(&mut Expr)) {
    for e in lit_exprs_mut(l) {
        visit_expr_deep(e, f);
    }
}

/// Visit `e` and every expression under it, aggregate bodies and targets included.
pub fn visit_expr_deep(e: &mut Expr, f: &mut dyn FnMut(&mut Expr)) {
    f(e);
    match &mut e.kind {
        ExprKind::Neg(x) => visit_expr_deep(x, f),
        ExprKind::Bin(_, a, b) => {
            visit_expr_deep(a, f);
            visit_expr_deep(b, f);
        }
        ExprKind::Builtin(_, args) | ExprKind::Ext(_, args) => {
            args.iter_mut().for_each(|a| visit_expr_deep(a, f))
        }
        ExprKind::Agg(g) => {
            if let Some(t) = &mut g.target {
                visit_expr_deep(t, f);
            }
            for l in &mut g.body {
                visit_lit_deep(l, f);
            }
        }
        _ => {}
    }
}

/// Rename every variable of a literal (aggregate bodies included) through `map`.
pub fn rename_lit(l: &mut Literal, map: &mut dyn FnMut(&str) -> Option<ExprKind>) {
    for e in lit_exprs_mut(l) {
        rename_expr(e, map);
    }
}

/// Rename every variable of an expression (aggregate bodies included) through `map`.
pub fn rename_expr(e: &mut Expr, map: &mut dyn FnMut(&str) -> Option<ExprKind>) {
    visit_expr_deep(e, &mut |e| {
        if let ExprKind::Var(v) = &e.kind {
            if let Some(k) = map(v) {
                e.kind = k;
            }
        }
    });
}

/// Every variable of a literal, aggregate bodies included.
pub fn lit_vars_deep(l: &Literal) -> std::collections::BTreeSet<String> {
    let mut out = std::collections::BTreeSet::new();
    visit_lit_deep(&mut l.clone(), &mut |e| {
        if let ExprKind::Var(v) = &e.kind {
            out.insert(v.clone());
        }
    });
    out
}

/// Whether `autoinc()` occurs in the literal (aggregate bodies included).
pub fn lit_has_autoinc(l: &Literal) -> bool {
    let mut found = false;
    visit_lit_deep(&mut l.clone(), &mut |e| {
        found |= matches!(e.kind, ExprKind::Builtin(Builtin::Autoinc, _));
    });
    found
}

/// Whether `autoinc()` occurs in the rule, head or body.
pub fn rule_has_autoinc(r: &Rule) -> bool {
    r.body.iter().any(lit_has_autoinc)
        || r.head
            .args
            .iter()
            .any(|a| lit_has_autoinc(&Literal::Cmp(CmpOp::Eq, a.clone(), a.clone(), a.span)))
}

/// Each atom of a body, aggregate bodies included: the atom, whether it is negated, and
/// whether it is inside an aggregate.
pub fn for_each_atom(body: &[Literal], in_agg: bool, f: &mut dyn FnMut(&Atom, bool, bool)) {
    for l in body {
        match l {
            Literal::Pos(a) => f(a, false, in_agg),
            Literal::Neg(a) => f(a, true, in_agg),
            _ => {}
        }
        let mut aggs = Vec::new();
        visit_lit_deep(&mut l.clone(), &mut |e| {
            if let ExprKind::Agg(g) = &e.kind {
                aggs.push(g.body.clone());
            }
        });
        // `visit_lit_deep` reaches nested aggregates too: visit only their own atoms here.
        for body in aggs {
            for l in &body {
                match l {
                    Literal::Pos(a) => f(a, false, true),
                    Literal::Neg(a) => f(a, true, true),
                    _ => {}
                }
            }
        }
    }
}
