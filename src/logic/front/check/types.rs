//! Type checking: the `.type` hierarchy, relations and arities of atoms, and the
//! types of variables, expressions, functors, aggregates and comparisons.

use super::super::ast::*;
use super::super::diag::closest;
use super::checker::{Checker, Env};
use super::walk::walk_expr;
use std::collections::BTreeMap;

impl Checker<'_> {
    /// Base type of a type name, following `.type` declarations.
    pub(super) fn resolve_type(&self, name: &str) -> Option<BaseTy> {
        let mut cur = name.to_string();
        for _ in 0..64 {
            if let Some(b) = BaseTy::from_name(&cur) {
                return Some(b);
            }
            cur = self.types.get(&cur)?.parent.clone();
        }
        None
    }

    /// `name` with aliases (`.type T = U`) followed to the type they name.
    fn canonical(&self, name: &str) -> String {
        let mut cur = name.to_string();
        for _ in 0..64 {
            match self.types.get(&cur) {
                Some(t) if !t.is_subtype && t.members.is_empty() => cur = t.parent.clone(),
                _ => break,
            }
        }
        cur
    }

    /// Every type a value of `name` also has, `name` (alias-collapsed) first:
    /// its parents up to the primitive type and every union containing one of them.
    fn ancestors(&self, name: &str) -> Vec<String> {
        let first = self.canonical(name);
        let mut out = vec![first.clone()];
        let mut todo = vec![first];
        while let Some(t) = todo.pop() {
            let mut sup = Vec::new();
            match self.types.get(&t) {
                Some(d) if !d.members.is_empty() => {
                    sup.extend(self.resolve_type(&t).map(|b| b.name().to_string()))
                }
                Some(d) if d.is_subtype => sup.push(self.canonical(&d.parent)),
                _ => {}
            }
            for (u, d) in &self.types {
                if d.members.iter().any(|m| self.canonical(m) == t) {
                    sup.push(u.clone());
                }
            }
            for x in sup {
                if !out.contains(&x) {
                    out.push(x.clone());
                    todo.push(x);
                }
            }
        }
        out
    }

    pub(super) fn check_atom(&mut self, a: &Atom, rels: &[RelDecl], idx: &BTreeMap<String, usize>) {
        match idx.get(&a.rel) {
            None => {
                let hint = self.rel_hint(&a.rel, idx);
                self.error(a.span, format!("unknown relation `{}`", a.rel), hint);
            }
            Some(&i) => {
                let d = &rels[i];
                if d.arity() != a.args.len() {
                    let sig: Vec<String> = d
                        .attrs
                        .iter()
                        .map(|x| format!("{}: {}", x.name, x.ty_name))
                        .collect();
                    self.error(
                        a.span,
                        format!(
                            "relation `{}` has {} attribute(s) but is used with {} argument(s)",
                            a.rel,
                            d.arity(),
                            a.args.len()
                        ),
                        format!(
                            "it is declared as `{}({})` at {}",
                            a.rel,
                            sig.join(", "),
                            self.loc(d.span)
                        ),
                    );
                }
            }
        }
        for e in &a.args {
            self.check_exprs_atoms(e, rels, idx);
        }
    }

    fn check_exprs_atoms(&mut self, e: &Expr, rels: &[RelDecl], idx: &BTreeMap<String, usize>) {
        walk_expr(e, &mut |x| {
            if let ExprKind::Agg(a) = &x.kind {
                self.check_atoms_in(&a.body, rels, idx);
            }
        });
    }

    pub(super) fn check_atoms_in(
        &mut self,
        body: &[Literal],
        rels: &[RelDecl],
        idx: &BTreeMap<String, usize>,
    ) {
        for l in body {
            match l {
                Literal::Pos(a) | Literal::Neg(a) => self.check_atom(a, rels, idx),
                Literal::Cmp(_, a, b, _) => {
                    self.check_exprs_atoms(a, rels, idx);
                    self.check_exprs_atoms(b, rels, idx);
                }
                Literal::StrTest { args, .. } => {
                    for e in args.iter() {
                        self.check_exprs_atoms(e, rels, idx);
                    }
                }
            }
        }
    }

    pub(super) fn collect_atom_types(
        &mut self,
        a: &Atom,
        rels: &[RelDecl],
        idx: &BTreeMap<String, usize>,
        env: &mut Env,
        named: &mut BTreeMap<String, (String, Span)>,
    ) {
        let d = &rels[idx[&a.rel]];
        for (i, e) in a.args.iter().enumerate() {
            if let ExprKind::Var(v) = &e.kind {
                let attr = &d.attrs[i];
                if let Some(prev) = env.get(v) {
                    if *prev != attr.ty {
                        self.error(e.span, format!("type mismatch: `{v}` is a {} here (attribute `{}` of `{}`) but a {prev} elsewhere in the rule", attr.ty, attr.name, a.rel), "use different variables, or convert with itof/ftoi/to_string/to_number");
                        continue;
                    }
                }
                env.insert(v.clone(), attr.ty);
                if let Some((prev_name, _)) = named.get(v).cloned() {
                    let anc_new = self.ancestors(&attr.ty_name);
                    let anc_old = self.ancestors(&prev_name);
                    let compatible = anc_new.contains(&anc_old[0]) || anc_old.contains(&anc_new[0]);
                    if !compatible {
                        self.error(e.span, format!("type mismatch: `{v}` has type `{}` here but `{prev_name}` elsewhere, and neither is a subtype of the other", attr.ty_name), "subtypes of the same base type are distinct; use one declared type for both attributes");
                        continue;
                    }
                    // Keep the narrower of the two types.
                    if anc_new.contains(&anc_old[0]) {
                        named.insert(v.clone(), (attr.ty_name.clone(), e.span));
                    }
                } else {
                    named.insert(v.clone(), (attr.ty_name.clone(), e.span));
                }
            }
        }
    }

    pub(super) fn collect_types_in(
        &mut self,
        body: &[Literal],
        rels: &[RelDecl],
        idx: &BTreeMap<String, usize>,
        env: &mut Env,
        named: &mut BTreeMap<String, (String, Span)>,
    ) {
        for l in body {
            match l {
                Literal::Pos(a) | Literal::Neg(a) => {
                    self.collect_atom_types(a, rels, idx, env, named)
                }
                Literal::Cmp(_, a, b, _) => {
                    for e in [a, b] {
                        if let ExprKind::Agg(g) = &e.kind {
                            self.collect_types_in(&g.body, rels, idx, env, named);
                        }
                    }
                }
                Literal::StrTest { .. } => {}
            }
        }
    }

    /// Give types to variables defined by `x = expr` (repeated until stable).
    pub(super) fn infer_equalities(&mut self, body: &[Literal], env: &mut Env) {
        for _ in 0..=body.len() + 8 {
            let mut changed = false;
            self.visit_eqs(body, env, &mut changed);
            if !changed {
                break;
            }
        }
    }

    fn visit_eqs(&self, body: &[Literal], env: &mut Env, changed: &mut bool) {
        for l in body {
            if let Literal::Cmp(op, a, b, _) = l {
                for (x, y) in [(a, b), (b, a)] {
                    if let ExprKind::Agg(g) = &y.kind {
                        self.visit_eqs(&g.body, env, changed);
                    }
                    if let ExprKind::Var(v) = &x.kind {
                        if !env.contains_key(v) {
                            // An integer constant defaults to number, as in Soufflé.
                            let t = if *op == CmpOp::Eq {
                                self.peek_type(y, env)
                                    .or_else(|| is_int_const(y).then_some(BaseTy::Number))
                            } else {
                                None
                            };
                            if let Some(t) = t {
                                env.insert(v.clone(), t);
                                *changed = true;
                            }
                        }
                    }
                }
            }
        }
    }

    /// The type of `e` if it can be told without context.
    fn peek_type(&self, e: &Expr, env: &Env) -> Option<BaseTy> {
        match &e.kind {
            ExprKind::Var(v) => env.get(v).copied(),
            ExprKind::Wild | ExprKind::Int(_) => None,
            ExprKind::Float(_) => Some(BaseTy::Float),
            ExprKind::Str(_) => Some(BaseTy::Symbol),
            ExprKind::Neg(x) => self.peek_type(x, env),
            ExprKind::Bin(_, a, b) => self.peek_type(a, env).or_else(|| self.peek_type(b, env)),
            ExprKind::Builtin(b, args) => match b {
                Builtin::Min | Builtin::Max => args.iter().find_map(|a| self.peek_type(a, env)),
                _ => builtin_sig(*b).map(|s| s.1),
            },
            ExprKind::Ext(n, _) => self.functors.iter().find(|f| f.name == n).map(|f| f.ret),
            ExprKind::Agg(a) => match a.op {
                AggOp::Count => Some(BaseTy::Number),
                AggOp::Mean => Some(BaseTy::Float),
                _ => a.target.as_ref().and_then(|t| self.peek_type(t, env)),
            },
        }
    }

    fn mismatch(&mut self, span: Span, found: BaseTy, expected: BaseTy, what: &str) {
        self.error(span, format!("type mismatch: {what} is a {found} but a {expected} is expected here"), "convert explicitly (itof, ftoi, itou, utoi, to_string, to_number) or fix the attribute type");
    }

    /// Soufflé's overloads, resolved by operand type: `to_number`, `to_float`
    /// and `to_unsigned` convert between the number types too (not only from
    /// symbols), and `+` on two symbols concatenates them.
    fn resolve_overload(&self, e: &Expr, expected: Option<BaseTy>, env: &Env) -> Option<Expr> {
        use BaseTy::*;
        match &e.kind {
            ExprKind::Builtin(
                b @ (Builtin::ToNumber | Builtin::ToFloat | Builtin::ToUnsigned),
                args,
            ) if args.len() == 1 => {
                let arg = &args[0];
                let from = self
                    .peek_type(arg, env)
                    .or_else(|| is_int_const(arg).then_some(Number))?;
                let to = match b {
                    Builtin::ToNumber => Number,
                    Builtin::ToFloat => Float,
                    _ => Unsigned,
                };
                let conv = match (from, to) {
                    (a, b) if a == b => return Some(arg.clone()),
                    (Number, Float) => Builtin::Itof,
                    (Number, Unsigned) => Builtin::Itou,
                    (Unsigned, Number) => Builtin::Utoi,
                    (Unsigned, Float) => Builtin::Utof,
                    (Float, Number) => Builtin::Ftoi,
                    (Float, Unsigned) => Builtin::Ftou,
                    _ => return None,
                };
                Some(Expr {
                    kind: ExprKind::Builtin(conv, args.clone()),
                    ..e.clone()
                })
            }
            ExprKind::Bin(BinOp::Add, a, b) => {
                let symbolic = expected == Some(Symbol)
                    || self.peek_type(a, env) == Some(Symbol)
                    || self.peek_type(b, env) == Some(Symbol);
                symbolic.then(|| Expr {
                    kind: ExprKind::Builtin(Builtin::Cat, vec![(**a).clone(), (**b).clone()]),
                    ..e.clone()
                })
            }
            _ => None,
        }
    }

    /// Type-check `e` against `expected` (if any) and record its type.
    pub(super) fn check_expr(
        &mut self,
        e: &mut Expr,
        expected: Option<BaseTy>,
        env: &mut Env,
    ) -> Option<BaseTy> {
        if let Some(rewritten) = self.resolve_overload(e, expected, env) {
            *e = rewritten;
        }
        let span = e.span;
        let ty = match &mut e.kind {
            ExprKind::Var(v) => match (env.get(v).copied(), expected) {
                (Some(t), Some(x)) if t != x => {
                    let what = format!("variable `{v}`");
                    self.mismatch(span, t, x, &what);
                    return None;
                }
                (Some(t), _) => t,
                (None, Some(x)) => {
                    env.insert(v.clone(), x);
                    x
                }
                (None, None) => {
                    let v = v.clone();
                    self.error(
                        span,
                        format!("cannot deduce the type of variable `{v}`"),
                        format!("use `{v}` in an atom, or compare it with a typed value"),
                    );
                    return None;
                }
            },
            // A whole argument of a body atom never gets here (`check_lits` types it);
            // anywhere else `_` would be a value nothing binds, as Soufflé rejects it
            // ("Underscore in binary relation", "Underscore in head of rule").
            ExprKind::Wild => {
                self.error(
                    span,
                    "`_` inside an expression, comparison or aggregated value",
                    "`_` stands only for a whole argument of a body atom, as in `a(x, _)`; use a named variable here",
                );
                return None;
            }
            ExprKind::Int(i) => {
                let t = expected.unwrap_or(BaseTy::Number);
                let ok = match t {
                    BaseTy::Number => i64::try_from(*i).is_ok(),
                    BaseTy::Unsigned => u64::try_from(*i).is_ok(),
                    BaseTy::Float => true,
                    _ => {
                        self.mismatch(span, BaseTy::Number, t, "this integer constant");
                        return None;
                    }
                };
                if !ok {
                    self.error(
                        span,
                        format!("integer constant {i} does not fit a {t}"),
                        "number is a signed 64-bit integer, unsigned an unsigned 64-bit integer",
                    );
                    return None;
                }
                t
            }
            ExprKind::Float(_) => BaseTy::Float,
            ExprKind::Str(_) => BaseTy::Symbol,
            ExprKind::Neg(x) => {
                let t = self.check_expr(x, expected, env)?;
                if !t.is_numeric() {
                    self.mismatch(span, t, BaseTy::Number, "the operand of `-`");
                    return None;
                }
                t
            }
            ExprKind::Bin(op, a, b) => {
                let op = *op;
                let hint = expected
                    .or_else(|| self.peek_type(a, env))
                    .or_else(|| self.peek_type(b, env));
                let ta = self.check_expr(a, hint, env)?;
                let tb = self.check_expr(b, Some(ta), env)?;
                if !ta.is_numeric() || ta != tb {
                    self.error(span, format!("`{}` needs two numbers of the same type, found {ta} and {tb}", op.symbol()), "arithmetic works on number, unsigned or float; use cat() for symbols and @functors for geometry");
                    return None;
                }
                ta
            }
            ExprKind::Builtin(b, args) => {
                let b = *b;
                match b {
                    Builtin::Min | Builtin::Max | Builtin::Cat => {
                        if args.is_empty() || (b != Builtin::Cat && args.len() < 2) {
                            self.error(
                                span,
                                format!(
                                    "`{}` needs at least {} arguments",
                                    b.name(),
                                    if b == Builtin::Cat { 1 } else { 2 }
                                ),
                                "pass the values to combine",
                            );
                            return None;
                        }
                        let t = if b == Builtin::Cat {
                            BaseTy::Symbol
                        } else {
                            let h = expected
                                .or_else(|| args.iter().find_map(|a| self.peek_type(a, env)));
                            h.unwrap_or(BaseTy::Number)
                        };
                        for a in args.iter_mut() {
                            self.check_expr(a, Some(t), env)?;
                        }
                        if !(t.is_numeric() || t == BaseTy::Symbol) {
                            self.mismatch(span, t, BaseTy::Number, &format!("`{}`", b.name()));
                            return None;
                        }
                        t
                    }
                    _ => {
                        let (params, ret) = builtin_sig(b).expect("fixed-arity builtin");
                        if args.len() != params.len() {
                            self.error(
                                span,
                                format!(
                                    "`{}` takes {} argument(s), found {}",
                                    b.name(),
                                    params.len(),
                                    args.len()
                                ),
                                "see docs/RULES-LANGUAGE.md for functor signatures",
                            );
                            return None;
                        }
                        for (a, p) in args.iter_mut().zip(params) {
                            match p {
                                Some(p) => {
                                    self.check_expr(a, Some(*p), env)?;
                                }
                                None => {
                                    // to_string accepts any number type.
                                    let h = self.peek_type(a, env).unwrap_or(BaseTy::Number);
                                    let t = self.check_expr(a, Some(h), env)?;
                                    if !t.is_numeric() {
                                        self.mismatch(
                                            a.span,
                                            t,
                                            BaseTy::Number,
                                            "the argument of `to_string`",
                                        );
                                        return None;
                                    }
                                }
                            }
                        }
                        ret
                    }
                }
            }
            ExprKind::Ext(name, args) => {
                let Some(sig) = self
                    .functors
                    .iter()
                    .find(|f| f.name == name.as_str())
                    .copied()
                else {
                    let names: Vec<&str> = self.functors.iter().map(|f| f.name).collect();
                    let hint = match closest(name, names.iter().copied()) {
                        Some(c) => {
                            format!("did you mean `@{c}`? known functors: {}", names.join(", "))
                        }
                        None => format!("known functors: {}", names.join(", ")),
                    };
                    let name = name.clone();
                    self.error(span, format!("unknown functor `@{name}`"), hint);
                    return None;
                };
                if args.len() != sig.params.len() {
                    let ps: Vec<&str> = sig.params.iter().map(|p| p.name()).collect();
                    self.error(
                        span,
                        format!(
                            "`@{}` takes {} argument(s), found {}",
                            sig.name,
                            sig.params.len(),
                            args.len()
                        ),
                        format!("signature: @{}({}) -> {}", sig.name, ps.join(", "), sig.ret),
                    );
                    return None;
                }
                for (a, p) in args.iter_mut().zip(sig.params) {
                    self.check_expr(a, Some(*p), env)?;
                }
                sig.ret
            }
            ExprKind::Agg(_) => {
                // Aggregate bodies are checked by `check_body_types`.
                let ExprKind::Agg(a) = &mut e.kind else {
                    unreachable!()
                };
                self.check_aggregate(a, span, env)?
            }
        };
        if let Some(x) = expected {
            if x != ty {
                self.mismatch(span, ty, x, "this expression");
                return None;
            }
        }
        e.ty = Some(ty);
        Some(ty)
    }

    fn check_aggregate(&mut self, a: &mut Aggregate, span: Span, env: &mut Env) -> Option<BaseTy> {
        // The body's atoms were typed with the rule; check its literals now.
        let mut body = std::mem::take(&mut a.body);
        self.check_lits(&mut body, env);
        a.body = body;
        match a.op {
            AggOp::Count => Some(BaseTy::Number),
            op => {
                let t = a.target.as_mut()?;
                let h = self.peek_type(t, env);
                let ty = self.check_expr(t, h, env)?;
                if !ty.is_numeric() {
                    self.error(
                        span,
                        format!("`{}` aggregates numbers, found {ty}", op.name()),
                        "aggregate a number, unsigned or float expression",
                    );
                    return None;
                }
                Some(if op == AggOp::Mean { BaseTy::Float } else { ty })
            }
        }
    }

    pub(super) fn check_lits(&mut self, body: &mut [Literal], env: &mut Env) {
        for l in body.iter_mut() {
            match l {
                Literal::Pos(a) | Literal::Neg(a) => {
                    let tys = self.atom_types.get(&a.rel).cloned().unwrap_or_default();
                    for (e, t) in a.args.iter_mut().zip(tys) {
                        if let ExprKind::Wild = e.kind {
                            e.ty = Some(t);
                        } else {
                            self.check_expr(e, Some(t), env);
                        }
                    }
                }
                Literal::Cmp(op, a, b, span) => {
                    let h = self.peek_type(a, env).or_else(|| self.peek_type(b, env));
                    let Some(t) = self.check_expr(a, h, env) else {
                        continue;
                    };
                    if self.check_expr(b, Some(t), env).is_none() {
                        continue;
                    }
                    if !t.is_numeric()
                        && t != BaseTy::Symbol
                        && !matches!(op, CmpOp::Eq | CmpOp::Ne)
                    {
                        self.error(*span, format!("`{}` cannot compare {t} values", op.symbol()), "only `=` and `!=` apply to geometric values; use @functors to compare them");
                    }
                }
                Literal::StrTest { args, .. } => {
                    for e in args.iter_mut() {
                        self.check_expr(e, Some(BaseTy::Symbol), env);
                    }
                }
            }
        }
    }
}

