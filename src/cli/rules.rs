//! `framewright rules run|check`: run a rule program like
//! `souffle -F FACTS -D OUT PROG.dl`, or only check it.
use super::{CmdResult, print_stdout};
use framewright::logic::{Engine, Limits, Options, Program, io, provenance};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Subcommand)]
pub enum RulesCommand {
    /// Run a rule program: read `.input` facts, write `.output` relations.
    Run {
        program: PathBuf,
        /// Directory of the `.facts` input files (Soufflé's -F).
        #[arg(short = 'F', long = "facts", default_value = ".")]
        facts: PathBuf,
        /// Directory for the `.csv` output files (Soufflé's -D).
        #[arg(short = 'D', long = "out", default_value = ".")]
        out: PathBuf,
        /// Explain a tuple: 'rel(a, b)' (how it was derived) or 'not rel(a, b)' (why not). Repeatable.
        #[arg(long)]
        explain: Vec<String>,
        /// Folder every `.include` must stay in (default: the program file's folder).
        #[arg(long)]
        rules_dir: Option<PathBuf>,
        /// Stop when the relations hold more tuples than this.
        #[arg(long, default_value_t = Limits::default().max_tuples)]
        max_tuples: usize,
        /// Stop when a recursive stratum needs more iterations than this (default: no bound, as
        /// in Soufflé; a program that never stops is caught by --max-tuples).
        #[arg(long)]
        max_iterations: Option<usize>,
        /// Stop when the joins of the run have visited more body tuples than this.
        #[arg(long, default_value_t = Limits::default().max_steps)]
        max_steps: u64,
    },
    /// Check a rule program without running it.
    Check {
        program: PathBuf,
        /// Folder every `.include` must stay in (default: the program file's folder).
        #[arg(long)]
        rules_dir: Option<PathBuf>,
    },
    /// Print the reference of the built-in relations (docs/RELATIONS.md) as Markdown.
    Relations,
}

pub fn run(cmd: RulesCommand) -> CmdResult {
    match cmd {
        RulesCommand::Relations => {
            let base = Program::builtin()?;
            print_stdout(&framewright::user_rules::relations_doc::relations_markdown(
                &base,
            ))
        }
        RulesCommand::Check { program, rules_dir } => {
            let p = Program::parse_files_within(&[&program], rules_dir.as_deref())?;
            print_stdout(&format!(
                "{}: ok ({} relations, {} rules and facts, {} strata)\n",
                program.display(),
                p.relations.len(),
                p.rules.len(),
                p.strata.len()
            ))
        }
        RulesCommand::Run {
            program,
            facts,
            out,
            explain,
            rules_dir,
            max_tuples,
            max_iterations,
            max_steps,
        } => {
            let p = std::sync::Arc::new(Program::parse_files_within(
                &[&program],
                rules_dir.as_deref(),
            )?);
            // Parse the queries before running so a typo fails fast and writes nothing.
            let mut queries = Vec::new();
            for q in &explain {
                let (negated, text) = match q.trim().strip_prefix("not ") {
                    Some(rest) => (true, rest),
                    None => (false, q.as_str()),
                };
                queries.push((negated, provenance::parse_query(&p, text)?));
            }
            let options = Options {
                provenance: !queries.is_empty(),
                limits: Limits {
                    max_tuples,
                    max_iterations: max_iterations.unwrap_or(Limits::default().max_iterations),
                    max_steps,
                },
            };
            let mut engine = Engine::new(p, options);
            io::load_inputs(&mut engine, &facts)?;
            for w in engine.run()?.warnings {
                eprintln!("warning: {w}");
            }
            let mut report = String::new();
            for (negated, (rel, tuple)) in &queries {
                if *negated {
                    report.push_str(&engine.explain_not(rel, tuple)?.render());
                } else {
                    report.push_str(&engine.explain(rel, tuple)?.render());
                }
            }
            let (_, stdout) = io::write_outputs(&engine, &out)?;
            report.insert_str(0, &stdout);
            if report.is_empty() {
                Ok(ExitCode::SUCCESS)
            } else {
                print_stdout(&report)
            }
        }
    }
}
