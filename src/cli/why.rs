//! `framewright why MODEL.ifc ID` and `framewright why-not MODEL.ifc 'rel(…)'`:
//! an element's verdicts with their derivations down to IFC entities, cell
//! keys and rule lines; or which rule could have derived a tuple and which
//! condition failed.

use super::check::{load_inputs, rule_base};
use super::{CmdResult, Failure, print_stdout};
use framewright::user_rules::render::{render_why, render_why_not};
use framewright::user_rules::why::{Context, WhyError, why, why_not};
use serde::Serialize;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct WhyArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// A piece id, an IFC GlobalId or an entity `#id`.
    pub id: String,
    #[command(flatten)]
    pub common: Common,
}

#[derive(clap::Args)]
pub struct WhyNotArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// The tuple, e.g. 'role(#47, king_stud)' (`#id` stands for the piece of that entity).
    pub tuple: String,
    #[command(flatten)]
    pub common: Common,
}

#[derive(clap::Args)]
pub struct Common {
    /// The robot cell: a built-in name (study-abb, study-kuka) or a TOML file.
    #[arg(long, default_value = "study-abb")]
    pub cell: String,
    /// Print the complete trees as JSON.
    #[arg(long)]
    pub json: bool,
    /// User rule files whose findings are explained too. Repeatable.
    #[arg(long = "rules", value_name = "FILE.dl")]
    pub rules: Vec<PathBuf>,
    /// Replace the built-in rule base with every .dl file of this directory.
    #[arg(long, value_name = "DIR")]
    pub rules_dir: Option<PathBuf>,
    /// Largest gap between two pieces still taken as touching, millimetres.
    #[arg(long, value_name = "MM", default_value_t = 3.0)]
    pub contact_tolerance: f64,
}

#[derive(Serialize)]
struct Envelope<'a, T: Serialize> {
    model: String,
    cell: &'a str,
    query: &'a str,
    #[serde(flatten)]
    answer: T,
}

fn json<T: Serialize>(value: &T) -> Result<String, Failure> {
    let mut s = serde_json::to_string_pretty(value)
        .map_err(|e| Failure::bad_input(format!("cannot write JSON: {e}")))?;
    s.push('\n');
    Ok(s)
}

fn failure(e: WhyError) -> Failure {
    Failure::from(e)
}

pub fn run_why(args: WhyArgs) -> CmdResult {
    let c = &args.common;
    let base = rule_base(&c.rules_dir);
    let (model, cell, facts) = load_inputs(&args.model, &c.cell, c.contact_tolerance)?;
    let ctx = Context {
        model: &model,
        facts: &facts,
        base: &base,
        user_files: &c.rules,
    };
    let reports = why(&ctx, &args.id).map_err(failure)?;
    let text = if c.json {
        #[derive(Serialize)]
        struct Elements<T> {
            elements: T,
        }
        json(&Envelope {
            model: args.model.display().to_string(),
            cell: &cell.name,
            query: &args.id,
            answer: Elements { elements: &reports },
        })?
    } else {
        render_why(&reports)
    };
    print_stdout(&text)
}

pub fn run_why_not(args: WhyNotArgs) -> CmdResult {
    let c = &args.common;
    let base = rule_base(&c.rules_dir);
    let (model, cell, facts) = load_inputs(&args.model, &c.cell, c.contact_tolerance)?;
    let ctx = Context {
        model: &model,
        facts: &facts,
        base: &base,
        user_files: &c.rules,
    };
    let report = why_not(&ctx, &args.tuple).map_err(failure)?;
    let text = if c.json {
        json(&Envelope {
            model: args.model.display().to_string(),
            cell: &cell.name,
            query: &args.tuple,
            answer: &report,
        })?
    } else {
        render_why_not(&args.tuple, &report)
    };
    print_stdout(&text)
}
