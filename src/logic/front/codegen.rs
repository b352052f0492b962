//! Code generator: a checked program → an `ascent!` program plus a wrapper
//! that takes and returns `Value` tuples. Used by `build.rs` for the built-in
//! rule base (`rules/*.dl`) and the test programs (`tests/logic/*.dl`).
//!
//! Aggregates become an auxiliary relation holding one tuple per match of the
//! aggregate body (outer variables, the aggregated value, the body's other
//! variables; min and max only the outer variables and the value), aggregated
//! with ascent's `agg` clause; negated atoms with `_` become a projection
//! relation.

use super::Program;
use super::ast::*;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::{self, Write as _};

/// Why a rule program cannot be compiled to ascent: the rule and what in it the compiled
/// engine does not support. (Std only, as the rest of `front`: `build.rs` includes it.)
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CodegenError {
    /// The rule's name (`Program::rule_name`).
    pub rule: String,
    pub reason: &'static str,
}

impl CodegenError {
    fn new(b: &Body, reason: &'static str) -> Self {
        CodegenError {
            rule: b.rule_name.clone(),
            reason,
        }
    }
}

impl fmt::Display for CodegenError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.rule, self.reason)
    }
}

impl std::error::Error for CodegenError {}

/// The Rust type of a column of type `t` in a generated program.
pub fn rust_ty(t: BaseTy) -> &'static str {
    match t {
        BaseTy::Number => "i64",
        BaseTy::Unsigned => "u64",
        BaseTy::Float => "F64",
        BaseTy::Symbol => "Sym",
        BaseTy::Vec3 => "Vec3",
        BaseTy::Iso => "Iso",
        BaseTy::Box => "OBox",
    }
}

fn ident(name: &str) -> String {
    name.replace('?', "_Q")
}

/// The field of a generated program's `Prog` that holds relation `name`.
pub fn rel_name(name: &str) -> String {
    format!("r_{}", ident(name))
}

fn var_name(name: &str) -> String {
    format!("v_{}", ident(name))
}

struct Gen<'p> {
    prog: &'p Program,
    aux_decls: Vec<String>,
    aux_rules: Vec<String>,
    fresh: usize,
    /// The rule being generated derives a relation of a recursive stratum.
    head_recursive: bool,
}

/// One rule being written: its clauses and the variables bound so far.
struct Body {
    clauses: Vec<String>,
    bound: BTreeSet<String>,
    rule_name: String,
}

pub fn generate(prog: &Program, module: &str) -> Result<String, CodegenError> {
    let mut g = Gen {
        prog,
        aux_decls: Vec::new(),
        aux_rules: Vec::new(),
        fresh: 0,
        head_recursive: false,
    };
    let mut rules_text = String::new();
    for (i, rule) in prog.rules.iter().enumerate() {
        let text = g.rule(i, rule)?;
        rules_text.push_str(&text);
    }
    let mut s = String::new();
    let _ = writeln!(s, "/// Generated from the rule program `{module}`.");
    let _ = writeln!(
        s,
        "#[allow(unused, non_snake_case, non_camel_case_types, clippy::all)]"
    );
    let _ = writeln!(
        s,
        "pub mod {} {{",
        ident(&module.replace(['/', '.', '-'], "_"))
    );
    s.push_str("use crate::logic::compiled::rt;\nuse crate::logic::value::{Column, Value, F64, Sym, Vec3, Iso, OBox};\nuse std::collections::BTreeMap;\n");
    s.push_str("ascent::ascent! {\npub struct Prog;\n");
    for r in &prog.relations {
        let cols: Vec<&str> = r.attrs.iter().map(|a| rust_ty(a.ty)).collect();
        let _ = writeln!(s, "relation {}({});", rel_name(&r.name), cols.join(", "));
    }
    for d in &g.aux_decls {
        s.push_str(d);
    }
    s.push_str(&rules_text);
    for r in &g.aux_rules {
        s.push_str(r);
    }
    s.push_str("}\n");
    // Wrapper.
    s.push_str("/// Run on the given input tuples; returns every relation, sorted.\n");
    s.push_str("pub fn run(edb: &BTreeMap<String, Vec<Vec<Value>>>) -> Result<BTreeMap<String, Vec<Vec<Value>>>, crate::logic::compiled::CompiledError> {\n");
    s.push_str("    rt::reset_error();\n    let mut p = Prog::default();\n");
    for r in &prog.relations {
        let conv: Vec<String> = r
            .attrs
            .iter()
            .enumerate()
            .map(|(i, a)| format!("<{} as Column>::from_value(&t[{i}]),", rust_ty(a.ty)))
            .collect();
        let _ = writeln!(
            s,
            "    if let Some(ts) = edb.get({:?}) {{ p.{} = ts.iter().map(|t| ({})).collect(); }}",
            r.name,
            rel_name(&r.name),
            conv.join(" ")
        );
    }
    s.push_str("    p.run();\n    if let Some(e) = rt::take_error() { return Err(e); }\n    let mut out = BTreeMap::new();\n");
    for r in &prog.relations {
        let conv: Vec<String> = (0..r.arity())
            .map(|i| format!("t.{i}.clone().into_value()"))
            .collect();
        let _ = writeln!(
            s,
            "    {{ let mut v: Vec<Vec<Value>> = p.{}.iter().map(|t| vec![{}]).collect(); v.sort(); v.dedup(); out.insert({:?}.to_string(), v); }}",
            rel_name(&r.name),
            conv.join(", "),
            r.name
        );
    }
    s.push_str("    Ok(out)\n}\n}\n");
    Ok(s)
}

