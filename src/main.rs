//! The `framewright` command line. Each subcommand lives in `cli/<name>.rs`;
//! library errors are reported here with exit code 2 (bad input).

mod cli;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

// The rule tables make and free millions of small tuples, from several threads at once;
// mimalloc does that with less work than the system allocator. It is built without asking
// for transparent huge pages (feature `no_thp`: no madvise): faulting those in cost `plan`
// on a 49,410-member model 0.2-0.5 s more system time, varying from run to run, on a host
// whose THP setting is `madvise` (one set to `always` still gives them).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser)]
#[command(
    name = "framewright",
    version,
    about = "IFC wood-frame walls to a checked, simulated robotic assembly"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Read an IFC model and list its lumber pieces.
    Inspect(cli::inspect::InspectArgs),
    /// Infer walls, member roles, assembly order, nailing and framing targets.
    Plan(cli::plan::PlanArgs),
    /// Run or check a rule program (a subset of Soufflé's Datalog).
    #[command(subcommand)]
    Rules(cli::rules::RulesCommand),
    /// Robot kinematics: forward and inverse.
    #[command(subcommand)]
    Robot(cli::robot::RobotCommand),
    /// Write a synthetic wood-frame IFC model (the bundled examples, benchmark models).
    Synth(cli::synth::SynthArgs),
    /// Write the simulation world of a model on a cell (JSON scene or Webots world).
    World(cli::world::WorldArgs),
    /// Simulate the framing and nailing of every wall and print the verdicts.
    Simulate(cli::simulate::SimulateArgs),
    /// Simulate the model on several cells and set their figures side by side (the bid).
    Compare(cli::compare::CompareArgs),
    /// Write the simulated assembly as robot programs (ABB RAPID or KUKA KRL), per wall.
    Program(cli::program::ProgramArgs),
    /// Run user shop rules (violation/warning) over the model's relations.
    Check(cli::check::CheckArgs),
    /// Explain an element's verdicts down to IFC entities, cell keys and rules.
    Why(cli::why::WhyArgs),
    /// Say which rule could derive a tuple and which condition failed.
    WhyNot(cli::why::WhyNotArgs),
    /// Write the plan (and with --simulate the verdicts) back into a copy of the IFC model.
    Annotate(cli::annotate::AnnotateArgs),
    /// Show or clear the per-wall result cache.
    #[command(subcommand)]
    Cache(cli::cache::CacheCommand),
    /// What an edit changed: walls, elements, roles, assembly order, verdicts.
    Diff(cli::diff::DiffArgs),
    /// Simulate a model again on every save, redoing only the walls that changed.
    Watch(cli::watch::WatchArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Inspect(args) => cli::inspect::run(args),
        Command::Plan(args) => cli::plan::run(args),
        Command::Rules(cmd) => cli::rules::run(cmd),
        Command::Robot(cmd) => cli::robot::run(cmd),
        Command::Synth(args) => cli::synth::run(args),
        Command::World(args) => cli::world::run(args),
        Command::Simulate(args) => cli::simulate::run(args),
        Command::Compare(args) => cli::compare::run(args),
        Command::Program(args) => cli::program::run(args),
        Command::Check(args) => cli::check::run(args),
        Command::Why(args) => cli::why::run_why(args),
        Command::WhyNot(args) => cli::why::run_why_not(args),
        Command::Annotate(args) => cli::annotate::run(args),
        Command::Cache(cmd) => cli::cache::run(cmd),
        Command::Diff(args) => cli::diff::run(args),
        Command::Watch(args) => cli::watch::run(args),
    };
    match result {
        Ok(code) => code,
        Err(failure) => failure.report(),
    }
}
