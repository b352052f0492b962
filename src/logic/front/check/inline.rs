//! Soufflé's inlining: a relation declared `inline` is not computed; each use of it
//! is replaced by the bodies of its rules (variables renamed apart, its head unified
//! with the use), so both engines see a program without it. A negated use becomes the
//! negation of the disjunction of those bodies (De Morgan). Soufflé's restrictions on
//! inline relations are errors here, worded as Soufflé words them.

use super::super::ast::*;
use super::checker::Checker;
use super::walk::{
    for_each_atom, lit_has_autoinc, lit_vars_deep, rename_expr, rename_lit, rule_has_autoinc,
};
use std::collections::{BTreeMap, BTreeSet};

/// More rules than this from one rule means the inlining blows up (a product of many
/// inline relations with many rules each): refused rather than left to exhaust memory.
const MAX_INLINED_RULES: usize = 10_000;

/// The inline relations: name → declaration span and its rules as written.
pub(super) type InlineDefs = BTreeMap<String, (Span, Vec<Rule>)>;

impl Checker<'_> {
    /// Soufflé's restrictions on inline relations (input/output, `eqrel`, cycles of inline
    /// relations, `autoinc()`, negated uses that bind variables or hold `_`, uses inside
    /// aggregates); errors are recorded.
    pub(super) fn check_inlining(
        &mut self,
        defs: &InlineDefs,
        relations: &[RelDecl],
        rules: &[Rule],
        eqrel: &[(String, Span)],
    ) {
        for r in relations.iter().filter(|r| defs.contains_key(&r.name)) {
            if r.input.is_some() || r.output.is_some() {
                self.error(
                    r.span,
                    format!("IO relation `{}` cannot be inlined", r.name),
                    "an input or output relation must be computed: remove `inline`",
                );
            }
        }
        for (name, span) in eqrel.iter().filter(|(n, _)| defs.contains_key(n)) {
            self.error(
                *span,
                format!("`eqrel` relation `{name}` cannot be inlined"),
                "its closure is recursive: remove `inline` or `eqrel`",
            );
        }
        if let Some(cycle) = inline_cycle(defs) {
            let span = defs[&cycle[0]].0;
            self.error(
                span,
                format!(
                    "cannot inline cyclically dependent relations {{{}}}",
                    cycle.join(", ")
                ),
                "a cycle of inline relations has nothing to substitute: remove `inline` from one of them",
            );
        }
        for (_, rules) in defs.values() {
            for r in rules.iter().filter(|r| rule_has_autoinc(r)) {
                self.error(
                    r.span,
                    "cannot inline a clause containing `autoinc()`",
                    "each use would count separately: remove `inline`",
                );
            }
        }
        // A negated use must not bind variables: every body variable of the inline
        // relation's rules is in its head.
        let mut binds_new: BTreeMap<&str, Span> = BTreeMap::new();
        for (name, (_, rules)) in defs {
            for r in rules {
                let head: BTreeSet<String> = r
                    .head
                    .args
                    .iter()
                    .flat_map(|a| {
                        lit_vars_deep(&Literal::Cmp(CmpOp::Eq, a.clone(), a.clone(), a.span))
                    })
                    .collect();
                if r.body
                    .iter()
                    .any(|l| lit_vars_deep(l).iter().any(|v| !head.contains(v)))
                {
                    binds_new.entry(name.as_str()).or_insert(r.span);
                }
            }
        }
        let mut errors = Vec::new();
        for rule in rules {
            let mut visit = |a: &Atom, negated: bool, in_agg: bool| {
                if !defs.contains_key(&a.rel) {
                    return;
                }
                if in_agg {
                    errors.push((
                        a.span,
                        "cannot inline relations that appear in an aggregate".to_string(),
                        "remove `inline`, or aggregate over a relation that is computed"
                            .to_string(),
                    ));
                    return;
                }
                let literal = Literal::Pos(a.clone());
                if lit_has_autoinc(&literal) {
                    errors.push((
                        a.span,
                        "cannot inline a literal containing `autoinc()`".into(),
                        "remove `inline`".into(),
                    ));
                }
                if negated && a.args.iter().any(|e| matches!(e.kind, ExprKind::Wild)) {
                    errors.push((
                        a.span,
                        "cannot inline negated atom containing an unnamed variable `_`".into(),
                        "name the variable and bind it in a positive atom, or remove `inline`"
                            .into(),
                    ));
                } else if negated {
                    if let Some(at) = binds_new.get(a.rel.as_str()) {
                        errors.push((a.span, format!("cannot inline negated relation `{}` which may introduce new variables (its rule at {} has body variables not in its head)", a.rel, self.loc(*at)), "remove `inline`, or use the relation only positively".into()));
                    }
                }
            };
            for_each_atom(&rule.body, false, &mut visit);
        }
        for (span, msg, hint) in errors {
            self.error(span, msg, hint);
        }
    }

    /// The rules that replace `rule` once every use of an inline relation in its body is
    /// substituted (none when a positive use has no rule to substitute); None after an error.
    pub(super) fn inline_uses(&mut self, rule: Rule, defs: &InlineDefs) -> Option<Vec<Rule>> {
        let mut done = Vec::new();
        let mut todo = vec![rule];
        while let Some(r) = todo.pop() {
            let at = r.body.iter().position(
                |l| matches!(l, Literal::Pos(a) | Literal::Neg(a) if defs.contains_key(&a.rel)),
            );
            let Some(i) = at else {
                done.push(r);
                continue;
            };
            let mut expanded = match &r.body[i] {
                Literal::Pos(a) => self.positive_use(&r, i, a, &defs[&a.rel].1),
                Literal::Neg(a) => self.negated_use(&r, i, a, &defs[&a.rel].1)?,
                _ => unreachable!("an atom was found"),
            };
            expanded.reverse();
            todo.extend(expanded);
            if done.len() + todo.len() > MAX_INLINED_RULES {
                self.error(
                    r.span,
                    format!("inlining makes more than {MAX_INLINED_RULES} rules of this rule"),
                    "remove `inline` from some of the relations it uses",
                );
                return None;
            }
        }
        Some(done)
    }

    /// `a(args)` replaced by each rule of `a`: one rule per rule of `a`.
    fn positive_use(&mut self, rule: &Rule, i: usize, atom: &Atom, defs: &[Rule]) -> Vec<Rule> {
        let mut atom = atom.clone();
        for arg in &mut atom.args {
            if matches!(arg.kind, ExprKind::Wild) {
                arg.kind = ExprKind::Var(format!("__inlw{}", self.inline_counter));
                self.inline_counter += 1;
            }
        }
        defs.iter()
            .map(|def| {
                let (_, lits) = self.unify(def, &atom);
                let mut r = rule.clone();
                r.body.splice(i..=i, lits);
                r
            })
            .collect()
    }

    /// `!a(args)`: for every way of picking one literal from each rule of `a`, the rule with
    /// the negations of the picked literals (`!(B1 ; B2)` is `!B1, !B2`, `!(l1, l2)` is `!l1 ; !l2`).
    fn negated_use(
        &mut self,
        rule: &Rule,
        i: usize,
        atom: &Atom,
        defs: &[Rule],
    ) -> Option<Vec<Rule>> {
        let mut choices: Vec<Vec<Literal>> = vec![Vec::new()];
        for def in defs {
            let (prefix, lits) = self.unify(def, atom);
            if lits
                .iter()
                .any(|l| lit_vars_deep(l).iter().any(|v| v.starts_with(&prefix)))
            {
                self.error(
                    atom.span,
                    format!(
                        "cannot inline negated relation `{}` which may introduce new variables (the head of its rule at {} is not made of variables)",
                        atom.rel,
                        self.loc(def.span)
                    ),
                    "remove `inline`, or use the relation only positively",
                );
                return None;
            }
            let mut next = Vec::new();
            for chosen in &choices {
                for l in &lits {
                    let mut c = chosen.clone();
                    c.push(negate(l));
                    next.push(c);
                }
            }
            choices = next;
            if choices.len() > MAX_INLINED_RULES {
                self.error(
                    rule.span,
                    format!("inlining makes more than {MAX_INLINED_RULES} rules of this rule"),
                    "remove `inline` from the negated relation",
                );
                return None;
            }
        }
        Some(
            choices
                .into_iter()
                .map(|lits| {
                    let mut r = rule.clone();
                    r.body.splice(i..=i, lits);
                    r
                })
                .collect(),
        )
    }

    /// The literals a use `atom` of `def`'s relation stands for: `def`'s body with its variables
    /// renamed apart and each head variable replaced by the use's argument at its first place,
    /// plus an equality for every other head argument (a repeated variable, a constant, an
    /// expression). Returns the renaming prefix too.
    fn unify(&mut self, def: &Rule, atom: &Atom) -> (String, Vec<Literal>) {
        let prefix = format!("__inl{}_", self.inline_counter);
        self.inline_counter += 1;
        let mut subst: BTreeMap<String, ExprKind> = BTreeMap::new();
        let mut equal = Vec::new();
        for (h, a) in def.head.args.iter().zip(&atom.args) {
            if let ExprKind::Var(v) = &h.kind {
                if !subst.contains_key(v) {
                    subst.insert(v.clone(), a.kind.clone());
                    continue;
                }
            }
            equal.push((h.clone(), a.clone()));
        }
        let mut ren = |v: &str| rename(v, &subst, &prefix);
        let mut lits = Vec::new();
        // The use's arguments keep their variables: only the head side is renamed.
        for (mut h, a) in equal {
            rename_expr(&mut h, &mut ren);
            let span = a.span;
            lits.push(Literal::Cmp(CmpOp::Eq, h, a, span));
        }
        for l in &def.body {
            let mut l = l.clone();
            rename_lit(&mut l, &mut ren);
            lits.push(l);
        }
        (prefix, lits)
    }
}