fn collect_var_types(e: &Expr, out: &mut BTreeMap<String, BaseTy>) {
    if let (ExprKind::Var(v), Some(t)) = (&e.kind, e.ty) {
        out.insert(v.clone(), t);
    }
    match &e.kind {
        ExprKind::Neg(x) => collect_var_types(x, out),
        ExprKind::Bin(_, a, b) => {
            collect_var_types(a, out);
            collect_var_types(b, out);
        }
        ExprKind::Builtin(_, args) | ExprKind::Ext(_, args) => {
            args.iter().for_each(|a| collect_var_types(a, out))
        }
        ExprKind::Agg(a) => {
            if let Some(t) = &a.target {
                collect_var_types(t, out);
            }
            for l in &a.body {
                collect_lit_types(l, out);
            }
        }
        _ => {}
    }
}

fn collect_lit_types(l: &Literal, out: &mut BTreeMap<String, BaseTy>) {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().for_each(|e| collect_var_types(e, out)),
        Literal::Cmp(_, a, b, _) => {
            collect_var_types(a, out);
            collect_var_types(b, out);
        }
        Literal::StrTest { args, .. } => args.iter().for_each(|e| collect_var_types(e, out)),
    }
}

fn float_lit(f: f64) -> String {
    format!("F64(f64::from_bits({:#x}u64))", f.to_bits())
}

