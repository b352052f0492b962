//! Groundedness: the evaluation order of a rule body, so every variable is bound
//! before it is read, and the variables each aggregate takes from outside.

use super::super::ast::*;
use super::checker::Checker;
use super::walk::{expr_free_vars, expr_vars, lit_exprs_mut, walk_expr};
use std::collections::BTreeSet;

impl Checker<'_> {
    /// Order `body` so every variable is bound before it is read; returns the
    /// steps and the variables bound at the end, or None after reporting.
    pub(super) fn plan(
        &mut self,
        body: &mut [Literal],
        bound_init: &BTreeSet<String>,
        outside_ctx: &mut BTreeSet<String>,
    ) -> Option<(Vec<Step>, BTreeSet<String>)> {
        // Injected variables of each aggregate: those also used outside it.
        let shallow: Vec<BTreeSet<String>> = body.iter().map(lit_shallow_vars).collect();
        for i in 0..body.len() {
            let mut outside: BTreeSet<String> = outside_ctx.clone();
            for (j, s) in shallow.iter().enumerate() {
                if j != i {
                    outside.extend(s.iter().cloned());
                }
            }
            outside.extend(shallow[i].iter().cloned());
            for e in lit_exprs_mut(&mut body[i]) {
                if let ExprKind::Agg(a) = &mut e.kind {
                    let mut inner_vars = BTreeSet::new();
                    for l in &a.body {
                        inner_vars.extend(lit_all_vars(l));
                    }
                    if let Some(t) = &a.target {
                        inner_vars.extend(expr_all_vars(t));
                    }
                    a.injected = inner_vars.intersection(&outside).cloned().collect();
                    let injected: BTreeSet<String> = a.injected.iter().cloned().collect();
                    let mut ctx = outside.clone();
                    if let Some(t) = &a.target {
                        ctx.extend(expr_vars(t));
                    }
                    let (plan, sub_bound) = self.plan(&mut a.body, &injected, &mut ctx)?;
                    if let Some(t) = &a.target {
                        for v in expr_vars(t) {
                            if !sub_bound.contains(&v) {
                                self.error(t.span, format!("variable `{v}` of the aggregated expression is not grounded by the aggregate body"), format!("use `{v}` in a positive atom inside the aggregate body"));
                                return None;
                            }
                        }
                    }
                    a.plan = plan;
                }
            }
        }
        let mut bound = bound_init.clone();
        let mut remaining: Vec<usize> = (0..body.len()).collect();
        let mut steps = Vec::new();
        while !remaining.is_empty() {
            // `x = <float>` does not bind `x` while an atom still to come binds it: the atom
            // matches stored bits, the comparison is IEEE (-0.0 = 0.0, as in Soufflé).
            let binds_later = |v: &str| {
                remaining.iter().any(|&j| match &body[j] {
                    Literal::Pos(a) => a
                        .args
                        .iter()
                        .any(|e| matches!(&e.kind, ExprKind::Var(x) if x == v)),
                    _ => false,
                })
            };
            let float_eq = |i: usize| {
                matches!(&body[i], Literal::Cmp(_, a, b, _)
                    if a.ty == Some(BaseTy::Float) || b.ty == Some(BaseTy::Float))
            };
            let ready = remaining
                .iter()
                .position(|&i| match ready_step(&body[i], i, &bound) {
                    Some(Step::Assign { var, .. }) => !(float_eq(i) && binds_later(&var)),
                    Some(_) => true,
                    None => false,
                })
                .or_else(|| {
                    // Deferred float assignments run when nothing else can.
                    let scannable = remaining.iter().any(|&i| scannable(&body[i], &bound));
                    (!scannable)
                        .then(|| {
                            remaining
                                .iter()
                                .position(|&i| ready_step(&body[i], i, &bound).is_some())
                        })
                        .flatten()
                });
            if let Some(k) = ready {
                let i = remaining.remove(k);
                let step = ready_step(&body[i], i, &bound).unwrap();
                if let Step::Assign { var, .. } = &step {
                    bound.insert(var.clone());
                }
                steps.push(step);
                continue;
            }
            let scan = remaining.iter().position(|&i| scannable(&body[i], &bound));
            if let Some(k) = scan {
                let i = remaining.remove(k);
                if let Literal::Pos(a) = &body[i] {
                    for e in &a.args {
                        if let ExprKind::Var(v) = &e.kind {
                            bound.insert(v.clone());
                        }
                    }
                }
                steps.push(Step::Scan(i));
                continue;
            }
            // Nothing can run: report the first unbound variable.
            let i = remaining[0];
            let lit = &body[i];
            // An aggregate reads a variable that only its own body could bind:
            // the value cannot leave the aggregate (Soufflé's witness problem).
            if let Literal::Cmp(_, a, b, _) = lit {
                let witness = [a, b].into_iter().find_map(|e| match &e.kind {
                    ExprKind::Agg(g) => g.injected.iter().find(|v| !bound.contains(*v)).cloned(),
                    _ => None,
                });
                if let Some(v) = witness {
                    self.error(
                        lit.span(),
                        format!("variable `{v}` is grounded only inside the aggregate but used outside it (the witness problem: only a top-level min or max aggregate exports a witness, not count, sum, mean or a nested aggregate)"),
                        format!("bind `{v}` in a positive atom outside the aggregate, or use a fresh variable inside it"),
                    );
                    return None;
                }
            }
            let unbound: Vec<String> = lit_free_vars(lit)
                .into_iter()
                .filter(|v| !bound.contains(v))
                .collect();
            let v = unbound.first().cloned().unwrap_or_default();
            let shown = if v.starts_with("__agg") {
                "the aggregate's result".to_string()
            } else {
                format!("variable `{v}`")
            };
            let hint = match lit {
                Literal::Neg(_) => format!(
                    "a negated atom cannot bind variables: use `{v}` in a positive atom of the body too (or write `_`)"
                ),
                Literal::Cmp(..) if v.starts_with("__agg") => {
                    "an aggregate's outer variables must be bound by positive atoms outside it"
                        .to_string()
                }
                _ => format!(
                    "bind `{v}` in a positive atom of the body or with `{v} = <expression>`"
                ),
            };
            self.error(lit.span(), format!("{shown} is not grounded"), hint);
            return None;
        }
        let _ = outside_ctx;
        Some((steps, bound))
    }
}

