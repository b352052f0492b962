//! User rule files: shop rules written in the rule language that run on the
//! interpreter over the relations of the built-in rule base (or of a
//! `--rules-dir` replacement) and derive `violation(id, rule, message)` and
//! `warning(id, rule, message)` (declared in `findings.dl`).
//!
//! Two programs are built from the same files:
//! - the *evaluation* program (`UserRules::evaluate`): the base relations
//!   declared as inputs (at their own `file:line`, so errors cite them) plus
//!   the user rules. Only the base relations the user rules read are filled
//!   from an earlier (compiled) run, so a check costs little beyond `plan`.
//! - the *full* program (`full_program`): base rules and user rules as one
//!   program, for explanations that run from a finding down to IFC entities.
//!
//! A user file may read every base relation but not redefine one: declaring
//! it again, or deriving into it, is refused naming both places.

pub mod relations_doc;

use crate::frame::RuleEngine;
use crate::logic::compiled::{BUILTIN_SOURCES, Relations};
use crate::logic::front::ast::{Expr, ExprKind, Literal, Span};
use crate::logic::front::check::Loader;
use crate::logic::front::lex::{Tok, lex};
use crate::logic::front::{Diagnostic, Diagnostics, Source};
use crate::logic::{Engine, Limits, LogicError, Options, Origin, Program, Value, functors};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Path and text of the declarations of the findings relations.
pub const FINDINGS_SOURCE: (&str, &str) =
    ("src/user_rules/findings.dl", include_str!("findings.dl"));

/// The relations a user rule derives to report something.
pub const FINDING_RELATIONS: [&str; 2] = ["violation", "warning"];

#[derive(Debug, thiserror::Error)]
pub enum UserRulesError {
    /// A rule file does not parse or check, or redefines a base relation.
    #[error(transparent)]
    Rules(#[from] Diagnostics),
    /// A runtime error or a limit while evaluating the user rules.
    #[error(transparent)]
    Logic(#[from] LogicError),
    #[error("{}: cannot read the rules directory: {message}", path.display())]
    RulesDir { path: PathBuf, message: String },
    #[error("cannot read rule file {}: {message}; check the path", path.display())]
    RuleFile { path: PathBuf, message: String },
    #[error("the rule file {} derives into {feeds}, which feed the built-in rules, and reports {reports}: the first run before planning, the second after it; put them in two files", file.display())]
    FeedsAndFinds {
        file: PathBuf,
        feeds: String,
        reports: String,
    },
    #[error("the rule file {} feeds the rule base (a relation no rule of it derives); with --rules-dir {}, put the file in that directory", file.display(), dir.display())]
    FeedsRulesDir { file: PathBuf, dir: PathBuf },
    #[error("the user rule file {} lies in the rules directory {}, so it would also be read as part of the rule base; keep user rule files outside --rules-dir", file.display(), dir.display())]
    InsideRulesDir { file: PathBuf, dir: PathBuf },
}

/// A user file inside the `--rules-dir` directory would be loaded twice.
fn check_outside_rules_dir(files: &[PathBuf], base: &RuleEngine) -> Result<(), UserRulesError> {
    let RuleEngine::Directory(dir) = base else {
        return Ok(());
    };
    let Ok(dir_c) = dir.canonicalize() else {
        return Ok(());
    };
    for f in files {
        let parent = f
            .canonicalize()
            .ok()
            .and_then(|c| c.parent().map(Path::to_path_buf));
        if parent.as_deref() == Some(dir_c.as_path()) {
            return Err(UserRulesError::InsideRulesDir {
                file: f.clone(),
                dir: dir.clone(),
            });
        }
    }
    Ok(())
}

/// Every user file must be a readable file (checked up front for a plain message). A pipe
/// (`--rules <(…)`) is refused: the rules are read more than once (checks, cache key, load),
/// and a pipe gives its text only to the first read.
fn check_readable(files: &[PathBuf]) -> Result<(), UserRulesError> {
    for f in files {
        let refuse = |message: String| UserRulesError::RuleFile {
            path: f.clone(),
            message,
        };
        match std::fs::metadata(f) {
            Err(e) => return Err(refuse(e.to_string())),
            Ok(m) if !m.is_file() => {
                return Err(refuse(
                    "not a regular file (a pipe or a device); save the rules to a file and give its path".into(),
                ));
            }
            Ok(_) => {}
        }
        if let Err(e) = std::fs::read(f) {
            return Err(refuse(e.to_string()));
        }
    }
    Ok(())
}

/// One finding of a user rule.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct Finding {
    pub id: String,
    pub rule: String,
    pub message: String,
}

/// Everything the user rules found, each list sorted by (id, rule, message).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct Findings {
    pub violations: Vec<Finding>,
    pub warnings: Vec<Finding>,
}

