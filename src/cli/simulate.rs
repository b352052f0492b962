//! `framewright simulate MODEL.ifc [--cell C] [--json] [--wall W]…`: runs the framing and
//! nailing of every wall in the physics simulation and prints the verdicts.

use super::cache::{CacheArgs, warn_if_unwritable};
use super::check::{load_cell, rules_in_force};
use super::{CmdResult, Failure, leave_to_exit, print_stdout, write_stdout};
use framewright::cache::{Cache, CacheCounts, Need, Shard};
use framewright::cell::Cell;
use framewright::ifc::Model;
use framewright::pipeline::Run;
use framewright::report::bid::Bid;
use framewright::report::html::{ReportInput, write_report};
use framewright::report::simulate::SimReport;
use framewright::sim::{SimOptions, Simulation, Stepping};
use framewright::user_rules::UserRules;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::Mutex;

#[derive(clap::Args)]
pub struct SimulateArgs {
    /// The IFC model.
    pub model: PathBuf,
    /// The robot cell: a built-in name (study-abb, study-kuka, study-abb-track, framing-line) or a TOML file.
    #[arg(long, default_value = "study-abb")]
    pub cell: String,
    /// Print JSON instead of the tables.
    #[arg(long)]
    pub json: bool,
    /// Also write a report folder: index.html (tables, drawings, timeline), scene.glb (the
    /// animated run; one per wall when there are several) and simulate.json.
    #[arg(long, value_name = "DIR")]
    pub report: Option<PathBuf>,
    /// List every failed element, nail and contact, and each root cause's consequences
    /// (without it: the table and the root causes with their counts).
    #[arg(long, short = 'v')]
    pub verbose: bool,
    /// Simulate only this wall (id or name); repeat for more.
    #[arg(long = "wall", value_name = "W")]
    pub walls: Vec<String>,
    /// Replace the built-in rule base with every .dl file of this directory.
    #[arg(long, value_name = "DIR")]
    pub rules_dir: Option<PathBuf>,
    /// Your rule file (violation/warning rules, see docs/RULES.md) run over the built-in and
    /// simulation relations; its findings join the element verdicts. Repeat for more.
    #[arg(long = "rules", value_name = "FILE.dl")]
    pub rules: Vec<PathBuf>,
    /// Physics time step, milliseconds.
    #[arg(long, value_name = "MS", default_value_t = framewright::sim::DEFAULT_DT * 1000.0)]
    pub step_ms: f64,
    /// Fraction of the cell's programmed speeds to move at (0..1].
    #[arg(long, default_value_t = 1.0)]
    pub speed: f64,
    /// When the physics steps: `events` steps only while lumber can move on its own (belts,
    /// settling, the robot touching a loose piece); `fixed` steps at every time step (slower;
    /// for comparison).
    #[arg(long, value_enum, default_value_t = Stepping::Events)]
    pub stepping: Stepping,
    /// Where walls lie along the robot's x axis, overriding the cell: metres from the base
    /// to the wall's bottom edge, or `auto` (each wall where the arm reaches most of it).
    #[arg(long, value_name = "M|auto")]
    pub offset_x: Option<String>,
    #[command(flatten)]
    pub panels: super::check::PanelsArg,
    #[command(flatten)]
    pub bcf: super::bcf::BcfArgs,
    #[command(flatten)]
    pub cache: CacheArgs,
    /// Simulate only the walls whose key falls in shard K of N and store them in the cache
    /// (for array jobs; a plain run afterwards assembles the result from the cache).
    #[arg(long, value_name = "K/N", conflicts_with = "no_cache")]
    pub shard: Option<Shard>,
}

