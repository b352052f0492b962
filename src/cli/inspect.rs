//! `framewright inspect MODEL.ifc [--json]` (being built in issue 2).
use super::{CmdResult, Failure};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct InspectArgs {
    /// The IFC model (ISO 10303-21).
    pub model: PathBuf,
    /// Print JSON instead of a human summary.
    #[arg(long)]
    pub json: bool,
}

pub fn run(_args: InspectArgs) -> CmdResult {
    Err(Failure::bad_input("inspect is not built yet"))
}
