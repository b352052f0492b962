//! Frame reasoning: the built-in rule base (`rules/*.dl`) over the facts of a
//! model. The compiled (ascent) engine is the normal path; the interpreter
//! runs the same rules for `--rules-dir`, user rules and provenance.

mod ask;
pub mod builtin;
pub mod cell_facts;
pub mod containers;
pub mod facts;
pub mod limits;
pub mod panel;
pub mod panel_why;
pub mod panelize;
pub mod panels;
pub mod partition;
pub mod placement;
pub mod plan;
mod plan_build;
pub mod rows;
pub mod rule_reads;

use crate::logic::compiled::{self, Relations};
use crate::logic::{Diagnostics, Engine, LogicError, Options, Program, Value};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use ask::Ask;
pub use cell_facts::cell_facts;
pub use facts::{Facts, model_facts};
pub use limits::RuleLimits;

#[derive(Debug, thiserror::Error)]
pub enum FrameError {
    #[error(transparent)]
    Rules(#[from] Diagnostics),
    #[error(transparent)]
    Logic(#[from] LogicError),
    #[error("the compiled rule base failed: {0}")]
    Compiled(String),
    /// A runtime error of the compiled rule base (same text as `Compiled`).
    #[error("the compiled rule base failed: {0}")]
    CompiledRun(compiled::CompiledError),
    #[error("{}: cannot read the rules directory: {message}", path.display())]
    RulesDir { path: PathBuf, message: String },
    #[error(transparent)]
    Limit(#[from] limits::LimitError),
    #[error(transparent)]
    Row(#[from] rows::RowError),
}

/// Which engine evaluates the rule base.
#[derive(Debug, Clone, Default)]
pub enum RuleEngine {
    /// The built-in rules compiled with ascent (fast; no provenance).
    #[default]
    Compiled,
    /// The built-in rules on the interpreter.
    Interpreted,
    /// Every `.dl` file of a directory on the interpreter, replacing the built-in rules.
    Directory(PathBuf),
    /// The built-in rules and shop files that feed them (they derive into relations no
    /// built-in rule derives, such as `break_forbidden`), on the interpreter.
    Extended(Vec<PathBuf>),
}

/// The evaluated rule base: every relation by name. Tuples come in a
/// deterministic order: sorted from the interpreter; from the compiled engine,
/// storey by storey (each part sorted), small relations sorted whole.
pub struct Reasoned {
    pub relations: Relations,
    /// The interpreter that ran, when one did (for explanations).
    pub engine: Option<Engine>,
}

impl Reasoned {
    pub fn get(&self, relation: &str) -> &[Vec<Value>] {
        self.relations.get(relation).map_or(&[], Vec::as_slice)
    }
}

/// The `.dl` files of a rules directory, sorted (an error when it cannot be read or holds none).
pub fn directory_files(dir: &Path) -> Result<Vec<PathBuf>, FrameError> {
    let entries = std::fs::read_dir(dir).map_err(|e| FrameError::RulesDir {
        path: dir.to_path_buf(),
        message: e.to_string(),
    })?;
    let mut files: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "dl"))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(FrameError::RulesDir {
            path: dir.to_path_buf(),
            message: "it holds no .dl files".into(),
        });
    }
    Ok(files)
}

/// Every `.dl` file of `dir`, sorted, as one program.
pub fn directory_program(dir: &Path) -> Result<Program, FrameError> {
    Ok(Program::parse_files(&directory_files(dir)?)?)
}

/// The built-in rules with shop files added (`RuleEngine::Extended`) as one checked program.
pub fn extended_program(files: &[PathBuf]) -> Result<Program, FrameError> {
    let sigs = crate::logic::functors::signatures();
    let mut loader = crate::logic::front::check::Loader::new(&sigs);
    for (name, text) in crate::logic::compiled::BUILTIN_SOURCES {
        let dir = Path::new(name).parent().unwrap_or(Path::new("."));
        loader.load_text(name, text, dir)?;
    }
    for f in files {
        loader.load_file(f, None)?;
    }
    Ok(loader.finish()?)
}

static WHOLE_RUNS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
static CUT_RUNS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// How many times this process has run the rule base over a model's facts: what a test reads
/// to show that a command reasons a model as often as it says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RuleBaseRuns {
    /// Runs that derive every relation.
    pub whole: u64,
    /// Runs cut down to the relations a caller reads (the placement search's first pass,
    /// `plan`); a placed run, whose search sits between its two passes, counts once.
    pub cut: u64,
}

pub fn rule_base_runs() -> RuleBaseRuns {
    use std::sync::atomic::Ordering::Relaxed;
    RuleBaseRuns {
        whole: WHOLE_RUNS.load(Relaxed),
        cut: CUT_RUNS.load(Relaxed),
    }
}

fn count_run(cut: bool) {
    let runs = if cut { &CUT_RUNS } else { &WHOLE_RUNS };
    runs.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
}

