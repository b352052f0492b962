//! Semantic checks: relations, arities, types, groundedness (which also fixes
//! each rule's evaluation order) and stratification of negation/aggregation.

use super::ast::*;
use super::diag::{Diagnostic, Diagnostics, Source, closest};
use super::lex::lex;
use super::parse::{Item, Parser};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Signature of a Rust functor `@name(args) -> ret` (the implementations live
/// in `logic::functors`; the checker and code generator only need this).
#[derive(Clone, Copy, Debug)]
pub struct FunctorSig {
    pub name: &'static str,
    pub params: &'static [BaseTy],
    pub ret: BaseTy,
}

/// A checked program: every relation declared, every rule typed, grounded,
/// planned and assigned to a stratum.
#[derive(Clone, Debug)]
pub struct Program {
    pub sources: Vec<Source>,
    pub types: Vec<TypeDecl>,
    pub relations: Vec<RelDecl>,
    pub rel_index: BTreeMap<String, usize>,
    /// Rules and facts (a fact is a rule with an empty body).
    pub rules: Vec<Rule>,
    /// In evaluation order: a stratum only reads relations of itself and earlier strata.
    pub strata: Vec<Stratum>,
}

#[derive(Clone, Debug)]
pub struct Stratum {
    pub relations: Vec<usize>,
    pub rules: Vec<usize>,
    /// A relation of this stratum depends on itself.
    pub recursive: bool,
}

impl Program {
    pub fn relation(&self, name: &str) -> Option<&RelDecl> {
        self.rel_index.get(name).map(|&i| &self.relations[i])
    }
    /// `file:line` of a span.
    pub fn location(&self, span: Span) -> String {
        let file = self
            .sources
            .get(span.file as usize)
            .map_or("<unknown>", |s| s.name.as_str());
        format!("{file}:{}", span.line)
    }
    /// The relations whose tuples can change with any of `sources`: the sources and every
    /// relation a rule derives from one of them (through atoms, negations or aggregates),
    /// transitively.
    pub fn downstream_of(&self, sources: &[&str]) -> BTreeSet<String> {
        let mut reached: BTreeSet<String> = sources.iter().map(|s| s.to_string()).collect();
        loop {
            let before = reached.len();
            for rule in &self.rules {
                if reached.contains(&rule.head.rel) {
                    continue;
                }
                let mut deps = Vec::new();
                collect_deps(&rule.body, false, &self.rel_index, &mut deps);
                if deps
                    .iter()
                    .any(|(b, _, _)| reached.contains(&self.relations[*b].name))
                {
                    reached.insert(rule.head.rel.clone());
                }
            }
            if reached.len() == before {
                return reached;
            }
        }
    }

    /// The relations `targets` can depend on: the targets and every relation a rule for one
    /// of them reads (through atoms, negations or aggregates), transitively.
    pub fn upstream_of(&self, targets: &[&str]) -> BTreeSet<String> {
        let mut reached: BTreeSet<String> = targets.iter().map(|s| s.to_string()).collect();
        let mut todo: Vec<String> = reached.iter().cloned().collect();
        while let Some(relation) = todo.pop() {
            for rule in self.rules.iter().filter(|r| r.head.rel == relation) {
                let mut deps = Vec::new();
                collect_deps(&rule.body, false, &self.rel_index, &mut deps);
                for (b, _, _) in deps {
                    let name = &self.relations[b].name;
                    if reached.insert(name.clone()) {
                        todo.push(name.clone());
                    }
                }
            }
        }
        reached
    }

    /// The program with only the rules (and facts) whose head is one of `heads`; every
    /// relation stays declared, so the others can be filled as inputs. When `heads` is closed
    /// under `downstream_of`, running this over the other relations' complete tuples gives
    /// `heads` the tuples the whole program gives them (strata below stay as they were).
    pub fn restricted_to(&self, heads: &BTreeSet<String>) -> Program {
        let mut slice = self.clone();
        slice.rules.retain(|r| heads.contains(&r.head.rel));
        for stratum in &mut slice.strata {
            stratum.rules.clear();
        }
        for (i, rule) in slice.rules.iter().enumerate() {
            let head = self.rel_index[&rule.head.rel];
            if let Some(s) = slice
                .strata
                .iter_mut()
                .find(|s| s.relations.contains(&head))
            {
                s.rules.push(i);
            }
        }
        slice
    }

    /// The relations the rules read (in atoms, negations and aggregates).
    pub fn relations_read(&self) -> BTreeSet<String> {
        let mut deps = Vec::new();
        for rule in &self.rules {
            collect_deps(&rule.body, false, &self.rel_index, &mut deps);
        }
        deps.iter()
            .map(|(b, _, _)| self.relations[*b].name.clone())
            .collect()
    }

    /// How explanations cite a rule: `label (file:line)` or `rule (file:line)`.
    pub fn rule_name(&self, rule: usize) -> String {
        let r = &self.rules[rule];
        match &r.label {
            Some(l) => format!("{l} ({})", self.location(r.span)),
            None if r.body.is_empty() => format!("fact ({})", self.location(r.span)),
            None => format!("rule ({})", self.location(r.span)),
        }
    }
}

pub struct Loader<'f> {
    functors: &'f [FunctorSig],
    sources: Vec<Source>,
    items: Vec<(u32, Item)>,
    loading: Vec<PathBuf>,
    /// `--rules-dir`: the folder every `.include` must stay in, if given.
    include_root: Option<PathBuf>,
    /// The folder the file being loaded may include from (canonical); one per nesting level.
    roots: Vec<PathBuf>,
}

