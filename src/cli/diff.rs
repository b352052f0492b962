//! `framewright diff OLD.ifc NEW.ifc [--cell C] [--json]`: what an edit changed in the walls,
//! elements, roles and assembly order, and in the verdicts when the cache holds both
//! simulations (run `simulate` on each first; diff itself never simulates).

use super::cache::CacheArgs;
use super::{CmdResult, print_stdout};
use framewright::cache::{Cache, cached_simulation};
use framewright::cell::Cell;
use framewright::diff::{Version, diff};
use framewright::frame::plan::Plan;
use framewright::ifc::Model;
use framewright::report::simulate::SimReport;
use framewright::sim::{SimOptions, prepare};
use std::path::{Path, PathBuf};

#[derive(clap::Args)]
pub struct DiffArgs {
    /// The model before the edit.
    pub old: PathBuf,
    /// The model after the edit.
    pub new: PathBuf,
    /// The robot cell: a built-in name (study-abb, study-kuka, study-abb-track, framing-line) or a TOML file.
    #[arg(long, default_value = "study-abb")]
    pub cell: String,
    /// Print JSON instead of one line per change.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub panels: super::check::PanelsArg,
    #[command(flatten)]
    pub cache: CacheArgs,
}

/// `simulate`'s default options (its default time step, computed the way it computes it, so
/// the cache keys agree).
pub fn simulate_defaults() -> SimOptions {
    SimOptions {
        dt: (1000.0 / 240.0) / 1000.0,
        ..SimOptions::default()
    }
}

/// A model's plan and, when the cache holds all its walls, its simulation report.
pub fn plan_and_report(
    path: &Path,
    model: &Model,
    cell: &Cell,
    cache: Option<&Cache>,
) -> Result<(Plan, Option<SimReport>), super::Failure> {
    let options = simulate_defaults();
    if let Some(cache) = cache
        && let Some(sim) = cached_simulation(model, &file_name(path), cell, &options, cache)?
    {
        let report = SimReport::new(&sim, options.dt);
        return Ok((sim.plan, Some(report)));
    }
    // The plan a simulation of it would have: one wall per panel the cell builds.
    let prepared = prepare(model, &file_name(path), cell, &options.engine)?;
    Ok((prepared.plan, None))
}

pub fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

pub fn run(args: DiffArgs) -> CmdResult {
    let mut cell = Cell::load(&args.cell)?;
    cell.panel_mode = args.panels.panels;
    let cache = args.cache.open();
    let old = Model::open(&args.old)?;
    let new = Model::open(&args.new)?;
    let (old_plan, old_report) = plan_and_report(&args.old, &old, &cell, cache.as_ref())?;
    let (new_plan, new_report) = plan_and_report(&args.new, &new, &cell, cache.as_ref())?;
    let (old_name, new_name) = (
        args.old.display().to_string(),
        args.new.display().to_string(),
    );
    let d = diff(
        &Version {
            name: &old_name,
            model: &old,
            plan: &old_plan,
            report: old_report.as_ref(),
        },
        &Version {
            name: &new_name,
            model: &new,
            plan: &new_plan,
            report: new_report.as_ref(),
        },
    );
    if args.json {
        let text = serde_json::to_string_pretty(&d)
            .map_err(|e| super::Failure::bad_input(e.to_string()))?;
        print_stdout(&format!("{text}\n"))
    } else {
        print_stdout(&d.to_text())
    }
}
