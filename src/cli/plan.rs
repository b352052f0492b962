//! `framewright plan MODEL.ifc [--cell C] [--json]`: walls, roles, assembly
//! order, nailing and framing targets.

use super::{CmdResult, print_stdout, write_stdout};
use framewright::cell::Cell;
use framewright::frame::cell_facts::cell_facts;
use framewright::frame::plan::Plan;
use framewright::frame::{RuleEngine, model_facts, reason};
use framewright::geom::ContactOptions;
use framewright::ifc::Model;
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
    let model = Model::open(&args.model)?;
    let cell = Cell::load(&args.cell)?;
    let contacts = ContactOptions {
        tolerance: args.contact_tolerance / 1000.0,
        ..ContactOptions::default()
    };
    let mut facts = model_facts(&model, &contacts);
    facts.extend(cell_facts(&cell));
    let engine = args
        .rules_dir
        .map_or(RuleEngine::Compiled, RuleEngine::Directory);
    let reasoned = reason(&facts, &engine, false)?;
    let report = PlanReport::new(&model, &Plan::from_reasoned(&model, &reasoned));
    if args.json {
        write_stdout(|out| report.write_json(&mut &mut *out))
    } else {
        print_stdout(&report.to_text())
    }
}
