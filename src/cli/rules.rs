//! `framewright rules run|check` (being built in issue 3).
use super::{CmdResult, Failure};
use std::path::PathBuf;

#[derive(clap::Subcommand)]
pub enum RulesCommand {
    /// Check a rule program without running it.
    Check { program: PathBuf },
}

pub fn run(_cmd: RulesCommand) -> CmdResult {
    Err(Failure::bad_input("rules is not built yet"))
}