pub fn run(args: SimulateArgs) -> CmdResult {
    let model = super::open_model(&args.model)?;
    let mut cell = load_cell(&args.cell, args.offset_x.as_deref())?;
    cell.panel_mode = args.panels.panels;
    let (engine, findings_files) = rules_in_force(&args.rules_dir, &args.rules)?;
    let options = SimOptions {
        walls: args.walls,
        dt: args.step_ms / 1000.0,
        speed: args.speed,
        stepping: args.stepping,
        engine,
        max_seconds_per_wall: super::limits::max_sim_seconds_per_wall()?,
    };
    // Read before the run, so a bad bound is refused before hours of simulation.
    let report_bound = match &args.report {
        Some(_) => super::limits::max_report_bytes()?,
        None => 0,
    };
    let user_rules = if findings_files.is_empty() {
        None
    } else {
        Some(UserRules::load(&findings_files, &options.engine)?)
    };
    let name = super::diff::file_name(&args.model);
    let bars = Bars::new();
    let progress = |wall: &str, done, total| bars.update(wall, done, total);
    let cache = args.cache.open();
    // The report animates every wall from its pose trace: the cache must hand those back too.
    let need = if args.report.is_some() {
        Need::Traces
    } else {
        Need::Records
    };
    if let Some(shard) = args.shard {
        let Some(cache) = &cache else {
            return Err(super::Failure::bad_input(
                "--shard needs a cache folder to put its walls in: give --cache DIR",
            ));
        };
        let run = Run::new(&model, &cell, &options)
            .named(&name)
            .limits(super::rule_limits()?)
            .progress(&progress)
            .shard(cache, shard)?;
        bars.finish();
        warn_if_unwritable(Some(cache));
        return super::cache::print_shard(&run, args.json);
    }
    let (sim, counts) = simulate_through(
        need,
        &model,
        &name,
        &cell,
        &options,
        cache.as_ref(),
        &progress,
    )?;
    bars.finish();
    warn_if_unwritable(cache.as_ref());
    let mut report = SimReport::new(&sim, options.dt)?;
    report.sim.cache = counts;
    if let Some(rules) = &user_rules {
        report.add_findings(&rules.evaluate(&sim.reasoned.relations)?);
    }
    args.bcf.write(&model, &sim, &report)?;
    if let Some(dir) = &args.report {
        let input = ReportInput {
            model: &model,
            model_name: &name,
            cell: &cell,
            sim: &sim,
            report: &report,
        };
        write_report(dir, &input, report_bound).map_err(|e| {
            Failure::bad_input(format!("{}: cannot write the report: {e}", dir.display()))
        })?;
    }
    let written = if args.json {
        write_stdout(|out| report.write_json(out))
    } else {
        let totals = Bid::new(&sim, &report, &cell)?.totals_text();
        print_stdout(&format!("{}{totals}", report.to_terminal(args.verbose)))
    };
    leave_to_exit((model, sim, report));
    written
}

/// Simulates through the cache when there is one (counting its hits), else afresh.
pub(super) fn simulate_through(
    need: Need,
    model: &Model,
    name: &str,
    cell: &Cell,
    options: &SimOptions,
    cache: Option<&Cache>,
    progress: &(dyn Fn(&str, usize, usize) + Sync),
) -> Result<(Simulation, Option<CacheCounts>), Failure> {
    let run = Run::new(model, cell, options)
        .named(name)
        .limits(super::rule_limits()?)
        .cache(cache)
        .need(need)
        .progress(progress);
    Ok(run.simulate()?)
}

/// One progress bar per wall on a terminal (stderr); nothing otherwise.
pub(super) struct Bars {
    multi: Option<MultiProgress>,
    bars: Mutex<BTreeMap<String, ProgressBar>>,
}

impl Bars {
    pub(super) fn new() -> Bars {
        let multi = std::io::stderr()
            .is_terminal()
            .then(|| MultiProgress::with_draw_target(ProgressDrawTarget::stderr()));
        Bars {
            multi,
            bars: Mutex::new(BTreeMap::new()),
        }
    }

    pub(super) fn update(&self, wall: &str, done: usize, total: usize) {
        let Some(multi) = &self.multi else {
            return;
        };
        let Ok(mut bars) = self.bars.lock() else {
            return;
        };
        let bar = bars.entry(wall.to_string()).or_insert_with(|| {
            let bar = multi.add(ProgressBar::new(total as u64));
            if let Ok(style) =
                ProgressStyle::with_template("{prefix:>12} {bar:30} {pos}/{len} elements")
            {
                bar.set_style(style);
            }
            bar.set_prefix(wall.chars().take(12).collect::<String>());
            bar
        });
        bar.set_position(done as u64);
    }

    pub(super) fn finish(&self) {
        if let Ok(bars) = self.bars.lock() {
            for bar in bars.values() {
                bar.finish_and_clear();
            }
        }
    }
}