impl Findings {
    /// The findings about one element (piece or wall id).
    pub fn about<'a>(&'a self, id: &'a str) -> impl Iterator<Item = (&'static str, &'a Finding)> {
        let v = self.violations.iter().map(|f| ("violation", f));
        let w = self.warnings.iter().map(|f| ("warning", f));
        v.chain(w).filter(move |(_, f)| f.id == id)
    }

    pub fn is_empty(&self) -> bool {
        self.violations.is_empty() && self.warnings.is_empty()
    }
}

/// User rule files loaded against a rule base.
pub struct UserRules {
    files: Vec<PathBuf>,
    base: RuleEngine,
    program: Arc<Program>,
    reads: Vec<String>,
    limits: Limits,
}

impl UserRules {
    /// Loads and checks user rule files against the built-in rule base
    /// (`RuleEngine::Compiled`/`Interpreted`) or a rules directory
    /// (`RuleEngine::Directory`).
    pub fn load(files: &[PathBuf], base: &RuleEngine) -> Result<UserRules, UserRulesError> {
        check_readable(files)?;
        check_outside_rules_dir(files, base)?;
        let base_program = base_program(base)?;
        refuse_redeclarations(files, &base_program)?;
        let sigs = functors::signatures();
        let mut loader = Loader::new(&sigs);
        for (name, text) in input_prelude(&base_program) {
            loader.load_text(&name, &text, Path::new("."))?;
        }
        let first_user_source = loader_sources_after_prelude(&base_program) + 1;
        loader.load_text(FINDINGS_SOURCE.0, FINDINGS_SOURCE.1, Path::new("."))?;
        for f in files {
            loader.load_file(f, None)?;
        }
        let program = loader.finish()?;
        refuse_base_heads(&program, &base_program, first_user_source)?;
        let mut reads = BTreeSet::new();
        for rule in &program.rules {
            for lit in &rule.body {
                collect_atoms(lit, &mut reads);
            }
            for arg in &rule.head.args {
                collect_expr_atoms(arg, &mut reads);
            }
        }
        let reads = reads
            .into_iter()
            .filter(|r| base_program.relation(r).is_some())
            .collect();
        Ok(UserRules {
            files: files.to_vec(),
            base: base.clone(),
            program: Arc::new(program),
            reads,
            limits: Limits::default(),
        })
    }

    /// Bounds for the user rules (a user file may try to build values without end).
    pub fn with_limits(mut self, limits: Limits) -> UserRules {
        self.limits = limits;
        self
    }

    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }

    /// The base relations the user rules read (only these are copied in).
    pub fn reads(&self) -> &[String] {
        &self.reads
    }

    /// The checked evaluation program (base relations as inputs + user rules).
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// Runs the user rules over the relations of a reasoned model (the
    /// compiled or interpreted run of the base, with or without simulation
    /// facts). Relations the base run does not hold are empty.
    pub fn evaluate(&self, relations: &Relations) -> Result<Findings, UserRulesError> {
        let mut engine = Engine::new(
            self.program.clone(),
            Options {
                provenance: false,
                limits: self.limits,
            },
        );
        for name in &self.reads {
            for tuple in relations.get(name).into_iter().flatten() {
                engine.insert(name, tuple.clone(), Origin::Rust)?;
            }
        }
        engine.run()?;
        findings_of(&engine)
    }

    /// Base rules, findings and user rules as one program, for explanations.
    pub fn full_program(&self) -> Result<Program, UserRulesError> {
        full_program(&self.base, &self.files)
    }
}

