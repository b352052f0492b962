//! `framewright plan MODEL.ifc [--cell C] [--json]`: walls, roles, assembly
//! order, nailing and framing targets.

use super::check::{load_inputs, rule_base};
use super::{CmdResult, print_stdout, write_stdout};
use framewright::frame::plan::Plan;
use framewright::frame::reason;
use framewright::report::plan::PlanReport;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct PlanArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// The robot cell: a built-in name (study-abb, study-kuka) or a TOML file.
    #[arg(long, default_value = "study-abb")]
    pub cell: String,
    /// Print JSON instead of one line per wall.
    #[arg(long)]
    pub json: bool,
    /// Replace the built-in rule base with every .dl file of this directory.
    #[arg(long, value_name = "DIR")]
    pub rules_dir: Option<PathBuf>,
    /// Largest gap between two pieces still taken as touching, millimetres.
    #[arg(long, value_name = "MM", default_value_t = 3.0)]
    pub contact_tolerance: f64,
}

pub fn run(args: PlanArgs) -> CmdResult {
    let (model, _, facts) = load_inputs(&args.model, &args.cell, args.contact_tolerance)?;
    let reasoned = reason(&facts, &rule_base(&args.rules_dir), false)?;
    let report = PlanReport::new(&model, &Plan::from_reasoned(&model, &reasoned));
    if args.json {
        write_stdout(|out| report.write_json(&mut &mut *out))
    } else {
        print_stdout(&report.to_text())
    }
}
