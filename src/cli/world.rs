//! `framewright world MODEL.ifc [--cell C] --format json|wbt -o PATH`: the simulation world of a
//! model on a cell, as a JSON scene or a Webots R2023b world. The output is written to a
//! temporary file beside PATH and renamed over it, so a failure never leaves half a file.

use super::write_atomically;
use super::{CmdResult, Failure, print_stdout};
use framewright::cell::Cell;
use framewright::pipeline::Run;
use framewright::world::{json, wbt};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum WorldFormat {
    /// The scene as JSON (framewright.world/1).
    Json,
    /// A Webots R2023b world.
    Wbt,
    /// A glTF 2.0 binary (.glb) of the cell, the robot at home and the lumber at its targets.
    Gltf,
}

#[derive(clap::Args)]
pub struct WorldArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// Built-in cell name (study-abb, study-kuka, study-abb-track, framing-line) or a cell TOML file.
    #[arg(long, default_value = "study-abb")]
    pub cell: String,
    #[arg(long, value_enum)]
    pub format: WorldFormat,
    #[command(flatten)]
    pub panels: super::check::PanelsArg,
    /// Output file (`-` for stdout).
    #[arg(short = 'o', long = "output", value_name = "PATH")]
    pub output: PathBuf,
}

pub fn run(args: WorldArgs) -> CmdResult {
    let mut cell = Cell::load(&args.cell)?;
    cell.panel_mode = args.panels.panels;
    let model = super::open_model(&args.model)?;
    let name = super::diff::file_name(&args.model);
    // The scene of the panels the cell builds.
    let options = super::sim_defaults()?;
    let run = Run::new(&model, &cell, &options).named(&name);
    let scene = run.limits(super::rule_limits()?).prepare()?.scene;
    let bytes = match args.format {
        WorldFormat::Json => json::to_json(&scene).into_bytes(),
        WorldFormat::Wbt => wbt::to_wbt(&scene).into_bytes(),
        WorldFormat::Gltf => framewright::report::glb::world_glb(&cell, &scene),
    };
    for w in &scene.warnings {
        eprintln!("warning: {w}");
    }
    if args.output == Path::new("-") {
        if matches!(args.format, WorldFormat::Gltf) {
            return Err(Failure::bad_input(
                "a glTF binary is not written to a terminal: give -o FILE.glb".to_string(),
            ));
        }
        return print_stdout(&String::from_utf8_lossy(&bytes));
    }
    write_atomically(&args.output, &bytes).map_err(|e| {
        Failure::bad_input(format!(
            "{}: cannot write the world: {e}",
            args.output.display()
        ))
    })?;
    Ok(ExitCode::SUCCESS)
}