impl<'f> Loader<'f> {
    pub fn new(functors: &'f [FunctorSig]) -> Self {
        Loader {
            functors,
            sources: Vec::new(),
            items: Vec::new(),
            loading: Vec::new(),
            include_root: None,
            roots: Vec::new(),
        }
    }

    /// Confine every `.include` to `root` instead of the top-level file's own folder.
    pub fn set_include_root(&mut self, root: Option<&Path>) {
        self.include_root = root.map(Path::to_path_buf);
    }

    fn one(&self, span: Span, msg: impl Into<String>, hint: impl Into<String>) -> Diagnostics {
        Diagnostics(vec![Diagnostic::at(&self.sources, span, msg, hint)])
    }

    /// An error about a file given on the command line (no span to quote).
    fn file_error(path: &Path, message: String, hint: &str) -> Diagnostics {
        Diagnostics(vec![Diagnostic {
            file: path.display().to_string(),
            line: 0,
            col: 0,
            len: 1,
            source_line: String::new(),
            message,
            hint: hint.into(),
        }])
    }

    /// The folder `.include`s of a top-level source in `dir` must stay in.
    fn top_level_root(&self, dir: &Path) -> Result<PathBuf, String> {
        let root = self.include_root.as_deref().unwrap_or(dir);
        super::confine::canonical_root(root)
    }

    /// Load a top-level rule file: its `.include`s stay under its folder (or `--rules-dir`).
    pub fn load_file(&mut self, path: &Path, from: Option<Span>) -> Result<(), Diagnostics> {
        if let Some(span) = from {
            return self.load_included(path, span);
        }
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let root = self
            .top_level_root(&dir)
            .map_err(|m| Self::file_error(path, m, "check the path"))?;
        self.roots.push(root);
        let r = self.read_and_load(path, None);
        self.roots.pop();
        r
    }

    /// Load program text that stands for a file in `dir`.
    pub fn load_text(&mut self, name: &str, text: &str, dir: &Path) -> Result<(), Diagnostics> {
        // Embedded sources name folders that need not exist here: fall back to the name as given.
        let root = self
            .top_level_root(dir)
            .unwrap_or_else(|_| self.include_root.clone().unwrap_or(dir.to_path_buf()));
        self.roots.push(root);
        let r = self.load_text_in(name, text, dir);
        self.roots.pop();
        r
    }

