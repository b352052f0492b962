//! `framewright plan MODEL.ifc [--cell C] [--json]`: walls, roles, assembly
//! order, nailing and framing targets.

use super::check::{ReasoningInputs, load_inputs, rule_base};
use super::{CmdResult, print_stdout, write_stdout};
use framewright::frame::plan::Plan;
use framewright::frame::reason_selected;
use framewright::report::plan::PlanReport;
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
}

pub fn run(args: PlanArgs) -> CmdResult {
    let inputs = &args.inputs;
    let (model, _, facts) = load_inputs(&args.model, inputs)?;
    let reasoned = reason_selected(&facts, &rule_base(&inputs.rules_dir), Plan::RELATIONS)?;
    let report = PlanReport::new(&model, &Plan::from_reasoned(&model, &reasoned));
    if args.json {
        write_stdout(|out| report.write_json(&mut &mut *out))
    } else {
        print_stdout(&report.to_text())
    }
}