fn rename(v: &str, subst: &BTreeMap<String, ExprKind>, prefix: &str) -> Option<ExprKind> {
    Some(
        subst
            .get(v)
            .cloned()
            .unwrap_or_else(|| ExprKind::Var(format!("{prefix}{v}"))),
    )
}

/// The literal that holds exactly when `l` does not.
fn negate(l: &Literal) -> Literal {
    match l {
        Literal::Pos(a) => Literal::Neg(a.clone()),
        Literal::Neg(a) => Literal::Pos(a.clone()),
        Literal::Cmp(op, a, b, s) => Literal::Cmp(op.negate(), a.clone(), b.clone(), *s),
        Literal::StrTest {
            is_match,
            negated,
            args,
            span,
        } => Literal::StrTest {
            is_match: *is_match,
            negated: !negated,
            args: args.clone(),
            span: *span,
        },
    }
}

/// A cycle of inline relations (each reads the next, the last the first), if any.
fn inline_cycle(defs: &InlineDefs) -> Option<Vec<String>> {
    let reads = |name: &str| -> BTreeSet<String> {
        let mut out = BTreeSet::new();
        for r in &defs[name].1 {
            for_each_atom(&r.body, false, &mut |a, _, _| {
                if defs.contains_key(&a.rel) {
                    out.insert(a.rel.clone());
                }
            });
        }
        out
    };
    fn dfs(
        at: &str,
        reads: &dyn Fn(&str) -> BTreeSet<String>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(k) = path.iter().position(|p| p == at) {
            return Some(path[k..].to_vec());
        }
        if done.contains(at) {
            return None;
        }
        path.push(at.to_string());
        for next in reads(at) {
            if let Some(c) = dfs(&next, reads, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(at.to_string());
        None
    }
    let mut done = BTreeSet::new();
    for name in defs.keys() {
        if let Some(c) = dfs(name, &reads, &mut Vec::new(), &mut done) {
            return Some(c);
        }
    }
    None
}
