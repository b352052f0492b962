//! `framewright annotate MODEL.ifc [--cell C] [--simulate] -o OUT.ifc`: writes the plan
//! (property sets, the assembly sequence as tasks, the nails as fasteners) and optionally
//! the simulation verdicts back into a copy of the model.

use super::check::{ReasoningInputs, load_model_facts, rule_base};
use super::{CmdResult, Failure, write_atomically};
use framewright::bim::{AnnotateOptions, NailSize, annotate, element_verdicts};
use framewright::frame::Ask;
use framewright::frame::plan::Plan;
use framewright::pipeline::Run;
use framewright::sim::{SimOptions, Simulation};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(clap::Args)]
pub struct AnnotateArgs {
    /// The IFC model (IFC4 or IFC4X3).
    pub model: PathBuf,
    #[command(flatten)]
    pub inputs: ReasoningInputs,
    /// Simulate the walls first and write the framing and nailing verdicts too.
    #[arg(long)]
    pub simulate: bool,
    /// With --simulate: only this wall (id or name); repeat for more.
    #[arg(long = "wall", value_name = "W", requires = "simulate")]
    pub walls: Vec<String>,
    /// Date of the work schedule (ISO 8601, e.g. 2026-03-01T08:00:00); default: the
    /// model header's time stamp.
    #[arg(long, value_name = "DATE")]
    pub date: Option<String>,
    /// Length of the nails written as fasteners, millimetres.
    #[arg(long, value_name = "MM", default_value_t = 90.0)]
    pub nail_length: f64,
    /// Shank diameter of the nails, millimetres.
    #[arg(long, value_name = "MM", default_value_t = 3.3)]
    pub nail_diameter: f64,
    /// The annotated model to write (written whole or not at all).
    #[arg(short, long, value_name = "OUT.ifc")]
    pub output: PathBuf,
}

pub fn run(args: AnnotateArgs) -> CmdResult {
    let inputs = &args.inputs;
    let engine = rule_base(&inputs.rules_dir);
    let (model, plan, verdicts) = if args.simulate {
        inputs.tolerance_for_executor(
            "leave out --simulate to annotate the plan with this tolerance",
        )?;
        let (model, cell, _) = load_model_facts(&args.model, inputs)?;
        let options = SimOptions {
            walls: args.walls.clone(),
            engine: engine.clone(),
            ..super::sim_defaults()?
        };
        let (sim, _) = Run::new(&model, &cell, &options)
            .limits(super::rule_limits()?)
            .simulate()?;
        let verdicts = element_verdicts(&sim)?;
        // The model's own walls, each with its panels (the simulation's plan has one wall per
        // panel, of pieces partly not in the model).
        let Simulation {
            plan, model_plan, ..
        } = sim;
        (model, model_plan.unwrap_or(plan), Some(verdicts))
    } else {
        let (model, cell, facts) = load_model_facts(&args.model, inputs)?;
        let reasoned = Ask::new(&engine)
            .within(super::rule_limits()?)
            .placed(facts, &cell)?;
        let plan = Plan::from_reasoned(&model, &reasoned)?;
        (model, plan, None)
    };
    let options = AnnotateOptions {
        date: args.date.clone(),
        nail: NailSize {
            length: args.nail_length / 1000.0,
            diameter: args.nail_diameter / 1000.0,
        },
        verdicts,
    };
    let annotated = annotate(&model, &plan, &options)?;
    write_atomically(&args.output, &annotated.bytes)
        .map_err(|e| Failure::bad_input(format!("cannot write {}: {e}", args.output.display())))?;
    eprintln!(
        "{}: {} property sets, {} tasks, {} sequences, {} nails, {} panels with {} added members (entities from #{})",
        args.output.display(),
        annotated.property_sets,
        annotated.tasks,
        annotated.sequences,
        annotated.fasteners,
        annotated.panels.assemblies,
        annotated.panels.members,
        annotated.first_new_id
    );
    Ok(ExitCode::SUCCESS)
}
