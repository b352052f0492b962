//! `framewright synth` (being built in issue 2).
use super::{CmdResult, Failure};

#[derive(clap::Args)]
pub struct SynthArgs {
    /// Which model to write.
    pub model: String,
}

pub fn run(_args: SynthArgs) -> CmdResult {
    Err(Failure::bad_input("synth is not built yet"))
}