impl Gen<'_> {
    fn fresh(&mut self, prefix: &str) -> String {
        self.fresh += 1;
        format!("__{prefix}{}", self.fresh)
    }

    fn rule(&mut self, id: usize, rule: &Rule) -> Result<String, CodegenError> {
        let head = self.prog.rel_index[&rule.head.rel];
        self.head_recursive = self
            .prog
            .strata
            .iter()
            .any(|s| s.recursive && s.relations.contains(&head));
        let mut types = BTreeMap::new();
        for a in &rule.head.args {
            collect_var_types(a, &mut types);
        }
        for l in &rule.body {
            collect_lit_types(l, &mut types);
        }
        let mut body = Body {
            clauses: Vec::new(),
            bound: BTreeSet::new(),
            rule_name: self.prog.rule_name(id),
        };
        self.steps(&rule.body, &rule.plan, &mut body)?;
        let head: Vec<String> = rule
            .head
            .args
            .iter()
            .map(|e| self.expr(e, &body))
            .collect::<Result<_, _>>()?;
        let head = format!("{}({})", rel_name(&rule.head.rel), head.join(", "));
        Ok(if body.clauses.is_empty() {
            format!("{head};\n")
        } else {
            format!("{head} <--\n    {};\n", body.clauses.join(",\n    "))
        })
    }

    fn steps(&mut self, lits: &[Literal], plan: &[Step], b: &mut Body) -> Result<(), CodegenError> {
        for step in plan {
            match step {
                Step::Scan(i) => {
                    let Literal::Pos(a) = &lits[*i] else {
                        unreachable!()
                    };
                    self.scan(a, b)?;
                }
                Step::Negate(i) => {
                    let Literal::Neg(a) = &lits[*i] else {
                        unreachable!()
                    };
                    self.negate(a, b)?;
                }
                Step::Filter(i) => match &lits[*i] {
                    Literal::Cmp(op, x, y, _) => match (&x.kind, &y.kind) {
                        (ExprKind::Agg(g), _) => {
                            let v = self.fresh("a");
                            self.aggregate(g, &v, b)?;
                            let other = self.expr(y, b)?;
                            let c = self.cmp(*op, x.ty.or(y.ty), &format!("{v}.clone()"), &other);
                            b.clauses.push(format!("if {c}"));
                        }
                        (_, ExprKind::Agg(g)) => {
                            let v = self.fresh("a");
                            self.aggregate(g, &v, b)?;
                            let other = self.expr(x, b)?;
                            let c = self.cmp(*op, x.ty.or(y.ty), &other, &format!("{v}.clone()"));
                            b.clauses.push(format!("if {c}"));
                        }
                        _ => {
                            let (l, r) = (self.expr(x, b)?, self.expr(y, b)?);
                            let c = self.cmp(*op, x.ty.or(y.ty), &l, &r);
                            b.clauses.push(format!("if {c}"));
                        }
                    },
                    Literal::StrTest {
                        is_match,
                        negated,
                        args,
                        ..
                    } => {
                        let (x, y) = (self.expr(&args[0], b)?, self.expr(&args[1], b)?);
                        // An invalid pattern makes `match` and `!match` both false.
                        let test = if *is_match {
                            format!("rt::match_test(&{x}, &{y}, {negated})")
                        } else {
                            let not = if *negated { "!" } else { "" };
                            format!("{not}crate::logic::ops::contains(&{x}, &{y})")
                        };
                        b.clauses.push(format!("if {test}"));
                    }
                    _ => unreachable!(),
                },
                Step::Assign {
                    lit,
                    var,
                    var_on_left,
                } => {
                    let Literal::Cmp(_, x, y, _) = &lits[*lit] else {
                        unreachable!()
                    };
                    let e = if *var_on_left { y } else { x };
                    if let ExprKind::Agg(g) = &e.kind {
                        self.aggregate(g, &var_name(var), b)?;
                    } else {
                        let code = self.expr(e, b)?;
                        b.clauses.push(format!("let {} = {code}", var_name(var)));
                    }
                    b.bound.insert(var.clone());
                }
            }
        }
        Ok(())
    }

    fn scan(&mut self, a: &Atom, b: &mut Body) -> Result<(), CodegenError> {
        let mut args = Vec::new();
        let mut post = Vec::new();
        let mut seen: BTreeSet<String> = BTreeSet::new();
        for e in &a.args {
            match &e.kind {
                ExprKind::Wild => args.push("_".to_string()),
                ExprKind::Var(v) if seen.contains(v) => {
                    let d = self.fresh("d");
                    post.push(format!("if {d}.clone() == {}.clone()", var_name(v)));
                    args.push(d);
                }
                ExprKind::Var(v) => {
                    seen.insert(v.clone());
                    args.push(var_name(v));
                }
                _ => {
                    let vars = super::check::expr_vars(e);
                    if vars.iter().all(|v| b.bound.contains(v)) {
                        let k = self.fresh("k");
                        let code = self.expr(e, b)?;
                        b.clauses.push(format!("let {k} = {code}"));
                        args.push(k);
                    } else {
                        let d = self.fresh("d");
                        let code = self.expr(e, b)?;
                        post.push(format!("if {d}.clone() == {code}"));
                        args.push(d);
                    }
                }
            }
        }
        b.bound.extend(seen);
        b.clauses
            .push(format!("{}({})", rel_name(&a.rel), args.join(", ")));
        b.clauses.extend(post);
        Ok(())
    }

    fn negate(&mut self, a: &Atom, b: &mut Body) -> Result<(), CodegenError> {
        let decl = self
            .prog
            .relation(&a.rel)
            .ok_or_else(|| CodegenError::new(b, "unknown relation"))?;
        let has_wild = a.args.iter().any(|e| matches!(e.kind, ExprKind::Wild));
        let mut keys = Vec::new();
        for e in a.args.iter().filter(|e| !matches!(e.kind, ExprKind::Wild)) {
            match &e.kind {
                ExprKind::Var(v) => keys.push(var_name(v)),
                _ => {
                    let k = self.fresh("k");
                    let code = self.expr(e, b)?;
                    b.clauses.push(format!("let {k} = {code}"));
                    keys.push(k);
                }
            }
        }
        let target = if has_wild {
            // Project away the `_` columns.
            let name = self.fresh("neg");
            let mut cols = Vec::new();
            let mut pats = Vec::new();
            let mut head = Vec::new();
            for (c, e) in a.args.iter().enumerate() {
                if matches!(e.kind, ExprKind::Wild) {
                    pats.push("_".to_string());
                } else {
                    cols.push(rust_ty(decl.attrs[c].ty));
                    pats.push(format!("p{c}"));
                    head.push(format!("p{c}.clone()"));
                }
            }
            self.aux_decls
                .push(format!("relation {name}({});\n", cols.join(", ")));
            self.aux_rules.push(format!(
                "{name}({}) <-- {}({});\n",
                head.join(", "),
                rel_name(&a.rel),
                pats.join(", ")
            ));
            name
        } else {
            rel_name(&a.rel)
        };
        b.clauses.push(format!("!{target}({})", keys.join(", ")));
        Ok(())
    }

    /// Bind `result` to the aggregate's value for the current outer bindings.
    fn aggregate(&mut self, g: &Aggregate, result: &str, b: &mut Body) -> Result<(), CodegenError> {
        // Body with `_` in atoms made into distinct variables (each match counts).
        let mut lits = g.body.clone();
        let mut locals: Vec<(String, BaseTy)> = Vec::new();
        for l in &mut lits {
            if let Literal::Pos(a) = l {
                for e in &mut a.args {
                    if let ExprKind::Wild = e.kind {
                        let w = self.fresh("w");
                        locals.push((w.clone(), e.ty.unwrap_or(BaseTy::Number)));
                        e.kind = ExprKind::Var(w);
                    }
                }
            }
        }
        let mut types = BTreeMap::new();
        for l in &lits {
            collect_lit_types(l, &mut types);
        }
        if let Some(t) = &g.target {
            collect_var_types(t, &mut types);
        }
        for (w, t) in &locals {
            types.insert(w.clone(), *t);
        }
        let injected: Vec<String> = g.injected.clone();
        for (v, t) in &types {
            if !injected.contains(v) && !locals.iter().any(|(w, _)| w == v) {
                locals.push((v.clone(), *t));
            }
        }
        // Order: scans in plan order, other literals as soon as their variables are bound.
        let mut inner = Body {
            clauses: Vec::new(),
            bound: BTreeSet::new(),
            rule_name: b.rule_name.clone(),
        };
        let mut deferred: Vec<Step> = Vec::new();
        for step in &g.plan {
            match step {
                Step::Scan(_) => {
                    self.steps(&lits, std::slice::from_ref(step), &mut inner)?;
                    let mut still = Vec::new();
                    for d in std::mem::take(&mut deferred) {
                        if self.step_ready(&lits, &d, &inner.bound) {
                            self.steps(&lits, std::slice::from_ref(&d), &mut inner)?;
                        } else {
                            still.push(d);
                        }
                    }
                    deferred = still;
                }
                other => {
                    if self.step_ready(&lits, other, &inner.bound) && deferred.is_empty() {
                        self.steps(&lits, std::slice::from_ref(other), &mut inner)?;
                    } else {
                        deferred.push(other.clone());
                    }
                }
            }
        }
        if !deferred.is_empty() || injected.iter().any(|v| !inner.bound.contains(v)) {
            // The body alone does not bind the outer variables (`y < n` with `n`
            // from outside): evaluate it after the outer literals that bind them.
            // In a recursive stratum that would aggregate over the head's own
            // stratum, which ascent refuses.
            if self.head_recursive {
                return Err(CodegenError::new(
                    b,
                    "in a recursive rule the compiled engine needs every outer variable of an aggregate to occur in a positive atom of its body",
                ));
            }
            inner = Body {
                clauses: b.clauses.clone(),
                bound: b.bound.clone(),
                rule_name: b.rule_name.clone(),
            };
            self.steps(&lits, &g.plan, &mut inner)?;
        }
        let name = self.fresh("agg");
        let mut cols: Vec<&str> = injected.iter().map(|v| rust_ty(types[v])).collect();
        let mut head: Vec<String> = injected
            .iter()
            .map(|v| format!("{}.clone()", var_name(v)))
            .collect();
        let target_ty = g
            .target
            .as_ref()
            .and_then(|t| t.ty)
            .unwrap_or(BaseTy::Number);
        if let Some(t) = &g.target {
            cols.push(rust_ty(target_ty));
            head.push(self.expr(t, &inner)?);
        }
        // Each match counts for count, sum and mean, so their tuples keep the body's other
        // variables; the least or greatest value is the same over the distinct values, so
        // min and max keep only the value (no boxes or poses hashed per match).
        let witnesses: &[(String, BaseTy)] = match g.op {
            AggOp::Min | AggOp::Max if g.target.is_some() => &[],
            _ => &locals,
        };
        for (v, t) in witnesses {
            cols.push(rust_ty(*t));
            head.push(format!("{}.clone()", var_name(v)));
        }
        self.aux_decls
            .push(format!("relation {name}({});\n", cols.join(", ")));
        if inner.clauses.is_empty() {
            self.aux_rules
                .push(format!("{name}({});\n", head.join(", ")));
        } else {
            self.aux_rules.push(format!(
                "{name}({}) <--\n    {};\n",
                head.join(", "),
                inner.clauses.join(",\n    ")
            ));
        }
        let mut pats: Vec<String> = injected.iter().map(|v| var_name(v)).collect();
        let t = self.fresh("t");
        if g.target.is_some() {
            pats.push(t.clone());
        }
        pats.extend(witnesses.iter().map(|_| "_".to_string()));
        let suffix = match target_ty {
            BaseTy::Number => "i64",
            BaseTy::Unsigned => "u64",
            _ => "f64",
        };
        let call = match g.op {
            AggOp::Count => "rt::count()".to_string(),
            AggOp::Sum => format!("rt::sum_{suffix}({t})"),
            AggOp::Mean => format!("rt::mean_{suffix}({t})"),
            AggOp::Min => format!(
                "rt::min_{}({t})",
                if target_ty == BaseTy::Float {
                    "f64"
                } else {
                    "ord"
                }
            ),
            AggOp::Max => format!(
                "rt::max_{}({t})",
                if target_ty == BaseTy::Float {
                    "f64"
                } else {
                    "ord"
                }
            ),
        };
        b.clauses.push(format!(
            "agg {result} = {call} in {name}({})",
            pats.join(", ")
        ));
        Ok(())
    }

    fn step_ready(&self, lits: &[Literal], step: &Step, bound: &BTreeSet<String>) -> bool {
        let vars: Vec<String> = match step {
            Step::Scan(_) => return true,
            Step::Negate(i) | Step::Filter(i) => match &lits[*i] {
                Literal::Neg(a) => a.args.iter().flat_map(super::check::expr_vars).collect(),
                Literal::Cmp(_, x, y, _) => super::check::expr_free_vars(x)
                    .into_iter()
                    .chain(super::check::expr_free_vars(y))
                    .collect(),
                Literal::StrTest { args, .. } => {
                    args.iter().flat_map(super::check::expr_vars).collect()
                }
                Literal::Pos(_) => return true,
            },
            Step::Assign {
                lit, var_on_left, ..
            } => match &lits[*lit] {
                Literal::Cmp(_, x, y, _) => {
                    super::check::expr_free_vars(if *var_on_left { y } else { x })
                }
                _ => return true,
            },
        };
        vars.iter().all(|v| bound.contains(v))
    }

    fn cmp(&self, op: CmpOp, ty: Option<BaseTy>, a: &str, b: &str) -> String {
        if ty == Some(BaseTy::Float) {
            format!("({a}).0 {} ({b}).0", rust_cmp(op))
        } else {
            format!("{a} {} {b}", rust_cmp(op))
        }
    }

    /// Rust code computing an owned value of the expression's type.
    fn expr(&self, e: &Expr, b: &Body) -> Result<String, CodegenError> {
        let ty = e.ty.unwrap_or(BaseTy::Number);
        let rn = &b.rule_name;
        Ok(match &e.kind {
            ExprKind::Var(v) => format!("{}.clone()", var_name(v)),
            ExprKind::Wild => return Err(CodegenError::new(b, "`_` outside an atom")),
            ExprKind::Int(i) => match ty {
                BaseTy::Unsigned => format!("({i}u64)"),
                BaseTy::Float => float_lit(*i as f64),
                _ => format!("({i}i64)"),
            },
            ExprKind::Float(f) => float_lit(*f),
            ExprKind::Str(s) => format!("rt::sym({s:?})"),
            ExprKind::Neg(x) => {
                let x = self.expr(x, b)?;
                match ty {
                    BaseTy::Float => format!("F64(-({x}).0)"),
                    _ => format!("({x}).wrapping_neg()"),
                }
            }
            ExprKind::Bin(op, x, y) => {
                let (x, y) = (self.expr(x, b)?, self.expr(y, b)?);
                match (ty, op) {
                    (BaseTy::Float, BinOp::Pow) => format!("F64(({x}).0.powf(({y}).0))"),
                    (BaseTy::Float, op) => format!("F64(({x}).0 {} ({y}).0)", op.symbol()),
                    (_, BinOp::Add) => format!("({x}).wrapping_add({y})"),
                    (_, BinOp::Sub) => format!("({x}).wrapping_sub({y})"),
                    (_, BinOp::Mul) => format!("({x}).wrapping_mul({y})"),
                    (BaseTy::Unsigned, BinOp::Div) => format!("rt::div_u64({x}, {y}, {rn:?})"),
                    (BaseTy::Unsigned, BinOp::Rem) => format!("rt::rem_u64({x}, {y}, {rn:?})"),
                    (BaseTy::Unsigned, BinOp::Pow) => {
                        format!("crate::logic::ops::pow_u64({x}, {y})")
                    }
                    (_, BinOp::Div) => format!("rt::div_i64({x}, {y}, {rn:?})"),
                    (_, BinOp::Rem) => format!("rt::rem_i64({x}, {y}, {rn:?})"),
                    (_, BinOp::Pow) => format!("crate::logic::ops::pow_i64({x}, {y})"),
                }
            }
            ExprKind::Builtin(Builtin::Autoinc, _) => {
                return Err(CodegenError::new(
                    b,
                    "autoinc() is interpreter-only: its numbers follow the interpreter's evaluation order",
                ));
            }
            ExprKind::Builtin(bi, args) => {
                let a: Vec<String> = args
                    .iter()
                    .map(|x| self.expr(x, b))
                    .collect::<Result<_, _>>()?;
                match bi {
                    Builtin::Min | Builtin::Max => {
                        let f = match (bi, ty) {
                            (Builtin::Min, BaseTy::Float) => "rt::min2_f64",
                            (Builtin::Max, BaseTy::Float) => "rt::max2_f64",
                            (Builtin::Min, _) => "std::cmp::min",
                            _ => "std::cmp::max",
                        };
                        let mut acc = a[0].clone();
                        for x in &a[1..] {
                            acc = format!("{f}({acc}, {x})");
                        }
                        acc
                    }
                    Builtin::Cat => format!(
                        "crate::logic::ops::cat(&[{}])",
                        a.iter()
                            .map(|x| format!("&*{x}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                    Builtin::Strlen => format!("crate::logic::ops::strlen(&{})", a[0]),
                    Builtin::Substr => format!("rt::substr(&{}, {}, {}, {rn:?})", a[0], a[1], a[2]),
                    Builtin::Ord => format!("crate::logic::ops::ord(&{})", a[0]),
                    Builtin::ToNumber => format!("rt::to_number(&{}, {rn:?})", a[0]),
                    Builtin::ToUnsigned => format!("rt::to_unsigned(&{}, {rn:?})", a[0]),
                    Builtin::ToFloat => format!("rt::to_float(&{}, {rn:?})", a[0]),
                    Builtin::ToString => match args[0].ty {
                        Some(BaseTy::Unsigned) => {
                            format!("crate::logic::ops::u64_to_string({})", a[0])
                        }
                        Some(BaseTy::Float) => {
                            format!("crate::logic::ops::f64_to_string({})", a[0])
                        }
                        _ => format!("crate::logic::ops::i64_to_string({})", a[0]),
                    },
                    Builtin::Itof => format!("F64(({}) as f64)", a[0]),
                    Builtin::Itou => format!("(({}) as u64)", a[0]),
                    Builtin::Utoi => format!("(({}) as i64)", a[0]),
                    Builtin::Utof => format!("F64(({}) as f64)", a[0]),
                    Builtin::Ftoi => format!("(({}).0 as i64)", a[0]),
                    Builtin::Ftou => format!("(({}).0 as u64)", a[0]),
                    Builtin::Autoinc => unreachable!("refused above"),
                }
            }
            ExprKind::Ext(name, args) => {
                let a: Vec<String> = args
                    .iter()
                    .map(|x| self.expr(x, b))
                    .collect::<Result<_, _>>()?;
                format!("crate::logic::functors::defs::{name}({})", a.join(", "))
            }
            ExprKind::Agg(_) => {
                return Err(CodegenError::new(
                    b,
                    "nested aggregates are not supported by the compiled engine",
                ));
            }
        })
    }
}

fn rust_cmp(op: CmpOp) -> &'static str {
    match op {
        CmpOp::Eq => "==",
        CmpOp::Ne => "!=",
        CmpOp::Lt => "<",
        CmpOp::Le => "<=",
        CmpOp::Gt => ">",
        CmpOp::Ge => ">=",
    }
}
