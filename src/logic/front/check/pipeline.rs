//! The order of the checker's work: declarations, I/O directives and clauses into a
//! `Program`, and each rule through rewriting, typing and grounding.

use super::super::ast::*;
use super::super::diag::{Diagnostics, closest};
use super::super::parse::Item;
use super::checker::{Checker, Env};
use super::desugar::eqrel_rules;
use super::inline::InlineDefs;
use super::program::Program;
use super::program::Stratum;
use super::walk::{collect_deps, expr_vars, lit_exprs_mut, rule_has_autoinc};
use std::collections::{BTreeMap, BTreeSet};

impl Checker<'_> {
    pub(super) fn run(mut self, items: Vec<(u32, Item)>) -> Result<Program, Diagnostics> {
        // Types first (they may be declared after use).
        for (_, item) in &items {
            if let Item::Type(t) = item {
                if BaseTy::from_name(&t.name).is_some() || self.types.contains_key(&t.name) {
                    self.error(
                        t.span,
                        format!("type `{}` is already defined", t.name),
                        "choose another type name",
                    );
                    continue;
                }
                self.types.insert(t.name.clone(), t.clone());
            }
        }
        let type_list: Vec<TypeDecl> = self.types.values().cloned().collect();
        for t in &type_list {
            if self.resolve_type(&t.name).is_none() {
                self.error(t.span, format!("type `{}` does not resolve to a primitive type (unknown parent `{}` or a cycle)", t.name, t.parent), "types derive from number, unsigned, float, symbol, vec3, iso or box");
            }
        }
        for t in type_list.iter().filter(|t| !t.members.is_empty()) {
            let base = self.resolve_type(&t.name);
            for m in &t.members {
                let mb = self.resolve_type(m);
                if mb.is_none() {
                    self.error(
                        t.span,
                        format!("union type `{}`: unknown member type `{m}`", t.name),
                        "declare the member type with `.type`",
                    );
                } else if mb != base {
                    self.error(
                        t.span,
                        format!(
                            "union type `{}` mixes {} and {} members",
                            t.name,
                            base.map_or("?", |b| b.name()),
                            mb.map_or("?", |b| b.name())
                        ),
                        "the members of a union must all derive from the same primitive type",
                    );
                }
            }
        }
        // Relations.
        let mut relations: Vec<RelDecl> = Vec::new();
        let mut rel_index: BTreeMap<String, usize> = BTreeMap::new();
        for (_, item) in &items {
            if let Item::Decl {
                name, attrs, span, ..
            } = item
            {
                if let Some(&prev) = rel_index.get(name) {
                    let prev_loc = self.loc(relations[prev].span);
                    self.error(
                        *span,
                        format!("relation `{name}` is declared twice (first at {prev_loc})"),
                        "remove one of the declarations",
                    );
                    continue;
                }
                let mut out = Vec::new();
                for (a, t, aspan) in attrs {
                    match self.resolve_type(t) {
                        Some(ty) => out.push(Attr {
                            name: a.clone(),
                            ty_name: t.clone(),
                            ty,
                        }),
                        None => {
                            let known: Vec<String> = [
                                "number", "unsigned", "float", "symbol", "vec3", "iso", "box",
                            ]
                            .iter()
                            .map(|s| s.to_string())
                            .chain(self.types.keys().cloned())
                            .collect();
                            let hint = match closest(t, known.iter().map(String::as_str)) {
                                Some(c) => format!("did you mean `{c}`?"),
                                None => "use number, unsigned, float, symbol, vec3, iso, box or a `.type`".into(),
                            };
                            self.error(
                                *aspan,
                                format!("unknown type `{t}` for attribute `{a}`"),
                                hint,
                            );
                            out.push(Attr {
                                name: a.clone(),
                                ty_name: t.clone(),
                                ty: BaseTy::Number,
                            });
                        }
                    }
                }
                rel_index.insert(name.clone(), relations.len());
                relations.push(RelDecl {
                    name: name.clone(),
                    attrs: out,
                    input: None,
                    output: None,
                    span: *span,
                });
            }
        }
        self.atom_types = relations
            .iter()
            .map(|r| (r.name.clone(), r.attrs.iter().map(|a| a.ty).collect()))
            .collect();
        // I/O directives.
        for (_, item) in &items {
            if let Item::Io {
                output,
                rels,
                params,
                span,
            } = item
            {
                let mut spec = IoSpec {
                    filename: None,
                    delimiter: "\t".into(),
                    stdout: false,
                    span: *span,
                };
                for (k, v, kspan) in params {
                    match (k.as_str(), v.as_str()) {
                        ("IO", "file") => {}
                        ("IO", "stdout") if *output => spec.stdout = true,
                        ("IO", other) => self.error(
                            *kspan,
                            format!("I/O kind `IO={other}` is not supported"),
                            "use `IO=file` (or `IO=stdout` for outputs)",
                        ),
                        ("filename", f) => spec.filename = Some(f.to_string()),
                        ("delimiter", d) => {
                            if d.is_empty() {
                                self.error(*kspan, "empty delimiter", "use e.g. `delimiter=\",\"`");
                            }
                            spec.delimiter = d.to_string();
                        }
                        (other, _) => self.error(
                            *kspan,
                            format!("I/O parameter `{other}` is not supported"),
                            "supported parameters: IO, filename, delimiter",
                        ),
                    }
                }
                for (r, rspan) in rels {
                    match rel_index.get(r) {
                        Some(&i) => {
                            let slot = if *output {
                                &mut relations[i].output
                            } else {
                                &mut relations[i].input
                            };
                            *slot = Some(spec.clone());
                        }
                        None => {
                            let hint = self.rel_hint(r, &rel_index);
                            self.error(*rspan, format!("unknown relation `{r}`"), hint);
                        }
                    }
                }
            }
        }
        let items_eqrel: Vec<(String, Span)> = items
            .iter()
            .filter_map(|(_, item)| match item {
                Item::Decl {
                    name,
                    eqrel: true,
                    span,
                    ..
                } if rel_index.contains_key(name) => Some((name.clone(), *span)),
                _ => None,
            })
            .collect();
        let inline: BTreeMap<String, Span> = items
            .iter()
            .filter_map(|(_, item)| match item {
                Item::Decl {
                    name,
                    inline: true,
                    span,
                    ..
                } if rel_index.contains_key(name) => Some((name.clone(), *span)),
                _ => None,
            })
            .collect();
        // Clauses.
        let mut clauses = Vec::new();
        let mut labels: BTreeMap<String, Span> = BTreeMap::new();
        for (_, item) in items {
            if let Item::Clause(rule) = item {
                if let Some(l) = &rule.label {
                    if let Some(prev) = labels.get(l) {
                        if prev.line != rule.span.line || prev.file != rule.span.file {
                            let loc = self.loc(*prev);
                            self.error(
                                rule.span,
                                format!("rule label `{l}` is used twice (also at {loc})"),
                                "give every rule its own `// @rule` name",
                            );
                        }
                    }
                    labels.insert(l.clone(), rule.span);
                }
                if rule.body.is_empty() && rule_has_autoinc(&rule) {
                    self.error(
                        rule.span,
                        "argument in fact is not constant: `autoinc()` in a fact",
                        "a fact's arguments are constants; derive the tuple with a rule instead",
                    );
                    continue;
                }
                clauses.push(rule);
            }
        }
        let mut rules = Vec::new();
        for rule in &clauses {
            let mut rule = rule.clone();
            if self.check_rule(&mut rule, &relations, &rel_index) {
                rules.push(rule);
            }
        }
        if !inline.is_empty() && self.errors.is_empty() {
            // Checked as written first (errors point at what was written), then inlined.
            let defs: InlineDefs = inline
                .iter()
                .map(|(name, span)| {
                    let defining = clauses.iter().filter(|r| &r.head.rel == name);
                    (name.clone(), (*span, defining.cloned().collect()))
                })
                .collect();
            self.check_inlining(&defs, &relations, &clauses, &items_eqrel);
            if !self.errors.is_empty() {
                return Err(Diagnostics(self.errors));
            }
            relations.retain(|r| !defs.contains_key(&r.name));
            rel_index = relations
                .iter()
                .enumerate()
                .map(|(i, r)| (r.name.clone(), i))
                .collect();
            rules.clear();
            for rule in clauses
                .into_iter()
                .filter(|r| !defs.contains_key(&r.head.rel))
            {
                for mut rule in self.inline_uses(rule, &defs).unwrap_or_default() {
                    if self.check_rule(&mut rule, &relations, &rel_index) {
                        rules.push(rule);
                    }
                }
            }
        }
        // `eqrel`: the reflexive, symmetric and transitive closure, as rules
        // (what Soufflé's documentation says an eqrel relation holds).
        for (name, span) in items_eqrel {
            if relations[rel_index[&name]].attrs[0].ty != relations[rel_index[&name]].attrs[1].ty {
                self.error(
                    span,
                    format!("the two attributes of `eqrel` relation `{name}` have different types"),
                    "give both attributes the same type",
                );
                continue;
            }
            for mut rule in eqrel_rules(&name, span) {
                if self.check_rule(&mut rule, &relations, &rel_index) {
                    rules.push(rule);
                }
            }
        }
        if !self.errors.is_empty() {
            return Err(Diagnostics(self.errors));
        }
        let strata = self.stratify(&relations, &rel_index, &rules);
        self.check_autoinc_recursion(&strata, &rules, &rel_index);
        if !self.errors.is_empty() {
            return Err(Diagnostics(self.errors));
        }
        Ok(Program {
            sources: self.sources,
            types: type_list,
            relations,
            rel_index,
            rules,
            strata,
        })
    }

    /// Soufflé refuses `autoinc()` in a rule that reads its own stratum (a recursive rule).
    fn check_autoinc_recursion(
        &mut self,
        strata: &[Stratum],
        rules: &[Rule],
        rel_index: &BTreeMap<String, usize>,
    ) {
        for s in strata.iter().filter(|s| s.recursive) {
            for &ri in &s.rules {
                let rule = &rules[ri];
                if !rule_has_autoinc(rule) {
                    continue;
                }
                let mut deps = Vec::new();
                collect_deps(&rule.body, false, rel_index, &mut deps);
                if deps.iter().any(|(b, _, _)| s.relations.contains(b)) {
                    self.error(
                        rule.span,
                        "auto-increment functor `autoinc()` in a recursive rule",
                        "Soufflé refuses it (each iteration would count anew): compute the numbers in a non-recursive rule",
                    );
                }
            }
        }
    }

    /// Returns false (after recording errors) if the rule is unusable.
    fn check_rule(
        &mut self,
        rule: &mut Rule,
        rels: &[RelDecl],
        idx: &BTreeMap<String, usize>,
    ) -> bool {
        let before = self.errors.len();
        // Lift aggregates out of expressions into `__aggN = <aggregate>` literals.
        let mut lifted = Vec::new();
        for a in &mut rule.head.args {
            self.lift_aggs(a, &mut lifted);
        }
        let mut body = std::mem::take(&mut rule.body);
        self.lift_in_body(&mut body);
        for l in &mut body {
            // `x = agg` stays as it is (the planner makes it an assignment).
            let top_cmp = matches!(l, Literal::Cmp(..));
            for e in lit_exprs_mut(l) {
                if top_cmp && matches!(e.kind, ExprKind::Agg(_)) {
                    continue;
                }
                self.lift_aggs(e, &mut lifted);
            }
        }
        body.extend(lifted);
        // An expression argument reading a variable its own atom binds (`e(2*n, n)`) is
        // matched after the atom binds it: a fresh variable in its place, equal to it.
        self.lift_self_bound_args(&mut body, false);
        rule.body = body;
        self.ground_witnesses(rule);
        // Relations and arities.
        self.check_atom(&rule.head, rels, idx);
        self.check_atoms_in(&rule.body, rels, idx);
        if self.errors.len() > before {
            return false;
        }
        // Types.
        let mut env = Env::new();
        let mut named: BTreeMap<String, (String, Span)> = BTreeMap::new();
        self.collect_atom_types(&rule.head, rels, idx, &mut env, &mut named);
        self.collect_types_in(&rule.body, rels, idx, &mut env, &mut named);
        if self.errors.len() > before {
            return false;
        }
        self.infer_equalities(&rule.body, &mut env);
        let head_rel = &rels[idx[&rule.head.rel]];
        for (i, a) in rule.head.args.iter_mut().enumerate() {
            let ty = head_rel.attrs[i].ty;
            if let ExprKind::Wild = a.kind {
                self.error(a.span, "`_` in a rule head", "every head argument needs a value: use a variable bound in the body or a constant");
                continue;
            }
            self.check_expr(a, Some(ty), &mut env);
        }
        self.check_lits(&mut rule.body, &mut env);
        if self.errors.len() > before {
            return false;
        }
        // Groundedness and evaluation order.
        let head_vars: BTreeSet<String> = rule.head.args.iter().flat_map(expr_vars).collect();
        let mut outside = head_vars.clone();
        let errors_before_plan = self.errors.len();
        let mut plan = self.plan(&mut rule.body, &BTreeSet::new(), &mut outside);
        // Atoms whose expression arguments read variables only other such atoms bind
        // (`p(X-1, Y), p(Y-2, X)`): Soufflé grounds them by matching first and checking the
        // expression after; so do we, by lifting every expression argument out.
        if plan.is_none() {
            let mut lifted = rule.body.clone();
            if self.lift_self_bound_args(&mut lifted, true) {
                let mut env = Env::new();
                let mut named: BTreeMap<String, (String, Span)> = BTreeMap::new();
                let errors = self.errors.split_off(errors_before_plan);
                self.collect_atom_types(&rule.head, rels, idx, &mut env, &mut named);
                self.collect_types_in(&lifted, rels, idx, &mut env, &mut named);
                self.infer_equalities(&lifted, &mut env);
                self.check_lits(&mut lifted, &mut env);
                let mut outside = head_vars.clone();
                let retry = (self.errors.len() == errors_before_plan)
                    .then(|| self.plan(&mut lifted, &BTreeSet::new(), &mut outside))
                    .flatten();
                if retry.is_some() {
                    rule.body = lifted;
                    plan = retry;
                } else {
                    // The lifted rule fails too: report the rule as written.
                    self.errors.truncate(errors_before_plan);
                    self.errors.extend(errors);
                }
            }
        }
        if let Some((plan, bound)) = plan {
            for a in &rule.head.args {
                for v in expr_vars(a) {
                    if !bound.contains(&v) {
                        self.error(a.span, format!("variable `{v}` in the head is not grounded"), format!("bind `{v}` in a positive atom of the body or with `{v} = <expression>`"));
                    }
                }
            }
            rule.plan = plan;
        }
        self.errors.len() == before
    }
}