/// The findings an engine derived (any program that declares them).
pub fn findings_of(engine: &Engine) -> Result<Findings, UserRulesError> {
    let read = |rel: &str| -> Result<Vec<Finding>, LogicError> {
        if engine.program().relation(rel).is_none() {
            return Ok(Vec::new());
        }
        let mut out: Vec<Finding> = engine
            .relation(rel)?
            .into_iter()
            .map(|t| Finding {
                id: text(&t[0]),
                rule: text(&t[1]),
                message: text(&t[2]),
            })
            .collect();
        out.sort();
        Ok(out)
    };
    Ok(Findings {
        violations: read("violation")?,
        warnings: read("warning")?,
    })
}

fn text(v: &Value) -> String {
    v.as_symbol().map_or_else(|| v.to_string(), str::to_string)
}

/// The rule base named by `base`: the embedded built-in rules or a directory.
pub fn base_program(base: &RuleEngine) -> Result<Program, UserRulesError> {
    let sigs = functors::signatures();
    let mut loader = Loader::new(&sigs);
    load_base(&mut loader, base)?;
    Ok(loader.finish()?)
}

/// Base rules + findings declarations + user files as one checked program
/// (user files refused when they redefine a base relation).
pub fn full_program(base: &RuleEngine, user_files: &[PathBuf]) -> Result<Program, UserRulesError> {
    check_readable(user_files)?;
    check_outside_rules_dir(user_files, base)?;
    let base_prog = base_program(base)?;
    refuse_redeclarations(user_files, &base_prog)?;
    let sigs = functors::signatures();
    let mut loader = Loader::new(&sigs);
    load_base(&mut loader, base)?;
    let first_user_source = base_prog.sources.len() + 1;
    loader.load_text(FINDINGS_SOURCE.0, FINDINGS_SOURCE.1, Path::new("."))?;
    for f in user_files {
        loader.load_file(f, None)?;
    }
    let program = loader.finish()?;
    refuse_base_heads(&program, &base_prog, first_user_source)?;
    Ok(program)
}

fn load_builtin(loader: &mut Loader<'_>) -> Result<(), UserRulesError> {
    for (name, text) in BUILTIN_SOURCES {
        let dir = Path::new(name).parent().unwrap_or(Path::new("."));
        loader.load_text(name, text, dir)?;
    }
    Ok(())
}

/// Sorts `--rules` files into those that feed the built-in rules (they derive into a relation
/// the rule base declares and none of its rules derives, a shop hook such as
/// `break_forbidden`) and the rest (findings rules). The first kind joins the rule base, on
/// the interpreter (`RuleEngine::Extended`); the engine to reason with and the findings files
/// come back. A file doing both, or feeding a `--rules-dir` rule base, is refused.
pub fn engine_for(
    files: &[PathBuf],
    base: &RuleEngine,
) -> Result<(RuleEngine, Vec<PathBuf>), UserRulesError> {
    // Most runs give no rule file: the rule base is not parsed for nothing.
    if files.is_empty() {
        return Ok((base.clone(), Vec::new()));
    }
    check_readable(files)?;
    check_outside_rules_dir(files, base)?;
    let base_program = base_program(base)?;
    refuse_redeclarations(files, &base_program)?;
    let derived: BTreeSet<&str> = base_program
        .rules
        .iter()
        .map(|r| r.head.rel.as_str())
        .collect();
    let sigs = functors::signatures();
    let mut feeding = Vec::new();
    let mut findings = Vec::new();
    for f in files {
        let mut loader = Loader::new(&sigs);
        load_base(&mut loader, base)?;
        loader.load_text(FINDINGS_SOURCE.0, FINDINGS_SOURCE.1, Path::new("."))?;
        loader.load_file(f, None)?;
        let program = loader.finish()?;
        let first_own = base_program.sources.len() + 1;
        let heads: BTreeSet<&str> = program
            .rules
            .iter()
            .filter(|r| r.span.file as usize >= first_own)
            .map(|r| r.head.rel.as_str())
            .collect();
        let feeds: Vec<&str> = heads
            .iter()
            .copied()
            .filter(|h| base_program.relation(h).is_some() && !derived.contains(h))
            .collect();
        let reports: Vec<&str> = heads
            .iter()
            .copied()
            .filter(|h| FINDING_RELATIONS.contains(h))
            .collect();
        match (feeds.is_empty(), reports.is_empty()) {
            (true, _) => findings.push(f.clone()),
            (false, true) => feeding.push(f.clone()),
            (false, false) => {
                return Err(UserRulesError::FeedsAndFinds {
                    file: f.clone(),
                    feeds: feeds.join(", "),
                    reports: reports.join(", "),
                });
            }
        }
    }
    if feeding.is_empty() {
        return Ok((base.clone(), findings));
    }
    match base {
        RuleEngine::Compiled | RuleEngine::Interpreted => {
            Ok((RuleEngine::Extended(feeding), findings))
        }
        RuleEngine::Extended(earlier) => Ok((
            RuleEngine::Extended(earlier.iter().chain(&feeding).cloned().collect()),
            findings,
        )),
        RuleEngine::Directory(dir) => Err(UserRulesError::FeedsRulesDir {
            file: feeding[0].clone(),
            dir: dir.clone(),
        }),
    }
}