/// The step a literal can take now, if all it reads is bound.
/// Whether a positive atom can be matched now: every expression argument reads only bound
/// variables or the atom's own plain arguments.
fn scannable(l: &Literal, bound: &BTreeSet<String>) -> bool {
    match l {
        Literal::Pos(a) => {
            let mut b = bound.clone();
            b.extend(a.args.iter().filter_map(|e| match &e.kind {
                ExprKind::Var(v) => Some(v.clone()),
                _ => None,
            }));
            a.args
                .iter()
                .all(|e| expr_vars(e).iter().all(|v| b.contains(v)))
        }
        _ => false,
    }
}

fn ready_step(l: &Literal, i: usize, bound: &BTreeSet<String>) -> Option<Step> {
    let all_bound = |vs: Vec<String>| vs.iter().all(|v| bound.contains(v));
    match l {
        Literal::Pos(_) => None,
        Literal::Neg(a) => {
            all_bound(a.args.iter().flat_map(expr_vars).collect()).then_some(Step::Negate(i))
        }
        Literal::StrTest { args, .. } => {
            all_bound(args.iter().flat_map(expr_free_vars).collect()).then_some(Step::Filter(i))
        }
        Literal::Cmp(op, a, b, _) => {
            let fa = expr_free_vars(a);
            let fb = expr_free_vars(b);
            if all_bound(fa.clone()) && all_bound(fb.clone()) {
                return Some(Step::Filter(i));
            }
            if *op == CmpOp::Eq {
                if let ExprKind::Var(v) = &a.kind {
                    if !bound.contains(v) && all_bound(fb.clone()) && !fb.contains(v) {
                        return Some(Step::Assign {
                            lit: i,
                            var: v.clone(),
                            var_on_left: true,
                        });
                    }
                }
                if let ExprKind::Var(v) = &b.kind {
                    if !bound.contains(v) && all_bound(fa.clone()) && !fa.contains(v) {
                        return Some(Step::Assign {
                            lit: i,
                            var: v.clone(),
                            var_on_left: false,
                        });
                    }
                }
            }
            None
        }
    }
}

fn lit_free_vars(l: &Literal) -> Vec<String> {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().flat_map(expr_vars).collect(),
        Literal::Cmp(_, a, b, _) => expr_free_vars(a)
            .into_iter()
            .chain(expr_free_vars(b))
            .collect(),
        Literal::StrTest { args, .. } => args.iter().flat_map(expr_free_vars).collect(),
    }
}

/// Variables outside aggregates.
fn lit_shallow_vars(l: &Literal) -> BTreeSet<String> {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().flat_map(expr_vars).collect(),
        Literal::Cmp(_, a, b, _) => expr_vars(a).into_iter().chain(expr_vars(b)).collect(),
        Literal::StrTest { args, .. } => args.iter().flat_map(expr_vars).collect(),
    }
}

fn lit_all_vars(l: &Literal) -> BTreeSet<String> {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().flat_map(expr_all_vars).collect(),
        Literal::Cmp(_, a, b, _) => expr_all_vars(a)
            .into_iter()
            .chain(expr_all_vars(b))
            .collect(),
        Literal::StrTest { args, .. } => args.iter().flat_map(expr_all_vars).collect(),
    }
}

fn expr_all_vars(e: &Expr) -> BTreeSet<String> {
    let mut out: BTreeSet<String> = expr_vars(e).into_iter().collect();
    walk_expr(e, &mut |x| {
        if let ExprKind::Agg(a) = &x.kind {
            for l in &a.body {
                out.extend(lit_all_vars(l));
            }
            if let Some(t) = &a.target {
                out.extend(expr_all_vars(t));
            }
        }
    });
    out
}
