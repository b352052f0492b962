//! `framewright program MODEL.ifc [--cell C] --format rapid|krl --out DIR [--wall W]…`:
//! simulates the walls and writes, per wall (or panel) the simulation built, the robot
//! program of exactly the motion it ran and validated (ABB RAPID or KUKA KRL).

use super::check::load_cell;
use super::{CmdResult, leave_to_exit, print_stdout};
use framewright::pipeline::Run;
use framewright::program::{Language, programs, write_files};
use framewright::report::simulate::SimReport;
use framewright::sim::SimOptions;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct ProgramArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// The robot cell: a built-in name (study-abb, study-kuka, study-abb-track, framing-line) or a TOML file.
    #[arg(long, default_value = "study-abb")]
    pub cell: String,
    /// The controller language: `rapid` (ABB, one .mod per wall) or `krl` (KUKA, a .src and
    /// a .dat per wall).
    #[arg(long, value_enum)]
    pub format: Language,
    /// The folder to write the programs into (created if need be).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Only this wall (id or name); repeat for more.
    #[arg(long = "wall", value_name = "W")]
    pub walls: Vec<String>,
    /// Replace the built-in rule base with every .dl file of this directory.
    #[arg(long, value_name = "DIR")]
    pub rules_dir: Option<PathBuf>,
    /// Where walls lie along the robot's x axis, overriding the cell: metres from the base
    /// to the wall's bottom edge, or `auto`.
    #[arg(long, value_name = "M|auto")]
    pub offset_x: Option<String>,
    #[command(flatten)]
    pub panels: super::check::PanelsArg,
}

pub fn run(args: ProgramArgs) -> CmdResult {
    let model = super::open_model(&args.model)?;
    let mut cell = load_cell(&args.cell, args.offset_x.as_deref())?;
    cell.panel_mode = args.panels.panels;
    let options = SimOptions {
        walls: args.walls,
        engine: super::check::rule_base(&args.rules_dir),
        ..super::sim_defaults()?
    };
    let name = super::diff::file_name(&args.model);
    let (sim, _) = Run::new(&model, &cell, &options)
        .named(&name)
        .limits(super::rule_limits()?)
        .simulate()?;
    let report = SimReport::new(&sim, options.dt)?;
    // Every file is made before any is written: a bad `[io]` writes nothing.
    let walls = programs(&sim, &report, &cell, &name, args.format)?;
    let mut summary = String::new();
    for wall in &walls {
        write_files(&args.out, &wall.files)?;
        let first = &wall.files[0].file_name;
        let _ = writeln!(
            summary,
            "{}: {}",
            args.out.join(first).display(),
            wall.counts
        );
    }
    leave_to_exit((model, sim, report));
    print_stdout(&summary)
}
