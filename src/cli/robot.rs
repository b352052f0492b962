//! `framewright robot fk|ik` (being built in issue 5).
use super::{CmdResult, Failure};

#[derive(clap::Subcommand)]
pub enum RobotCommand {
    /// Forward kinematics.
    Fk { robot: String },
}

pub fn run(_cmd: RobotCommand) -> CmdResult {
    Err(Failure::bad_input("robot is not built yet"))
}
