//! The interpreter: semi-naive bottom-up evaluation, stratum by stratum, over
//! hash-indexed relations; optionally records provenance for explanations.

pub mod compile;
mod eval;
mod exec;
mod run;
pub mod store;

use self::compile::CRule;
use self::store::Relation;
use super::error::{EvalError, LogicError};
use super::front::Program;
use super::value::Value;
use serde::Serialize;
use std::sync::Arc;

pub use self::eval::compare;
pub(crate) use self::exec::Exec;

/// Evaluate a compiled expression (used by explanations).
pub(crate) fn eval_pub(e: &compile::CExpr, env: &[Value]) -> Result<Value, EvalError> {
    eval::eval(e, env)
}

/// Where an input tuple came from, so explanations can point at it.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub enum Origin {
    /// A line of a facts file.
    File { file: String, line: u32 },
    /// An IFC entity `#id`.
    Entity(u64),
    /// A simulation event (its id or description).
    Event(String),
    /// Inserted by Rust code without a source.
    Rust,
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::File { file, line } => write!(f, "{file}:{line}"),
            Origin::Entity(id) => write!(f, "IFC #{id}"),
            Origin::Event(e) => write!(f, "event {e}"),
            Origin::Rust => f.write_str("inserted by the program"),
        }
    }
}

/// How a stored tuple was obtained.
#[derive(Clone, Debug)]
pub enum Prov {
    Input(Origin),
    /// Rule index and the (relation, tuple id) matched by each positive body atom, in plan order.
    Derived {
        rule: u32,
        body: Box<[(u32, u32)]>,
        height: u32,
    },
}

/// Bounds that stop runaway programs (e.g. `n(x+1) :- n(x).`), not long ones: a program that
/// never stops keeps adding tuples, so the tuple bound catches it; a long program that
/// terminates runs as in Soufflé, which has no bound on iterations.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Total tuples over all relations (memory).
    pub max_tuples: usize,
    /// Semi-naive iterations per stratum; `usize::MAX` (the default) is no bound.
    pub max_iterations: usize,
    /// Body tuples visited over the whole run: the work of joins, which can be huge for
    /// few derived tuples (`r(1) :- a(x), a(y), a(z).`).
    pub max_steps: u64,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_tuples: 50_000_000,
            // None: counting to 10^6 one step at a time is an ordinary program.
            max_iterations: usize::MAX,
            // About 3 minutes of joining on one core (10^7 visits/s measured); far above
            // any rule set framewright ships.
            max_steps: 2_000_000_000,
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    pub provenance: bool,
    pub limits: Limits,
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct RunStats {
    pub iterations: usize,
    pub tuples: usize,
    /// Problems that did not stop the run (a `match` pattern that is not a
    /// regular expression), each once, sorted.
    pub warnings: Vec<String>,
}

pub struct Engine {
    pub(crate) program: Arc<Program>,
    pub(crate) rels: Vec<Relation>,
    pub(crate) prov: Option<Vec<Vec<Prov>>>,
    /// Compiled rules, per stratum.
    strata: Vec<Vec<CRule>>,
    options: Options,
    ran: bool,
    /// What `ord` handed out in this engine's run (explanations evaluate with the same).
    ords: std::cell::RefCell<super::ops::OrdTable>,
    /// Body tuples the run may still visit (`Limits::max_steps`).
    steps_left: std::cell::Cell<u64>,
}

impl Engine {
    pub fn new(program: Arc<Program>, options: Options) -> Engine {
        let mut rels: Vec<Relation> = program
            .relations
            .iter()
            .map(|r| Relation::new(r.arity()))
            .collect();
        let mut strata = Vec::new();
        // One `autoinc()` counter per engine, as Soufflé has one per program run.
        let autoinc = std::sync::Arc::new(std::sync::atomic::AtomicI64::new(0));
        for s in &program.strata {
            let mut in_stratum = vec![false; rels.len()];
            for &r in &s.relations {
                in_stratum[r] = true;
            }
            strata.push(
                s.rules
                    .iter()
                    .map(|&id| {
                        compile::compile_rule(&program, id, &mut rels, &in_stratum, &autoinc)
                    })
                    .collect(),
            );
        }
        let prov = options.provenance.then(|| vec![Vec::new(); rels.len()]);
        Engine {
            program,
            rels,
            prov,
            strata,
            options,
            ran: false,
            ords: Default::default(),
            steps_left: std::cell::Cell::new(options.limits.max_steps),
        }
    }

    pub fn program(&self) -> &Program {
        &self.program
    }

    /// Run `f` with this engine's `ord` table (explanations re-evaluate rule expressions).
    pub(crate) fn with_ords<R>(&self, f: impl FnOnce() -> R) -> R {
        super::ops::with_ords(&self.ords, f)
    }

    pub(crate) fn rel_id(&self, name: &str) -> Result<usize, LogicError> {
        self.program
            .rel_index
            .get(name)
            .copied()
            .ok_or_else(|| LogicError::Usage(format!("unknown relation `{name}`")))
    }

    /// Check a tuple against the relation's declared types.
    pub(crate) fn check_tuple(&self, rel: usize, tuple: &[Value]) -> Result<(), LogicError> {
        let d = &self.program.relations[rel];
        if d.arity() != tuple.len() {
            return Err(LogicError::Usage(format!(
                "relation `{}` has {} attributes, tuple has {}",
                d.name,
                d.arity(),
                tuple.len()
            )));
        }
        for (a, v) in d.attrs.iter().zip(tuple) {
            if a.ty != v.ty() {
                return Err(LogicError::Usage(format!(
                    "attribute `{}` of `{}` is a {}, got the {} {v}",
                    a.name,
                    d.name,
                    a.ty,
                    v.ty()
                )));
            }
        }
        Ok(())
    }

    /// Add an input tuple; returns false if it was already present.
    pub fn insert(
        &mut self,
        rel: &str,
        tuple: Vec<Value>,
        origin: Origin,
    ) -> Result<bool, LogicError> {
        let r = self.rel_id(rel)?;
        self.check_tuple(r, &tuple)?;
        if self.ran {
            return Err(LogicError::Usage(
                "facts must be inserted before `run`; create a new Engine to run again".into(),
            ));
        }
        match self.rels[r].insert(&tuple) {
            Some(_) => {
                if let Some(p) = &mut self.prov {
                    p[r].push(Prov::Input(origin));
                }
                Ok(true)
            }
            None => Ok(false),
        }
    }

    /// The tuples of a relation, sorted.
    pub fn relation(&self, name: &str) -> Result<Vec<Vec<Value>>, LogicError> {
        Ok(self.rels[self.rel_id(name)?].sorted())
    }

    /// Whether the relation holds the tuple.
    pub fn contains(&self, name: &str, tuple: &[Value]) -> Result<bool, LogicError> {
        Ok(self.rels[self.rel_id(name)?].find(tuple).is_some())
    }

    pub(crate) fn compiled_rules(&self) -> impl Iterator<Item = &CRule> {
        self.strata.iter().flatten()
    }

    pub fn len(&self, name: &str) -> Result<usize, LogicError> {
        Ok(self.rels[self.rel_id(name)?].len())
    }
}

pub(crate) fn show(v: &Value) -> String {
    match v {
        Value::Symbol(s) => format!("{:?}", &**s),
        other => other.to_string(),
    }
}