    /// An `.include`: refused before it is opened unless it resolves (symlinks
    /// followed) under the current root, so a refused file is never read or quoted.
    fn load_included(&mut self, path: &Path, span: Span) -> Result<(), Diagnostics> {
        let root = self.roots.last().cloned().unwrap_or_default();
        let canonical = match path.canonicalize() {
            Ok(c) => c,
            Err(e) => {
                return Err(self.one(
                    span,
                    format!("`.include`: cannot read rule file {}: {e}", path.display()),
                    "check the path (relative to the including file)",
                ));
            }
        };
        if !canonical.starts_with(&root) {
            return Err(self.one(
                span,
                format!(
                    "`.include` refused: {} is outside the folder {} that included rule files must stay in",
                    path.display(),
                    root.display()
                ),
                format!(
                    "copy the file under {} (symbolic links out of it are refused too), or pass --rules-dir with a folder that holds both",
                    root.display()
                ),
            ));
        }
        self.read_and_load(path, Some(span))
    }

    fn read_and_load(&mut self, path: &Path, from: Option<Span>) -> Result<(), Diagnostics> {
        let canonical = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
        if self.loading.contains(&canonical) {
            let span = from.unwrap_or_default();
            return Err(self.one(
                span,
                format!("`.include` cycle: {} includes itself", path.display()),
                "remove one of the `.include` directives",
            ));
        }
        let text = match std::fs::read_to_string(path) {
            Ok(t) => t,
            Err(e) => {
                let msg = format!("cannot read rule file {}: {e}", path.display());
                return Err(match from {
                    Some(span) => {
                        self.one(span, msg, "check the path (relative to the including file)")
                    }
                    None => Self::file_error(path, msg, "check the path"),
                });
            }
        };
        self.loading.push(canonical);
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let r = self.load_text_in(&path.display().to_string(), &text, &dir);
        self.loading.pop();
        r
    }

    fn load_text_in(&mut self, name: &str, text: &str, dir: &Path) -> Result<(), Diagnostics> {
        let file = self.sources.len() as u32;
        self.sources.push(Source {
            name: name.to_string(),
            text: text.to_string(),
        });
        let (toks, labels) = lex(file, text).map_err(|e| self.one(e.span, e.message, e.hint))?;
        let items = Parser::new(&toks, &labels)
            .items()
            .map_err(|e| self.one(e.span, e.message, e.hint))?;
        for item in items {
            if let Item::Include { path, span } = &item {
                let p = dir.join(path);
                self.load_included(&p, *span)?;
            } else {
                self.items.push((file, item));
            }
        }
        Ok(())
    }

    pub fn finish(self) -> Result<Program, Diagnostics> {
        Checker {
            sources: self.sources,
            functors: self.functors,
            errors: Vec::new(),
            types: BTreeMap::new(),
            agg_counter: 0,
            arg_counter: 0,
            atom_types: BTreeMap::new(),
        }
        .run(self.items)
    }
}

struct Checker<'f> {
    sources: Vec<Source>,
    functors: &'f [FunctorSig],
    errors: Vec<Diagnostic>,
    /// User type name → (parent name, is_subtype, span).
    types: BTreeMap<String, TypeDecl>,
    agg_counter: usize,
    /// Fresh variables standing for expression arguments of body atoms (`__argN`).
    arg_counter: usize,
    /// Relation name → attribute base types.
    atom_types: BTreeMap<String, Vec<BaseTy>>,
}

type Env = BTreeMap<String, BaseTy>;

