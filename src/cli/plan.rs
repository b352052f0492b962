//! `framewright plan MODEL.ifc [--cell C] [--json] [--cache DIR | --no-cache] [--truth FILE]`:
//! walls, roles, assembly order, nailing and framing targets; with `--truth`, each role's
//! precision and recall against a hand-labelled file. The built-in rules' results are cached per
//! independent part of the model, so a plan after a small edit reasons only what changed.

use super::cache::{CacheArgs, warn_if_unwritable};
use super::check::{ReasoningInputs, load_model_facts, rules_in_force};
use super::{CmdResult, Failure, leave_to_exit, print_stdout, write_stdout};
use framewright::frame::RuleEngine;
use framewright::pipeline::{self, Planned};
use framewright::report::plan::PlanReport;
use framewright::report::role_check::{RoleCheck, Truth};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct PlanArgs {
    /// The IFC model.
    pub model: PathBuf,
    #[command(flatten)]
    pub inputs: ReasoningInputs,
    /// Print JSON instead of one line per wall.
    #[arg(long)]
    pub json: bool,
    /// The cache holds the built-in rules' results per part of the model (not used with
    /// --rules-dir).
    #[command(flatten)]
    pub cache: CacheArgs,
    /// A shop rule file that feeds the rule base (it derives into a hook no built-in rule
    /// derives, such as `break_forbidden` or `break_wanted`): it joins the built-in rules, run
    /// on the interpreter. Repeat for more. (Findings rules run with `check`.)
    #[arg(long = "rules", value_name = "FILE.dl")]
    pub rules: Vec<PathBuf>,
    /// A hand-labelled truth file (JSON `{"members": [{"id", "role"}, …]}`, e.g. a `synth
    /// --truth` sidecar): also print each role's precision and recall against it.
    #[arg(long, value_name = "FILE")]
    pub truth: Option<PathBuf>,
}

pub fn run(args: PlanArgs) -> CmdResult {
    let inputs = &args.inputs;
    // A bad truth file is refused before any work.
    let truth = args.truth.as_deref().map(Truth::read).transpose()?;
    let (engine, findings_files) = rules_in_force(&inputs.rules_dir, &args.rules)?;
    if let Some(f) = findings_files.first() {
        return Err(Failure::bad_input(format!(
            "{}: plan runs no findings rules (violation/warning); run this file with `framewright check --rules`",
            f.display()
        )));
    }
    let (model, cell, facts) = load_model_facts(&args.model, inputs)?;
    let cache = match engine {
        RuleEngine::Compiled => args.cache.open(),
        _ => None,
    };
    let limits = super::rule_limits()?;
    let Planned {
        reasoned,
        plan,
        cache: counts,
    } = pipeline::plan(&model, &cell, facts, &engine, limits, cache.as_ref())?;
    let role_check = truth.map(|t| RoleCheck::new(&t, &model, &plan));
    let mut report = PlanReport::new(&model, &plan);
    report.cache = counts;
    report.role_check = role_check.as_ref();
    let written = if args.json {
        write_stdout(|out| report.write_json(&mut &mut *out))
    } else {
        print_stdout(&report.to_text())
    };
    leave_to_exit(report);
    leave_to_exit((model, reasoned, plan));
    // After the output: the cache's entries are written meanwhile.
    warn_if_unwritable(cache.as_ref());
    written
}