/// Fixed signatures of the built-in functors (`None` = any number type).
pub fn builtin_sig(b: Builtin) -> Option<(&'static [Option<BaseTy>], BaseTy)> {
    use BaseTy::*;
    Some(match b {
        Builtin::Min | Builtin::Max | Builtin::Cat => return None,
        Builtin::Strlen => (&[Some(Symbol)], Number),
        Builtin::Substr => (&[Some(Symbol), Some(Number), Some(Number)], Symbol),
        Builtin::Ord => (&[Some(Symbol)], Number),
        Builtin::ToNumber => (&[Some(Symbol)], Number),
        Builtin::ToString => (&[None], Symbol),
        Builtin::ToFloat => (&[Some(Symbol)], Float),
        Builtin::ToUnsigned => (&[Some(Symbol)], Unsigned),
        Builtin::Itof => (&[Some(Number)], Float),
        Builtin::Itou => (&[Some(Number)], Unsigned),
        Builtin::Utoi => (&[Some(Unsigned)], Number),
        Builtin::Utof => (&[Some(Unsigned)], Float),
        Builtin::Ftoi => (&[Some(Float)], Number),
        Builtin::Ftou => (&[Some(Float)], Unsigned),
        Builtin::Autoinc => (&[], Number),
    })
}

fn is_int_const(e: &Expr) -> bool {
    match &e.kind {
        ExprKind::Int(_) => true,
        ExprKind::Neg(x) => is_int_const(x),
        ExprKind::Bin(_, a, b) => is_int_const(a) && is_int_const(b),
        _ => false,
    }
}
