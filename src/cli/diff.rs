//! `framewright diff OLD.ifc NEW.ifc [--cell C] [--json]`: what an edit changed in the walls,
//! elements, roles and assembly order, and in the verdicts when the cache holds both
//! simulations (run `simulate` on each first; diff itself never simulates).

use super::cache::CacheArgs;
use super::{CmdResult, print_stdout};
use framewright::cache::Cache;
use framewright::cell::Cell;
use framewright::diff::{Version, diff};
use framewright::frame::plan::Plan;
use framewright::ifc::Model;
use framewright::pipeline::{FromCache, Run};
use framewright::report::simulate::SimReport;
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

/// A model's plan and, when the cache holds all its walls, its simulation report.
pub fn plan_and_report(
    path: &Path,
    model: &Model,
    cell: &Cell,
    cache: Option<&Cache>,
) -> Result<(Plan, Option<SimReport>), super::Failure> {
    let options = super::sim_defaults()?;
    let name = file_name(path);
    let run = Run::new(model, cell, &options).named(&name).cache(cache);
    // The plan a simulation of it would have: one wall per panel the cell builds.
    Ok(match run.limits(super::rule_limits()?).from_cache()? {
        FromCache::Whole(sim) => {
            let report = SimReport::new(&sim, options.dt)?;
            (sim.plan, Some(report))
        }
        FromCache::Missing(prepared) => (prepared.plan, None),
    })
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
    let old = super::open_model(&args.old)?;
    let new = super::open_model(&args.new)?;
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