fn load_base(loader: &mut Loader<'_>, base: &RuleEngine) -> Result<(), UserRulesError> {
    match base {
        RuleEngine::Directory(dir) => {
            for f in directory_files(dir)? {
                loader.load_file(&f, None)?;
            }
        }
        RuleEngine::Compiled | RuleEngine::Interpreted => load_builtin(loader)?,
        RuleEngine::Extended(files) => {
            load_builtin(loader)?;
            for f in files {
                loader.load_file(f, None)?;
            }
        }
    }
    Ok(())
}

/// The `.dl` files of a rules directory, sorted.
pub fn directory_files(dir: &Path) -> Result<Vec<PathBuf>, UserRulesError> {
    crate::frame::directory_files(dir).map_err(|e| match e {
        crate::frame::FrameError::RulesDir { path, message } => {
            UserRulesError::RulesDir { path, message }
        }
        other => UserRulesError::RulesDir {
            path: dir.to_path_buf(),
            message: other.to_string(),
        },
    })
}

/// Number of prelude sources `input_prelude` makes (one per base source).
fn loader_sources_after_prelude(base: &Program) -> usize {
    base.sources.len()
}

/// The base's type and relation declarations, each at its own line of a
/// source named like the base file (so "declared twice (first at
/// rules/roles.dl:217)" cites the real place), and every relation as an input.
fn input_prelude(base: &Program) -> Vec<(String, String)> {
    let mut lines: Vec<BTreeMap<u32, String>> = vec![BTreeMap::new(); base.sources.len()];
    let mut put = |span: Span, text: String| {
        if let Some(file) = lines.get_mut(span.file as usize) {
            let line = file.entry(span.line.max(1)).or_default();
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(&text);
        }
    };
    for t in &base.types {
        let op = if t.is_subtype { "<:" } else { "=" };
        put(t.span, format!(".type {} {op} {}", t.name, t.parent));
    }
    for r in &base.relations {
        let attrs: Vec<String> = r
            .attrs
            .iter()
            .map(|a| format!("{}: {}", a.name, a.ty_name))
            .collect();
        put(r.span, format!(".decl {}({})", r.name, attrs.join(", ")));
    }
    let mut out: Vec<(String, String)> = Vec::new();
    for (k, file) in lines.into_iter().enumerate() {
        let mut text = String::new();
        let mut at = 1;
        for (line, decl) in file {
            while at < line {
                text.push('\n');
                at += 1;
            }
            text.push_str(&decl);
        }
        text.push('\n');
        out.push((base.sources[k].name.clone(), text));
    }
    if let Some(last) = out.last_mut() {
        for r in &base.relations {
            last.1.push_str(&format!(".input {}\n", r.name));
        }
    }
    out
}

fn base_location(base: &Program, name: &str) -> Option<String> {
    if let Some(r) = base.relation(name) {
        return Some(base.location(r.span));
    }
    let findings = FINDINGS_SOURCE.1.lines().position(|l| {
        l.strip_prefix(".decl ")
            .is_some_and(|rest| rest.starts_with(&format!("{name}(")))
    })?;
    Some(format!("{}:{}", FINDINGS_SOURCE.0, findings + 1))
}

