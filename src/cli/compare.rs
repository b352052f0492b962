//! `framewright compare MODEL.ifc --cell A --cell B … [--json] [--report DIR]`: the bid
//! table. Each cell simulates the model as `simulate --cell C` would (through the cache), and
//! their figures are set side by side.

use super::cache::{CacheArgs, warn_if_unwritable};
use super::check::load_cell;
use super::simulate::{Bars, simulate_through};
use super::{CmdResult, Failure, leave_to_exit, print_stdout, write_stdout};
use framewright::cache::Need;
use framewright::report::bid::{Bid, table_text};
use framewright::report::bid_html::compare_page;
use framewright::report::html::write_folder;
use framewright::report::simulate::SimReport;
use framewright::sim::SimOptions;
use serde::Serialize;
use std::collections::BTreeSet;
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct CompareArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// A cell to compare: a built-in name (study-abb, study-abb-track, study-kuka) or a TOML
    /// file. Repeat for each cell, in the order the table lists them.
    #[arg(long = "cell", value_name = "C", required = true)]
    pub cells: Vec<String>,
    /// Print JSON instead of the table.
    #[arg(long)]
    pub json: bool,
    /// Also write a report folder: index.html (the table side by side, the time per panel on
    /// each cell, each cell's failures by cause and root causes) and compare.json.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// Compare only this wall (id or name); repeat for more.
    #[arg(long = "wall", value_name = "W")]
    pub walls: Vec<String>,
    /// Replace the built-in rule base with every .dl file of this directory.
    #[arg(long, value_name = "DIR")]
    pub rules_dir: Option<PathBuf>,
    #[command(flatten)]
    pub panels: super::check::PanelsArg,
    #[command(flatten)]
    pub cache: CacheArgs,
}

/// `compare --json`.
#[derive(Serialize)]
struct Comparison<'a> {
    schema: &'static str,
    model: &'a str,
    cells: &'a [Bid],
}

pub fn run(args: CompareArgs) -> CmdResult {
    let mut seen = BTreeSet::new();
    if let Some(twice) = args.cells.iter().find(|c| !seen.insert(c.as_str())) {
        return Err(Failure::bad_input(format!(
            "--cell {twice} is given twice: name each cell once"
        )));
    }
    // Every cell is checked before any simulation runs.
    let mut cells = Vec::new();
    for name in &args.cells {
        let mut cell = load_cell(name, None)?;
        cell.panel_mode = args.panels.panels;
        cells.push(cell);
    }
    let model = super::open_model(&args.model)?;
    let name = super::diff::file_name(&args.model);
    let options = SimOptions {
        walls: args.walls,
        engine: super::check::rule_base(&args.rules_dir),
        ..super::sim_defaults()?
    };
    let cache = args.cache.open();
    let mut bids = Vec::new();
    let mut reports = Vec::new();
    for cell in &cells {
        let bars = Bars::new();
        let progress =
            |wall: &str, done, total| bars.update(&format!("{} {wall}", cell.name), done, total);
        let (sim, _) = simulate_through(
            Need::Records,
            &model,
            &name,
            cell,
            &options,
            cache.as_ref(),
            &progress,
        )?;
        bars.finish();
        let report = SimReport::new(&sim, options.dt)?;
        bids.push(Bid::new(&sim, &report, cell)?);
        reports.push(report);
        // Each cell's simulation goes once its figures are taken: the peak memory stays one
        // cell's, not the sum of all.
        drop(sim);
    }
    warn_if_unwritable(cache.as_ref());
    let comparison = Comparison {
        schema: "framewright.compare/1",
        model: &name,
        cells: &bids,
    };
    let json = serde_json::to_string_pretty(&comparison)
        .map_err(|e| Failure::bad_input(format!("cannot write the comparison as JSON: {e}")))?;
    if let Some(dir) = &args.report {
        let report_refs: Vec<&SimReport> = reports.iter().collect();
        let files = vec![
            (
                "index.html".to_string(),
                compare_page(&name, &bids, &report_refs).into_bytes(),
            ),
            ("compare.json".to_string(), format!("{json}\n").into_bytes()),
        ];
        write_folder(dir, &files).map_err(|e| {
            Failure::bad_input(format!("{}: cannot write the report: {e}", dir.display()))
        })?;
    }
    let written = if args.json {
        write_stdout(|out| writeln!(out, "{json}"))
    } else {
        print_stdout(&format!("{name}\n\n{}", table_text(&bids)))
    };
    leave_to_exit((model, reports));
    written
}