fn reason_unchecked(
    facts: &Facts,
    engine: &RuleEngine,
    provenance: bool,
    selected: Option<&[&str]>,
    limits: &RuleLimits,
) -> Result<Reasoned, FrameError> {
    let program = match engine {
        RuleEngine::Compiled if !provenance => {
            return Ok(Reasoned {
                relations: reason_compiled(facts, selected, limits)?,
                engine: None,
            });
        }
        RuleEngine::Compiled | RuleEngine::Interpreted => Program::builtin()?,
        RuleEngine::Directory(dir) => directory_program(dir)?,
        RuleEngine::Extended(files) => extended_program(files)?,
    };
    let program = Arc::new(program);
    let mut interpreter = Engine::new(
        program.clone(),
        Options {
            provenance,
            ..Options::default()
        },
    );
    facts.insert_into(&mut interpreter)?;
    interpreter.run()?;
    let relations = program
        .relations
        .iter()
        .map(|r| interpreter.relation(&r.name).map(|t| (r.name.clone(), t)))
        .collect::<Result<Relations, LogicError>>()?;
    Ok(Reasoned {
        relations,
        engine: Some(interpreter),
    })
}

/// Relations up to this size are sorted and deduplicated after merging parts.
pub(crate) const SMALL_RELATION: usize = 4096;

/// The compiled rule base, run on each container's facts in parallel and the
/// results merged (same relations as one run over everything). With `selected`, only those
/// relations come back (and `wall`, for the wall bound). The tuples every part derives count
/// against the rule tuple bound.
fn reason_compiled(
    facts: &Facts,
    selected: Option<&[&str]>,
    limits: &RuleLimits,
) -> Result<Relations, FrameError> {
    reason_compiled_placing(facts.by_container(), selected, limits, None)
}

/// The placement search for one part: the first pass's relations (`placement::FIRST_PASS`)
/// in, the part's placement facts out.
pub(crate) type PlaceFn<'a> = &'a (dyn Fn(&Relations) -> Relations + Sync);

/// `reason_compiled` on the facts already split by container (`Facts::by_container`, or
/// `into_by_container` by a caller done with its facts); with `place` (and `selected`,
/// which the typed runner must handle),
/// each part's placement facts come from `place` between a first pass and the rules they
/// reach (`builtin::run_placed`).
pub(crate) fn reason_compiled_placing(
    mut parts: Vec<Relations>,
    selected: Option<&[&str]>,
    limits: &RuleLimits,
    place: Option<PlaceFn>,
) -> Result<Relations, FrameError> {
    use rayon::prelude::*;
    use std::sync::atomic::{AtomicU64, Ordering};
    let run = compiled::program("rules")
        .ok_or_else(|| FrameError::Compiled("no compiled rule base".into()))?;
    // Largest first, so the parallel runs finish together.
    parts.sort_by_key(|p| std::cmp::Reverse(p.get("piece").map_or(0, Vec::len)));
    let wanted: Option<Vec<&str>> = selected.map(|names| {
        let mut v: Vec<&str> = names.to_vec();
        v.push("wall");
        v
    });
    let total = AtomicU64::new(0);
    let results: Vec<Relations> = parts
        .into_par_iter()
        .map(|part| -> Result<Relations, FrameError> {
            let (relations, tuples) = match (&wanted, place) {
                (Some(w), Some(place)) if builtin::handles(&part, w) => {
                    let r = builtin::run_placed(&part, placement::FIRST_PASS, w, place)
                        .map_err(FrameError::CompiledRun)?;
                    (r.relations, r.tuples)
                }
                (_, Some(_)) => {
                    return Err(FrameError::Compiled(
                        "the placement search runs between passes of the typed rule runner only"
                            .into(),
                    ));
                }
                (Some(w), None) if builtin::handles(&part, w) => {
                    let r = builtin::run_selected(&part, w).map_err(FrameError::CompiledRun)?;
                    (r.relations, r.tuples)
                }
                _ => {
                    let r = run(&part).map_err(FrameError::CompiledRun)?;
                    let n = r.values().map(|t| t.len() as u64).sum();
                    (r, n)
                }
            };
            drop(part);
            let sum = total.fetch_add(tuples, Ordering::Relaxed) + tuples;
            limits.check_tuples(sum)?;
            Ok(relations)
        })
        .collect::<Result<_, FrameError>>()?;
    // Parts are in a fixed order and each part's tuples come sorted, so the
    // concatenation is deterministic. Relations keyed by a piece, wall or
    // storey cannot share tuples between parts; only the small relations
    // derived from the cell alone repeat in every part, so only small
    // relations need sorting and deduplication.
    let mut merged = Relations::new();
    for part in results {
        for (name, tuples) in part {
            merged.entry(name).or_default().extend(tuples);
        }
    }
    for tuples in merged.values_mut() {
        if tuples.len() <= SMALL_RELATION {
            tuples.sort_unstable();
            tuples.dedup();
        }
    }
    Ok(merged)
}