/// A user file that declares a base relation (or a findings relation) again.
fn refuse_redeclarations(files: &[PathBuf], base: &Program) -> Result<(), UserRulesError> {
    let mut errors = Vec::new();
    for f in files {
        // Unreadable files are reported by the loader with its own message.
        let Ok(text) = std::fs::read_to_string(f) else {
            continue;
        };
        let Ok((tokens, _)) = lex(0, &text) else {
            continue;
        };
        let sources = [Source {
            name: f.display().to_string(),
            text: text.clone(),
        }];
        for pair in tokens.windows(2) {
            let (Tok::Directive(d), Tok::Ident(name)) = (&pair[0].tok, &pair[1].tok) else {
                continue;
            };
            if d != "decl" {
                continue;
            }
            if let Some(place) = base_location(base, name) {
                errors.push(redefinition(
                    &sources,
                    pair[1].span,
                    name,
                    &place,
                    "declares",
                    false,
                ));
            }
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(Diagnostics(errors).into())
    }
}

/// `feeds_base`: no built-in rule derives the relation (an input, or a hook such as
/// `break_forbidden` left empty for a shop): what a user adds to it belongs in a rule base.
fn redefinition(
    sources: &[Source],
    span: Span,
    name: &str,
    place: &str,
    verb: &str,
    feeds_base: bool,
) -> Diagnostic {
    let what = if FINDING_RELATIONS.contains(&name) {
        "the findings relation"
    } else {
        "the built-in relation"
    };
    let hint = if FINDING_RELATIONS.contains(&name) {
        format!(
            "`{name}` is already declared as {name}(id: symbol, rule: symbol, message: symbol); derive it without declaring it"
        )
    } else if feeds_base {
        format!(
            "`{name}` feeds the built-in rules, which run before findings rules: keep such rules in a file of their own (no violation/warning rules), which `--rules` adds to the built-in rules, or put it in a rule base (`--rules-dir DIR`)"
        )
    } else {
        format!(
            "user rules may read `{name}` but not change it; give your relation another name (e.g. `my_{name}`)"
        )
    };
    Diagnostic::at(
        sources,
        span,
        format!("this file {verb} {what} `{name}`, declared at {place}"),
        hint,
    )
}

/// A user rule or fact whose head is a base relation.
fn refuse_base_heads(
    program: &Program,
    base: &Program,
    first_user_source: usize,
) -> Result<(), UserRulesError> {
    let derived: BTreeSet<&str> = base.rules.iter().map(|r| r.head.rel.as_str()).collect();
    let errors: Vec<Diagnostic> = program
        .rules
        .iter()
        .filter(|r| r.span.file as usize >= first_user_source)
        .filter_map(|r| {
            let decl = base.relation(&r.head.rel)?;
            Some(redefinition(
                &program.sources,
                r.head.span,
                &r.head.rel,
                &base.location(decl.span),
                "derives into",
                !derived.contains(r.head.rel.as_str()),
            ))
        })
        .collect();
    if errors.is_empty() {
        Ok(())
    } else {
        Err(Diagnostics(errors).into())
    }
}

fn collect_atoms(lit: &Literal, out: &mut BTreeSet<String>) {
    match lit {
        Literal::Pos(a) | Literal::Neg(a) => {
            out.insert(a.rel.clone());
            a.args.iter().for_each(|e| collect_expr_atoms(e, out));
        }
        Literal::Cmp(_, a, b, _) => {
            collect_expr_atoms(a, out);
            collect_expr_atoms(b, out);
        }
        Literal::StrTest { args, .. } => args.iter().for_each(|e| collect_expr_atoms(e, out)),
    }
}

fn collect_expr_atoms(e: &Expr, out: &mut BTreeSet<String>) {
    match &e.kind {
        ExprKind::Agg(a) => {
            a.body.iter().for_each(|l| collect_atoms(l, out));
            if let Some(t) = &a.target {
                collect_expr_atoms(t, out);
            }
        }
        ExprKind::Neg(x) => collect_expr_atoms(x, out),
        ExprKind::Bin(_, a, b) => {
            collect_expr_atoms(a, out);
            collect_expr_atoms(b, out);
        }
        ExprKind::Builtin(_, args) | ExprKind::Ext(_, args) => {
            args.iter().for_each(|x| collect_expr_atoms(x, out))
        }
        ExprKind::Var(_)
        | ExprKind::Wild
        | ExprKind::Int(_)
        | ExprKind::Float(_)
        | ExprKind::Str(_) => {}
    }
}