impl Checker<'_> {
    fn error(&mut self, span: Span, msg: impl Into<String>, hint: impl Into<String>) {
        self.errors
            .push(Diagnostic::at(&self.sources, span, msg, hint));
    }

    /// Base type of a type name, following `.type` declarations.
    fn resolve_type(&self, name: &str) -> Option<BaseTy> {
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

    fn run(mut self, items: Vec<(u32, Item)>) -> Result<Program, Diagnostics> {
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
        // Clauses.
        let mut rules = Vec::new();
        let mut labels: BTreeMap<String, Span> = BTreeMap::new();
        for (_, item) in items {
            if let Item::Clause(mut rule) = item {
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
                if self.check_rule(&mut rule, &relations, &rel_index) {
                    rules.push(rule);
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

    fn loc(&self, span: Span) -> String {
        let file = self
            .sources
            .get(span.file as usize)
            .map_or("<unknown>", |s| s.name.as_str());
        format!("{file}:{}:{}", span.line, span.col)
    }

    fn rel_hint(&self, name: &str, rel_index: &BTreeMap<String, usize>) -> String {
        match closest(name, rel_index.keys().map(String::as_str)) {
            Some(c) => format!("did you mean `{c}`? otherwise declare it with `.decl {name}(...)`"),
            None => format!("declare it with `.decl {name}(x: number, ...)`"),
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

    /// Replaces expression arguments of positive atoms (in aggregate bodies too) by fresh
    /// variables `__argN`, adding `__argN = <expression>` to the same body: all of them when
    /// `every`, else those reading a variable that the same atom binds as a plain argument.
    /// Returns whether any was replaced.
    fn lift_self_bound_args(&mut self, body: &mut Vec<Literal>, every: bool) -> bool {
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

    fn lift_in_body(&mut self, body: &mut [Literal]) {
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
    fn lift_aggs(&mut self, e: &mut Expr, out: &mut Vec<Literal>) {
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

    fn check_atom(&mut self, a: &Atom, rels: &[RelDecl], idx: &BTreeMap<String, usize>) {
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

    fn check_atoms_in(
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

    fn collect_atom_types(
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

    fn collect_types_in(
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
    fn infer_equalities(&mut self, body: &[Literal], env: &mut Env) {
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
    fn check_expr(
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

    fn check_lits(&mut self, body: &mut [Literal], env: &mut Env) {
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

impl Checker<'_> {
    /// Order `body` so every variable is bound before it is read; returns the
    /// steps and the variables bound at the end, or None after reporting.
    fn plan(
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
                        format!("variable `{v}` is grounded only inside the aggregate but used outside it (the witness problem: an aggregate cannot export a binding)"),
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

    fn stratify(
        &mut self,
        rels: &[RelDecl],
        idx: &BTreeMap<String, usize>,
        rules: &[Rule],
    ) -> Vec<Stratum> {
        let n = rels.len();
        // deps[h] = (body relation, negative or aggregated, span of the use)
        let mut deps: Vec<Vec<(usize, bool, Span)>> = vec![Vec::new(); n];
        for r in rules {
            let h = idx[&r.head.rel];
            collect_deps(&r.body, false, idx, &mut deps[h]);
        }
        let sccs = tarjan(n, &deps);
        let mut scc_of = vec![0usize; n];
        for (k, c) in sccs.iter().enumerate() {
            for &v in c {
                scc_of[v] = k;
            }
        }
        for h in 0..n {
            for &(b, neg, span) in &deps[h] {
                if neg && scc_of[h] == scc_of[b] {
                    let cycle = cycle_path(&deps, b, h, &scc_of);
                    let mut names: Vec<&str> = vec![rels[h].name.as_str()];
                    names.extend(cycle.iter().map(|&i| rels[i].name.as_str()));
                    self.error(span, format!("negation or aggregation of `{}` inside a recursive cycle: {}", rels[b].name, names.join(" -> ")), "the program is not stratifiable; break the cycle so the negated/aggregated relation does not depend on the rule's head");
                }
            }
        }
        sccs.iter()
            .map(|c| {
                let mut relations = c.clone();
                relations.sort();
                let recursive = c.len() > 1 || deps[c[0]].iter().any(|(b, _, _)| *b == c[0]);
                let rules = rules
                    .iter()
                    .enumerate()
                    .filter(|(_, r)| c.contains(&idx[&r.head.rel]))
                    .map(|(i, _)| i)
                    .collect();
                Stratum {
                    relations,
                    rules,
                    recursive,
                }
            })
            .collect()
    }
}

fn collect_deps(
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

/// Strongly connected components, dependencies first.
fn tarjan(n: usize, deps: &[Vec<(usize, bool, Span)>]) -> Vec<Vec<usize>> {
    struct St<'a> {
        deps: &'a [Vec<(usize, bool, Span)>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        on: Vec<bool>,
        stack: Vec<usize>,
        next: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut St, v: usize) {
        // Iterative DFS with an explicit stack of (node, next edge).
        let mut work = vec![(v, 0usize)];
        s.index[v] = Some(s.next);
        s.low[v] = s.next;
        s.next += 1;
        s.stack.push(v);
        s.on[v] = true;
        while let Some(&mut (u, ref mut ei)) = work.last_mut() {
            if *ei < s.deps[u].len() {
                let w = s.deps[u][*ei].0;
                *ei += 1;
                match s.index[w] {
                    None => {
                        s.index[w] = Some(s.next);
                        s.low[w] = s.next;
                        s.next += 1;
                        s.stack.push(w);
                        s.on[w] = true;
                        work.push((w, 0));
                    }
                    Some(iw) if s.on[w] => s.low[u] = s.low[u].min(iw),
                    _ => {}
                }
            } else {
                work.pop();
                if let Some(&(p, _)) = work.last() {
                    s.low[p] = s.low[p].min(s.low[u]);
                }
                if Some(s.low[u]) == s.index[u] {
                    let mut comp = Vec::new();
                    loop {
                        let w = s.stack.pop().unwrap();
                        s.on[w] = false;
                        comp.push(w);
                        if w == u {
                            break;
                        }
                    }
                    s.out.push(comp);
                }
            }
        }
    }
    let mut s = St {
        deps,
        index: vec![None; n],
        low: vec![0; n],
        on: vec![false; n],
        stack: Vec::new(),
        next: 0,
        out: Vec::new(),
    };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// A dependency path from `from` to `to` inside one component (inclusive of both ends).
fn cycle_path(
    deps: &[Vec<(usize, bool, Span)>],
    from: usize,
    to: usize,
    scc: &[usize],
) -> Vec<usize> {
    let mut prev: BTreeMap<usize, usize> = BTreeMap::new();
    let mut queue = std::collections::VecDeque::from([from]);
    let mut seen = BTreeSet::from([from]);
    while let Some(u) = queue.pop_front() {
        if u == to {
            break;
        }
        for &(w, _, _) in &deps[u] {
            if scc[w] == scc[from] && seen.insert(w) {
                prev.insert(w, u);
                queue.push_back(w);
            }
        }
    }
    let mut path = vec![to];
    let mut cur = to;
    while cur != from {
        match prev.get(&cur) {
            Some(&p) => {
                path.push(p);
                cur = p;
            }
            None => break,
        }
    }
    path.reverse();
    if from == to {
        path.push(to);
    }
    path
}

/// The rules that make `rel` an equivalence relation:
/// `rel(x, x) :- rel(x, _).`, `rel(y, x) :- rel(x, y).`,
/// `rel(x, z) :- rel(x, y), rel(y, z).` (cited at the declaration).
fn eqrel_rules(rel: &str, span: Span) -> Vec<Rule> {
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

#[cfg(test)]
mod slice_tests {
    use super::super::load_str;
    use std::collections::BTreeSet;

    const TEXT: &str = r#"
.decl seed(x: symbol)
.input seed
.decl other(x: symbol)
.input other
.decl a(x: symbol)
.decl b(x: symbol)
.decl c(x: symbol)
.decl d(x: symbol)
.output d
a(x) :- seed(x).
b(x) :- a(x).
c(x) :- other(x).
b(x) :- c(x).
d(x) :- c(x), !b(x).
"#;

    #[test]
    fn downstream_follows_atoms_and_negations_transitively() {
        let program = load_str("slice.dl", TEXT, &[]).expect("program");
        let reached = program.downstream_of(&["seed"]);
        let names: BTreeSet<&str> = reached.iter().map(String::as_str).collect();
        // c reads only `other`; d reads b through a negation.
        assert_eq!(names, BTreeSet::from(["seed", "a", "b", "d"]));
    }

    #[test]
    fn a_slice_keeps_every_rule_of_its_heads_and_reads_the_rest() {
        let program = load_str("slice.dl", TEXT, &[]).expect("program");
        let slice = program.restricted_to(&program.downstream_of(&["seed"]));
        let heads: Vec<&str> = slice.rules.iter().map(|r| r.head.rel.as_str()).collect();
        // Both rules for b stay, the one from c included; c's own rule goes.
        assert_eq!(heads, ["a", "b", "b", "d"]);
        let in_strata: usize = slice.strata.iter().map(|s| s.rules.len()).sum();
        assert_eq!(in_strata, 4, "every kept rule sits in its stratum");
        let read: BTreeSet<String> = slice.relations_read();
        let read: BTreeSet<&str> = read.iter().map(String::as_str).collect();
        assert_eq!(read, BTreeSet::from(["seed", "a", "b", "c"]));
    }
}
